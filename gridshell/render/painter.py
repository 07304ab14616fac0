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

from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

import numpy as np

from ..strips3d import strip_frames

__all__ = ["Camera", "Painter", "grow_polygons", "strip_faces", "strips_faces"]


def _unit(X: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(X, axis=-1, keepdims=True)
    return np.divide(X, n, out=np.zeros_like(X), where=n > 0)


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
    """The four long sides of a strip (:func:`gridshell.strips3d.strip_solid`) as quads, each
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
    quads, sides = [], []
    for a in range(4):
        A, B = corners[a], corners[(a + 1) % 4]
        Mid = 0.5 * (A + B)
        for X, Y in ((A, Mid), (Mid, B)):
            quads.append(np.stack([P[i0] + X[i0], P[i0] + Y[i0], P[i1] + Y[i1], P[i1] + X[i1]],
                                  axis=1))
            mid = 0.25 * (X[i0] + Y[i0] + X[i1] + Y[i1])
            sides.append(np.sum(mid * nm, axis=1))
    # (8, S) group-major -> axis by axis, each axis's groups in order
    nseg = sizes - 1
    start = np.concatenate([[0], np.cumsum(nseg)[:-1]]).astype(np.int64)
    lam = np.repeat(np.arange(len(sizes)), 8 * nseg)
    within = np.arange(len(lam)) - np.repeat(8 * start, 8 * nseg)
    g, j = within // np.repeat(nseg, 8 * nseg), within % np.repeat(nseg, 8 * nseg)
    order = g * len(i0) + start[lam] + j
    Q = np.concatenate(quads)[order]
    return Q, np.concatenate(sides)[order], np.tile(nm, (8, 1))[order]


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
        P = np.concatenate([p if p.shape[1] == k else
                            np.concatenate([p, np.repeat(p[:, -1:], k - p.shape[1], axis=1)],
                                           axis=1) for p in self.polys])
        order = np.argsort(np.concatenate(self.keys), kind="stable")
        return (P[order], np.concatenate(self.face)[order],
                np.concatenate(self.edge)[order])

    def draw(self, ax, linewidth: float = 0.2) -> None:
        """Paint everything, far to near, into a 2D matplotlib ``ax`` (one collection; its
        limits are the caller's and must be set before: the collection does not autoscale
        the axes).

        Each polygon is outlined by a line ``linewidth`` points wide in its edge colour, drawn
        as fills only (Agg's stroke takes as long as the fills; offsets by
        :func:`grow_polygons` in display pixels at the axes' limits and the figure's dpi): a
        polygon whose edge colour is its face colour (no seams between neighbours) is grown
        by half the line width; any other is filled, then its outline is filled as the ring
        between it grown and shrunk by half the line width. The covered areas are those of a
        fill and a stroke.
        """
        from matplotlib.path import Path as MplPath

        if not self.polys:
            return
        P, face, edge = self.sorted_polygons()
        rings: list[tuple[int, np.ndarray]] = []
        if linewidth > 0:
            M = ax.transData.get_matrix()[:2, :2]   # data -> display pixels (linear axes)
            half_px = 0.5 * float(linewidth) * ax.figure.dpi / 72.0
            outlined = ~np.all(face == edge, axis=1)
            X = P @ M.T
            out = (grow_polygons(X, 1.0) - X) @ np.linalg.inv(M).T * half_px  # outward
            P = np.where(outlined[:, None, None], P, P + out)
            if np.any(outlined):
                copies = np.where(outlined, 2, 1)
                idx = np.repeat(np.arange(len(P)), copies)
                ring = np.zeros(len(idx), bool)    # the outline after an outlined polygon
                ring[np.cumsum(copies)[outlined] - 1] = True
                rings = [(int(j), np.concatenate([P[i] + out[i], P[i][:1] + out[i][:1],
                                                  (P[i] - out[i])[::-1],
                                                  P[i][-1:] - out[i][-1:]]))
                         for j, i in zip(np.flatnonzero(ring), idx[ring])]
                P, face = P[idx], np.where(ring[:, None], edge[idx], face[idx])
        k = P.shape[1]
        loop = [MplPath.MOVETO] + [MplPath.LINETO] * (k - 1) + [MplPath.CLOSEPOLY]
        ring_codes = np.array(loop + loop, dtype=MplPath.code_type)
        # each outline: the grown polygon and, reversed, the shrunk one (a hole)
        paths = _PolygonPaths(P, {j: MplPath(v, ring_codes) for j, v in rings})
        ax.add_collection(_array_poly_collection()(paths, facecolors=face, edgecolors="none",
                                               linewidths=0.0), autolim=False)


def grow_polygons(P: np.ndarray, d: float) -> np.ndarray:
    """Polygons ``P (m, k, 2)`` moved outward by ``d`` (same units) along their edges' normals:
    each corner on the miter of its two edges (at most ``2 d`` from it, so a spike does not
    shoot out). A corner repeated (the padding of :meth:`Painter.sorted_polygons`) is cut:
    its first copy moves along the edge before it, its last along the edge after it, copies
    between stay in place (a notch of at most ``d``). A polygon of zero area becomes a band
    ``2 d`` wide, as a stroke of width ``2 d`` draws it."""
    P = np.asarray(P, float)
    E = np.roll(P, -1, axis=1) - P                      # edge i runs from corner i to i + 1
    L = np.hypot(E[..., 0], E[..., 1])[..., None]
    U = np.divide(E, L, out=np.zeros_like(E), where=L > 0)
    x, y = P[..., 0], P[..., 1]
    area2 = np.sum(x * np.roll(y, -1, axis=1) - np.roll(x, -1, axis=1) * y, axis=1)
    s = np.where(area2 >= 0, 1.0, -1.0)[:, None]
    N = np.stack([s * U[..., 1], -s * U[..., 0]], axis=-1)  # outward normal of edge i
    Nin = np.roll(N, 1, axis=1)                              # of the edge into corner i
    cos = np.sum(N * Nin, axis=-1, keepdims=True)
    return P + d * (N + Nin) / np.maximum(1.0 + cos, 0.5)


class _PolygonPaths(Sequence):
    """The closed paths of polygons ``P (m, k, 2)`` made one at a time when asked for (Agg
    converts them one by one): ``m`` matplotlib ``Path`` objects built and kept at once would
    cost as much again in the garbage collector's sweeps as in their making. ``special``
    replaces some by their index (the outlines)."""

    def __init__(self, P: np.ndarray, special: dict[int, Any]) -> None:
        from matplotlib.path import Path as MplPath

        self._verts = np.concatenate([P, P[:, :1]], axis=1)   # closed: first corner again
        self._template = MplPath(self._verts[0], closed=True)
        self._codes = self._template.codes
        self._special = special
        self._make = MplPath._fast_from_codes_and_verts  # what PolyCollection uses

    def __len__(self) -> int:
        return len(self._verts)

    def __getitem__(self, i):
        if isinstance(i, slice):
            return [self[j] for j in range(*i.indices(len(self)))]
        i = range(len(self))[i]
        if i in self._special:
            return self._special[i]
        return self._make(self._verts[i], self._codes, internals_from=self._template)


@lru_cache(maxsize=1)
def _array_poly_collection() -> type:
    """The ``PolyCollection`` class drawing a :class:`_PolygonPaths` (made on first use: this
    module does not import matplotlib)."""
    from matplotlib.collections import PolyCollection

    class ArrayPolyCollection(PolyCollection):
        """A ``PolyCollection`` drawing the paths of a :class:`_PolygonPaths`."""

        def __init__(self, paths: _PolygonPaths, **kwargs) -> None:
            super().__init__([], **kwargs)
            self._paths = paths

    return ArrayPolyCollection
