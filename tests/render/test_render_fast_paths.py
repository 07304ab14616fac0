"""The painter's one-array drawing (polygons padded to one corner count, matplotlib's array
fast path, no autoscaling, outlines as filled polygons) paints the picture that one stroked
polygon per list entry paints."""
from __future__ import annotations

import io

import numpy as np
import pytest

from gridshell.render.painter import (Camera, Painter, axis_major_order, grow_polygons,
                                      strip_faces)


def _pixels(draw) -> np.ndarray:
    from matplotlib.figure import Figure
    from PIL import Image

    fig = Figure(figsize=(4, 3), dpi=100)
    ax = fig.add_axes((0, 0, 1, 1))
    ax.set_xlim(-1.5, 1.5)      # before drawing: the painter grows polygons in pixels
    ax.set_ylim(-1.2, 1.2)
    ax.set_axis_off()
    draw(ax)
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
    # antialiasing noise along the lines: the outlines are filled rings (a black one round
    # every triangle here), not strokes; drawn without them the mean difference is ~3x
    assert np.abs(fast - ref).mean() < 1.0 and (diff > 16).mean() < 0.03

    P, face, _ = painter.sorted_polygons()
    assert P.shape[1:] == (8, 2) and len(P) == len(face) == sum(len(p) for p in painter.polys)


def test_grow_polygons_moves_every_edge_out_by_d():
    square = np.array([[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]])
    d = 0.1
    for P in (square, square[:, ::-1]):          # either orientation grows outward
        G = grow_polygons(P, d)[0]
        assert np.allclose(np.sort(G[:, 0]), [-d, -d, 1 + d, 1 + d])
        assert np.allclose(np.sort(G[:, 1]), [-d, -d, 1 + d, 1 + d])
    # a repeated corner (padding) bevels that corner: no point moves further than the miter
    padded = np.concatenate([square, square[:, -1:], square[:, -1:]], axis=1)
    G = grow_polygons(padded, d)[0]
    assert np.allclose(G[:3], grow_polygons(square, d)[0][:3])
    assert np.allclose(G[3], [-d, 1.0]) or np.allclose(G[3], [0.0, 1 + d])
    assert np.all(np.linalg.norm(G - padded[0], axis=1) <= 2 * d + 1e-12)
    # a zero-area polygon (a segment there and back) becomes a band 2 d wide
    seg = np.array([[[0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [0.0, 0.0]]])
    G = grow_polygons(seg, d)[0]
    assert np.isclose(G[:, 1].max() - G[:, 1].min(), 2 * d)


def test_grown_polygons_hide_seams_as_the_stroke_does():
    """A tilted grid of same-coloured quads: drawn grown without a line it matches the filled
    and stroked quads; filled alone it shows the seams between them."""
    from matplotlib.collections import PolyCollection

    painter = Painter(Camera(90.0, -90.0))        # looking down: screen x, y = world x, y
    g = np.linspace(-1.0, 1.0, 31)
    X, Y = np.meshgrid(g, g)
    c, s = np.cos(0.3), np.sin(0.3)
    corners = np.stack([np.stack([X[:-1, :-1], X[:-1, 1:], X[1:, 1:], X[1:, :-1]], -1),
                        np.stack([Y[:-1, :-1], Y[:-1, 1:], Y[1:, 1:], Y[1:, :-1]], -1)], -1)
    corners = corners.reshape(-1, 4, 2) @ np.array([[c, s], [-s, c]])
    Q = np.concatenate([corners, np.zeros(corners.shape[:2] + (1,))], axis=2)
    rgba = np.array([0.2, 0.4, 0.7, 1.0])
    painter.add(Q, rgba, rgba)

    def plain(ax, linewidth):
        P, face, edge = painter.sorted_polygons()
        ax.add_collection(PolyCollection(P, facecolors=face, edgecolors=edge,
                                         linewidths=linewidth))

    grown = _pixels(painter.draw)
    stroked, seams = _pixels(lambda ax: plain(ax, 0.2)), _pixels(lambda ax: plain(ax, 0.0))
    # antialiasing noise along the seams (the grown corners are mitred, the stroke's round)
    assert np.abs(grown - stroked).mean() < 0.5 and np.abs(grown - stroked).max() <= 32
    assert np.abs(seams - stroked).mean() > 3 * np.abs(grown - stroked).mean()


@pytest.mark.parametrize("tangent", [True, False])
def test_strips_faces_are_each_strips_solid_sides(tangent):
    """All strips at once: axis by axis, the quads of each side of strip_solid's section (each
    side in two halves), the same numbers as one strip at a time."""
    from gridshell.render.painter import strips_faces
    from gridshell.geometry.strips3d import strip_solid

    rng = np.random.default_rng(8)
    axes = [np.cumsum(rng.normal(size=(k, 3)), axis=0) for k in (2, 5, 17)]
    normals = [rng.normal(size=(len(a), 3)) for a in axes]
    Q, side, qn = strips_faces(axes, normals, 0.2, 0.01, tangent)
    one = [strip_faces(a, n, 0.2, 0.01, tangent) for a, n in zip(axes, normals)]
    for got, want in zip((Q, side, qn), zip(*one)):
        assert np.array_equal(got, np.concatenate(want))
    for (Qa, _, _), a, n in zip(one, axes, normals):
        V = strip_solid(a, n, 0.2, 0.01, tangent)[0].reshape(len(a), 4, 3)
        G = Qa.reshape(8, len(a) - 1, 4, 3)
        for s in range(4):
            A, B = V[:, s], V[:, (s + 1) % 4]
            M = 0.5 * (A + B)
            for g, (X, Y) in enumerate(((A, M), (M, B))):
                want = np.stack([X[:-1], Y[:-1], Y[1:], X[1:]], axis=1)
                assert np.allclose(G[2 * s + g], want, atol=1e-12)


def _padded_reference(painter: Painter, ax, linewidth: float = 0.2) -> None:
    """The drawing :meth:`Painter.draw` stands for, one padded array: every polygon padded to
    the most corners (:meth:`Painter.sorted_polygons`), grown by :func:`grow_polygons` as a
    whole, outlined ones filled and then their ring."""
    from matplotlib.collections import PathCollection
    from matplotlib.path import Path as MplPath

    P, face, edge = painter.sorted_polygons()
    M = ax.transData.get_matrix()[:2, :2]
    half_px = 0.5 * linewidth * ax.figure.dpi / 72.0
    X = P @ M.T
    out = (grow_polygons(X, 1.0) - X) @ np.linalg.inv(M).T * half_px
    paths, colours = [], []
    for p, o, f, e in zip(P, out, face, edge):
        if np.all(f == e):
            paths.append(MplPath(np.concatenate([p + o, p[:1] + o[:1]]), closed=True))
            colours.append(f)
        else:
            paths.append(MplPath(np.concatenate([p, p[:1]]), closed=True))
            colours.append(f)
            ring = np.concatenate([p + o, p[:1] + o[:1], (p - o)[::-1], p[-1:] - o[-1:]])
            loop = [MplPath.MOVETO] + [MplPath.LINETO] * (len(p) - 1) + [MplPath.CLOSEPOLY]
            paths.append(MplPath(ring, loop + loop))
            colours.append(e)
    ax.add_collection(PathCollection(paths, facecolors=colours, edgecolors="none",
                                     linewidths=0.0), autolim=False)


@pytest.mark.parametrize("dots", [8, 5, 0])
def test_painter_draw_list_by_list_paints_the_padded_array(dots):
    """Each list of polygons grown with its own corner count (the padding's notch at the last
    corner made directly: one, two or more copies) paints exactly the pixels of the padded
    array grown as a whole."""
    rng = np.random.default_rng(11)
    painter = Painter(Camera(35.0, -50.0))
    r, u, _ = painter.camera.basis()
    tri = rng.uniform(-1, 1, (40, 3, 3))
    grey = np.column_stack([rng.uniform(0.3, 1, (40, 3)), np.ones(40)])
    painter.add(tri, grey, grey)
    quad = rng.uniform(-1, 1, (50, 1, 3)) + rng.uniform(-0.2, 0.2, (50, 4, 3))
    blue = np.column_stack([rng.uniform(0.1, 0.9, (50, 3)), np.ones(50)])
    painter.add(quad, blue, blue, rng.uniform(-0.1, 0.1, 50))
    if dots:
        ring = np.linspace(0, 2 * np.pi, dots + 1)[:-1]
        J = rng.uniform(-1, 1, (12, 3))
        dot = J[:, None] + 0.06 * (np.cos(ring)[None, :, None] * r +
                                   np.sin(ring)[None, :, None] * u)
        painter.add(dot, np.array([0.1, 0.1, 0.1, 1.0]), np.array([0.0, 0.0, 0.0, 1.0]), 0.02)
    fast, ref = _pixels(painter.draw), _pixels(lambda ax: _padded_reference(painter, ax))
    assert fast.std() > 10
    assert np.array_equal(fast, ref)


def test_linear_is_the_matrix_product_bit_for_bit():
    """The growth's data <-> pixel scale: a diagonal matrix as products by its entries, the
    same numbers as numpy's stacked product; any other matrix through the product."""
    from gridshell.render.painter import _linear

    rng = np.random.default_rng(3)
    P = rng.normal(size=(500, 6, 2)) * 37.0
    D = np.diag([779.3523568869717, 779.3523568869716])
    for A in (D, np.linalg.inv(D).T, np.array([[2.0, 0.5], [-0.25, 3.0]])):
        assert np.array_equal(_linear(P, A), P @ A)


@pytest.mark.parametrize("rect", [(0.01, 0.01, 0.98, 0.91), (0.01, 0.01, 0.98, 0.98)])
def test_picture_transform_is_the_axes_transdata(rect):
    """render_ribbons draws without an axes: its data -> pixel map is the ``transData`` of an
    axes at ``rect`` with the same limits, number for number."""
    from matplotlib.figure import Figure

    from gridshell.render.ribbons import _data_to_pixels

    fig = Figure(figsize=(10.0, 7.5), dpi=100)
    lo, hi = np.array([-3.123456789, -1.2345]), np.array([4.98765, 2.718281828])
    ax = fig.add_axes(rect)
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    assert np.array_equal(_data_to_pixels(fig, rect, lo, hi).get_matrix(),
                          ax.transData.get_matrix())


def _strips_faces_by_groups(axes, normals, width, thickness, tangent):
    """strips_faces as it was written first: each of the 8 groups stacked from the frames'
    rows, the groups concatenated, then reordered axis by axis."""
    from gridshell.geometry.strips3d import strip_frames

    P, N, _, W, H = strip_frames(axes, normals, tangent)
    sizes = np.array([len(a) for a in axes], dtype=np.int64)
    w, h = 0.5 * float(width) * W, 0.5 * float(thickness) * H
    corners = [-w - h, +w - h, +w + h, -w + h]
    seg = np.ones(len(P), bool)
    seg[np.cumsum(sizes) - 1] = False
    i0 = np.flatnonzero(seg)
    i1 = i0 + 1
    nm = 0.5 * (N[i0] + N[i1])
    quads, sides = [], []
    for a in range(4):
        A, B = corners[a], corners[(a + 1) % 4]
        Mid = 0.5 * (A + B)
        for X, Y in ((A, Mid), (Mid, B)):
            quads.append(np.stack([P[i0] + X[i0], P[i0] + Y[i0], P[i1] + Y[i1], P[i1] + X[i1]],
                                  axis=1))
            sides.append(np.sum(0.25 * (X[i0] + Y[i0] + X[i1] + Y[i1]) * nm, axis=1))
    order = axis_major_order(sizes)     # (the bookkeeping, shared: not what is compared)
    return (np.concatenate(quads)[order], np.concatenate(sides)[order],
            np.tile(nm, (8, 1))[order])


@pytest.mark.parametrize("tangent", [False, True])
def test_strips_faces_written_in_place_are_the_stacked_groups_bit_for_bit(tangent):
    from gridshell.render.painter import strips_faces

    rng = np.random.default_rng(11)
    axes = [np.cumsum(rng.normal(size=(int(k), 3)) * 10.0 ** rng.integers(-3, 2), axis=0)
            for k in rng.integers(2, 120, 25)]
    normals = [rng.normal(size=a.shape) for a in axes]
    got = strips_faces(axes, normals, 0.2, 0.01, tangent)
    want = _strips_faces_by_groups(axes, normals, 0.2, 0.01, tangent)
    for x, y in zip(got, want):
        assert x.dtype == y.dtype and x.shape == y.shape and x.tobytes() == y.tobytes()


def test_picture_extent_is_the_stacked_min_and_max():
    from gridshell.render.ribbons import _extent

    rng = np.random.default_rng(2)
    polys = [rng.normal(size=(50, 4, 2)), rng.normal(size=(30, 6, 2)) * 3,
             rng.normal(size=(7, 8, 2)) - 5]
    xy = np.concatenate([p.reshape(-1, 2) for p in polys])
    lo, hi = _extent(polys)
    assert lo.tobytes() == xy.min(axis=0).tobytes() and hi.tobytes() == xy.max(axis=0).tobytes()
    polys[1][3, 2, 1] = np.nan
    lo, hi = _extent(polys)
    assert np.isnan(lo[1]) and np.isnan(hi[1]) and lo[0] == xy[:, 0].min()


def test_unit_rows_by_row_norms_are_numpys_norm_bit_for_bit():
    from gridshell.render import painter, ribbons

    rng = np.random.default_rng(9)
    for shape in [(3,), (1, 3), (2000, 3), (40, 4, 3)]:
        for scale in (1e-9, 1.0, 1e7):
            X = rng.normal(size=shape) * scale
            X.reshape(-1, 3)[:1] = 0.0                     # a zero row stays zero
            n = np.linalg.norm(X, axis=-1, keepdims=True)
            want = np.divide(X, n, out=np.zeros_like(X), where=n > 0)
            for unit in (painter._unit, ribbons._unit):
                assert unit(X).tobytes() == want.tobytes()


def test_grow_polygons_miter_cosine_is_the_summed_product():
    """_grow_parts' corner cosine written as two products and one addition: grow_polygons of
    random polygons equals the formula with numpy's sum over the last axis, bit for bit."""
    from gridshell.render.painter import _grow_parts

    rng = np.random.default_rng(4)
    P = rng.normal(size=(500, 6, 2))
    G, N, Nin = _grow_parts(P, 0.3)
    cos = np.sum(N * Nin, axis=-1, keepdims=True)
    want = P + 0.3 * (N + Nin) / np.maximum(1.0 + cos, 0.5)
    assert G.tobytes() == want.tobytes()


def _grow_parts_with_copies(P, d):
    """_grow_parts as it was written first: rolled copies of each coordinate, the normals
    stacked, the move multiplied by ``d`` whatever it is."""
    E = np.roll(P, -1, axis=1) - P
    L = np.hypot(E[..., 0], E[..., 1])[..., None]
    U = np.divide(E, L, out=np.zeros_like(E), where=L > 0)
    x, y = P[..., 0], P[..., 1]
    area2 = np.sum(x * np.roll(y, -1, axis=1) - np.roll(x, -1, axis=1) * y, axis=1)
    s = np.where(area2 >= 0, 1.0, -1.0)[:, None]
    N = np.stack([s * U[..., 1], -s * U[..., 0]], axis=-1)
    Nin = np.roll(N, 1, axis=1)
    cos = (N[..., 0] * Nin[..., 0] + N[..., 1] * Nin[..., 1])[..., None]
    return P + d * (N + Nin) / np.maximum(1.0 + cos, 0.5), N, Nin


def _grow_as_padded_with_copies(P, M, Minv_T, half_px, pad, grow):
    """_grow_as_padded as it was written first: the growth, the pixel corners and the
    polygons padded as arrays, the result closed by a concatenation."""
    from gridshell.render.painter import _linear, _padded_layout

    X = _linear(P, M.T)
    G, N, Nin = _grow_parts_with_copies(X, 1.0)
    if pad:
        last = X[:, -1:]
        moved = [G[:, :-1], last + 1.0 * Nin[:, -1:]]
        if pad >= 2:
            moved.append(last)
        G = np.concatenate(moved + [last + 1.0 * N[:, -1:]], axis=1)
        X = _padded_layout(X, pad)
    out = _linear(G - X, Minv_T) * half_px
    Pp = _padded_layout(P, pad)
    V = Pp + out if grow.all() else np.where(grow[:, None, None], Pp + out, Pp)
    return np.concatenate([V, V[:, :1]], axis=1)


@pytest.mark.parametrize("pad", [0, 1, 2, 4])
def test_grow_as_padded_in_place_is_the_padded_formula_bit_for_bit(pad):
    """The growth written into one closed output (no padded copies, no roll per coordinate,
    no product by 1): the numbers of the padded arrays' formula, bit for bit, for every
    padding, grown or not, a diagonal or a general pixel map, degenerate polygons too."""
    from gridshell.render.painter import _grow_as_padded, _grow_parts

    rng = np.random.default_rng(pad)
    for k in (3, 4, 8):
        P = rng.normal(size=(400, k, 2)) * 10.0 ** rng.integers(-3, 3, (400, 1, 1))
        P[:20, 1] = P[:20, 0]                        # a zero-length edge
        P[20:40] = P[20:40, :1]                      # a polygon that is one point
        P[40:60, 2:] = P[40:60, 1:2]                 # corners repeated at the end
        for M in (np.diag([779.3523568869717, 779.3523568869716]),
                  np.array([[512.0, 3.5], [-2.25, 498.0]])):
            Minv_T = np.linalg.inv(M).T
            for grow in (np.ones(400, bool), rng.uniform(size=400) < 0.7,
                         np.zeros(400, bool)):
                got = _grow_as_padded(P, M, Minv_T, 0.1389, pad, grow)
                want = _grow_as_padded_with_copies(P, M, Minv_T, 0.1389, pad, grow)
                assert got.shape == want.shape and got.tobytes() == want.tobytes()
        for d in (1.0, 0.3, -2.0):
            for got, want in zip(_grow_parts(P, d), _grow_parts_with_copies(P, d)):
                assert got.tobytes() == want.tobytes()


def test_outline_rings_are_each_rings_concatenation_bit_for_bit():
    """The outlines (rings round polygons whose edge colour is not their face colour) built
    in one array: each ring the vertices of its own concatenation (grown polygon, its first
    corner, the shrunk one reversed, its last corner), bit for bit, as matplotlib Paths."""
    from matplotlib.figure import Figure
    from matplotlib.path import Path as MplPath

    rng = np.random.default_rng(12)
    painter = Painter(Camera(35.0, -50.0))
    r, u, _ = painter.camera.basis()
    quad = rng.uniform(-1, 1, (30, 1, 3)) + rng.uniform(-0.2, 0.2, (30, 4, 3))
    grey = np.column_stack([rng.uniform(0.3, 1, (30, 3)), np.ones(30)])
    painter.add(quad, grey, grey)
    ring = np.linspace(0, 2 * np.pi, 9)[:-1]
    J = rng.uniform(-1, 1, (12, 3))
    dots = J[:, None] + 0.06 * (np.cos(ring)[None, :, None] * r + np.sin(ring)[None, :, None] * u)
    painter.add(dots, np.array([0.1, 0.1, 0.1, 1.0]), np.array([0.0, 0.0, 0.0, 1.0]), 0.02)
    fig = Figure(figsize=(4, 3), dpi=100)
    ax = fig.add_axes((0, 0, 1, 1))
    ax.set_xlim(-1.5, 1.5)
    ax.set_ylim(-1.2, 1.2)
    for agg_only in (True, False):
        paths = painter.collection(ax.transData, fig.dpi, 0.2, agg_only=agg_only).get_paths()
        rings = [paths[i] for i in range(len(paths)) if len(paths[i].codes) == 18]
        assert len(rings) == 12 and all(isinstance(p, MplPath) for p in rings)
        P, face, edge = painter.sorted_polygons()
        Po = P[~np.all(face == edge, axis=1)]
        M = ax.transData.get_matrix()[:2, :2]
        X = Po @ M.T
        out = (grow_polygons(X, 1.0) - X) @ np.linalg.inv(M).T * (0.5 * 0.2 * 100 / 72.0)
        for path, p, o in zip(rings, Po, out):
            want = np.concatenate([p + o, p[:1] + o[:1], (p - o)[::-1], p[-1:] - o[-1:]])
            assert path.vertices.tobytes() == want.tobytes()
