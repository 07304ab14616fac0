"""Fabrication: flat lamellae with joint features, nested on sheets, as DXF/SVG cut files.

Works on plain arrays and :class:`~gridshell.fabrication.strip.Strip` objects; reads a design bundle
only through :mod:`gridshell.design.bundle` and never imports an optimizer. Lengths in millimetres.

:func:`fabricate` (and with it the nesting, shapely and, when it writes, ezdxf) is imported on
first use, so that reading the fabrication parameters (:mod:`gridshell.fabrication.params`) stays cheap.

May import: :mod:`gridshell.core`, :mod:`gridshell.geometry`, :mod:`gridshell.design` (the
bundle); never a pipeline, render or structure. (Before 0.2 this package was the top-level
``fabrication``; that name is kept, deprecated, for one release.)
"""
from gridshell.fabrication.params import FabParams, parse_scale, parse_sheet
from gridshell.fabrication.strip import Strip

__all__ = ["FabParams", "Strip", "fabricate", "parse_scale", "parse_sheet"]


def __getattr__(name: str):
    if name == "fabricate":
        from gridshell.fabrication.pipeline import fabricate

        return fabricate
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
