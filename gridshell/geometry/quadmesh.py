"""Quad meshes (and triangle meshes for targets): the data type and its checks.

``QuadMesh`` holds ``V (n,3) float64`` (metres) and ``F (m,4) int64``; topology queries that
need a halfedge structure go through an OpenMesh ``PolyMesh`` built lazily and cached.

Mesh files are read and written by :mod:`gridshell.geometry.meshfile`.
"""
from __future__ import annotations

from functools import cached_property
from typing import Sequence

import numpy as np
import openmesh as om
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from gridshell.core.errors import MeshError

#: Mesh file formats read and written by :func:`read_mesh` / :func:`write_mesh`.
MESH_FORMATS = (".obj", ".ply", ".off")
#: Meshes above this many faces or vertices are refused (memory and solver time explode).
MAX_ELEMENTS = 5_000_000
#: A face is degenerate if its area is below ``DEGENERATE_AREA * bbox_diagonal**2``.
DEGENERATE_AREA = 1e-12
#: Bounding-box diagonals (metres) a mesh file may have: coordinates are read as metres, and a
#: gridshell (or its model) spans millimetres to kilometres. Outside this range the file is in
#: other units or corrupt, and the optimizers' tolerances lose their meaning.
EXTENT_RANGE = (1e-6, 1e6)

_FLOAT_FMT = "%.17g"  # shortest format that round-trips every float64


# --------------------------------------------------------------------------------------------
# array helpers (pure functions)
# --------------------------------------------------------------------------------------------

def _as_padded(F: np.ndarray | Sequence[Sequence[int]]) -> tuple[np.ndarray, np.ndarray]:
    """Faces as a ``(m,k)`` int64 array padded with -1, plus face sizes ``(m,)``."""
    if isinstance(F, np.ndarray) and F.dtype != object:
        if F.ndim != 2:
            raise MeshError(f"faces must be a 2D array (m, k), got shape {F.shape}; "
                            "pass one row of vertex indices per face")
        if F.size and not np.issubdtype(F.dtype, np.integer):
            if not np.all(np.isfinite(F)) or np.any(F != np.round(F)):
                raise MeshError("face indices must be integers; pass F as an int64 array")
        P = F.astype(np.int64, copy=False)
        sizes = np.full(len(P), P.shape[1], dtype=np.int64) if P.size else np.zeros(len(P), np.int64)
        if P.size and np.any(P < 0):
            sizes = (P >= 0).sum(axis=1)
        return P, sizes
    rows = [np.asarray(f, dtype=np.int64).reshape(-1) for f in F]
    sizes = np.array([len(r) for r in rows], dtype=np.int64)
    k = int(sizes.max()) if len(rows) else 0
    P = np.full((len(rows), k), -1, dtype=np.int64)
    if len(rows):
        mask = np.arange(k)[None, :] < sizes[:, None]
        P[mask] = np.concatenate(rows)
    return P, sizes


def bbox_diagonal(V: np.ndarray) -> float:
    """Length of the diagonal of the axis-aligned bounding box of ``V (n,3)``, metres."""
    V = np.asarray(V, dtype=float)
    if len(V) == 0:
        return 0.0
    if V.ndim == 2:   # column by column: max(axis=0)'s numbers without its slow row-wise loop
        hi = np.array([V[:, j].max() for j in range(V.shape[1])])
        lo = np.array([V[:, j].min() for j in range(V.shape[1])])
        return float(np.linalg.norm(hi - lo))
    return float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))


def polygon_vector_areas(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """Vector areas ``(m,3)`` of polygons ``F (m,k)`` (padded with -1): normal times area, m^2.

    Uses the shoelace sum ``1/2 sum_i v_i x v_{i+1}``; for a non-planar quad this equals
    ``1/2 (v2 - v0) x (v3 - v1)``.
    """
    V = np.asarray(V, dtype=float)
    F = np.asarray(F, dtype=np.int64)
    m, k = F.shape
    if m == 0:
        return np.zeros((0, 3))
    valid = F >= 0
    Fi = np.where(valid, F, F[:, :1])  # padding repeats the first vertex: zero contribution
    nxt = np.roll(Fi, -1, axis=1)
    # the last valid vertex must close onto the first one
    last = valid.sum(axis=1) - 1
    nxt[np.arange(m), last] = Fi[:, 0]
    nxt[~valid] = np.broadcast_to(Fi[:, :1], (m, k))[~valid]
    # np.cross(P, P_next).sum(axis=1) by coordinates, the same operations in the same order
    # (3-4x faster on the 200k faces of a big target: no (m, k, 3) temporaries)
    x, y, z = (V[:, i][Fi] for i in range(3))
    xn, yn, zn = (V[:, i][nxt] for i in range(3))
    out = np.empty((m, 3))
    for i, c in enumerate((y * zn - z * yn, z * xn - x * zn, x * yn - y * xn)):
        acc = c[:, 0].copy()
        for j in range(1, k):
            acc += c[:, j]
        out[:, i] = acc
    return 0.5 * out


def unique_ints(a: np.ndarray) -> np.ndarray:
    """``np.unique`` of an integer array (flattened), by sorting: numpy 2.4's default unique
    hashes, ~30x slower on big arrays (0.33 s against 0.01 s for the 600k edge keys of a
    200k-triangle mesh)."""
    s = np.sort(np.asarray(a).ravel())
    return s[np.r_[True, s[1:] != s[:-1]]] if len(s) else s


def _unit(X: np.ndarray) -> np.ndarray:
    """Rows of ``X`` normalized to unit length (zero rows stay zero)."""
    n = np.linalg.norm(X, axis=1, keepdims=True)
    return np.divide(X, n, out=np.zeros_like(X), where=n > 0)


def _face_edges(F: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Directed face edges of padded faces: ``src (h,)``, ``dst (h,)``, ``face (h,)``.

    Edge ``h`` goes from corner ``c`` to corner ``c+1`` of its face (cyclically).
    """
    m, k = F.shape
    valid = F >= 0
    sizes = valid.sum(axis=1)
    nxt_col = (np.arange(k)[None, :] + 1) % np.maximum(sizes[:, None], 1)
    dst = np.take_along_axis(F, nxt_col, axis=1)
    face = np.broadcast_to(np.arange(m)[:, None], (m, k))
    return F[valid], dst[valid], face[valid]


def _unique_edges(src: np.ndarray, dst: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Unique undirected edges ``(E,2)`` (sorted ``i<j``) and, per directed edge, its edge index."""
    lo, hi = np.minimum(src, dst), np.maximum(src, dst)
    key = lo * np.int64(max(n, 1)) + hi
    ukey, inv = np.unique(key, return_inverse=True)
    E = np.stack([ukey // max(n, 1), ukey % max(n, 1)], axis=1)
    return E, inv.reshape(-1)


def mesh_edges(F: np.ndarray, n_vertices: int) -> np.ndarray:
    """Unique undirected edges ``(E,2)`` int64 of faces ``F (m,k)``, rows sorted with ``i<j``."""
    P, _ = _as_padded(F)
    src, dst, _ = _face_edges(P)
    return _unique_edges(src, dst, n_vertices)[0]


def area_weighted_vertex_normals(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """Unit vertex normals ``(n,3)``: sum of incident faces' vector areas, normalized."""
    V = np.asarray(V, dtype=float)
    P, _ = _as_padded(F)
    A = polygon_vector_areas(V, P)
    N = np.zeros_like(V)
    valid = P >= 0
    rows = np.broadcast_to(np.arange(len(P))[:, None], P.shape)[valid]
    idx = P[valid]
    if len(idx) and idx.max() < len(V):
        # np.add.at(N, idx, A[rows]) by coordinates: bincount adds the same terms in the same
        # order (corner by corner, from 0), the same sums, ~4x faster
        Ar = A[rows]
        for c in range(3):
            N[:, c] = np.bincount(idx, weights=Ar[:, c], minlength=len(V))
    else:
        np.add.at(N, idx, A[rows])
    return _unit(N)


def boundary_vertices_of(F: np.ndarray, n_vertices: int) -> np.ndarray:
    """Sorted indices ``(b,)`` of vertices on an edge used by exactly one face."""
    P, _ = _as_padded(F)
    src, dst, _ = _face_edges(P)
    E, inv = _unique_edges(src, dst, n_vertices)
    count = np.bincount(inv, minlength=len(E))
    return np.unique(E[count == 1])


# --------------------------------------------------------------------------------------------
# validation
# --------------------------------------------------------------------------------------------

def validate_mesh(V: np.ndarray, F: np.ndarray | Sequence[Sequence[int]],
                  require_quads: bool = False, name: str = "mesh",
                  manifold_vertices: bool = True) -> None:
    """Raise :class:`MeshError` if ``(V, F)`` is unusable; the message names the problem and the fix.

    Parameters
    ----------
    V : (n,3) float
        Vertex positions, metres.
    F : (m,k) int or list of index sequences
        Faces; a 2D array may be padded with -1 for mixed face sizes.
    require_quads : bool
        Every face must have exactly 4 vertices.
    name : str
        Name of the mesh (e.g. its file name) used in messages.
    manifold_vertices : bool
        Reject vertices whose faces form several fans (a bow-tie). ``False`` accepts them, as
        in a net whose loops touch at a corner where a loop is missing; edges must still be
        manifold and consistently oriented.

    Raises
    ------
    MeshError
        Empty, too large, non-finite coordinates, indices out of range, not quads (if required),
        repeated vertex in a face, non-manifold edge or vertex, inconsistent orientation,
        degenerate (zero-area) face.
    """
    V = np.asarray(V)
    if V.ndim != 2 or (V.size and V.shape[1] != 3):
        raise MeshError(f"{name}: vertices must have shape (n, 3), got {V.shape}; "
                        "pass one row x, y, z per vertex")
    P, sizes = _as_padded(F)
    n, m = len(V), len(P)
    if n == 0 or m == 0:
        raise MeshError(f"{name}: the mesh is empty ({n} vertices, {m} faces); "
                        "give a mesh with at least one face")
    if n > MAX_ELEMENTS or m > MAX_ELEMENTS:
        raise MeshError(f"{name}: the mesh is too large ({n} vertices, {m} faces, limit "
                        f"{MAX_ELEMENTS}); decimate or remesh it to a coarser resolution")
    V = V.astype(float, copy=False)
    bad = ~np.isfinite(V).all(axis=1)
    if bad.any():
        raise MeshError(f"{name}: {int(bad.sum())} vertices have NaN or infinite coordinates "
                        f"(the first is vertex {int(np.flatnonzero(bad)[0])}); "
                        "fix or remove them before use")
    valid = np.arange(P.shape[1])[None, :] < sizes[:, None]
    oor = (valid & ((P < 0) | (P >= n))).any(axis=1)
    if oor.any():
        f = int(np.flatnonzero(oor)[0])
        raise MeshError(f"{name}: {int(oor.sum())} faces use vertex indices outside 0..{n - 1} "
                        f"(the first is face {f}: {P[f, valid[f]].tolist()}); "
                        "the file is corrupt or its faces refer to missing vertices")
    small = sizes < 3
    if small.any():
        f = int(np.flatnonzero(small)[0])
        raise MeshError(f"{name}: {int(small.sum())} faces have fewer than 3 vertices "
                        f"(face {f} has {int(sizes[f])}); remove them")
    if require_quads and np.any(sizes != 4):
        notq = np.flatnonzero(sizes != 4)
        f = int(notq[0])
        raise MeshError(f"{name}: {len(notq)} faces are not quads (a face of {int(sizes[f])} "
                        f"vertices is face {f}); give a quad mesh or use a triangle mesh as target")
    # repeated vertex inside a face (padding -1 sorts first and is ignored)
    S = np.sort(np.where(valid, P, -1 - np.arange(P.shape[1])[None, :]), axis=1)
    rep = (np.diff(S, axis=1) == 0).any(axis=1)
    if rep.any():
        f = int(np.flatnonzero(rep)[0])
        raise MeshError(f"{name}: {int(rep.sum())} faces are degenerate, repeating a vertex "
                        f"(the first is face {f}: {P[f, valid[f]].tolist()}); "
                        "remove them or merge the mesh properly")
    problem = _topology_problem(P, n, vertices=manifold_vertices)
    if problem is not None:
        raise MeshError(f"{name}: {problem}")
    check_face_areas(V, P, name)


def check_face_areas(V: np.ndarray, P: np.ndarray, name: str = "mesh") -> None:
    """:class:`MeshError` naming the faces of padded ``P`` with (near) zero area (below
    ``DEGENERATE_AREA * bbox_diagonal**2``)."""
    A = np.linalg.norm(polygon_vector_areas(V, P), axis=1)
    tiny = (A < DEGENERATE_AREA * bbox_diagonal(V) ** 2) | (A == 0)
    if tiny.any():
        f = int(np.flatnonzero(tiny)[0])
        raise MeshError(f"{name}: {int(tiny.sum())} faces are degenerate, with (near) zero area "
                        f"(the first is face {f}); remove or repair them")


def _topology_problem(P: np.ndarray, n: int, vertices: bool = True) -> str | None:
    """First topological problem of padded faces ``P`` as a message, or None if manifold.

    Checks non-manifold edges (more than two faces), inconsistent orientation (an edge run
    the same way by two faces) and, if ``vertices``, non-manifold vertices (faces around a
    vertex forming more than one fan), all vectorized.
    """
    src, dst, face = _face_edges(P)
    E, inv = _unique_edges(src, dst, n)
    count = np.bincount(inv, minlength=len(E))
    if np.any(count > 2):
        nm = np.flatnonzero(count > 2)
        a, b = E[nm[0]]
        return (f"{len(nm)} edges are non-manifold, shared by more than two faces (the first "
                f"joins vertices {a} and {b}); split the mesh so each edge has at most two faces")
    # orientation: two faces on one edge must run it in opposite directions
    directed = np.sort(src * np.int64(n) + dst)
    twice = directed[1:] == directed[:-1]          # a directed edge run by two faces
    if np.any(twice):
        d = unique_ints(directed[1:][twice])
        return (f"{len(d)} edges are run in the same direction by both of their faces, so the "
                f"faces are inconsistently oriented (the first joins vertices {d[0] // n} and "
                f"{d[0] % n}); reorient the faces consistently (or the surface is non-orientable)")
    if not vertices:
        return None
    # vertex fans: connect the corners of a vertex across shared edges
    h = np.arange(len(src))
    # the corner at dst of edge h is the src corner of the next edge in the same face
    k_sizes = (P >= 0).sum(axis=1)
    start = np.concatenate([[0], np.cumsum(k_sizes)[:-1]])
    pos = h - start[face]
    nxt = start[face] + (pos + 1) % k_sizes[face]
    order = np.argsort(inv, kind="stable")
    inner = count[inv[order]] == 2
    pairs = order[inner].reshape(-1, 2)  # the two directed edges of each interior edge
    h1, h2 = pairs[:, 0], pairs[:, 1]  # opposite directions (orientation checked above)
    # src(h1) == dst(h2) and dst(h1) == src(h2)
    ca = np.concatenate([h1, nxt[h1]])
    cb = np.concatenate([nxt[h2], h2])
    nc = len(src)
    G = coo_matrix((np.ones(len(ca)), (ca, cb)), shape=(nc, nc))
    _, label = connected_components(G, directed=False)
    vert = src  # vertex of each corner (corner = src of its edge)
    pair = unique_ints(vert * np.int64(nc) + label)
    fans = np.bincount(pair // nc, minlength=n)
    if np.any(fans > 1):
        bad = np.flatnonzero(fans > 1)
        return (f"{len(bad)} vertices are non-manifold, their faces forming several fans (the "
                f"first is vertex {bad[0]}); split the mesh at these vertices")
    return None


# --------------------------------------------------------------------------------------------
# mesh types
# --------------------------------------------------------------------------------------------

class _MeshBase:
    """Shared geometry of :class:`QuadMesh` and :class:`TriMesh` (``_k`` vertices per face)."""

    _k = 0

    def __init__(self, V: np.ndarray, F: np.ndarray, check: bool = True) -> None:
        V = np.array(V, dtype=np.float64, copy=True)
        F = np.array(F, dtype=np.int64, copy=True)
        if check:
            validate_mesh(V, F, require_quads=self._k == 4, name=type(self).__name__)
            if F.shape[1] != self._k:
                raise MeshError(f"{type(self).__name__}: faces must have {self._k} vertices, "
                                f"got shape {F.shape}; pass an (m, {self._k}) index array")
        elif V.ndim != 2 or V.shape[1:] != (3,) or F.ndim != 2 or F.shape[1:] != (self._k,):
            raise MeshError(f"{type(self).__name__}: expected V (n,3) and F (m,{self._k}), "
                            f"got {V.shape} and {F.shape}")
        V.setflags(write=False)
        F.setflags(write=False)
        self._V = V
        self._F = F

    @property
    def V(self) -> np.ndarray:
        """Vertex positions ``(n,3)`` float64, metres (read-only)."""
        return self._V

    @property
    def F(self) -> np.ndarray:
        """Faces ``(m,k)`` int64, counter-clockwise seen from the normal side (read-only)."""
        return self._F

    @property
    def n_vertices(self) -> int:
        """Number of vertices."""
        return len(self._V)

    @property
    def n_faces(self) -> int:
        """Number of faces."""
        return len(self._F)

    @cached_property
    def edges(self) -> np.ndarray:
        """Unique undirected edges ``(E,2)`` int64, each row sorted ``i<j``, rows sorted."""
        E = mesh_edges(self._F, self.n_vertices)
        E.setflags(write=False)
        return E

    @property
    def edge_lengths(self) -> np.ndarray:
        """Lengths ``(E,)`` of :attr:`edges`, metres."""
        E = self.edges
        return np.linalg.norm(self._V[E[:, 1]] - self._V[E[:, 0]], axis=1)

    @property
    def face_areas(self) -> np.ndarray:
        """Face areas ``(m,)``, m^2 (norm of the vector area for non-planar quads)."""
        return np.linalg.norm(polygon_vector_areas(self._V, self._F), axis=1)

    @property
    def face_normals(self) -> np.ndarray:
        """Unit face normals ``(m,3)`` (right-hand rule on the face order)."""
        return _unit(polygon_vector_areas(self._V, self._F))

    @property
    def vertex_normals(self) -> np.ndarray:
        """Unit vertex normals ``(n,3)``, area-weighted mean of incident face normals."""
        return area_weighted_vertex_normals(self._V, self._F)

    @property
    def bbox_diagonal(self) -> float:
        """Diagonal of the axis-aligned bounding box, metres."""
        return bbox_diagonal(self._V)

    @cached_property
    def boundary_vertices(self) -> np.ndarray:
        """Sorted indices ``(b,)`` of boundary vertices."""
        return boundary_vertices_of(self._F, self.n_vertices)

    @cached_property
    def boundary_loops(self) -> list[np.ndarray]:
        """Boundary loops, each an index array ``(b_i,)`` in boundary-halfedge order.

        Follows OpenMesh's boundary halfedges (those without a face); loops are sorted by
        their smallest vertex index and each starts at its smallest vertex.
        """
        mesh = self._om
        hf = mesh.hf_indices()
        hv = mesh.halfedge_vertex_indices()  # (h, 2): from, to
        bnd = hv[hf < 0]
        if len(bnd) == 0:
            return []
        nxt = np.full(self.n_vertices, -1, dtype=np.int64)
        nxt[bnd[:, 0]] = bnd[:, 1]  # manifold: one outgoing boundary halfedge per vertex
        seen = np.zeros(self.n_vertices, dtype=bool)
        loops = []
        for s in np.sort(bnd[:, 0]):
            if seen[s]:
                continue
            loop = [s]
            seen[s] = True
            v = nxt[s]
            while v != s:
                loop.append(v)
                seen[v] = True
                v = nxt[v]
            loops.append(np.asarray(loop, dtype=np.int64))
        return loops

    @cached_property
    def is_manifold(self) -> bool:
        """True if every edge has at most two faces, orientations agree and vertices are fans."""
        P, _ = _as_padded(self._F)
        return _topology_problem(P, self.n_vertices) is None

    @property
    def euler_characteristic(self) -> int:
        """``V - E + F`` (vertices counted whether referenced or not)."""
        return self.n_vertices - len(self.edges) + self.n_faces

    @property
    def is_disk(self) -> bool:
        """True for a manifold with one boundary loop and Euler characteristic 1."""
        return (self.is_manifold and len(self.boundary_loops) == 1
                and self.euler_characteristic == 1)

    @cached_property
    def _om(self) -> om.PolyMesh:
        """OpenMesh halfedge structure of this mesh (built once)."""
        if not self.is_manifold:
            raise MeshError(f"{type(self).__name__}: the mesh is not manifold, so it has no "
                            "halfedge structure; run validate_mesh on it to see why and repair it")
        mesh = om.PolyMesh(self._V, self._F)
        if mesh.n_faces() != self.n_faces or mesh.n_vertices() != self.n_vertices:
            raise MeshError(f"{type(self).__name__}: OpenMesh could not build the halfedge "
                            "structure; run validate_mesh on the mesh to find the bad faces")
        return mesh

    def copy(self):
        """An independent copy (arrays copied, caches dropped)."""
        return type(self)(self._V, self._F, check=False)

    def with_vertices(self, V: np.ndarray):
        """The same connectivity with new positions ``V (n,3)``, metres."""
        V = np.asarray(V, dtype=np.float64)
        if V.shape != self._V.shape:
            raise MeshError(f"{type(self).__name__}.with_vertices: expected V of shape "
                            f"{self._V.shape}, got {V.shape}; keep the vertex count and order")
        new = type(self)(V, self._F, check=False)
        new._F = self._F  # share the read-only faces and the topology caches
        for key in ("edges", "boundary_vertices", "boundary_loops", "is_manifold"):
            if key in self.__dict__:
                new.__dict__[key] = self.__dict__[key]
        return new

    def __repr__(self) -> str:
        return f"{type(self).__name__}(n_vertices={self.n_vertices}, n_faces={self.n_faces})"


class QuadMesh(_MeshBase):
    """A quad mesh ``V (n,3)`` float64 (metres), ``F (m,4)`` int64.

    Parameters
    ----------
    V : (n,3) float
        Vertex positions, metres.
    F : (m,4) int
        Quads, counter-clockwise seen from the normal side.
    check : bool
        Run :func:`validate_mesh` (quads, finite, manifold, non-degenerate) first.
    """

    _k = 4

    def triangulate(self) -> tuple[np.ndarray, np.ndarray]:
        """Split each quad along its shorter diagonal.

        Returns
        -------
        V : (n,3) float
            The vertices (same array, read-only).
        F3 : (2m,3) int64
            Triangles; quad ``i`` gives triangles ``2i`` and ``2i+1`` with its orientation.
        """
        return self._V, triangulate_quads(self._V, self._F)

    def to_trimesh(self) -> "TriMesh":
        """:class:`TriMesh` of :meth:`triangulate`."""
        return TriMesh(self._V, triangulate_quads(self._V, self._F), check=False)

    def grid(self) -> np.ndarray:
        """Vertex indices ``(R, C)`` of a structured grid mesh (see :func:`gridshell.geometry.grid.grid_from_quads`)."""
        if "_grid" not in self.__dict__:
            from gridshell.geometry.grid import grid_from_quads
            G = grid_from_quads(self._F, self.n_vertices)
            G.setflags(write=False)
            self.__dict__["_grid"] = G
        return self.__dict__["_grid"]


class TriMesh(_MeshBase):
    """A triangle mesh ``V (n,3)`` float64 (metres), ``F (m,3)`` int64, e.g. a target surface.

    Parameters
    ----------
    V : (n,3) float
        Vertex positions, metres.
    F : (m,3) int
        Triangles, counter-clockwise seen from the normal side.
    check : bool
        Run :func:`validate_mesh` first.
    """

    _k = 3


def triangulate_quads(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """Triangles ``(2m,3)`` splitting each quad of ``F (m,4)`` along its shorter diagonal."""
    V = np.asarray(V, dtype=float)
    F = np.asarray(F, dtype=np.int64)
    d02 = np.linalg.norm(V[F[:, 2]] - V[F[:, 0]], axis=1)
    d13 = np.linalg.norm(V[F[:, 3]] - V[F[:, 1]], axis=1)
    use02 = (d02 <= d13)[:, None]
    t1 = np.where(use02, F[:, [0, 1, 2]], F[:, [0, 1, 3]])
    t2 = np.where(use02, F[:, [0, 2, 3]], F[:, [1, 2, 3]])
    return np.stack([t1, t2], axis=1).reshape(-1, 3)


def _triangulate_padded(V: np.ndarray, P: np.ndarray, sizes: np.ndarray) -> np.ndarray:
    """Triangles of mixed polygons: triangles kept, quads on the shorter diagonal, others fanned."""
    out = []
    order = []
    for k in np.unique(sizes):
        idx = np.flatnonzero(sizes == k)
        Fk = P[idx, :k]
        if k == 3:
            T, owner = Fk, idx
        elif k == 4:
            T, owner = triangulate_quads(V, Fk), np.repeat(idx, 2)
        else:
            j = np.arange(1, k - 1)
            T = np.stack([np.repeat(Fk[:, :1], k - 2, axis=1), Fk[:, j], Fk[:, j + 1]],
                         axis=2).reshape(-1, 3)
            owner = np.repeat(idx, k - 2)
        out.append(T)
        order.append(owner)
    T = np.concatenate(out)
    return T[np.argsort(np.concatenate(order), kind="stable")]
