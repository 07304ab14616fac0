"""The tool's version (written into every manifest and report)."""
__version__ = "0.1.0"
