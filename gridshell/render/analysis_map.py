"""The analysis picture (``analysis.png``): three maps over the target seen from above its
best-fit plane - the sign of K with the near-umbilic samples, the principal-curvature gap
``|k1 - k2| D``, and the largest patch each NCP mode admits. Plain arrays in, PNG bytes out.
"""
from __future__ import annotations

from typing import Mapping

import numpy as np

from gridshell.render.figure import png_bytes, pyplot

__all__ = ["analysis_png", "cell_corners", "plan_coordinates"]

#: outline colour of each mode's patch
_MODE_COLOURS = {"phlw": "#1b9e77", "cnc": "#d95f02", "aa": "#7570b3"}


def plan_coordinates(S: np.ndarray) -> np.ndarray:
    """``(..., 2)`` coordinates of the points ``S (..., 3)`` in their best-fit plane (the two
    largest principal axes of the points, metres; the first axis the longer)."""
    P = np.asarray(S, float).reshape(-1, 3)
    c = P.mean(0)
    _, _, Vt = np.linalg.svd(P - c, full_matrices=False)
    return ((P - c) @ Vt[:2].T).reshape(*np.shape(S)[:-1], 2)


def cell_corners(XY: np.ndarray) -> np.ndarray:
    """``(n + 1, m + 1, 2)`` corners of the cells around the ``(n, m, 2)`` sample points
    ``XY``: the mean of the four samples around each inner corner, the grid extended
    linearly by one sample on every side for the outer ones (the cells of a flat
    ``pcolormesh`` over a curved sample grid)."""
    P = np.asarray(XY, float)
    P = np.concatenate([2 * P[:1] - P[1:2], P, 2 * P[-1:] - P[-2:-1]], axis=0)
    P = np.concatenate([2 * P[:, :1] - P[:, 1:2], P, 2 * P[:, -1:] - P[:, -2:-1]], axis=1)
    return 0.25 * (P[:-1, :-1] + P[1:, :-1] + P[:-1, 1:] + P[1:, 1:])


def analysis_png(S: np.ndarray, sign: np.ndarray, gap: np.ndarray, umbilic: np.ndarray,
                 on_target: np.ndarray, rectangles: Mapping[str, tuple | None], *,
                 title: str = "", dpi: int = 100) -> bytes:
    """PNG of the maps. ``S (n, n, 3)`` samples (metres); ``sign``, ``gap`` (``|k1-k2| D``),
    ``umbilic``, ``on_target`` ``(n, n)``; ``rectangles``: mode -> ``(i0, i1, j0, j1)``
    sample ranges (inclusive) or None."""
    import matplotlib.colors as mcolors

    plt = pyplot()
    XY = plan_coordinates(S)
    C = cell_corners(XY)
    X, Y = C[..., 0], C[..., 1]
    off = ~np.asarray(on_target, bool)
    fig, axes = plt.subplots(1, 3, figsize=(15.0, 5.4), dpi=dpi, constrained_layout=True)
    s = np.ma.masked_where(off, np.asarray(sign, float))
    cmap = mcolors.ListedColormap(["#4575b4", "#dddddd", "#d73027"])
    axes[0].pcolormesh(X, Y, s, cmap=cmap, vmin=-1.5, vmax=1.5, shading="flat")
    um = np.ma.masked_where(off | ~np.asarray(umbilic, bool), np.ones_like(s))
    axes[0].pcolormesh(X, Y, um, cmap=mcolors.ListedColormap(["black"]), shading="flat")
    axes[0].set_title("K > 0 red, K < 0 blue, flat grey; near umbilic black")
    g = np.ma.masked_where(off, np.asarray(gap, float))
    im = axes[1].pcolormesh(X, Y, g, cmap="viridis", shading="flat")
    fig.colorbar(im, ax=axes[1], shrink=0.8, label="|k1 - k2| x diagonal")
    axes[1].set_title("principal-curvature gap (< 0.1: near umbilic)")
    axes[2].pcolormesh(X, Y, np.ma.masked_where(off, np.zeros_like(s)),
                       cmap=mcolors.ListedColormap(["#eeeeee"]), shading="flat")
    for mode, box in rectangles.items():
        if box is None:
            continue
        i0, i1, j0, j1 = box
        ring = np.concatenate([XY[i0, j0:j1 + 1], XY[i0:i1 + 1, j1], XY[i1, j0:j1 + 1][::-1],
                               XY[i0:i1 + 1, j0][::-1]])
        axes[2].plot(ring[:, 0], ring[:, 1], lw=2.5 if mode != "cnc" else 1.5,
                     ls="-" if mode != "cnc" else "--", color=_MODE_COLOURS.get(mode, "k"),
                     label=f"{mode.upper()} patch")
    axes[2].set_title("largest patch each NCP mode admits")
    if any(b is not None for b in rectangles.values()):
        axes[2].legend(loc="lower right", fontsize=9)
    for ax in axes:
        ax.set_aspect("equal")
        ax.set_xlabel("m")
    if title:
        fig.suptitle(title, fontsize=12)
    return png_bytes(fig)
