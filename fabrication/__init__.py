"""Fabrication: flat lamellae with joint features, nested on sheets, as DXF/SVG cut files.

Works on plain arrays and :class:`~fabrication.strip.Strip` objects; reads a design bundle
only through :mod:`gridshell.bundle` and never imports an optimizer. Lengths in millimetres.

:func:`fabricate` (and with it the nesting, shapely and, when it writes, ezdxf) is imported on
first use, so that reading the fabrication parameters (:mod:`fabrication.params`) stays cheap.
"""
from .params import FabParams, parse_scale, parse_sheet
from .strip import Strip

__all__ = ["FabParams", "Strip", "fabricate", "parse_scale", "parse_sheet"]


def __getattr__(name: str):
    if name == "fabricate":
        from .pipeline import fabricate

        return fabricate
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
