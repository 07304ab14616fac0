"""A headless preview picture of a net on its surface, loops coloured by a value (e.g. Delta_a).

Plain arrays in, one PNG out; matplotlib's Agg backend, no display needed.
"""
from __future__ import annotations

from pathlib import Path
from typing import Sequence

import numpy as np

from gridshell.core.errors import InputError

__all__ = ["net_preview"]


def net_preview(path: str | Path, V: np.ndarray, F: np.ndarray, joints: np.ndarray,
                loops: np.ndarray, axes: Sequence[np.ndarray] = (),
                values: np.ndarray | None = None, *, title: str | None = None,
                label: str = "alignability error [%]", size: tuple[float, float] = (6.4, 5.2),
                dpi: int = 110, max_faces: int = 4000) -> Path:
    """Write a PNG of the surface (light grey), the lamella axes and the net-loops coloured by
    ``values``.

    Parameters
    ----------
    path : path-like
        Output ``.png`` file (written directly; wrap in :func:`gridshell.core.atomic.atomic_path`
        or a bundle's ``extra`` for atomicity).
    V : (n, 3) float
        Surface vertices, metres.
    F : (m, 3) or (m, 4) int
        Surface faces; thinned to at most ``max_faces`` for drawing.
    joints : (p, 3) float
        Joint positions.
    loops : (q, 4) int
        Net-loops (indices into ``joints``).
    axes : list of (k_i, 3) float
        Lamella axes, drawn as thin dark lines.
    values : (q,) float, optional
        One value per loop, coloured with viridis and a colour bar labelled ``label``.
    title : str, optional

    Returns
    -------
    Path
        ``path``.
    """
    import matplotlib
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

    from gridshell.render.figure import cube_limits, png_bytes, pyplot

    plt = pyplot()

    V = np.asarray(V, float)
    F = np.asarray(F, np.int64)
    J = np.asarray(joints, float).reshape(-1, 3)
    L = np.asarray(loops, np.int64).reshape(-1, 4)
    if values is not None:
        values = np.asarray(values, float).reshape(-1)
        if len(values) != len(L):
            raise InputError(f"net_preview: {len(values)} values for {len(L)} loops")
    fig = plt.figure(figsize=size, dpi=dpi)
    ax = fig.add_subplot(projection="3d")
    Fd = F[:: max(1, int(np.ceil(len(F) / max_faces)))]
    ax.add_collection3d(Poly3DCollection(V[Fd], facecolor=(0.85, 0.85, 0.85, 0.35),
                                         edgecolor="none"))
    if len(L):
        poly = Poly3DCollection(J[L], edgecolor=(0.2, 0.2, 0.2, 0.6), linewidth=0.3)
        if values is not None:
            finite = values[np.isfinite(values)]
            vmax = float(finite.max()) if len(finite) and finite.max() > 0 else 1.0
            cmap = plt.get_cmap("viridis")
            norm = matplotlib.colors.Normalize(vmin=0.0, vmax=vmax)
            poly.set_facecolor(cmap(norm(np.nan_to_num(values))))
            sm = matplotlib.cm.ScalarMappable(norm=norm, cmap=cmap)
            fig.colorbar(sm, ax=ax, shrink=0.6, label=label)
        else:
            poly.set_facecolor((0.3, 0.5, 0.8, 0.6))
        ax.add_collection3d(poly)
    segs = [np.stack([a[:-1], a[1:]], axis=1) for a in axes if len(a) > 1]
    if segs:
        ax.add_collection3d(Line3DCollection(np.concatenate(segs), colors=(0.1, 0.1, 0.1, 0.8),
                                             linewidths=0.6))
    pts = np.concatenate([V, J]) if len(J) else V
    cube_limits(ax, pts)
    if title:
        ax.set_title(title, fontsize=9)
    path = Path(path)
    path.write_bytes(png_bytes(fig))
    return path
