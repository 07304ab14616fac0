"""A working copy of a big target: the design samples and projects onto a mesh of at most
:data:`WORKING_FACES` faces, while the deviations are measured against the full mesh.

A 200k-triangle target made ``gg`` spend most of its time on the target (the parameterization
and harmonic maps of the initial grid, closest-point queries every round) although its design
grid has a few thousand vertices. A triangle mesh is decimated by pymeshlab's quadric edge
collapse would keep boundary and topology but costs ~5 s of CPU on 200k triangles, as much as
the whole design; pymeshlab's vertex clustering costs ~0.3 s, so it comes first, with a cell
size for about :data:`WORKING_FACES` faces, and its result is used when it is one manifold,
consistently oriented disk (a cluster can pinch an edge: then a slightly different cell, then
the quadric collapse). Its vertices move by less than a cell (measured on a 200k-triangle
hill: 0.004 % of the diagonal at most). A structured quad grid keeps every k-th row and
column (the last ones included), so it stays a grid.
"""
from __future__ import annotations

from typing import Any

import numpy as np

#: a target with more faces is replaced by a working copy of about this many for the design
WORKING_FACES = 10_000


def working_mesh(V: np.ndarray, F: np.ndarray, max_faces: int = WORKING_FACES
                 ) -> tuple[np.ndarray, np.ndarray, dict[str, Any] | None]:
    """``(V, F, info)``: the mesh itself when it has at most ``max_faces`` faces (``info``
    None), else a coarser copy (metres) and ``info`` = ``{"faces": [full, working],
    "method"}``."""
    F = np.asarray(F, dtype=np.int64)
    if len(F) <= max_faces:
        return V, F, None
    if F.shape[1] == 4:
        from gridshell.core.errors import MeshError
        from gridshell.geometry.grid import grid_from_quads, grid_quads

        try:
            G = grid_from_quads(F, len(V))
        except MeshError:
            return V, F, None  # unstructured quads: gg refuses them anyway
        R, C = G.shape
        step = int(np.ceil(np.sqrt(len(F) / max_faces)))
        rows = np.unique(np.r_[np.arange(0, R, step), R - 1])
        cols = np.unique(np.r_[np.arange(0, C, step), C - 1])
        Gw = G[np.ix_(rows, cols)]
        Vw = np.asarray(V, float)[Gw.ravel()]
        return Vw, grid_quads(len(rows), len(cols)), {
            "faces": [int(len(F)), int((len(rows) - 1) * (len(cols) - 1))],
            "method": f"every {step}th grid line"}
    return _decimate(np.asarray(V, float), F, max_faces)


def _decimate(V: np.ndarray, T: np.ndarray, max_faces: int
              ) -> tuple[np.ndarray, np.ndarray, dict[str, Any] | None]:
    import pymeshlab

    from gridshell.core.errors import MeshError
    from gridshell.measure.metrics import surface_area
    from gridshell.geometry.quadmesh import bbox_diagonal, validate_mesh
    from gridshell.io.read import check_disk

    diag = bbox_diagonal(V)
    cell = np.sqrt(2.0 * surface_area(V, T) / max_faces)
    for factor in (1.0, 1.13, 1.27):
        ms = pymeshlab.MeshSet()
        ms.add_mesh(pymeshlab.Mesh(vertex_matrix=V, face_matrix=T.astype(np.int32)))
        ms.meshing_decimation_clustering(
            threshold=pymeshlab.PercentageValue(100.0 * factor * cell / diag))
        try:  # a cluster may pinch an edge or a vertex: split there, keep the largest piece
            ms.meshing_repair_non_manifold_edges(method=1)
            ms.meshing_repair_non_manifold_vertices()
        except pymeshlab.PyMeshLabException:  # pragma: no cover
            continue
        m = ms.current_mesh()
        Vw, Tw = _largest_piece(np.asarray(m.vertex_matrix(), dtype=np.float64),
                                np.asarray(m.face_matrix(), dtype=np.int64))
        try:
            validate_mesh(Vw, Tw, name="working mesh")
            check_disk(Vw, Tw, "working mesh", weld_hint=False)
        except MeshError:
            continue
        if _same_side(V, T, Vw, Tw):
            return Vw, Tw, {"faces": [int(len(T)), int(len(Tw))], "method": "vertex clustering"}
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=V, face_matrix=T.astype(np.int32)))
    try:
        ms.meshing_decimation_quadric_edge_collapse(
            targetfacenum=int(max_faces), preserveboundary=True, preservetopology=True)
    except pymeshlab.PyMeshLabException:  # pragma: no cover - keep the full mesh
        return V, T, None
    m = ms.current_mesh()
    Vw = np.asarray(m.vertex_matrix(), dtype=np.float64)
    Tw = np.asarray(m.face_matrix(), dtype=np.int64)
    return Vw, Tw, {"faces": [int(len(T)), int(len(Tw))], "method": "quadric edge collapse"}


def _largest_piece(V: np.ndarray, T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The connected piece of ``(V, T)`` with the most faces, its vertices renumbered."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    from gridshell.geometry.quadmesh import unique_ints

    n = len(V)
    src, dst = T.ravel(), np.roll(T, -1, axis=1).ravel()
    _, label = connected_components(coo_matrix((np.ones(len(src)), (src, dst)), shape=(n, n)),
                                    directed=False)
    face_label = label[T[:, 0]]
    best = np.bincount(face_label).argmax()
    T = T[face_label == best]
    used = unique_ints(T)
    renum = np.full(n, -1, np.int64)
    renum[used] = np.arange(len(used))
    return V[used], renum[T]


def _same_side(V: np.ndarray, T: np.ndarray, Vw: np.ndarray, Tw: np.ndarray) -> bool:
    """Whether the working mesh faces the way the target does (summed vector areas agree)."""
    def vec_area(X: np.ndarray, F: np.ndarray) -> np.ndarray:
        return np.cross(X[F[:, 1]] - X[F[:, 0]], X[F[:, 2]] - X[F[:, 0]]).sum(axis=0)

    return float(vec_area(V, T) @ vec_area(Vw, Tw)) > 0
