"""Quad meshes (and triangle meshes for targets): the data type, its checks, and mesh files.

``QuadMesh`` holds ``V (n,3) float64`` (metres) and ``F (m,4) int64``; topology queries that
need a halfedge structure go through an OpenMesh ``PolyMesh`` built lazily and cached.

Mesh files (OBJ, PLY, OFF) are parsed and written here with numpy rather than through
``openmesh.read_polymesh`` / ``openmesh.write_mesh``, because OpenMesh 1.2.1 (python bindings)
is unusable as a file layer for this project:

* its readers and writers go through single precision: a round trip loses ~3e-8 relative
  (OBJ is written with ``%f``, OFF with 6 significant digits, binary PLY as float32, and even a
  file holding doubles is read into float32);
* on bad input it repairs silently instead of failing: a face on a non-manifold edge gets
  fresh copies of its vertices (vertex count and indices change), a repeated index in a face
  is dropped (a quad becomes a triangle), an out-of-range face is skipped, a truncated vertex
  record is skipped; failures only go to stderr, and a missing/garbage file yields an empty mesh;
* a PLY file truncated inside its header makes ``read_polymesh`` loop forever.

Our writers emit ASCII with 17 significant digits (exact for float64); OpenMesh reads them.
"""
from __future__ import annotations

import os
from functools import cached_property
from pathlib import Path
from typing import Sequence

import numpy as np
import openmesh as om
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from .atomic import atomic_path
from .errors import MeshError

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
    P = V[Fi]  # (m,k,3)
    nxt = np.roll(P, -1, axis=1)
    # the last valid vertex must close onto the first one
    last = valid.sum(axis=1) - 1
    nxt[np.arange(m), last] = P[:, 0]
    nxt[~valid] = P[:, :1].repeat(k, axis=1)[~valid]
    return 0.5 * np.cross(P, nxt).sum(axis=1)


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
    np.add.at(N, P[valid], A[rows])
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
    directed = src * np.int64(n) + dst
    _, dcount = np.unique(directed, return_counts=True)
    if np.any(dcount > 1):
        d = np.unique(directed)[dcount > 1]
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
    pair = np.unique(vert * np.int64(nc) + label)
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
        """Vertex indices ``(R, C)`` of a structured grid mesh (see :func:`gridshell.grid.grid_from_quads`)."""
        if "_grid" not in self.__dict__:
            from .grid import grid_from_quads
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


# --------------------------------------------------------------------------------------------
# files
# --------------------------------------------------------------------------------------------

def _check_readable(path: Path) -> str:
    """Extension (lower case) of a readable, non-empty mesh file, else :class:`MeshError`."""
    if not path.exists():
        raise MeshError(f"{path}: no such file; check the path")
    if not path.is_file():
        raise MeshError(f"{path}: not a file; give the path of an OBJ, PLY or OFF mesh")
    if not os.access(path, os.R_OK):
        raise MeshError(f"{path}: cannot read the file (permission denied); fix its permissions")
    ext = path.suffix.lower()
    if ext not in MESH_FORMATS:
        raise MeshError(f"{path.name}: unknown mesh format '{path.suffix}'; "
                        "give an .obj, .ply or .off file")
    if path.stat().st_size == 0:
        raise MeshError(f"{path.name}: the file is empty; export the mesh again")
    return ext


def _corrupt(path: Path, what: str) -> MeshError:
    return MeshError(f"{path.name}: {what}; the file is truncated or corrupt, export it again")


def _decode(path: Path) -> list[str]:
    data = path.read_bytes()
    if b"\x00" in data:
        raise _corrupt(path, f"not a text {path.suffix.upper()[1:]} file (binary bytes found)")
    try:
        return data.decode("utf-8").splitlines()
    except UnicodeDecodeError:
        return data.decode("latin-1").splitlines()


def _parse_obj(path: Path, lines: list[str]) -> tuple[np.ndarray, list[list[int]], list[list[int]]]:
    """Vertices, faces (0-based) and polylines (0-based) of OBJ ``lines``."""
    verts: list[list[str]] = []
    faces: list[list[int]] = []
    polylines: list[list[int]] = []
    known = {"vt", "vn", "vp", "o", "g", "s", "usemtl", "mtllib", "p", "#"}
    for lineno, raw in enumerate(lines, 1):
        t = raw.split()
        if not t or t[0].startswith("#"):
            continue
        tag = t[0]
        try:
            if tag == "v":
                if len(t) < 4:
                    raise ValueError
                verts.append(t[1:4])
            elif tag in ("f", "l"):
                idx = [int(s.split("/")[0]) for s in t[1:]]
                nv = len(verts)
                idx = [i - 1 if i > 0 else nv + i for i in idx]  # negative = relative
                (faces if tag == "f" else polylines).append(idx)
            elif tag not in known:
                raise ValueError
        except ValueError:
            raise _corrupt(path, f"line {lineno} is not a valid OBJ record ({raw[:40]!r})") from None
    try:
        V = np.array(verts, dtype=float).reshape(-1, 3)
    except ValueError:
        raise _corrupt(path, "a vertex record holds a non-number") from None
    return V, faces, polylines


def _parse_off(path: Path, lines: list[str]) -> tuple[np.ndarray, list[list[int]]]:
    body = [ln.split("#")[0].split() for ln in lines]
    body = [t for t in body if t]
    if not body or not body[0][0].upper().endswith("OFF"):
        raise _corrupt(path, "no OFF header")
    head = body[0][1:] if len(body[0]) > 1 else (body[1] if len(body) > 1 else [])
    rest = body[1:] if len(body[0]) > 1 else body[2:]
    try:
        nv, nf = int(head[0]), int(head[1])
    except (IndexError, ValueError):
        raise _corrupt(path, "the OFF header has no vertex and face counts") from None
    if len(rest) < nv + nf:
        raise _corrupt(path, f"the header announces {nv} vertices and {nf} faces but the file "
                       f"holds {len(rest)} records")
    try:
        V = np.array([r[:3] for r in rest[:nv]], dtype=float).reshape(-1, 3)
        faces = []
        for r in rest[nv:nv + nf]:
            k = int(r[0])
            if len(r) < k + 1:
                raise ValueError
            faces.append([int(s) for s in r[1:k + 1]])
    except ValueError:
        raise _corrupt(path, "a vertex or face record is incomplete or not numeric") from None
    return V, faces


_PLY_TYPES = {"char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2",
              "int16": "i2", "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4",
              "uint": "u4", "uint32": "u4", "float": "f4", "float32": "f4", "double": "f8",
              "float64": "f8"}


def _parse_ply(path: Path) -> tuple[np.ndarray, list[list[int]] | np.ndarray]:
    data = path.read_bytes()
    end = data.find(b"end_header")
    if not data.startswith(b"ply") or end < 0:
        raise _corrupt(path, "no complete PLY header")
    nl = data.find(b"\n", end)
    header = data[:end].decode("ascii", errors="replace").splitlines()
    body = data[nl + 1:] if nl >= 0 else b""
    fmt, elements = None, []  # elements: [name, count, [(prop, type, list_types|None)]]
    try:
        for ln in header[1:]:
            t = ln.split()
            if not t or t[0] in ("comment", "obj_info"):
                continue
            if t[0] == "format":
                fmt = t[1]
            elif t[0] == "element":
                elements.append([t[1], int(t[2]), []])
            elif t[0] == "property":
                if t[1] == "list":
                    elements[-1][2].append((t[4], _PLY_TYPES[t[3]], _PLY_TYPES[t[2]]))
                else:
                    elements[-1][2].append((t[2], _PLY_TYPES[t[1]], None))
    except (IndexError, KeyError, ValueError):
        raise _corrupt(path, "the PLY header is malformed") from None
    if fmt not in ("ascii", "binary_little_endian", "binary_big_endian"):
        raise _corrupt(path, f"unknown PLY format {fmt!r}")
    names = [e[0] for e in elements]
    if "vertex" not in names or "face" not in names:
        raise _corrupt(path, "the PLY file has no vertex or no face element")
    V = None
    faces: list[list[int]] | np.ndarray = []
    if fmt == "ascii":
        rows = [ln.split() for ln in body.decode("ascii", errors="replace").splitlines()]
        rows = [r for r in rows if r]
        pos = 0
        for name, count, props in elements:
            chunk = rows[pos:pos + count]
            if len(chunk) < count:
                raise _corrupt(path, f"the {name} element announces {count} records, "
                               f"found {len(chunk)}")
            pos += count
            try:
                if name == "vertex":
                    col = {p[0]: i for i, p in enumerate(props)}
                    V = np.array([[r[col["x"]], r[col["y"]], r[col["z"]]] for r in chunk],
                                 dtype=float).reshape(-1, 3)
                elif name == "face":
                    faces = [[int(s) for s in r[1:1 + int(r[0])]] for r in chunk]
                    if any(len(f) != int(r[0]) for f, r in zip(faces, chunk)):
                        raise ValueError
            except (KeyError, ValueError, IndexError):
                raise _corrupt(path, f"a {name} record is incomplete or not numeric") from None
        return V, faces
    bo = "<" if fmt == "binary_little_endian" else ">"
    off = 0
    for name, count, props in elements:
        if any(p[2] is not None for p in props):
            if name != "face" or len(props) != 1:
                raise MeshError(f"{path.name}: PLY element '{name}' with list properties is not "
                                "supported; export vertices and faces only")
            _, itype, ctype = props[0]
            faces, off = _ply_binary_lists(path, body, off, count, bo + ctype, bo + itype)
            continue
        dt = np.dtype([(p[0], bo + p[1]) for p in props])
        need = dt.itemsize * count
        if len(body) - off < need:
            raise _corrupt(path, f"the {name} element is cut short")
        arr = np.frombuffer(body, dtype=dt, count=count, offset=off)
        off += need
        if name == "vertex":
            try:
                V = np.stack([arr["x"], arr["y"], arr["z"]], axis=1).astype(float)
            except (KeyError, ValueError):
                raise _corrupt(path, "the PLY vertices have no x, y, z") from None
    return V, faces


def _ply_binary_lists(path: Path, body: bytes, off: int, count: int, ctype: str,
                      itype: str) -> tuple[np.ndarray | list[list[int]], int]:
    """Binary PLY face lists: vectorized when all faces have the same size."""
    cdt, idt = np.dtype(ctype), np.dtype(itype)
    if count == 0:
        return np.zeros((0, 3), np.int64), off
    if len(body) - off < cdt.itemsize:
        raise _corrupt(path, "the face element is cut short")
    k = int(np.frombuffer(body, dtype=cdt, count=1, offset=off)[0])
    dt = np.dtype([("n", cdt), ("i", idt, (k,))])
    if len(body) - off >= dt.itemsize * count:
        arr = np.frombuffer(body, dtype=dt, count=count, offset=off)
        if np.all(arr["n"] == k):
            return arr["i"].astype(np.int64), off + dt.itemsize * count
    faces = []
    for _ in range(count):  # mixed sizes: sequential
        if len(body) - off < cdt.itemsize:
            raise _corrupt(path, "the face element is cut short")
        k = int(np.frombuffer(body, dtype=cdt, count=1, offset=off)[0])
        off += cdt.itemsize
        if len(body) - off < k * idt.itemsize:
            raise _corrupt(path, "the face element is cut short")
        faces.append(np.frombuffer(body, dtype=idt, count=k, offset=off).tolist())
        off += k * idt.itemsize
    return faces, off


def _read_raw(path: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``V (n,3)``, padded faces ``(m,k)`` and face sizes ``(m,)`` of a mesh file."""
    ext = _check_readable(path)
    try:
        if ext == ".obj":
            V, faces, _ = _parse_obj(path, _decode(path))
        elif ext == ".off":
            V, faces = _parse_off(path, _decode(path))
        else:
            V, faces = _parse_ply(path)
    except OSError as exc:
        raise MeshError(f"{path}: cannot read the file ({exc.strerror or exc})") from exc
    if V is None or len(V) == 0:
        raise _corrupt(path, "no vertices found")
    P, sizes = _as_padded(faces if not isinstance(faces, np.ndarray) else faces)
    return V, P, sizes


def read_configuration(path: str | os.PathLike) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Vertices ``V (n,3)``, padded faces ``(m,k)`` (``-1`` padded) and face sizes ``(m,)`` of a
    mesh file, without the geometry checks of :func:`read_mesh`.

    For configurations that are degenerate by design: a collapsed (aligned) net puts every
    joint of a loop on one line, which :func:`validate_mesh` rejects as zero-area faces. The
    file must still parse and hold at least one vertex (:class:`MeshError` otherwise);
    coordinates must be finite.
    """
    path = Path(path)
    V, P, sizes = _read_raw(path)
    V = np.asarray(V, dtype=np.float64).reshape(-1, 3)
    if not np.all(np.isfinite(V)):
        raise MeshError(f"{path.name}: {int((~np.isfinite(V)).any(axis=1).sum())} vertices have "
                        "NaN or infinite coordinates; re-export the mesh")
    if len(P) and (P.max() >= len(V)):
        raise MeshError(f"{path.name}: a face refers to vertex {int(P.max())} but the file has "
                        f"{len(V)} vertices; the file is truncated or corrupt")
    check_coordinates(V, path.name)
    return V, P, sizes


def check_coordinates(V: np.ndarray, name: str, what: str = "vertex") -> None:
    """:class:`MeshError` naming the first finite coordinate of ``V (n,3)`` (metres) beyond
    ``EXTENT_RANGE[1]`` from the origin: out-of-range coordinates (other units, or a corrupt
    file), reported as such rather than as the degenerate faces they cause."""
    V = np.asarray(V, dtype=np.float64).reshape(-1, 3)
    fin = np.isfinite(V).all(axis=1)
    big = fin & (np.abs(np.where(np.isfinite(V), V, 0.0)).max(axis=1, initial=0.0)
                 > EXTENT_RANGE[1])
    if big.any():
        i = int(np.flatnonzero(big)[0])
        x, y, z = V[i]
        raise MeshError(f"{name}: {int(big.sum())} points have coordinates out of range ({what} "
                        f"{i} at ({x:.3g}, {y:.3g}, {z:.3g}) m, beyond +-{EXTENT_RANGE[1]:g} m: "
                        "the mesh spans more than a gridshell can); coordinates are read as "
                        "metres - rescale the mesh or repair the file")


def read_mesh(path: str | os.PathLike, kind: str = "any",
              manifold_vertices: bool = True) -> QuadMesh | TriMesh:
    """Read an OBJ, PLY (ASCII or binary) or OFF mesh, keeping vertex and face order.

    Parameters
    ----------
    path : path-like
        The mesh file; the format is taken from the extension.
    kind : {"any", "quad", "tri"}
        ``"quad"``: every face must be a quad, gives a :class:`QuadMesh`. ``"tri"``: gives a
        :class:`TriMesh`, quads split along their shorter diagonal (other polygons fanned).
        ``"any"``: a :class:`QuadMesh` if all faces are quads, a :class:`TriMesh` otherwise
        (mixed faces triangulated).
    manifold_vertices : bool
        ``False`` accepts vertices whose faces form several fans (see :func:`validate_mesh`).

    Returns
    -------
    QuadMesh or TriMesh
        Coordinates in the file's units (metres by convention), full float64 precision.

    Raises
    ------
    MeshError
        Missing, unreadable, empty, truncated or garbage file, unknown extension, a mesh
        that fails :func:`validate_mesh`, or one whose size is outside :data:`EXTENT_RANGE`.
    """
    if kind not in ("any", "quad", "tri"):
        raise ValueError(f"kind must be 'any', 'quad' or 'tri', got {kind!r}")
    path = Path(path)
    V, P, sizes = _read_raw(path)
    check_coordinates(V, path.name)
    validate_mesh(V, P, require_quads=kind == "quad", name=path.name,
                  manifold_vertices=manifold_vertices)
    _check_extent(V, path.name)
    if kind != "tri" and np.all(sizes == 4):
        return QuadMesh(V, P[:, :4], check=False)
    if np.all(sizes == 3):
        return TriMesh(V, P[:, :3], check=False)
    return TriMesh(V, _triangulate_padded(V, P, sizes), check=False)


def _check_extent(V: np.ndarray, name: str) -> None:
    """:class:`MeshError` unless the bounding-box diagonal of ``V`` lies in :data:`EXTENT_RANGE`."""
    d = bbox_diagonal(V)
    lo, hi = EXTENT_RANGE
    if not lo <= d <= hi:
        raise MeshError(f"{name}: the mesh spans {d:.3g} m (bounding-box diagonal), outside the "
                        f"{lo:g} .. {hi:g} m a gridshell can have; coordinates are read as "
                        "metres - rescale the mesh (or export it in metres)")


def _obj_vertex_text(V: np.ndarray) -> str:
    V = np.asarray(V, dtype=np.float64).reshape(-1, 3)
    return "".join(f"v {x!r} {y!r} {z!r}\n" for x, y, z in V.tolist())


def _index_text(prefix: str, F: np.ndarray, offset: int) -> str:
    if len(F) == 0:
        return ""
    S = (np.asarray(F, dtype=np.int64) + offset).astype(str)
    return "".join(prefix + " ".join(row) + "\n" for row in S.tolist())


def orientation_problem(F: np.ndarray, n_vertices: int) -> str | None:
    """Why the faces ``F (m,k)`` (rows padded with -1 for smaller faces) are not consistently
    oriented, or None.

    Purely combinatorial (each directed edge ``(F[i, j], F[i, j+1])`` at most once, so the two
    faces of an interior edge run it in opposite directions), so it holds for a collapsed net
    whose loops are geometrically degenerate (aligned.obj).
    """
    F = np.asarray(F, dtype=np.int64)
    if F.size == 0:
        return None
    src, dst, _ = _face_edges(F)  # rows padded with -1 (faces of mixed sizes) allowed
    directed = src * np.int64(max(n_vertices, 1)) + dst
    u, c = np.unique(directed, return_counts=True)
    if np.any(c > 1):
        d = u[c > 1]
        n = max(n_vertices, 1)
        return (f"{len(d)} edges are run in the same direction by two faces (the first joins "
                f"vertices {d[0] // n} and {d[0] % n}): the faces are inconsistently oriented")
    return None


def _check_writable_mesh(name: str, V: np.ndarray, F: np.ndarray) -> None:
    """:class:`GridshellError` (a bug of the caller: the tool never writes such a file) unless
    ``V`` is finite, ``F`` refers to existing vertices and is consistently oriented."""
    from .errors import GridshellError

    bad = ~np.isfinite(V).all(axis=1)
    if bad.any():
        raise GridshellError(f"refusing to write {name}: {int(bad.sum())} vertices are not "
                             f"finite (NaN or Inf; the first is vertex {int(np.flatnonzero(bad)[0])})"
                             "; this is a bug, please report it")
    if F.size and (F.min() < 0 or F.max() >= len(V)):
        raise GridshellError(f"refusing to write {name}: faces refer to vertices outside 0 .. "
                             f"{len(V) - 1}; this is a bug, please report it")
    problem = orientation_problem(F, len(V))
    if problem is not None:
        raise GridshellError(f"refusing to write {name}: {problem}; this is a bug, please "
                             "report it")


def write_mesh(path: str | os.PathLike, V: np.ndarray, F: np.ndarray) -> None:
    """Write ``V (n,3)``, ``F (m,k)`` to an OBJ, PLY or OFF file (ASCII), atomically.

    Vertex and face order are kept and coordinates are written with 17 significant digits,
    so :func:`read_mesh` returns exactly ``V`` and ``F``. (OpenMesh's writers are not used:
    they round coordinates to single precision.)

    Parameters
    ----------
    path : path-like
        Output file; ``.obj``, ``.ply`` or ``.off``.
    V : (n,3) float
        Vertex positions, metres.
    F : (m,k) int
        Faces (0-based vertex indices), all of one size ``k``, consistently oriented
        (:func:`orientation_problem`).

    Raises :class:`~gridshell.errors.GridshellError` for non-finite vertices, faces outside
    the vertices or inconsistent orientation: the tool never writes such a mesh.
    """
    path = Path(path)
    ext = path.suffix.lower()
    if ext not in MESH_FORMATS:
        raise MeshError(f"{path.name}: unknown mesh format '{path.suffix}'; "
                        "write an .obj, .ply or .off file")
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
    if V.ndim != 2 or V.shape[1] != 3 or F.ndim != 2:
        raise MeshError(f"{path.name}: expected V (n,3) and F (m,k), got {V.shape} and {F.shape}")
    _check_writable_mesh(path.name, V, F)
    vtext = "".join(" ".join(map(repr, r)) + "\n" for r in V.tolist())
    if ext == ".obj":
        text = (f"# {len(V)} vertices, {len(F)} faces\n" + "".join("v " + s for s in
                vtext.splitlines(keepends=True)) + _index_text("f ", F, 1))
    elif ext == ".off":
        text = (f"OFF\n{len(V)} {len(F)} 0\n" + vtext
                + _index_text(f"{F.shape[1]} ", F, 0))
    else:
        text = ("ply\nformat ascii 1.0\n"
                f"element vertex {len(V)}\nproperty double x\nproperty double y\n"
                f"property double z\nelement face {len(F)}\n"
                "property list uchar int vertex_indices\nend_header\n"
                + vtext + _index_text(f"{F.shape[1]} ", F, 0))
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="ascii")


def write_polylines(path: str | os.PathLike, polylines: Sequence[np.ndarray]) -> None:
    """Write polylines to an OBJ file (``v`` records, then one ``l`` record each), atomically.

    Parameters
    ----------
    path : path-like
        Output ``.obj`` file.
    polylines : list of (k_i,3) float
        Polylines in order, metres; each needs at least 2 points.
    """
    parts, lines, start = [], [], 1
    for i, P in enumerate(polylines):
        P = np.asarray(P, dtype=np.float64)
        if P.ndim != 2 or P.shape[1] != 3 or len(P) < 2:
            raise MeshError(f"polyline {i}: expected (k,3) points with k >= 2, got {P.shape}")
        if not np.all(np.isfinite(P)):
            from .errors import GridshellError
            raise GridshellError(f"refusing to write {Path(path).name}: polyline {i} has "
                                 "non-finite points (NaN or Inf); this is a bug, please report it")
        parts.append(_obj_vertex_text(P))
        lines.append("l " + " ".join(map(str, range(start, start + len(P)))) + "\n")
        start += len(P)
    with atomic_path(path) as tmp:
        tmp.write_text(f"# {len(lines)} polylines\n" + "".join(parts) + "".join(lines),
                       encoding="ascii")


def read_polylines(path: str | os.PathLike) -> list[np.ndarray]:
    """Polylines ``[(k_i,3) float]`` of the ``l`` records of an OBJ file, in file order."""
    path = Path(path)
    if _check_readable(path) != ".obj":
        raise MeshError(f"{path.name}: polylines are read from OBJ files only; give an .obj file")
    V, _, lines = _parse_obj(path, _decode(path))
    out = []
    for i, idx in enumerate(lines):
        idx = np.asarray(idx, dtype=np.int64)
        if np.any((idx < 0) | (idx >= len(V))):
            raise _corrupt(path, f"polyline {i} refers to missing vertices")
        P = np.asarray(V[idx], dtype=np.float64)
        if not np.all(np.isfinite(P)):
            raise MeshError(f"{path.name}: polyline {i} has "
                            f"{int((~np.isfinite(P)).any(axis=1).sum())} points with NaN or "
                            "infinite coordinates; re-run the design command")
        check_coordinates(P, path.name, f"polyline {i} point")
        out.append(P)
    return out
