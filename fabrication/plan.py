"""The assembly plan (issue item 6): the net seen from its best-fitting plane, every lamella
drawn with its id at its middle, family 1 in one colour and family 3 in another; PNG and SVG
through matplotlib's Agg backend (no display, no global pyplot state).

In ``plan.svg`` the ids stay text (``<text>``, not glyph outlines), each in a group
``<g id="lamella-ID">`` anchored at the projected midpoint of the lamella's axis, so the plan
can be searched and checked."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from gridshell.atomic import atomic_path
from gridshell.net import Net, polyline_arclength

FAMILY_COLOURS = {1: "#1f77b4", 3: "#d62728"}


def plan_frame(net: Net) -> tuple[np.ndarray, np.ndarray]:
    """Centroid ``(3,)`` and the two principal directions ``(2,3)`` of the joints and axis
    points (metres): the best-fitting plane the plan looks at."""
    X = np.concatenate([net.joints] + [lam.axis for lam in net.lamellae])
    c = X.mean(axis=0)
    _, _, Vt = np.linalg.svd(X - c, full_matrices=False)
    return c, Vt[:2]


def plan_figure(net: Net, title: str = ""):
    """A matplotlib Figure of the plan."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    c, E = plan_frame(net)
    fig = Figure(figsize=(8, 8))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 1, 1)
    for lam in net.lamellae:
        P = (lam.axis - c) @ E.T
        col = FAMILY_COLOURS.get(lam.family, "k")
        ax.plot(P[:, 0], P[:, 1], color=col, lw=1.0)
        s = polyline_arclength(lam.axis)
        mid = np.array([np.interp(s[-1] / 2, s, P[:, j]) for j in range(2)])
        ax.text(mid[0], mid[1], str(lam.id), color=col, fontsize=7, ha="center", va="center",
                gid=f"lamella-{lam.id}",
                bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": col, "lw": 0.5})
    J = (net.joints - c) @ E.T
    ax.plot(J[:, 0], J[:, 1], "k.", ms=2)
    ax.set_aspect("equal")
    ax.set_xlabel("m")
    ax.set_ylabel("m")
    ax.set_title(title or "assembly plan: lamella ids (blue family 1, red family 3)")
    fig.tight_layout()
    return fig


def write_plan(path_png: str | Path, path_svg: str | Path, net: Net, title: str = "") -> None:
    """Write the plan as PNG and SVG, atomically (SVG text kept as text)."""
    import matplotlib

    fig = plan_figure(net, title)
    with atomic_path(path_png) as tmp:
        fig.savefig(tmp, format="png", dpi=150)
    with atomic_path(path_svg) as tmp, matplotlib.rc_context({"svg.fonttype": "none"}):
        fig.savefig(tmp, format="svg", metadata={"Date": None})
