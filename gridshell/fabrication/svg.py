"""SVG cut files, written directly (issue item 5).

One file per sheet. ``width``/``height`` in mm with a matching ``viewBox`` (1 user unit =
1 mm), y flipped so that the drawing reads as the DXF does (sheet origin at the bottom left),
coordinates written flipped (no transforms, which some laser importers ignore),
``fill="none"``, hairline strokes (0.025 mm) in pure colours: CUT ``#FF0000``, SCORE
``#0000FF``, ENGRAVE ``#00FF00`` (:mod:`gridshell.fabrication.layers`). Arcs are SVG elliptical arcs (``A``) with equal radii.
Element order as in the DXF: engrave, score, holes, outlines.
"""
from __future__ import annotations

from pathlib import Path as FsPath

import numpy as np

from gridshell.core.atomic import atomic_path

from gridshell.fabrication.layers import COLOURS
from gridshell.fabrication.params import FabParams
from gridshell.fabrication.part import Part
from gridshell.fabrication.path import Path, arc_geometry

STROKE = 0.025  # mm, a hairline


def _f(v: float) -> str:
    return f"{v:.4f}".rstrip("0").rstrip(".")


def path_data(path: Path, H: float) -> str:
    """SVG path data of a bulge path, y flipped about the sheet height ``H``."""
    V = np.column_stack([path.V[:, 0], H - path.V[:, 1]])
    n = len(V)
    d = [f"M{_f(V[0, 0])},{_f(V[0, 1])}"]
    spans = n if path.closed else n - 1
    for i in range(spans):
        j = (i + 1) % n
        b = path.B[i]
        if b == 0:
            if j == 0 and path.closed:
                continue
            d.append(f"L{_f(V[j, 0])},{_f(V[j, 1])}")
        else:
            _, r, theta = arc_geometry(path.V[i], path.V[j], b)
            large = 1 if abs(theta) > np.pi else 0
            sweep = 0 if b > 0 else 1     # counter-clockwise turns clockwise once y flips
            d.append(f"A{_f(r)},{_f(r)} 0 {large} {sweep} {_f(V[j, 0])},{_f(V[j, 1])}")
    if path.closed:
        d.append("Z")
    return " ".join(d)


def sheet_svg(parts: list[Part], sheet: tuple[float, float], params: FabParams,
              title: str = "") -> str:
    """The SVG text of one sheet."""
    W, H = sheet

    def style(layer):
        return f'fill="none" stroke="{COLOURS[layer]}" stroke-width="{STROKE}"'

    out = ['<?xml version="1.0" encoding="UTF-8"?>',
           f'<svg xmlns="http://www.w3.org/2000/svg" version="1.1" width="{_f(W)}mm" '
           f'height="{_f(H)}mm" viewBox="0 0 {_f(W)} {_f(H)}">']
    if title:
        out.append(f"<title>{title}</title>")
    out.append(f'<g id="ENGRAVE" {style("ENGRAVE")}>')
    for p in parts:
        for L in p.engrave:
            pts = " ".join(f"{_f(x)},{_f(H - y)}" for x, y in L.tolist())
            out.append(f'<polyline points="{pts}" {style("ENGRAVE")}/>')
    out.append("</g>")
    out.append(f'<g id="SCORE" {style("SCORE")}>')
    for p in parts:
        for (x1, y1), (x2, y2) in p.scores:
            out.append(f'<line x1="{_f(x1)}" y1="{_f(H - y1)}" x2="{_f(x2)}" y2="{_f(H - y2)}" '
                       f'{style("SCORE")}/>')
    out.append("</g>")
    out.append(f'<g id="CUT" {style("CUT")}>')
    for p in parts:
        for (x, y), r in zip(p.holes, p.radii):
            out.append(f'<circle cx="{_f(x)}" cy="{_f(H - y)}" r="{_f(r)}" {style("CUT")}/>')
    for p in parts:
        path = p.outline.segments(params.tolerance) if params.segments else p.outline
        out.append(f'<path d="{path_data(path, H)}" {style("CUT")}/>')
    out.append("</g>")
    out.append("</svg>")
    return "\n".join(out) + "\n"


def write_sheet_svg(path: str | FsPath, parts: list[Part], sheet: tuple[float, float],
                    params: FabParams, title: str = "") -> None:
    """Write one sheet's SVG to ``path``, atomically."""
    text = sheet_svg(parts, sheet, params, title)
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
