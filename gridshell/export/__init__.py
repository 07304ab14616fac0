"""Exports of a design bundle to other tools' formats (Rhino ``.3dm``: :mod:`.rhino`).

Heavy third-party modules are imported inside the functions, so importing this package is cheap.

May import: every floor below it (the pipelines included, though it uses none); never
workflow, the API or a face.
"""
from __future__ import annotations

__all__ = ["export_3dm"]


def __getattr__(name: str):
    """``export_3dm``: :func:`gridshell.export.rhino.export_3dm` itself, imported on first use."""
    if name == "export_3dm":
        from gridshell.export.rhino import export_3dm

        return export_3dm
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
