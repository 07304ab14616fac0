"""A headless picture of a gridshell's elastic equilibrium over its design.

The design's lamellae are drawn as thin grey lines, the equilibrium's as lines coloured by
family, the joints as dots coloured by their distance from the design (% of the bounding-box
diagonal). Deviations too small to see are exaggerated by a stated factor. The camera and the
equal-axes framing are :mod:`gridshell.render.ribbons`'s.
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import Sequence

import numpy as np

from gridshell.core.atomic import atomic_path
from gridshell.render.ribbons import FAMILY_COLOURS, view_angles


def _fit_view(fig, ax, P: np.ndarray, fill: float = 0.92) -> None:
    """Equal axis scales around ``P (k,3)`` and the zoom that makes the projected points fill
    ``fill`` of the axes rectangle (3D axes otherwise draw into a centred square)."""
    from mpl_toolkits.mplot3d import proj3d

    _set_equal_limits(ax, P, zoom=1.0)
    ax.apply_aspect()  # the centred square that draw() would use, so transData is final
    x, y, _ = proj3d.proj_transform(P[:, 0], P[:, 1], P[:, 2], ax.get_proj())
    xy = ax.transData.transform(np.column_stack([x, y]))
    box = ax.get_position(original=True).transformed(fig.transFigure)
    cx, cy = 0.5 * (box.x0 + box.x1), 0.5 * (box.y0 + box.y1)
    dx = float(np.max(np.abs(xy[:, 0] - cx))) or 1.0
    dy = float(np.max(np.abs(xy[:, 1] - cy))) or 1.0
    zoom = fill * min(0.5 * box.width / dx, 0.5 * box.height / dy)
    _set_equal_limits(ax, P, zoom=float(np.clip(zoom, 0.2, 5.0)))


def _set_equal_limits(ax, P: np.ndarray, pad: float = 0.0, zoom: float = 1.0) -> None:
    lo, hi = P.min(axis=0), P.max(axis=0)
    span = hi - lo
    m = float(span.max()) or 1.0
    span = np.maximum(span, 0.05 * m)
    c = 0.5 * (lo + hi)
    half = 0.5 * span * (1 + 2 * pad)
    ax.set_xlim(c[0] - half[0], c[0] + half[0])
    ax.set_ylim(c[1] - half[1], c[1] + half[1])
    ax.set_zlim(c[2] - half[2], c[2] + half[2])
    ax.set_box_aspect(tuple(2 * half), zoom=zoom)


def exaggeration(deviation_max_pct: float, visible_pct: float = 3.0) -> float:
    """Factor on the displacements that makes the largest one ``visible_pct`` % of the
    diagonal (1 when it already is, or when there is none)."""
    if not deviation_max_pct > 0 or deviation_max_pct >= visible_pct:
        return 1.0
    f = visible_pct / deviation_max_pct
    return float(10 ** np.floor(np.log10(f)) * (5 if f >= 5 * 10 ** np.floor(np.log10(f))
                                                 else 2 if f >= 2 * 10 ** np.floor(np.log10(f))
                                                 else 1))


def render_equilibrium(path: str | os.PathLike, design_axes: Sequence[np.ndarray],
                       eq_axes: Sequence[np.ndarray], families: Sequence[int],
                       joints: np.ndarray, eq_joints: np.ndarray, deviation: np.ndarray,
                       supports: np.ndarray | None = None, *, title: str | None = None,
                       factor: float | None = None, size: tuple[int, int] = (1100, 800),
                       dpi: int = 100) -> Path:
    """Write a PNG of the equilibrium (``eq_axes``, ``eq_joints``, metres) over the design
    (``design_axes``, ``joints``); ``deviation (n,)`` % colours the joints; ``supports`` are
    drawn as triangles; ``factor`` exaggerates the displacements (default
    :func:`exaggeration`). ``design_axes[i]`` and ``eq_axes[i]`` are the same nodes of
    lamella ``i`` in the design and at equilibrium.
    """
    from matplotlib import colormaps
    from matplotlib.colors import Normalize
    from matplotlib.figure import Figure

    J0 = np.asarray(joints, float)
    J1 = np.asarray(eq_joints, float)
    dev = np.asarray(deviation, float)
    f = exaggeration(float(dev.max(initial=0.0))) if factor is None else float(factor)
    Jx = J0 + f * (J1 - J0)
    ex_axes = [_exaggerate(a0, a1, f) for a0, a1 in zip(design_axes, eq_axes)]
    pts = np.concatenate([J0, Jx] + list(ex_axes))
    elev, azim = view_angles(pts)
    fig = Figure(figsize=(size[0] / dpi, size[1] / dpi), dpi=dpi)
    ax = fig.add_axes((0.0, 0.0, 0.88, 0.92), projection="3d")
    for a in design_axes:
        a = np.asarray(a, float)
        ax.plot(a[:, 0], a[:, 1], a[:, 2], color=(0.55, 0.55, 0.58), lw=0.8, alpha=0.7)
    for a, fam in zip(ex_axes, families):
        ax.plot(a[:, 0], a[:, 1], a[:, 2], color=FAMILY_COLOURS.get(int(fam), (0.3, 0.3, 0.3)),
                lw=1.4)
    norm = Normalize(vmin=0.0, vmax=max(float(dev.max(initial=0.0)), 1e-12))
    cmap = colormaps["viridis"]
    ax.scatter(Jx[:, 0], Jx[:, 1], Jx[:, 2], s=10, c=cmap(norm(dev)), depthshade=False)
    if supports is not None and len(supports):
        S = J0[np.asarray(supports, np.int64)]
        ax.scatter(S[:, 0], S[:, 1], S[:, 2], s=28, marker="^", color=(0.1, 0.1, 0.1),
                   depthshade=False)
    ax.view_init(elev=elev, azim=azim)
    ax.set_axis_off()
    _fit_view(fig, ax, pts, fill=0.85)
    from matplotlib.cm import ScalarMappable

    cax = fig.add_axes((0.9, 0.15, 0.02, 0.6))
    cb = fig.colorbar(ScalarMappable(norm=norm, cmap=cmap), cax=cax)
    cb.set_label("joint deviation, % of diagonal", fontsize=8)
    cb.ax.tick_params(labelsize=7)
    note = "grey: design; colour: equilibrium" + \
        (f" (displacements x{f:g})" if f != 1.0 else "") + "; triangles: supports"
    fig.text(0.01, 0.01, note, fontsize=8)
    if title:
        fig.suptitle(title, fontsize=max(6.0, min(10.0, size[0] / 60.0)))
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=dpi)
    return Path(path)


def _exaggerate(a0: np.ndarray, a1: np.ndarray, f: float) -> np.ndarray:
    """The equilibrium polyline ``a1`` with its displacement from ``a0`` (the same nodes in the
    design) scaled by ``f``."""
    a0, a1 = np.asarray(a0, float), np.asarray(a1, float)
    return a0 + f * (a1 - a0)
