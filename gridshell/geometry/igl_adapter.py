"""The one module that calls libigl (2.6.x): closest points, curvature, parameterization.

libigl's Python API shifts between releases (``principal_curvature`` gained a fifth return
value in 2.6) and silently misbehaves on input it does not expect: quads are read as
triangles, out-of-range indices crash the interpreter, and ``int32`` / Fortran-ordered arrays
are rejected by some bindings. Every call therefore goes through this module, which

- accepts a mesh as ``(V, F)`` with ``F`` of width 3 or 4, or a ``QuadMesh`` (anything with
  ``V`` and ``F`` attributes) in place of ``V``;
- splits quads ``(a, b, c, d)`` along the shorter diagonal (``a-c`` on ties) into two
  triangles and keeps the map back to the quad;
- validates shapes, finiteness and indices, and hands igl C-contiguous ``float64`` / ``int64``.

Sign convention for curvatures matches :mod:`gridshell.geometry.diffgeo`: positive when the surface
bends towards the (per-vertex) normal, ``k1 <= k2``.
"""
from __future__ import annotations

from typing import Any, Callable, Literal

import igl
import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from gridshell.core.errors import InputError, MeshError
from gridshell.core.recent import Recent, array_key

__all__ = [
    "ask_closest_points",
    "closest_points",
    "closest_points_with_normals",
    "cotangent_laplacian",
    "flipped_triangles",
    "parameterize_disk",
    "per_vertex_normals",
    "principal_curvature",
    "principal_curvature_at",
    "triangulate",
]


# ----------------------------------------------------------------------------- input handling


def triangulate(V: Any, F: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Triangle mesh for igl from ``(V, F)`` (``F`` width 3 or 4) or a ``QuadMesh``.

    Parameters
    ----------
    V : (n, 3) float or QuadMesh
        Vertex positions, metres, or a mesh object with ``V`` and ``F`` attributes (then ``F``
        must be ``None``).
    F : (m, 3) or (m, 4) int, optional
        Faces.

    Returns
    -------
    V : (n, 3) float64, C-contiguous
    T : (t, 3) int64, C-contiguous
        Triangles; quad ``q`` becomes triangles ``2q`` and ``2q + 1`` split along its shorter
        diagonal.
    face_of : (t,) int64
        Row of the input ``F`` each triangle comes from.
    """
    if F is None:
        if not (hasattr(V, "V") and hasattr(V, "F")):
            raise InputError("pass a mesh as (V, F) arrays or as a QuadMesh; F is missing")
        V, F = V.V, V.F
    V = np.ascontiguousarray(V, dtype=np.float64)
    if V.ndim != 2 or V.shape[1] != 3 or len(V) == 0:
        raise MeshError(f"vertices must have shape (n, 3) with n > 0, got {V.shape}")
    if not np.all(np.isfinite(V)):
        raise MeshError("vertices contain NaN or infinite coordinates; clean the mesh")
    F = np.asarray(F)
    if F.ndim != 2 or F.shape[1] not in (3, 4) or len(F) == 0:
        raise MeshError(f"faces must have shape (m, 3) or (m, 4) with m > 0, got {F.shape}")
    if not np.issubdtype(F.dtype, np.integer):
        if not np.all(np.isfinite(F)) or np.any(F != np.round(F)):
            raise MeshError("face indices must be integers")
    F = F.astype(np.int64)
    if F.min() < 0 or F.max() >= len(V):
        raise MeshError(f"face indices must lie in [0, {len(V) - 1}], got [{F.min()}, {F.max()}]; "
                        "the faces do not belong to these vertices")
    m = len(F)
    if F.shape[1] == 3:
        return V, np.ascontiguousarray(F), np.arange(m, dtype=np.int64)
    a, b, c, d = F.T
    use_ac = (np.linalg.norm(V[a] - V[c], axis=1) <= np.linalg.norm(V[b] - V[d], axis=1))
    t1 = np.where(use_ac[:, None], np.stack([a, b, c], 1), np.stack([a, b, d], 1))
    t2 = np.where(use_ac[:, None], np.stack([a, c, d], 1), np.stack([b, c, d], 1))
    T = np.empty((2 * m, 3), dtype=np.int64)
    T[0::2], T[1::2] = t1, t2
    return V, T, np.repeat(np.arange(m, dtype=np.int64), 2)


def _points(P: np.ndarray) -> np.ndarray:
    P = np.ascontiguousarray(P, dtype=np.float64)
    if P.ndim != 2 or P.shape[1] != 3:
        raise InputError(f"query points must have shape (k, 3), got {P.shape}")
    if not np.all(np.isfinite(P)):
        raise InputError("query points contain NaN or infinite coordinates; remove them")
    return P


# ----------------------------------------------------------------------------- queries


def per_vertex_normals(V: Any, F: np.ndarray | None = None) -> np.ndarray:
    """Unit per-vertex normals ``(n, 3)``: igl's default (angle-weighted) face-normal average.

    Orientation follows the face winding (counter-clockwise seen from the normal's tip);
    unreferenced vertices get a zero row.
    """
    V, T, _ = triangulate(V, F)
    N = np.asarray(igl.per_vertex_normals(V, T))
    N = np.nan_to_num(N, nan=0.0)
    return N


# ----------------------------------------------------------------------------- repeated queries

#: results of the closest-point queries asked with ``reuse=True`` in this process, by the
#: content of their arrays (:func:`gridshell.core.recent.array_key`): the same query again (a
#: design verified, then exported: the joints' and the axes' closest points on surface.obj)
#: is answered without igl. A few, newest last, of at most 16 MB together. Opt-in: a loop
#: that queries new points on one large mesh would only pay for the hashing.
_QUERIES = Recent(8, copy=lambda v: tuple(a.copy() for a in v),
                  nbytes=lambda v: sum(a.nbytes for a in v), max_bytes=16 << 20)


def _once(what: str, arrays: tuple[np.ndarray, ...],
          compute: Callable[[], tuple[np.ndarray, ...]], reuse: bool) -> tuple[np.ndarray, ...]:
    """``compute()`` (a tuple of arrays, a pure function of ``arrays``); with ``reuse``, a copy
    of what it gave for arrays of the same content before, if it did (each caller gets its
    own copies)."""
    if not reuse:
        return compute()
    key = (what, array_key(*arrays))
    hit = _QUERIES.get(key)
    if hit is not None:
        return hit
    out = tuple(np.asarray(a) for a in compute())
    _QUERIES.put(key, out)
    return out


def ask_closest_points(Ps: list[np.ndarray], V: Any, F: np.ndarray | None = None) -> None:
    """Answer the closest-point queries of the point sets ``Ps`` (each ``(k_i, 3)``, metres)
    on the mesh ``(V, F)`` ahead, for the ``reuse`` queries that will ask them
    (:func:`closest_points`, :func:`closest_points_with_normals`): the sets not answered
    before go to igl in one query, so that it builds its AABB tree of the mesh once instead
    of once per set (~10 ms for 20k triangles). igl answers each point from the tree alone,
    whatever the other points of its query: each set gets the arrays its own query gives
    (tests/geometry/test_igl_adapter.py)."""
    Ps = [_points(P) for P in Ps]
    V, T, _ = triangulate(V, F)
    keys = [("closest", array_key(P, V, T)) for P in Ps]
    todo = [i for i, key in enumerate(keys) if _QUERIES.get(key) is None]
    if len(todo) < 2:       # nothing to share: the query itself asks igl
        return
    out = igl.point_mesh_squared_distance(np.concatenate([Ps[i] for i in todo]), V, T)
    cut = np.cumsum([len(Ps[i]) for i in todo])[:-1]
    for i, *parts in zip(todo, *(np.split(np.asarray(a), cut) for a in out)):
        _QUERIES.put(keys[i], tuple(np.ascontiguousarray(a) for a in parts))


def closest_points(P: np.ndarray, V: Any, F: np.ndarray | None = None,
                   reuse: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Closest points on a mesh (``igl.point_mesh_squared_distance``); with ``reuse``, the
    answer of an earlier ``reuse`` query of the same points and mesh (by content) if there was
    one (the same arrays, copied).

    Parameters
    ----------
    P : (k, 3) float
        Query points, metres.
    V, F
        The mesh (see :func:`triangulate`).

    Returns
    -------
    sqr_dist : (k,) float
        Squared distances, m^2.
    face_index : (k,) int64
        Row of the input ``F`` (the quad for quad meshes) holding the closest point.
    C : (k, 3) float
        Closest points, metres.
    """
    P = _points(P)
    V, T, face_of = triangulate(V, F)
    sqr, tri, C = _once("closest", (P, V, T), lambda: igl.point_mesh_squared_distance(P, V, T),
                        reuse)
    return np.asarray(sqr, dtype=float), face_of[np.asarray(tri, dtype=np.int64)], np.asarray(C)


def closest_points_with_normals(P: np.ndarray, V: Any, F: np.ndarray | None = None,
                                reuse: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Closest points and the interpolated unit normal there (``reuse``: as for
    :func:`closest_points`).

    The normal is the barycentric interpolation (``igl.barycentric_coordinates``) of the
    per-vertex normals (:func:`per_vertex_normals`) over the closest triangle, renormalized;
    where that interpolation vanishes the triangle's face normal is used.

    Returns
    -------
    C : (k, 3) float
        Closest points, metres.
    N : (k, 3) float
        Unit normals at ``C``, oriented by the face winding.
    """
    P = _points(P)
    V, T, _ = triangulate(V, F)
    return _once("closest_with_normals", (P, V, T),
                 lambda: _closest_with_normals(P, V, T, reuse), reuse)


def _closest_with_normals(P: np.ndarray, V: np.ndarray, T: np.ndarray,
                          reuse: bool) -> tuple[np.ndarray, np.ndarray]:
    """:func:`closest_points_with_normals` of checked points and triangles."""
    _, tri, C = _once("closest", (P, V, T), lambda: igl.point_mesh_squared_distance(P, V, T),
                      reuse)
    tri = np.asarray(tri, dtype=np.int64)
    C = np.ascontiguousarray(C, dtype=np.float64)
    corners = T[tri]
    A, B, D = (np.ascontiguousarray(V[corners[:, i]]) for i in range(3))
    bary = np.asarray(igl.barycentric_coordinates(C, A, B, D))
    Nv = np.nan_to_num(np.asarray(igl.per_vertex_normals(V, T)), nan=0.0)
    N = np.einsum("ki,kij->kj", bary, Nv[corners])
    fn = np.cross(B - A, D - A)
    norm = np.linalg.norm(N, axis=1)
    bad = ~(norm > 1e-12) | ~np.all(np.isfinite(bary), axis=1)
    N[bad] = fn[bad]
    norm = np.linalg.norm(N, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        N = N / norm[:, None]
    return C, N


def principal_curvature(V: Any, F: np.ndarray | None = None,
                        radius: int = 5) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Per-vertex principal curvatures by quadric fitting (``igl.principal_curvature``).

    igl reports curvature positive for a surface bending *away* from its normal and orders
    ``PV1 >= PV2``; both are converted here to the project convention (positive towards the
    per-vertex normal of :func:`per_vertex_normals`, ``k1 <= k2``). The quadric fit
    over-estimates curvature on coarse neighbourhoods (a 2,000-vertex sphere: +1 % with
    ``radius=2``, +4 % with ``radius=5``); use a small radius on dense meshes.

    Parameters
    ----------
    V, F
        The mesh (see :func:`triangulate`).
    radius : int
        Neighbourhood size (k-ring), in units of the average edge length, igl's default 5.

    Returns
    -------
    d1, d2 : (n, 3) float
        Unit principal directions of ``k1`` and ``k2``.
    k1, k2 : (n,) float
        Principal curvatures, 1/m, ``k1 <= k2``; NaN at vertices igl flags as bad.
    """
    V, T, _ = triangulate(V, F)
    if int(radius) < 1:
        raise InputError(f"radius must be an integer >= 1, got {radius!r}")
    return _principal_curvature(V, T, int(radius))


def principal_curvature_at(V: Any, F: np.ndarray | None, vertices: np.ndarray,
                           radius: int = 5) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                     np.ndarray]:
    """:func:`principal_curvature` of the vertices ``vertices (k,)`` only: ``d1, d2 (k,3)``,
    ``k1, k2 (k,)``, the same numbers (bit for bit), computed on the part of the mesh they
    depend on.

    igl fits each vertex's quadric to its ``radius``-ring (the vertices joined to it by at
    most ``radius`` edges) with the average of their normals, each normal from the faces
    round its vertex: the triangles with a corner within the ``radius``-ring of ``vertices``
    hold all of that; of the outermost ring's normals igl reads only on which side of the
    vertex's normal they lie, so when that side is certain (:func:`_outer_ring_agrees`) the
    triangles with a corner within one ring less suffice (~half as many vertices for igl to
    fit). They are handed to igl in their order, their vertices renumbered in theirs, so
    that igl meets every neighbour in the same order and adds in the same order
    (tests/design/test_bundle_cache.py compares with the whole mesh's figures)."""
    V, T, _ = triangulate(V, F)
    if int(radius) < 1:
        raise InputError(f"radius must be an integer >= 1, got {radius!r}")
    vertices = np.asarray(vertices, dtype=np.int64).reshape(-1)
    if vertices.size and (vertices.min() < 0 or vertices.max() >= len(V)):
        raise InputError(f"vertex indices must lie in [0, {len(V) - 1}]")
    r = max(int(radius), 2)     # igl takes a radius below 2 as 2
    # one ring less when the ring's outermost normals provably face the vertex's side
    # (_outer_ring_agrees): then the triangles round those outermost vertices do not count
    rings = r - 1 if _outer_ring_agrees(V, T, vertices, r) else r
    near = np.zeros(len(V), dtype=bool)
    near[vertices] = True
    for _ in range(rings):
        near[T[near[T].any(axis=1)]] = True
    faces = near[T].any(axis=1)
    keep = np.zeros(len(V), dtype=bool)
    keep[T[faces]] = True
    if not keep[vertices].all() or 10 * keep.sum() > 9 * len(V):
        # a vertex on no triangle, or nearly all of the mesh anyway: the whole mesh
        return tuple(a[vertices] for a in _principal_curvature(V, T, int(radius)))
    old = np.flatnonzero(keep)
    new = np.full(len(V), -1, dtype=np.int64)
    new[old] = np.arange(len(old))
    d1, d2, k1, k2 = _principal_curvature(np.ascontiguousarray(V[old]),
                                          np.ascontiguousarray(new[T[faces]]), int(radius))
    at = new[vertices]
    return d1[at], d2[at], k1[at], k2[at]


def _outer_ring_agrees(V: np.ndarray, T: np.ndarray, vertices: np.ndarray, r: int) -> bool:
    """Whether igl's figures at ``vertices`` are those of the part holding only the
    triangles with a corner within their ``(r-1)``-ring (``r``: igl's k-ring radius).

    igl (principal_curvature.cpp: local mode, average normal, projection-plane check) uses
    at a vertex v: the positions of its r-ring, found breadth first over index-sorted
    adjacency lists of the vertices within r - 1 (complete in that part, their order kept by
    the renumbering), v's own vertex normal (all its triangles are in the part) and, for
    each ring vertex u, only the sign of ``n(u) . n(v)``. Every vertex normal igl computes
    is a non-negative combination of the face normals round its vertex, so that sign is
    positive with any subset of u's triangles (and with all of them) when every triangle
    near v lies within a quarter turn of every triangle round v. Checked here with a cone
    round v's triangles and a margin of 1e-6 rad, far above rounding: True only then (a
    degenerate or non-finite triangle near a vertex: False, the full part is used)."""
    n, m, k = len(V), len(T), len(vertices)
    VF = sp.csr_matrix((np.ones(3 * m, dtype=np.int32),
                        (T.reshape(-1), np.repeat(np.arange(m), 3))), shape=(n, m))
    FV = VF.T.tocsr()
    R = sp.csr_matrix((np.ones(k, dtype=np.int32), (np.arange(k), vertices)), shape=(k, n))
    for _ in range(r):      # one ring more: the corners of the triangles round the ring
        R = ((R @ VF) @ FV).astype(bool).astype(np.int32)
    near = (R @ VF).tocoo()                   # (pick, triangle with a corner in its r-ring)
    own = VF[vertices].tocoo()                # (pick, triangle round it)
    U = np.zeros((m, 3))
    used = np.zeros(m, dtype=bool)
    used[near.col] = True          # (the triangles round each vertex are among them)
    used = np.flatnonzero(used)
    t = T[used]
    e, f = V[t[:, 1]] - V[t[:, 0]], V[t[:, 2]] - V[t[:, 0]]
    fn = np.column_stack([e[:, 1] * f[:, 2] - e[:, 2] * f[:, 1],
                          e[:, 2] * f[:, 0] - e[:, 0] * f[:, 2],
                          e[:, 0] * f[:, 1] - e[:, 1] * f[:, 0]])
    length = np.sqrt((fn * fn).sum(axis=1))
    if not (np.all(length > 0) and np.all(np.isfinite(fn))):
        return False
    U[used] = fn / length[:, None]
    c = np.zeros((k, 3))
    np.add.at(c, own.row, U[own.col])
    cn = np.sqrt((c * c).sum(axis=1))
    if not np.all(cn > 0.5):     # the triangles round a vertex are far from one side
        return False
    c /= cn[:, None]
    alpha = np.zeros(k)
    np.maximum.at(alpha, own.row,
                  np.arccos(np.clip((c[own.row] * U[own.col]).sum(axis=1), -1.0, 1.0)))
    beta = np.arccos(np.clip((c[near.row] * U[near.col]).sum(axis=1), -1.0, 1.0))
    return bool(np.all(alpha[near.row] + beta < np.pi / 2 - 1e-6))


def _principal_curvature(V: np.ndarray, T: np.ndarray,
                         radius: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """:func:`principal_curvature` of a checked triangle mesh."""
    out = igl.principal_curvature(V, T, radius)
    # libigl < 2.6 returns (PD1, PD2, PV1, PV2); 2.6 appends the list of bad vertices.
    if len(out) == 5:
        pd1, pd2, pv1, pv2, bad = out
    elif len(out) == 4:
        pd1, pd2, pv1, pv2 = out
        bad = []
    else:  # pragma: no cover - a future API change lands here, in one place
        raise RuntimeError(f"igl.principal_curvature returned {len(out)} values; "
                           "update gridshell.geometry.igl_adapter.principal_curvature")
    k1, k2 = -np.asarray(pv1, dtype=float), -np.asarray(pv2, dtype=float)  # igl: PV1 >= PV2
    d1, d2 = np.array(pd1, dtype=float), np.array(pd2, dtype=float)
    bad = np.asarray(bad, dtype=np.int64)
    if bad.size:
        k1[bad] = k2[bad] = np.nan
        d1[bad] = d2[bad] = np.nan
    return d1, d2, k1, k2


# ----------------------------------------------------------------------------- parameterization


def _check_disk(V: np.ndarray, T: np.ndarray) -> np.ndarray:
    """Raise :class:`MeshError` unless ``(V, T)`` is a single disk; return its boundary loop."""
    n = len(V)
    used = np.zeros(n, dtype=bool)
    used[T.ravel()] = True
    if not used.all():
        raise MeshError(f"{int((~used).sum())} vertices belong to no face; "
                        "remove unreferenced vertices before parameterizing")
    adj = sp.coo_matrix((np.ones(3 * len(T)), (T.ravel(), np.roll(T, 1, axis=1).ravel())),
                        shape=(n, n))
    n_comp, _ = connected_components(adj, directed=False)
    if n_comp != 1:
        raise MeshError(f"mesh has {n_comp} connected components; parameterize one disk at a time")
    manifold = igl.is_edge_manifold(T)
    if not (manifold[0] if isinstance(manifold, tuple) else manifold):
        raise MeshError("mesh is not edge-manifold; repair it (e.g. remove duplicate faces)")
    # Undirected edges used once are boundary edges.
    E = np.sort(np.concatenate([T[:, [0, 1]], T[:, [1, 2]], T[:, [2, 0]]]), axis=1)
    _, counts = np.unique(E, axis=0, return_counts=True)
    n_boundary = int(np.sum(counts == 1))
    chi = int(igl.euler_characteristic(T))
    if n_boundary == 0:
        raise MeshError("mesh is closed (no boundary); cut it open into a disk before "
                        "parameterizing")
    loop = np.asarray(igl.boundary_loop(T), dtype=np.int64)
    if chi != 1 or len(loop) != n_boundary:
        raise MeshError(f"mesh is not a disk (Euler characteristic {chi}, {n_boundary} boundary "
                        f"edges, longest boundary loop {len(loop)}); fill holes or cut handles "
                        "so that exactly one boundary loop remains")
    return loop


def parameterize_disk(V: Any, F: np.ndarray | None = None,
                      method: Literal["lscm", "harmonic"] = "lscm",
                      normalize: bool = True) -> np.ndarray:
    """Parameterize a disk-topology mesh in the plane.

    ``"lscm"`` (default): least-squares conformal map (``igl.lscm``) with a free boundary and
    two fixed boundary vertices (the farthest-apart pair found by a double sweep), mapped to
    ``(0, 0)`` and ``(1, 0)``. ``"harmonic"``: cotangent-harmonic map (``igl.harmonic``) with
    the boundary loop on the unit circle, spaced by arc length (cotangent weights can flip
    triangles on meshes with very obtuse angles; LSCM is the safer choice).

    With ``normalize`` the result is rotated to its principal axes, mirrored if needed so
    that every triangle keeps its orientation, and scaled per axis onto ``[0, 1]^2`` - ready
    for :func:`gridshell.geometry.bspline.fit_points` (first coordinate -> ``u``).

    Parameters
    ----------
    V, F
        The mesh (see :func:`triangulate`), one connected disk.
    method : {"lscm", "harmonic"}
    normalize : bool

    Returns
    -------
    UV : (n, 2) float
        Parameters of the vertices (dimensionless if normalized, metres otherwise for LSCM).

    Raises
    ------
    MeshError
        If the mesh is not a single edge-manifold disk or has unreferenced vertices.
    """
    V, T, _ = triangulate(V, F)
    loop = _check_disk(V, T)
    if method == "lscm":
        # Double sweep on the boundary for a far-apart pair of fixed vertices.
        Vb = V[loop]
        i0 = int(np.argmax(np.linalg.norm(Vb - Vb[0], axis=1)))
        i1 = int(np.argmax(np.linalg.norm(Vb - Vb[i0], axis=1)))
        b = np.array([loop[i0], loop[i1]], dtype=np.int64)
        bc = np.array([[0.0, 0.0], [1.0, 0.0]])
        out = igl.lscm(V, T, b, bc)
        UV = np.asarray(out[0] if isinstance(out, tuple) else out, dtype=float)
    elif method == "harmonic":
        seg = np.linalg.norm(V[np.roll(loop, -1)] - V[loop], axis=1)
        ang = 2.0 * np.pi * np.concatenate([[0.0], np.cumsum(seg)[:-1]]) / seg.sum()
        bc = np.ascontiguousarray(np.stack([np.cos(ang), np.sin(ang)], axis=1))
        UV = np.asarray(igl.harmonic(V, T, loop, bc, 1), dtype=float)
    else:
        raise InputError(f"method must be 'lscm' or 'harmonic', got {method!r}")
    if not np.all(np.isfinite(UV)):
        raise MeshError("parameterization failed (non-finite result); the mesh may have "
                        "degenerate triangles - remove zero-area faces")
    if normalize:
        C = UV - UV.mean(axis=0)
        _, _, Vt = np.linalg.svd(C, full_matrices=False)
        UV = C @ Vt.T
        if _signed_areas(UV, T).sum() < 0:
            UV[:, 1] = -UV[:, 1]
        lo, hi = UV.min(axis=0), UV.max(axis=0)
        UV = (UV - lo) / np.where(hi > lo, hi - lo, 1.0)
    return UV


def cotangent_laplacian(V: Any, F: np.ndarray | None = None) -> sp.csr_matrix:
    """Cotangent Laplacian ``L (n, n)`` of a mesh (``igl.cotmatrix``), sign flipped to be
    positive semi-definite: ``x^T L x`` is twice the Dirichlet energy of the piecewise-linear
    ``x`` (1/m^0: cotangent weights are dimensionless). Quads are split first."""
    V, T, _ = triangulate(V, F)
    return sp.csr_matrix(-igl.cotmatrix(V, T))


def _signed_areas(UV: np.ndarray, T: np.ndarray) -> np.ndarray:
    """Signed areas ``(t,)`` of triangles in the plane (positive = counter-clockwise)."""
    a, b, c = UV[T[:, 0]], UV[T[:, 1]], UV[T[:, 2]]
    ab, ac = b - a, c - a
    return 0.5 * (ab[:, 0] * ac[:, 1] - ab[:, 1] * ac[:, 0])


def flipped_triangles(UV: np.ndarray, V: Any, F: np.ndarray | None = None) -> np.ndarray:
    """Indices of triangles (of :func:`triangulate`) whose orientation a parameterization flips.

    Parameters
    ----------
    UV : (n, 2) float
        Vertex parameters.
    V, F
        The mesh.

    Returns
    -------
    idx : (f,) int64
        Triangles with non-positive signed area in ``UV`` (empty for a bijective map of a
        consistently oriented disk).
    """
    _, T, _ = triangulate(V, F)
    UV = np.asarray(UV, dtype=float)
    if UV.ndim != 2 or UV.shape[1] != 2 or UV.shape[0] <= T.max():
        raise InputError(f"UV must have shape (n, 2) for the mesh's vertices, got {UV.shape}")
    return np.flatnonzero(_signed_areas(UV, T) <= 0)
