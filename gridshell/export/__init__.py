"""Exports of a design bundle to other tools' formats (Rhino ``.3dm``: :mod:`.rhino`).

Heavy third-party modules are imported inside the functions, so importing this package is cheap.

May import: every floor below it (the pipelines included, though it uses none); never
workflow, the API or a face.
"""
from __future__ import annotations

__all__ = ["export_3dm"]


def export_3dm(bundle_dir, path, **kwargs):
    """See :func:`gridshell.export.rhino.export_3dm`."""
    from gridshell.export.rhino import export_3dm as _export

    return _export(bundle_dir, path, **kwargs)
