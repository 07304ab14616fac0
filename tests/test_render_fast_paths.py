"""The painter's one-array drawing (polygons padded to one corner count, matplotlib's array
fast path, no autoscaling) paints the picture that one polygon per list entry paints."""
from __future__ import annotations

import io

import numpy as np

from gridshell.render.painter import Camera, Painter, strip_faces


def _pixels(draw) -> np.ndarray:
    from matplotlib.figure import Figure
    from PIL import Image

    fig = Figure(figsize=(4, 3), dpi=100)
    ax = fig.add_axes((0, 0, 1, 1))
    draw(ax)
    ax.set_xlim(-1.5, 1.5)
    ax.set_ylim(-1.2, 1.2)
    ax.set_axis_off()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100)
    return np.asarray(Image.open(buf)).astype(int)


def _reference(painter: Painter, ax, linewidth: float = 0.2) -> None:
    """The straightforward drawing: a list of polygons of their own corner counts."""
    from matplotlib.collections import PolyCollection

    polys = [p for chunk in painter.polys for p in chunk]
    keys = np.concatenate(painter.keys)
    face, edge = np.concatenate(painter.face), np.concatenate(painter.edge)
    order = np.argsort(keys, kind="stable")
    ax.add_collection(PolyCollection([polys[i] for i in order], facecolors=face[order],
                                     edgecolors=edge[order], linewidths=linewidth))


def test_painter_draw_equals_one_polygon_at_a_time():
    rng = np.random.default_rng(5)
    painter = Painter(Camera(35.0, -50.0))
    r, u, c = painter.camera.basis()
    # triangles and quads of a surface, a strip and octagon dots, interleaved in depth
    tri = rng.uniform(-1, 1, (60, 3, 3))
    painter.add(tri, np.column_stack([rng.uniform(0.3, 1, (60, 3)), np.ones(60)]),
                np.array([0.0, 0.0, 0.0, 1.0]))
    t = np.linspace(-1, 1, 25)
    axis = np.column_stack([t, 0.4 * np.sin(3 * t), 0.2 * t])
    Q, side, qn = strip_faces(axis, np.tile([0.0, 0.0, 1.0], (25, 1)), 0.15, 0.03, False)
    painter.add_strip(Q, side, qn, np.tile([0.2, 0.4, 0.7], (len(Q), 1)),
                      np.array([0.3, 0.5, 0.8]), 0.05)
    ring = np.linspace(0, 2 * np.pi, 9)[:-1]
    J = rng.uniform(-1, 1, (15, 3))
    dots = J[:, None] + 0.05 * (np.cos(ring)[None, :, None] * r + np.sin(ring)[None, :, None] * u)
    painter.add(dots, np.array([0.1, 0.1, 0.1, 1.0]), np.array([0.0, 0.0, 0.0, 1.0]), 0.02)

    fast, ref = _pixels(painter.draw), _pixels(lambda ax: _reference(painter, ax))
    diff = np.abs(fast - ref).max(axis=2)
    assert fast.std() > 10                      # something was drawn
    assert (diff > 0).mean() < 1e-3 and diff.max() <= 64   # pixel noise at most

    P, face, _ = painter.sorted_polygons()
    assert P.shape[1:] == (8, 2) and len(P) == len(face) == sum(len(p) for p in painter.polys)
