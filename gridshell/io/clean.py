"""Cleaning a user's mesh through pymeshlab: weld coincident vertices, drop duplicate faces and
unreferenced vertices, orient the faces consistently (before the disk / manifold checks).

pymeshlab (MeshLab's filters) works on triangles. Polygons are kept as polygons: each polygon is
fanned into triangles that carry its index as their face quality and every vertex carries its
own index as vertex quality; after pymeshlab's filters the polygons are rebuilt from the
original ones, with the surviving vertices (found by those indices; a welded vertex maps to the
survivor within the weld tolerance) and each polygon flipped when pymeshlab flipped its
triangles. Coordinates stay exact: each welded vertex is the first copy of its group in the
file (its float64 coordinates and its place in the order).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gridshell.core.errors import MeshError

#: vertices closer than this fraction of the mean edge length are welded
WELD_TOLERANCE = 1e-3


@dataclass
class CleanReport:
    """What :func:`clean_mesh` did: vertex and face counts before and after, and one line each."""

    vertices: tuple[int, int]
    faces: tuple[int, int]
    welded: int = 0
    duplicate_faces: int = 0
    degenerate_faces: int = 0
    unreferenced: int = 0
    flipped: int = 0
    tolerance: float = 0.0
    lines: list[str] = field(default_factory=list)

    def summary(self) -> str:
        """One line: ``"welded 9216 -> 1617 vertices, dropped 3 duplicate faces"`` or
        ``"nothing to clean"``."""
        return ", ".join(self.lines) or "nothing to clean"

    def to_json(self) -> dict:
        return {"vertices": list(self.vertices), "faces": list(self.faces),
                "welded": self.welded, "duplicate_faces": self.duplicate_faces,
                "degenerate_faces": self.degenerate_faces, "unreferenced": self.unreferenced,
                "flipped": self.flipped, "tolerance_m": self.tolerance,
                "summary": self.summary()}


def mean_edge_length(V: np.ndarray, P: np.ndarray, sizes: np.ndarray) -> float:
    """Mean length of the polygon edges of ``V (n,3)``, padded faces ``P (m,k)`` (metres)."""
    m, k = P.shape
    if m == 0:
        return 0.0
    j = np.arange(k)[None, :]
    nxt = np.where(j + 1 < sizes[:, None], j + 1, 0)
    a = P
    b = np.take_along_axis(P, nxt, axis=1)
    ok = j < sizes[:, None]
    d = np.linalg.norm(V[a[ok]] - V[b[ok]], axis=1)
    return float(d.mean()) if len(d) else 0.0


def coincident_vertices(V: np.ndarray, tol: float, P: np.ndarray | None = None) -> int:
    """How many vertices of ``V (n,3)`` lie within ``tol`` of an earlier vertex (0 for a welded
    mesh; about two thirds of them for a triangle soup). With faces ``P (m,k)`` (padded), pairs
    already joined by an edge do not count: they are a degenerate face, not an unwelded seam,
    and welding them would collapse faces."""
    from scipy.spatial import cKDTree

    if len(V) < 2:
        return 0
    pairs = cKDTree(V).query_pairs(max(tol, 0.0), output_type="ndarray")
    if len(pairs) and P is not None and len(P):
        from gridshell.geometry.quadmesh import _face_edges

        a, b, _ = _face_edges(P)
        n = np.int64(len(V))
        edges = np.minimum(a, b) * n + np.maximum(a, b)
        key = np.minimum(pairs[:, 0], pairs[:, 1]) * n + np.maximum(pairs[:, 0], pairs[:, 1])
        pairs = pairs[~np.isin(key, edges)]
    return int(len(np.unique(pairs[:, 1]))) if len(pairs) else 0


def _fan(P: np.ndarray, sizes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Triangles ``(t,3)`` fanning each padded polygon from its first vertex, and the polygon of
    each triangle ``(t,)``."""
    tris, owner = [], []
    for j in range(1, int(sizes.max(initial=3)) - 1):
        rows = np.flatnonzero(sizes > j + 1)
        tris.append(np.stack([P[rows, 0], P[rows, j], P[rows, j + 1]], axis=1))
        owner.append(rows)
    return np.concatenate(tris), np.concatenate(owner)


def clean_mesh(V: np.ndarray, P: np.ndarray, sizes: np.ndarray, *, name: str = "mesh",
               tolerance: float = WELD_TOLERANCE
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray, CleanReport]:
    """Weld, de-duplicate and orient a polygon mesh with pymeshlab, keeping its polygons.

    Parameters
    ----------
    V : (n,3) float
        Vertices, metres.
    P : (m,k) int
        Faces padded with -1 (``sizes`` gives each face's vertex count).
    sizes : (m,) int
    name : str
        For messages.
    tolerance : float
        Weld distance as a fraction of the mean edge length.

    Returns
    -------
    V, P, sizes : the cleaned mesh (each vertex the first copy of its welded group, in file
        order; faces in file order among the kept ones)
    report : CleanReport
    """
    V = np.asarray(V, dtype=np.float64)
    P = np.asarray(P, dtype=np.int64)
    sizes = np.asarray(sizes, dtype=np.int64)
    n0, m0 = len(V), len(P)
    tol = tolerance * mean_edge_length(V, P, sizes)
    weld = coincident_vertices(V, tol, P) > 0
    if not weld and not needs_cleaning(V, P, sizes, tol, check_weld=False):  # the usual case: welded, oriented
        return V, P, sizes, CleanReport(vertices=(n0, n0), faces=(m0, m0), tolerance=tol)
    T, owner = _fan(P, sizes)
    keep, Tn, born = _pymeshlab_clean(V, T, owner, weld, tol, name)
    vmap = _vertex_map(V, keep, tol)
    kept, Pm, sz, flipped = _oriented_polygons(P, sizes, T, Tn, born, vmap)
    keep_rows, dup, degenerate = _collapsed_and_repeated(P[kept], Pm, sz)
    dup += m0 - len(kept)
    Pm, sz, flipped = Pm[keep_rows], sz[keep_rows], flipped[keep_rows]
    Vout, Pout = _first_copy_numbering(V, Pm, vmap, len(keep))
    rep = _report(P, len(keep), (n0, len(Vout)), (m0, len(Pout)), tol, dup, degenerate,
                  int(flipped.sum()))
    return Vout, Pout, sz, rep


def _pymeshlab_clean(V: np.ndarray, T: np.ndarray, owner: np.ndarray, weld: bool, tol: float,
                     name: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """pymeshlab's weld (within ``tol`` m when ``weld``), duplicate faces, unreferenced
    vertices and coherent orientation of the fan triangles ``T`` (of the polygons ``owner``):
    ``(keep, Tn, born)``, the original index of each surviving vertex, the surviving
    triangles in survivor numbering and the polygon each came from."""
    import pymeshlab

    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=V, face_matrix=T.astype(np.int32),
                               v_scalar_array=np.arange(len(V), dtype=np.float64),
                               f_scalar_array=owner.astype(np.float64)))
    try:
        if weld:  # exact copies first: fast, and fewer to merge
            ms.meshing_remove_duplicate_vertices()
        if weld and tol > 0:
            ms.meshing_merge_close_vertices(threshold=pymeshlab.PureValue(tol))
        ms.meshing_remove_duplicate_faces()
        ms.meshing_remove_unreferenced_vertices()
    except pymeshlab.PyMeshLabException as exc:  # pragma: no cover - filters on valid arrays
        msg = " ".join(str(exc).split())
        raise MeshError(f"{name}: cleaning the mesh failed ({msg}); repair it in the modeller "
                        "or pass --no-clean") from None
    try:
        ms.meshing_re_orient_faces_coherently()
    except pymeshlab.PyMeshLabException:
        pass  # not manifold: nothing to orient; the mesh checks name the non-manifold part
    cm = ms.current_mesh()
    keep = np.rint(cm.vertex_scalar_array()).astype(np.int64)  # original index of survivors
    Tn = cm.face_matrix().astype(np.int64)                     # in survivor numbering
    born = np.rint(cm.face_scalar_array()).astype(np.int64)    # polygon of each triangle
    return keep, Tn, born


def _vertex_map(V: np.ndarray, keep: np.ndarray, tol: float) -> np.ndarray:
    """Every original vertex -> a survivor (index into ``keep``): itself, or the nearest
    survivor within ``tol`` m (a welded one); -1 for none."""
    vmap = np.full(len(V), -1, np.int64)
    vmap[keep] = np.arange(len(keep))
    lost = np.flatnonzero(vmap < 0)
    if len(lost) and len(keep):
        from scipy.spatial import cKDTree

        dist, near = cKDTree(V[keep]).query(V[lost])
        vmap[lost] = np.where(dist <= max(tol, 0.0) * (1 + 1e-9), near, -1)
    return vmap


def _oriented_polygons(P: np.ndarray, sizes: np.ndarray, T: np.ndarray, Tn: np.ndarray,
                       born: np.ndarray, vmap: np.ndarray
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(kept, Pm, sz, flipped)``: the polygons with a surviving triangle (their rows of
    ``P``), in survivor numbering, reversed where pymeshlab flipped that triangle (the side
    most faces of the input face kept), their sizes and whether each was flipped."""
    first = np.full(len(P), -1, np.int64)
    first[born[::-1]] = np.arange(len(born))[::-1]
    kept = np.flatnonzero(first >= 0)
    Pm = np.where(P[kept] >= 0, vmap[np.maximum(P[kept], 0)], -1)
    Pm[P[kept] < 0] = -1
    sz = sizes[kept]
    tri_orig = T[first[kept]]  # the surviving triangle, original numbering and orientation
    flipped = ~_same_cycle(vmap[tri_orig], Tn[first[kept]])
    if flipped.sum() > len(flipped) / 2:  # keep the side most faces of the input face
        flipped = ~flipped
    j = np.arange(Pm.shape[1])[None, :]
    rev = np.where(j < sz[:, None], sz[:, None] - 1 - j, j)
    Pm = np.where(flipped[:, None], np.take_along_axis(Pm, rev, axis=1), Pm)
    return kept, Pm, sz, flipped


def _collapsed_and_repeated(P0: np.ndarray, Pm: np.ndarray, sz: np.ndarray
                            ) -> tuple[np.ndarray, int, int]:
    """``(keep_rows, duplicates, degenerate)`` of the polygons ``Pm`` (``P0`` the same rows
    before the weld): drop those the weld collapsed (a vertex twice; a face repeating a vertex
    in the file is left for the checks to name) or without a vertex, and the second copy of
    each polygon pymeshlab's duplicates left twice."""
    inside = np.arange(Pm.shape[1])[None, :] < sz[:, None]
    big = np.iinfo(np.int64).max
    S = np.sort(np.where(inside, Pm, big), axis=1)
    S0 = np.sort(np.where(inside, P0, big), axis=1)
    repeat = ((np.diff(S, axis=1) == 0) & (S[:, 1:] != big)).any(axis=1)
    repeat &= ~((np.diff(S0, axis=1) == 0) & (S0[:, 1:] != big)).any(axis=1)
    valid = ~repeat & (np.where(inside, Pm, 0) >= 0).all(axis=1)
    _, first_key = np.unique(S, axis=0, return_index=True)
    unique = np.zeros(len(Pm), bool)
    unique[first_key] = True
    return valid & unique, int((valid & ~unique).sum()), int((~valid).sum())


def _first_copy_numbering(V: np.ndarray, Pm: np.ndarray, vmap: np.ndarray,
                          n_keep: int) -> tuple[np.ndarray, np.ndarray]:
    """``(V, P)`` renumbered canonically: each welded vertex is its first copy in the file (its
    coordinates, its place in the order), so a grid exported face by face keeps its first
    corner first (:func:`gridshell.geometry.grid.grid_from_quads` starts from the corner of
    smallest index); survivors no polygon uses are left out."""
    used = np.zeros(n_keep, bool)
    used[Pm[Pm >= 0]] = True
    first_copy = np.full(n_keep, np.iinfo(np.int64).max)
    ok = vmap >= 0
    np.minimum.at(first_copy, vmap[ok], np.flatnonzero(ok))
    surv = np.flatnonzero(used)
    order = surv[np.argsort(first_copy[surv], kind="stable")]
    renum = np.full(n_keep, -1, np.int64)
    renum[order] = np.arange(len(order))
    return V[first_copy[order]], np.where(Pm >= 0, renum[np.maximum(Pm, 0)], -1)


def _report(P: np.ndarray, n_keep: int, vertices: tuple[int, int], faces: tuple[int, int],
            tol: float, dup: int, degenerate: int, flipped: int) -> CleanReport:
    """The :class:`CleanReport` of a cleaning (``vertices``, ``faces``: counts before and
    after; ``n_keep`` vertices survived pymeshlab) with its summary lines."""
    n0 = vertices[0]
    unref = _unreferenced_count(P, n0)
    rep = CleanReport(vertices=vertices, faces=faces, tolerance=tol, duplicate_faces=dup,
                      degenerate_faces=degenerate, unreferenced=unref, flipped=flipped)
    rep.welded = max(n0 - n_keep - unref, 0)
    if rep.welded:
        rep.lines.append(f"welded {n0} -> {n0 - rep.welded} vertices")
    if rep.unreferenced:
        rep.lines.append(f"removed {rep.unreferenced} unreferenced vertices")
    if dup:
        rep.lines.append(f"dropped {dup} duplicate faces")
    if degenerate:
        rep.lines.append(f"dropped {degenerate} faces the weld collapsed")
    if rep.flipped:
        rep.lines.append(f"flipped {rep.flipped} faces to a consistent orientation")
    return rep


def needs_cleaning(V: np.ndarray, P: np.ndarray, sizes: np.ndarray, tol: float,
                   check_weld: bool = True) -> bool:
    """Whether :func:`clean_mesh` has anything to do: coincident vertices (within ``tol``,
    metres), duplicate faces, unreferenced vertices or inconsistently oriented faces. Cheap
    (numpy), so a clean mesh never goes through pymeshlab."""
    from gridshell.geometry.meshfile import orientation_problem

    if _unreferenced_count(P, len(V)) or (check_weld and coincident_vertices(V, tol, P)):
        return True
    j = np.arange(P.shape[1])[None, :]
    S = np.sort(np.where(j < sizes[:, None], P, -1), axis=1)
    if len(S) > 1:
        order = np.lexsort(S.T[::-1])
        if (np.diff(S[order], axis=0) == 0).all(axis=1).any():
            return True
    return orientation_problem(P, len(V)) is not None


def _unreferenced_count(P: np.ndarray, n: int) -> int:
    used = np.zeros(n, bool)
    used[P[P >= 0]] = True
    return int((~used).sum())


def _same_cycle(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise: is triangle ``b`` a rotation of triangle ``a`` (same orientation)?"""
    return ((a == b).all(axis=1) | (a == np.roll(b, 1, axis=1)).all(axis=1)
            | (a == np.roll(b, 2, axis=1)).all(axis=1))
