"""Inverse design of alignable lamella gridshells."""
__version__ = "0.1.0"
