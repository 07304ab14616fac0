"""The cut-file layers and their colours, one table for DXF, SVG and the PNG previews.

Each layer has an AutoCAD Colour Index (ACI) and the same colour as a true colour (RGB), so
that CAM software reading either sees one colour per layer. No layer is ACI 7 (black on a
light background, white on a dark one): ENGRAVE is green, visible on both.
"""
from __future__ import annotations

#: layer -> (ACI, (r, g, b)); the RGB is the ACI's own colour
LAYERS: dict[str, tuple[int, tuple[int, int, int]]] = {
    "CUT": (1, (255, 0, 0)),
    "SCORE": (5, (0, 0, 255)),
    "ENGRAVE": (3, (0, 255, 0)),
}

#: layer -> the name of its colour, for people (legends, the previews' PNG description)
COLOUR_NAMES: dict[str, str] = {"CUT": "red", "SCORE": "blue", "ENGRAVE": "green"}


def hex_colour(layer: str) -> str:
    """``"#RRGGBB"`` of ``layer``."""
    r, g, b = LAYERS[layer][1]
    return f"#{r:02X}{g:02X}{b:02X}"


#: layer -> "#RRGGBB"
COLOURS: dict[str, str] = {name: hex_colour(name) for name in LAYERS}


def legend() -> str:
    """``"CUT red, SCORE blue, ENGRAVE green"``: every layer with its colour's name."""
    return ", ".join(f"{name} {COLOUR_NAMES[name]}" for name in LAYERS)
