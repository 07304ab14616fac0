"""Fabrication: flat lamellae with joint features, nested on sheets, as DXF/SVG cut files.

Works on plain arrays and :class:`~fabrication.strip.Strip` objects; reads a design bundle
only through :mod:`gridshell.bundle` and never imports an optimizer. Lengths in millimetres.
"""
from .params import FabParams, parse_scale, parse_sheet
from .pipeline import fabricate
from .strip import Strip

__all__ = ["FabParams", "Strip", "fabricate", "parse_scale", "parse_sheet"]
