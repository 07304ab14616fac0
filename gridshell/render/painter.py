"""A painter's algorithm for strips on a surface: every polygon sorted by depth in one list.

matplotlib's 3D axes sort polygons per collection and by their mean depth only, so thin strips
lying on (GG) or standing on (NCP) a surface are painted in the wrong order where the surface's
faces are larger than the strips' segments: strips on the far side of a saddle show through the
near side, strips vanish under the faces they lie on. Here the surface is opaque and each
polygon is placed by its own key:

- a **surface face**: its mean depth;
- a **strip face**: its mean depth moved by ``bias`` towards the viewer when the face lies on
  the side of the surface that faces the viewer (or in it), away from the viewer otherwise
  (``bias`` is about the size of a surface face, the depth error the mean-depth order makes
  between a strip and the face under it);

and only strip faces turned to the viewer are drawn (a closed strip hides its back faces).
The projection is orthographic, the camera given as matplotlib's ``(elev, azim)``.
"""
from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from gridshell.geometry.strips3d import strip_frames
from gridshell.geometry.vectors import unit_rows as _unit

__all__ = ["Camera", "Painter", "grow_polygons", "strip_faces", "strips_faces"]


@dataclass(frozen=True)
class Camera:
    """Orthographic camera looking along ``-dir``; ``dir`` points from the scene to the viewer,
    ``(elev, azim)`` in degrees as in matplotlib."""

    elev: float
    azim: float

    @property
    def dir(self) -> np.ndarray:
        e, a = np.radians(self.elev), np.radians(self.azim)
        return np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])

    def basis(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(right, up, towards the viewer)`` unit vectors; ``up`` is the world's z made
        orthogonal to the view (or y when looking straight down)."""
        c = self.dir
        r = np.cross([0.0, 0.0, 1.0], c)
        if np.linalg.norm(r) < 1e-9:
            r = np.array([1.0, 0.0, 0.0])
        r = _unit(r)
        return r, np.cross(c, r), c

    def project(self, P: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Screen coordinates ``(..., 2)`` and depth ``(...)`` (larger = nearer) of ``P``."""
        r, u, c = self.basis()
        P = np.asarray(P, float)
        return np.stack([P @ r, P @ u], axis=-1), P @ c


def strip_faces(axis: np.ndarray, normals: np.ndarray, width: float, thickness: float,
                tangent: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The four long sides of a strip (:func:`gridshell.geometry.strips3d.strip_solid`) as quads, each
    side split in two along its width: ``Q (8(k-1), 4, 3)``; ``side (8(k-1),)``, the signed
    distance of each quad's centre from the surface along the normal (metres; 0 for a quad in
    the surface); and that unit normal under each quad ``(8(k-1), 3)``."""
    return strips_faces([axis], [normals], width, thickness, tangent)


def strips_faces(axes: list[np.ndarray], normals: list[np.ndarray], width: float,
                 thickness: float, tangent: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`strip_faces` of every axis ``(k_i,3)`` with its normals, concatenated axis by
    axis (each axis's 8 groups of one quad per segment), in one vectorized pass."""
    P, N, _, W, H = strip_frames(axes, normals, tangent)
    sizes = np.array([len(a) for a in axes], dtype=np.int64)
    w, h = 0.5 * float(width) * W, 0.5 * float(thickness) * H
    corners = [-w - h, +w - h, +w + h, -w + h]  # strip_solid's order around the section
    seg = np.ones(len(P), bool)                  # points that start a segment of their axis
    seg[np.cumsum(sizes) - 1] = False
    i0 = np.flatnonzero(seg)
    i1 = i0 + 1
    nm = 0.5 * (N[i0] + N[i1])
    # the points and corner offsets at both ends of every segment, taken once (the same
    # numbers: an element-wise sum of rows taken is the rows taken of the sum)
    P0, P1 = P[i0], P[i1]
    C0 = [X[i0] for X in corners]
    C1 = [X[i1] for X in corners]
    quads = np.empty((8, len(i0), 4, 3))    # group-major, written in place (no stack, concat)
    sides = np.empty((8, len(i0)))
    for a in range(4):
        b = (a + 1) % 4
        M0, M1 = 0.5 * (C0[a] + C0[b]), 0.5 * (C1[a] + C1[b])
        for g, (X0, Y0, X1, Y1) in enumerate(((C0[a], M0, C1[a], M1), (M0, C0[b], M1, C1[b])),
                                             2 * a):
            q = quads[g]
            np.add(P0, X0, out=q[:, 0])
            np.add(P0, Y0, out=q[:, 1])
            np.add(P1, Y1, out=q[:, 2])
            np.add(P1, X1, out=q[:, 3])
            mid = 0.25 * (X0 + Y0 + X1 + Y1)
            sides[g] = np.sum(mid * nm, axis=1)
    order = axis_major_order(sizes)
    Q = quads.reshape(-1, 4, 3)[order]
    return Q, sides.reshape(-1)[order], np.tile(nm, (8, 1))[order]


def axis_major_order(sizes: np.ndarray) -> np.ndarray:
    """The rows of 8 group-major arrays of one row per segment of axes of ``sizes`` points
    (``(8, S)`` flattened) axis by axis instead: each axis's 8 groups in order."""
    nseg = np.asarray(sizes, dtype=np.int64) - 1
    start = np.concatenate([[0], np.cumsum(nseg)[:-1]]).astype(np.int64)
    lam = np.repeat(np.arange(len(nseg)), 8 * nseg)
    within = np.arange(len(lam)) - np.repeat(8 * start, 8 * nseg)
    g, j = within // np.repeat(nseg, 8 * nseg), within % np.repeat(nseg, 8 * nseg)
    return g * int(nseg.sum()) + start[lam] + j


@dataclass
class Painter:
    """Polygons collected with their colours and sort keys, drawn far to near."""

    camera: Camera
    polys: list[np.ndarray] = field(default_factory=list)     # (m_i, k_i, 2) screen, per add
    keys: list[np.ndarray] = field(default_factory=list)      # (m_i,)
    face: list[np.ndarray] = field(default_factory=list)      # (m_i, 4) RGBA
    edge: list[np.ndarray] = field(default_factory=list)

    def add(self, Q: np.ndarray, face_rgba: np.ndarray, edge_rgba: np.ndarray,
            bias: np.ndarray | float = 0.0) -> None:
        """Add polygons ``Q (m, k, 3)`` with colours ``(m, 4)`` and depth ``bias`` (metres,
        positive = nearer)."""
        if not len(Q):
            return
        xy, z = self.camera.project(Q)
        key = z.mean(axis=1) + np.broadcast_to(np.asarray(bias, float), (len(Q),))
        self.polys.append(xy)
        self.keys.append(key)
        self.face.append(np.broadcast_to(np.asarray(face_rgba, float), (len(Q), 4)))
        self.edge.append(np.broadcast_to(np.asarray(edge_rgba, float), (len(Q), 4)))

    def add_strip(self, Q: np.ndarray, side: np.ndarray, axis_normals: np.ndarray,
                  rgb: np.ndarray, light: np.ndarray, bias: float,
                  layer: float | np.ndarray = 0.0) -> None:
        """Strip quads of :func:`strip_faces` (``side`` from it; ``axis_normals (m,3)`` the
        surface normal under each quad): back faces dropped, faces shaded, each placed nearer
        by ``bias`` on the viewer's side of the surface, farther on the other side.

        ``layer`` (metres) orders strips that lie in the surface and cross each other (GG: two
        layers bolted at the joints): positive puts this strip on the side of the normal, i.e.
        nearer by ``layer`` where the normal faces the viewer, farther where it does not (one
        value, or one per quad)."""
        c = self.camera.dir
        n = _unit(np.cross(Q[:, 2] - Q[:, 0], Q[:, 3] - Q[:, 1]))
        keep = n @ c > 1e-9
        if not np.any(keep):
            return
        shade = 0.55 + 0.45 * np.abs(n[keep] @ light)
        face = np.column_stack([np.clip(rgb[keep] * shade[:, None], 0, 1),
                                np.ones(int(keep.sum()))])
        edge = face  # no seams between the segments
        viewer_side = np.sign(axis_normals[keep] @ c)
        s = np.sign(np.where(np.abs(side[keep]) < 1e-12, 0.0, side[keep]))
        layer = np.broadcast_to(np.asarray(layer, float), (len(Q),))[keep]
        b = np.where(s * viewer_side >= 0, bias, -bias) + layer * np.where(viewer_side >= 0, 1, -1)
        self.add(Q[keep], face, edge, b)

    def sorted_polygons(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """All polygons far to near as one array ``(m, k, 2)`` (``k`` the most corners of
        any; a polygon with fewer repeats its last corner, which draws the same shape) and
        their face and edge colours ``(m, 4)``."""
        k = max(p.shape[1] for p in self.polys)
        P = np.concatenate([_pad_to(p, k) for p in self.polys])
        order = np.argsort(np.concatenate(self.keys), kind="stable")
        return (P[order], np.concatenate(self.face)[order],
                np.concatenate(self.edge)[order])

    def draw(self, ax, linewidth: float = 0.2) -> None:
        """Paint everything, far to near, into a 2D matplotlib ``ax`` (one collection,
        :meth:`collection` through ``ax.transData``; its limits are the caller's and must be
        set before: the collection does not autoscale the axes)."""
        coll = self.collection(ax.transData, ax.figure.dpi, linewidth)
        if coll is not None:
            ax.add_collection(coll, autolim=False)

    def collection(self, transform, dpi: float, linewidth: float = 0.2, *,
                   agg_only: bool = False):
        """Everything, far to near, as one matplotlib collection in data coordinates drawn
        through ``transform`` (an affine data -> display pixels map, e.g. an axes'
        ``transData``) at ``dpi``; None when there is nothing to draw.

        ``agg_only``: for a figure that only matplotlib's Agg canvas draws, each polygon is
        handed over as a :class:`_Polygon`, which holds only what Agg reads of a path (its
        vertices, codes and simplification settings, those of the matplotlib ``Path`` it
        stands for), made in a fraction of the time of a ``Path``; the same pixels. Otherwise
        (any backend: some call ``Path`` methods) as matplotlib ``Path`` objects. A collection
        of one path is always made of ``Path`` objects (matplotlib then measures it).

        Each polygon is outlined by a line ``linewidth`` points wide in its edge colour, drawn
        as fills only (Agg's stroke takes as long as the fills; offsets by
        :func:`grow_polygons` in display pixels at the axes' limits and the figure's dpi): a
        polygon whose edge colour is its face colour (no seams between neighbours) is grown
        by half the line width; any other is filled, then its outline is filled as the ring
        between it grown and shrunk by half the line width. The covered areas are those of a
        fill and a stroke.

        The shapes are those of :meth:`sorted_polygons` (a polygon with fewer corners than the
        most is padded by repeating its last corner, which the growth turns into a notch at
        that corner: :func:`grow_polygons`), computed and drawn list by list of
        :meth:`add` with each list's own corner count (:func:`_grow_as_padded`): the same
        vertices without the repeated points (six corners for a surface or strip quad instead of
        eight when the joint dots have eight).
        """
        from matplotlib.collections import PathCollection

        if not self.polys:
            return None
        kmax = max(p.shape[1] for p in self.polys)
        order = np.argsort(np.concatenate(self.keys), kind="stable")
        face = np.concatenate(self.face)[order]
        edge = np.concatenate(self.edge)[order]
        outlined = ~np.all(face == edge, axis=1) if linewidth > 0 else np.zeros(len(face), bool)
        sizes = [len(p) for p in self.polys]
        starts = np.concatenate([[0], np.cumsum(sizes)[:-1]])
        chunk = np.repeat(np.arange(len(sizes)), sizes)[order]   # list of each drawn polygon
        local = order - starts[chunk]                             # its index in that list
        out_of = np.empty(len(order), bool)
        out_of[order] = outlined                                  # outlined, in list order
        M = Minv_T = None
        half_px = 0.0
        if linewidth > 0:
            M = transform.get_matrix()[:2, :2]   # data -> display pixels (linear axes)
            Minv_T = np.linalg.inv(M).T
            half_px = 0.5 * float(linewidth) * float(dpi) / 72.0
        sources = self._sources(kmax, starts, out_of, M, Minv_T, half_px)
        special: list[Any] = []
        if np.any(outlined):
            special, chunk, local, face = self._outlines(outlined, chunk, local, face, edge,
                                                         kmax, M, Minv_T, half_px)
        light = agg_only and len(chunk) > 1 and transform.is_affine
        paths = (_LightPolygonPaths if light else _PolygonPaths)(sources, chunk, local, special)
        coll = PathCollection(paths, facecolors=face, edgecolors="none", linewidths=0.0)
        coll.set_transform(transform)
        return coll

    def _sources(self, kmax: int, starts: np.ndarray, out_of: np.ndarray, M, Minv_T,
                 half_px: float) -> list[tuple[np.ndarray, type]]:
        """Per list of :meth:`add`: its polygons' closed vertices (data coordinates; grown by
        ``half_px`` display pixels where not ``out_of`` when ``M`` is given, else only padded)
        and the :func:`_polygon_type` a ``Path`` of them would have (the rcParams now)."""
        from matplotlib.path import Path as MplPath

        sources = []
        for P, s0 in zip(self.polys, starts):
            pad = kmax - P.shape[1]
            if M is not None:       # closed: the first corner again at the end
                V = _grow_as_padded(P, M, Minv_T, half_px, pad,
                                    ~out_of[s0:s0 + len(P)])
            else:
                V = _padded_layout(P, pad)
                V = np.concatenate([V, V[:, :1]], axis=1)
            # what a Path of these vertices would say (the rcParams now): one for all rows
            template = MplPath(V[0], closed=True)
            sources.append((V, _polygon_type(len(template.codes), template.should_simplify,
                                             template.simplify_threshold)))
        return sources

    def _outlines(self, outlined: np.ndarray, chunk: np.ndarray, local: np.ndarray,
                  face: np.ndarray, edge: np.ndarray, kmax: int, M: np.ndarray,
                  Minv_T: np.ndarray, half_px: float):
        """The outline rings (matplotlib ``Path``: the polygon grown by ``half_px`` display
        pixels and, reversed as a hole, shrunk by as much) of the ``outlined`` polygons, each
        drawn right after its polygon: the rings, and the drawn order's ``chunk`` / ``local``
        (a ring: chunk -1, its index in the rings) and face colours (a ring: the edge's)."""
        from matplotlib.path import Path as MplPath

        copies = np.where(outlined, 2, 1)
        idx = np.repeat(np.arange(len(chunk)), copies)
        ring = np.zeros(len(idx), bool)    # the outline after an outlined polygon
        ring[np.cumsum(copies)[outlined] - 1] = True
        # the outlined polygons padded, as the growth defines them
        Po = np.empty((int(outlined.sum()), kmax, 2))
        ch, lo = chunk[outlined], local[outlined]
        for c, P in enumerate(self.polys):
            sel = ch == c
            if sel.any():
                Po[sel] = _pad_to(P[lo[sel]], kmax)
        X = Po @ M.T
        out = (grow_polygons(X, 1.0) - X) @ Minv_T * half_px   # outward
        loop = [MplPath.MOVETO] + [MplPath.LINETO] * (kmax - 1) + [MplPath.CLOSEPOLY]
        ring_codes = np.array(loop + loop, dtype=MplPath.code_type)
        # each outline: the grown polygon and, reversed, the shrunk one (a hole), all
        # rings in one array (the numbers of each ring's own concatenation)
        grown, shrunk = Po + out, Po - out
        R = np.empty((len(Po), 2 * kmax + 2, 2))
        R[:, :kmax], R[:, kmax] = grown, grown[:, 0]
        R[:, kmax + 1:-1], R[:, -1] = shrunk[:, ::-1], shrunk[:, -1]
        special = [MplPath(r, ring_codes) for r in R]
        chunk, local = chunk[idx], local[idx]
        chunk[ring], local[ring] = -1, np.arange(len(special))
        return special, chunk, local, np.where(ring[:, None], edge[idx], face[idx])


def _pad_to(P: np.ndarray, k: int) -> np.ndarray:
    """Polygons ``P (m, k_P, 2)`` with ``k_P <= k`` corners as ``(m, k, 2)``, the last corner
    repeated."""
    return P if P.shape[1] == k else np.concatenate(
        [P, np.repeat(P[:, -1:], k - P.shape[1], axis=1)], axis=1)


def _padded_layout(P: np.ndarray, pad: int) -> np.ndarray:
    """Polygons ``P (m, k, 2)`` as :meth:`Painter.sorted_polygons` pads them with ``pad``
    copies of the last corner, keeping at most two copies (more draw the same)."""
    return _pad_to(P, P.shape[1] + min(pad, 2))


def _grow_as_padded(P: np.ndarray, M: np.ndarray, Minv_T: np.ndarray, half_px: float,
                    pad: int, grow: np.ndarray) -> np.ndarray:
    """The polygons ``P (m, k, 2)`` (data coordinates) padded with ``pad`` copies of their
    last corner and those where ``grow (m,)`` grown by ``half_px`` display pixels (``M`` the
    linear data -> pixel map, ``Minv_T`` its inverse transposed), as :func:`grow_polygons`
    grows the padded polygons, the same numbers with at most two copies of the last corner:
    padded, the last corner moves along the edge before it only, its last copy along the
    closing edge only and copies between stay (:func:`_padded_layout` order); closed, i.e.
    with the first corner again at the end ``(m, k + min(pad, 2) + 1, 2)``.

    Each number is that of the padded arrays' formula ``Pp + (G - Xp) Minv_T half_px`` (``G``
    the padded growth, ``Xp`` the padded pixel corners), computed in place into the one
    output (no padded copies of ``G``, ``X`` and ``P``, no closing copy)."""
    m, k = P.shape[:2]
    kk = k + min(pad, 2)
    X = _linear(P, M.T)
    G, N, Nin = _grow_parts(X, 1.0)
    D = np.empty((m, kk, 2))                 # G - Xp
    np.subtract(G, X, out=D[:, :k])
    if pad:
        last = X[:, -1:]
        np.subtract(last + Nin[:, -1:], last, out=D[:, k - 1:k])
        if pad >= 2:
            np.subtract(last, last, out=D[:, k:k + 1])
        np.subtract(last + N[:, -1:], last, out=D[:, kk - 1:kk])
    if Minv_T[0, 1] == 0.0 and Minv_T[1, 0] == 0.0:     # _linear, in place
        np.multiply(D, np.diag(Minv_T), out=D)
    else:
        D = D @ Minv_T
    D *= half_px
    V = np.empty((m, kk + 1, 2))
    np.add(P, D[:, :k], out=V[:, :k])        # Pp + out
    np.add(P[:, -1:], D[:, k:], out=V[:, k:kk])
    if not grow.all():
        keep = ~grow
        V[keep, :k] = P[keep]
        V[keep, k:kk] = P[keep, -1:]
    V[:, kk] = V[:, 0]
    return V


def _linear(P: np.ndarray, A: np.ndarray) -> np.ndarray:
    """``P @ A`` for points ``P (..., 2)`` and a ``(2, 2)`` matrix ``A``: when ``A`` is diagonal
    (the axes' data -> pixel scale) the product of each coordinate by its diagonal entry, the
    same numbers (the other term is a product by zero) without numpy's stacked product of
    many 2 x 2 ones (~2 ms for 35k quads)."""
    if A[0, 1] == 0.0 and A[1, 0] == 0.0:
        return P * np.diag(A)
    return P @ A


def _grow_parts(P: np.ndarray, d: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`grow_polygons` of ``P (m, k, 2)`` and the outward unit normals of the edge out
    of each corner and of the edge into it ``(m, k, 2)``."""
    P = np.asarray(P, float)
    Pn = np.roll(P, -1, axis=1)                         # corner i + 1 at i
    E = Pn - P                                          # edge i runs from corner i to i + 1
    L = np.hypot(E[..., 0], E[..., 1])[..., None]
    U = np.divide(E, L, out=np.zeros_like(E), where=L > 0)
    x, y = P[..., 0], P[..., 1]
    area2 = np.sum(x * Pn[..., 1] - Pn[..., 0] * y, axis=1)
    s = np.where(area2 >= 0, 1.0, -1.0)[:, None]
    N = np.empty_like(U)                                # outward normal of edge i
    np.multiply(s, U[..., 1], out=N[..., 0])
    np.multiply(-s, U[..., 0], out=N[..., 1])
    Nin = np.roll(N, 1, axis=1)                              # of the edge into corner i
    # np.sum(N * Nin, axis=-1) written out: a sum of two terms is one addition either way
    cos = (N[..., 0] * Nin[..., 0] + N[..., 1] * Nin[..., 1])[..., None]
    move = N + Nin
    if d != 1.0:                      # (a product by 1 is the number itself)
        move = d * move
    return P + move / np.maximum(1.0 + cos, 0.5), N, Nin


def grow_polygons(P: np.ndarray, d: float) -> np.ndarray:
    """Polygons ``P (m, k, 2)`` moved outward by ``d`` (same units) along their edges' normals:
    each corner on the miter of its two edges (at most ``2 d`` from it, so a spike does not
    shoot out). A corner repeated (the padding of :meth:`Painter.sorted_polygons`) is cut:
    its first copy moves along the edge before it, its last along the edge after it, copies
    between stay in place (a notch of at most ``d``). A polygon of zero area becomes a band
    ``2 d`` wide, as a stroke of width ``2 d`` draws it."""
    return _grow_parts(P, d)[0]


class _Polygon:
    """A closed polygon as matplotlib's Agg renderer reads a path of a collection: the
    attributes ``vertices`` (``(n, 2)`` float, the collection's data coordinates), ``codes``,
    ``should_simplify`` and ``simplify_threshold`` (those of the matplotlib ``Path`` it stands
    for; the last three per subclass, :func:`_polygon_type`), nothing else: no ``Path``
    method can be called on it. Only for a collection that only Agg draws
    (:meth:`Painter.collection` with ``agg_only``)."""

    __slots__ = ("vertices",)
    codes: np.ndarray
    should_simplify: bool
    simplify_threshold: float


@functools.lru_cache(maxsize=16)
def _polygon_type(n: int, should_simplify: bool, simplify_threshold: float) -> type:
    """The :class:`_Polygon` of ``n`` vertices (the last one closing it: the codes of a
    ``Path(..., closed=True)``, read only) with these simplification settings."""
    from matplotlib.path import Path as MplPath

    codes = np.full(n, MplPath.LINETO, dtype=MplPath.code_type)
    codes[0], codes[-1] = MplPath.MOVETO, MplPath.CLOSEPOLY
    codes.flags.writeable = False
    return type("_Polygon", (_Polygon,), {"__slots__": (), "codes": codes,
                                          "should_simplify": bool(should_simplify),
                                          "simplify_threshold": float(simplify_threshold)})


class _PolygonPaths(Sequence):
    """The paths of the drawn polygons, made one at a time when asked for (Agg converts them
    one by one): ``m`` path objects made and kept at once would cost as much again in the
    garbage collector's sweeps as in their making. Path ``i`` is polygon ``local[i]`` of
    ``sources[chunk[i]]`` (closed vertices ``(m_c, n_c, 2)`` and their :func:`_polygon_type`)
    as a matplotlib ``Path`` of those vertices and codes (:class:`_LightPolygonPaths`: as
    that :class:`_Polygon`); where ``chunk[i]`` is -1 the path ``special[local[i]]`` (the
    outlines)."""

    def __init__(self, sources: list[tuple[np.ndarray, type]], chunk: np.ndarray,
                 local: np.ndarray, special: list[Any]) -> None:
        from matplotlib.path import Path as MplPath

        self._sources = sources
        self._chunk = chunk.tolist()
        self._local = local.tolist()
        self._special = special
        self._path = MplPath

    def __len__(self) -> int:
        return len(self._chunk)

    def __getitem__(self, i):
        if isinstance(i, slice):
            return [self[j] for j in range(*i.indices(len(self)))]
        c = self._chunk[i]
        if c < 0:
            return self._special[self._local[i]]
        V, kind = self._sources[c]
        return self._path(V[self._local[i]], kind.codes)


class _LightPolygonPaths(_PolygonPaths):
    """:class:`_PolygonPaths` with each polygon a :class:`_Polygon` (the path of a polygon
    asked for by its index: the ~35k calls from Agg take this one test; anything else, as
    a slice or an outline, as :class:`_PolygonPaths` makes it)."""

    def __getitem__(self, i):
        c = self._chunk[i]
        if c.__class__ is int and c >= 0:
            V, kind = self._sources[c]
            p = kind()
            p.vertices = V[self._local[i]]
            return p
        return super().__getitem__(i)
