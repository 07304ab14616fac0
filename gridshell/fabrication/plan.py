"""The assembly plan (issue item 6): the net seen from its best-fitting plane, every lamella
drawn with its id on it (at its middle where the ids' boxes do not overlap, else moved along
it until they do not), family 1 in one colour and family 3 in another; PNG and SVG
through matplotlib's Agg backend (no display, no global pyplot state).

In ``plan.svg`` the ids stay text (``<text>``, not glyph outlines), each in a group
``<g id="lamella-ID">`` anchored on the lamella's projected axis, so the plan can be
searched and checked."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from gridshell.core.atomic import atomic_path
from gridshell.geometry.net import Net, polyline_arclength

FAMILY_COLOURS = {1: "#1f77b4", 3: "#d62728"}


def plan_frame(net: Net) -> tuple[np.ndarray, np.ndarray]:
    """Centroid ``(3,)`` and the two principal directions ``(2,3)`` of the joints and axis
    points (metres): the best-fitting plane the plan looks at."""
    X = np.concatenate([net.joints] + [lam.axis for lam in net.lamellae])
    c = X.mean(axis=0)
    _, _, Vt = np.linalg.svd(X - c, full_matrices=False)
    return c, Vt[:2]


#: where along its axis (fraction of the arc length) a label may go, in the order tried
LABEL_AT = (0.5, 0.42, 0.58, 0.34, 0.66, 0.26, 0.74, 0.18, 0.82, 0.46, 0.54, 0.38, 0.62,
            0.3, 0.7, 0.22, 0.78, 0.12, 0.88)
FONT_SIZE = 7
LABEL_PAD = 0.15   # of the font size, the white box around each id


def plan_figure(net: Net, title: str = ""):
    """A matplotlib Figure of the plan. Each id sits on its lamella, at the middle unless its
    box would overlap a box placed before: then at the first place along the lamella
    (:data:`LABEL_AT`) where it overlaps none (or, if there is none, overlaps least)."""
    import textwrap

    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    c, E = plan_frame(net)
    fig = Figure(figsize=(8, 8))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 1, 1)
    lines = []
    for lam in net.lamellae:
        P = (lam.axis - c) @ E.T
        col = FAMILY_COLOURS.get(lam.family, "k")
        ax.plot(P[:, 0], P[:, 1], color=col, lw=1.0)
        lines.append((lam, P, col))
    J = (net.joints - c) @ E.T
    ax.plot(J[:, 0], J[:, 1], "k.", ms=2)
    ax.set_aspect("equal")
    ax.set_xlabel("m")
    ax.set_ylabel("m")
    # one line per "; " clause, each wrapped to the figure's width: never clipped at its edges
    text = title or "assembly plan: lamella ids (blue family 1, red family 3)"
    ax.set_title("\n".join(textwrap.fill(part, 72) for part in text.split("; ")), fontsize=11)
    fig.tight_layout()
    ax.set_xlim(ax.get_xlim())      # the ids do not move the limits or the layout
    ax.set_ylim(ax.get_ylim())
    renderer = fig.canvas.get_renderer()
    pad = (LABEL_PAD * FONT_SIZE + 0.5) * fig.dpi / 72.0
    placed: list = []
    for lam, P, col in lines:
        s = polyline_arclength(lam.axis)         # along the lamella itself
        t = ax.text(0.0, 0.0, str(lam.id), color=col, fontsize=FONT_SIZE, ha="center",
                    va="center", gid=f"lamella-{lam.id}",
                    bbox={"boxstyle": f"round,pad={LABEL_PAD}", "fc": "white", "ec": col,
                          "lw": 0.5})
        best = None
        for f in LABEL_AT:
            at = [float(np.interp(f * s[-1], s, P[:, j])) for j in range(2)]
            t.set_position(at)
            box = t.get_window_extent(renderer).padded(pad)
            hit = sum(_overlap(box, b) for b in placed)
            if best is None or hit < best[0]:
                best = (hit, at, box)
            if hit == 0:
                break
        t.set_position(best[1])
        placed.append(best[2])
    return fig


def _overlap(a, b) -> float:
    """Overlap area of two matplotlib Bboxes (display units)."""
    w = min(a.x1, b.x1) - max(a.x0, b.x0)
    h = min(a.y1, b.y1) - max(a.y0, b.y0)
    return w * h if w > 0 and h > 0 else 0.0


def label_boxes(fig) -> dict[int, tuple[float, float, float, float]]:
    """``{lamella id: (x0, y0, x1, y1)}``: the box of each id label of a plan figure, in
    display units (pixels), its white frame included."""
    renderer = fig.canvas.get_renderer()
    pad = (LABEL_PAD * FONT_SIZE + 0.5) * fig.dpi / 72.0
    out = {}
    for t in fig.axes[0].texts:
        gid = t.get_gid() or ""
        if gid.startswith("lamella-"):
            b = t.get_window_extent(renderer).padded(pad)
            out[int(gid.split("-", 1)[1])] = (b.x0, b.y0, b.x1, b.y1)
    return out


def write_plan(path_png: str | Path, path_svg: str | Path, net: Net, title: str = "") -> None:
    """Write the plan as PNG and SVG, atomically (SVG text kept as text)."""
    import matplotlib

    from gridshell.fabrication.preview import PNG_LEVEL

    fig = plan_figure(net, title)
    with atomic_path(path_png) as tmp:
        fig.savefig(tmp, format="png", dpi=150, pil_kwargs={"compress_level": PNG_LEVEL})
    with atomic_path(path_svg) as tmp, matplotlib.rc_context({"svg.fonttype": "none"}):
        fig.savefig(tmp, format="svg", metadata={"Date": None})
