"""Regular grids: the rows and columns of a structured quad mesh as index arrays.

Convention: a grid of ``rows x cols`` vertices has vertex ``G[i, j]``; ``j`` runs along the
first parameter direction (x) and ``i`` along the second (y). Face ``(i, j)`` is
``[G[i,j], G[i,j+1], G[i+1,j+1], G[i+1,j]]``: counter-clockwise seen from +z when the grid
lies in the xy-plane with x growing with ``j`` and y with ``i``.
"""
from __future__ import annotations

import numpy as np

from gridshell.core.errors import MeshError

_FIX = "remesh it as a grid or pass a triangle mesh so the tool builds one"


def _not_grid(why: str) -> MeshError:
    return MeshError(f"not a structured quad grid: {why}; {_FIX}")


def grid_quads(rows: int, cols: int) -> np.ndarray:
    """Quads ``(m,4)`` int64, ``m = (rows-1)(cols-1)``, of a ``rows x cols`` vertex grid.

    Vertex ``(i, j)`` has index ``i*cols + j``; face ``(i, j)`` (row-major) is
    ``[(i,j), (i,j+1), (i+1,j+1), (i+1,j)]``, counter-clockwise seen from +z when ``j``
    runs along x and ``i`` along y.
    """
    if rows < 2 or cols < 2:
        raise MeshError(f"a grid needs at least 2 x 2 vertices, got {rows} x {cols}; "
                        "ask for more rows and columns")
    G = np.arange(rows * cols, dtype=np.int64).reshape(rows, cols)
    return np.stack([G[:-1, :-1], G[:-1, 1:], G[1:, 1:], G[1:, :-1]], axis=-1).reshape(-1, 4)


def _halfedges(F: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The halfedges of quads ``F (m, 4)`` over ``n`` vertices: source and target vertex,
    next halfedge in the face and the opposite halfedge (-1 on the boundary), each ``(4m,)``;
    halfedge ``4f+c`` runs from corner ``c`` to ``c+1`` of face ``f``."""
    m = len(F)
    src = F.ravel()
    dst = np.roll(F, -1, axis=1).ravel()
    h = np.arange(4 * m)
    nxt = h - h % 4 + (h + 1) % 4
    # opposite halfedges by key matching
    key = src * np.int64(n) + dst
    order = np.argsort(key, kind="stable")
    skey = key[order]
    if np.any(skey[1:] == skey[:-1]):
        raise _not_grid("an edge is used twice in the same direction (non-manifold or "
                        "inconsistently oriented faces)")
    rkey = dst * np.int64(n) + src
    pos = np.minimum(np.searchsorted(skey, rkey), len(skey) - 1)
    opp = np.where(skey[pos] == rkey, order[pos], -1)
    return src, dst, nxt, opp


def grid_from_quads(F: np.ndarray, n_vertices: int) -> np.ndarray:
    """Recover the vertex grid ``G (R, C)`` int64 of a quad mesh that is a regular grid.

    Long because the walk and its checks (each a named refusal) read best in one place; the
    halfedges are built by :func:`_halfedges`.

    Works on a halfedge structure of ``F`` (halfedge ``4f+c`` runs from corner ``c`` to
    ``c+1`` of face ``f``): from a corner vertex, base halfedges are propagated down the
    first column and then across all rows at once, one column step at a time.

    ``G[0, 0]`` is the corner vertex of smallest index and ``G[0, 1]`` follows it in its face's
    orientation, so ``F`` equals ``G[grid_quads(R, C)]`` up to face order and rotation; for
    ``F = grid_quads(R, C)`` the result is ``arange(R*C).reshape(R, C)``.

    Parameters
    ----------
    F : (m,4) int
        Quads, consistently oriented.
    n_vertices : int
        Number of vertices; all must be used by the grid.

    Raises
    ------
    MeshError
        If the mesh is not topologically a regular R x C grid (a disk whose interior vertices
        have valence 4 and with four corner vertices of valence 2).
    """
    F = np.asarray(F, dtype=np.int64)
    if F.ndim != 2 or F.shape[1] != 4 or len(F) == 0:
        raise _not_grid(f"expected quads F (m,4), got shape {F.shape}")
    n, m = int(n_vertices), len(F)
    if F.min() < 0 or F.max() >= n:
        raise _not_grid("face indices are out of range")
    src, dst, nxt, opp = _halfedges(F, n)

    # valences: number of distinct neighbours over edges
    lo, hi = np.minimum(src, dst), np.maximum(src, dst)
    E = np.unique(lo * np.int64(n) + hi)
    valence = np.bincount(np.concatenate([E // n, E % n]), minlength=n)
    corners = np.flatnonzero(valence == 2)
    if len(corners) != 4:
        raise _not_grid(f"{len(corners)} vertices of valence 2, a grid has 4 corners")
    c = corners[0]
    b0 = np.flatnonzero(src == c)
    if len(b0) != 1:
        raise _not_grid(f"corner vertex {c} lies in {len(b0)} faces, expected 1")
    # first column of base halfedges: b(i+1, 0) = opp(next(next(b(i, 0))))
    col = [int(b0[0])]
    while True:
        o = opp[nxt[nxt[col[-1]]]]
        if o < 0:
            break
        col.append(int(o))
        if len(col) > m:
            raise _not_grid("the faces of the first column form a cycle (cylinder or torus)")
    B = [np.asarray(col)]
    # column steps, all rows at once: b(i, j+1) = next(opp(next(b(i, j))))
    while True:
        o = opp[nxt[B[-1]]]
        if np.all(o < 0):
            break
        if np.any(o < 0):
            raise _not_grid("the rows of faces have different lengths")
        B.append(nxt[o])
        if len(B) * len(col) > m:
            raise _not_grid("the faces of a row form a cycle, or the mesh has extra faces")
    B = np.stack(B, axis=1)  # (R-1, C-1) base halfedges
    r1, c1 = B.shape
    if r1 * c1 != m or len(np.unique(B // 4)) != m:
        raise _not_grid(f"walking the grid reached {r1} x {c1} faces of {m}")
    R, C = r1 + 1, c1 + 1
    G = np.empty((R, C), dtype=np.int64)
    G[:-1, :-1] = src[B]
    G[:-1, -1] = dst[B[:, -1]]
    G[-1, :-1] = src[nxt[nxt[nxt[B[-1]]]]]
    G[-1, -1] = dst[nxt[B[-1, -1]]]
    if R * C != n or len(np.unique(G)) != n:
        raise _not_grid(f"the {R} x {C} grid walked does not use each of the {n} vertices "
                        "exactly once")
    # the walk must reproduce F exactly (same faces, same orientation)
    Q = G.ravel()[grid_quads(R, C)]
    Fwalk = np.stack([src[B], dst[B], dst[nxt[B]], src[nxt[nxt[nxt[B]]]]], axis=-1).reshape(-1, 4)
    if not np.array_equal(Q, Fwalk):
        raise _not_grid("faces do not close up as a grid")
    return G


def grid_polylines(G: np.ndarray) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """The two families of grid polylines as vertex-index arrays.

    Parameters
    ----------
    G : (R, C) int
        Vertex grid, e.g. from :func:`grid_from_quads`.

    Returns
    -------
    rows : list of (C,) int64
        ``rows[i] = G[i, :]``.
    cols : list of (R,) int64
        ``cols[j] = G[:, j]``.
    """
    G = np.asarray(G, dtype=np.int64)
    if G.ndim != 2:
        raise MeshError(f"a vertex grid must be a 2D index array, got shape {G.shape}")
    return [G[i].copy() for i in range(G.shape[0])], [G[:, j].copy() for j in range(G.shape[1])]
