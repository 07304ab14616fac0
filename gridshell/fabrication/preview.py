"""Headless PNG previews of the cut sheets: ``sheet_NN.png`` beside ``sheet_NN.dxf`` / ``.svg``.

Drawn with matplotlib's Agg backend (no display, no global pyplot state) from the same
:class:`~gridshell.fabrication.part.Part` geometry the DXF and SVG writers take: the outline path the
writers choose (bulges, or short segments with ``--segments``), hole circles, score lines and
label strokes, each layer in its cut-file colour (CUT red, SCORE blue, ENGRAVE green) on the
sheet drawn to scale (pale fill, grey edge). A title band above the sheet gives the sheet's
name, size in mm and part count; the same title is stored in the PNG's ``Title`` text chunk.

The sheet is drawn at :data:`PX_PER_LONG_SIDE` pixels along its long side, so that the drawn
sheet has the sheet's aspect ratio (to a pixel) whatever its size; lengths in mm.
"""
from __future__ import annotations

from pathlib import Path as FsPath

import numpy as np

from gridshell.core.atomic import atomic_path

from gridshell.fabrication.params import FabParams
from gridshell.fabrication.part import Part
from gridshell.fabrication.layers import COLOURS, legend

PX_PER_LONG_SIDE = 1200   # pixels along the sheet's long side
DPI = 100
PAD_PX = 8                # white border around the sheet
TITLE_PX = 30             # band above the sheet for the title
SHEET_FILL = "#F3EFE4"    # the material
SHEET_EDGE = "#8C8C8C"
LINE_WIDTH = {"CUT": 0.7, "SCORE": 0.7, "ENGRAVE": 0.5}   # points
#: zlib level of the PNG files (lossless, the same pixels at any level): 3 encodes these
#: drawings in ~60 % of the time of PIL's default 6, files within a few per cent
PNG_LEVEL = 3


def circle_polylines(centres: np.ndarray, radii: np.ndarray, n: int = 32) -> np.ndarray:
    """Closed polylines ``(k, n+1, 2)`` of circles with ``centres (k,2)`` and ``radii (k,)``, mm."""
    a = np.linspace(0.0, 2.0 * np.pi, n + 1)
    ring = np.stack([np.cos(a), np.sin(a)], axis=1)                  # (n+1, 2)
    return (np.asarray(centres, float).reshape(-1, 1, 2)
            + np.asarray(radii, float).reshape(-1, 1, 1) * ring[None])


def layer_polylines(parts: list[Part], params: FabParams,
                    tol: float) -> dict[str, list[np.ndarray]]:
    """Polylines ``(k,2)`` (mm, sheet coordinates) per layer of ``parts``: the outline each
    writer takes (flattened to ``tol`` mm, closed), holes as circles, score lines and label
    strokes."""
    cut: list[np.ndarray] = []
    score: list[np.ndarray] = []
    engrave: list[np.ndarray] = []
    for p in parts:
        path = p.outline.segments(params.tolerance) if params.segments else p.outline
        V = path.flatten(tol)
        cut.append(np.concatenate([V, V[:1]]) if path.closed else V)
        if len(p.holes):
            cut.extend(circle_polylines(p.holes, p.radii))
        score.extend(np.asarray(p.scores, float).reshape(-1, 2, 2))
        engrave.extend(p.engrave)
    return {"ENGRAVE": engrave, "SCORE": score, "CUT": cut}


def sheet_figure(parts: list[Part], sheet: tuple[float, float], params: FabParams,
                 title: str = ""):
    """A matplotlib Figure of one sheet (see the module docstring); ``sheet`` = (W, H) mm."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.collections import LineCollection
    from matplotlib.figure import Figure
    from matplotlib.patches import Rectangle

    W, H = (float(v) for v in sheet)
    k = PX_PER_LONG_SIDE / max(W, H)                 # px per mm
    w_px, h_px = W * k, H * k
    fw, fh = w_px + 2 * PAD_PX, h_px + 2 * PAD_PX + TITLE_PX
    fig = Figure(figsize=(fw / DPI, fh / DPI), dpi=DPI, facecolor="white")
    FigureCanvasAgg(fig)
    ax = fig.add_axes((PAD_PX / fw, PAD_PX / fh, w_px / fw, h_px / fh))
    ax.set_xlim(0.0, W)
    ax.set_ylim(0.0, H)
    ax.set_axis_off()
    ax.add_patch(Rectangle((0.0, 0.0), W, H, facecolor=SHEET_FILL, edgecolor=SHEET_EDGE,
                           linewidth=0.8, clip_on=False, zorder=0))
    lines = layer_polylines(parts, params, tol=0.15 / k)     # arcs within 0.15 px
    for z, layer in enumerate(("ENGRAVE", "SCORE", "CUT"), start=1):
        if lines[layer]:
            ax.add_collection(LineCollection(lines[layer], colors=COLOURS[layer],
                                             linewidths=LINE_WIDTH[layer], zorder=z,
                                             capstyle="round", joinstyle="round"))
    if title:
        fig.text(0.5, 1.0 - 0.5 * TITLE_PX / fh, title, ha="center", va="center", fontsize=11)
    return fig


def write_sheet_png(path: str | FsPath, parts: list[Part], sheet: tuple[float, float],
                    params: FabParams, title: str = "") -> None:
    """Write one sheet's preview PNG to ``path``, atomically."""
    fig = sheet_figure(parts, sheet, params, title)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=DPI, pil_kwargs={"compress_level": PNG_LEVEL},
                    metadata={"Title": title,
                              "Description": f"cut sheet preview: {legend()}; lengths in mm"})
