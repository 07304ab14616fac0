"""A lamella as built: its material frame along the axis and a closed solid of width x thickness.

A lamella is a thin flat strip of width ``w`` and thickness ``t`` (metres, real size) whose
centre line is the lamella axis. Its cross-section is spanned by

- the **width direction** ``W``: in the surface, ``n x T``, for tangent lamellae (GG, paper
  Fig. 6 centre); the surface normal ``n`` (made orthogonal to ``T``) for lamellae standing
  on the surface (NCP / CNC / AA, Fig. 6 left);
- the **thickness direction** ``H = T x W``,

with ``T`` the unit tangent of the axis and ``n`` the surface normal at each axis point. The
renderer, the WebGL viewer, the Rhino export and the structural check all take the strip's
geometry from here, so that what is drawn, exported and checked is the strip that is cut.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from gridshell.core.errors import InputError
from gridshell.core.recent import Recent, array_key
from gridshell.geometry.vectors import unit_rows as _unit

__all__ = ["TANGENT_KINDS", "is_tangent", "nearest_vertex_normals", "strip_frame",
           "strip_frames", "packed_strip_frames", "strip_solid", "strip_solid_faces",
           "solid_rings", "solid_rings_many", "ring_tolerance", "real_section_m"]

#: design kinds whose lamellae lie tangent to the surface (the others stand on it)
TANGENT_KINDS = ("GG",)
#: the surfaces of :func:`nearest_vertex_normals` in this process (normals, k-d tree), by
#: content; the values are read only, so each caller gets them as they are (no copies)
_SURFACES = Recent(2, copy=lambda v: v)


def is_tangent(kind: str) -> bool:
    """True when lamellae of a design of ``kind`` ("GG", "NCP", "CNC", "AA") lie tangent to
    the surface."""
    return str(kind).upper() in TANGENT_KINDS


def nearest_vertex_normals(P: np.ndarray, V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """Unit normals ``(k,3)`` at points ``P (k,3)``: the area-weighted vertex normal of the
    closest vertex of the surface ``V (n,3)``, ``F (m,3|4)`` (only vertices used by a face).

    The surface's side of it (the used vertices' normals and their k-d tree) is kept for the
    last few surfaces of this process, by content (:func:`_surface_lookup`): the picture and the
    report's viewer of one bundle ask about the same surface."""
    V = np.asarray(V, float).reshape(-1, 3)
    F = np.asarray(F, np.int64)
    if not len(V) or not F.size:
        raise InputError("the surface is empty; a strip's frame needs the surface mesh")
    N, tree = _surface_lookup(V, F)
    _, idx = tree.query(np.asarray(P, float).reshape(-1, 3))
    return N[idx]


def _surface_lookup(V: np.ndarray, F: np.ndarray) -> tuple[np.ndarray, Any]:
    """The unit area-weighted normals ``(u,3)`` of the vertices of ``V (n,3)`` used by the
    faces ``F`` and a ``cKDTree`` of those vertices; the same objects again for a surface of the
    same content (dtype, shape and bytes of ``V`` and ``F``). Both are read only: the normals
    are not writeable and a query does not change a tree."""
    from scipy.spatial import cKDTree

    from gridshell.geometry.quadmesh import area_weighted_vertex_normals, unique_ints

    key = array_key(V, F)
    hit = _SURFACES.get(key)
    if hit is not None:
        return hit
    used = unique_ints(F[F >= 0])
    N = area_weighted_vertex_normals(V, F)[used]
    N.flags.writeable = False
    out = (N, cKDTree(V[used]))
    _SURFACES.put(key, out)
    return out


def strip_frame(axis: np.ndarray, normals: np.ndarray, tangent: bool
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The strip's frame ``(T, W, H)``, each ``(k,3)`` unit vectors, at the axis points.

    Parameters
    ----------
    axis : (k,3) float
        Lamella axis polyline, metres (k >= 2).
    normals : (k,3) float
        Surface normals at the axis points (any length).
    tangent : bool
        True: width in the surface (``W = n x T``, GG); False: width along the normal
        (``W = n - (n.T) T``, lamellae standing on the surface).
    """
    P = np.asarray(axis, float).reshape(-1, 3)
    N = np.asarray(normals, float).reshape(-1, 3)
    if len(P) != len(N):
        raise InputError(f"strip frame: {len(P)} axis points but {len(N)} normals")
    if len(P) < 2:
        raise InputError("strip frame: a lamella axis needs at least 2 points")
    _, _, T, W, H = strip_frames([P], [N], tangent)
    return T, W, H


def strip_frames(axes: list[np.ndarray], normals: list[np.ndarray], tangent: bool
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """:func:`strip_frame` of every axis ``(k_i,3)`` (metres, ``k_i >= 2``)
    with its normals, in one vectorized pass: ``P, N, T, W, H``, each ``(sum k_i, 3)``, the
    axis points, unit normals and frames concatenated (the same numbers as one call per axis:
    the tangent is ``np.gradient``'s at unit spacing, central inside, one-sided at the ends)."""
    sizes = np.array([len(a) for a in axes], dtype=np.int64)
    if len(sizes) and sizes.min() < 2:
        raise InputError("strip frame: a lamella axis needs at least 2 points")
    P = np.concatenate([np.asarray(a, float).reshape(-1, 3) for a in axes]) if len(sizes) \
        else np.zeros((0, 3))
    N = np.concatenate([np.asarray(n, float).reshape(-1, 3) for n in normals]) \
        if len(sizes) else np.zeros((0, 3))
    return packed_strip_frames(P, N, sizes, tangent)


def packed_strip_frames(P: np.ndarray, N: np.ndarray, sizes: np.ndarray, tangent: bool
                        ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """:func:`strip_frames` of the axes packed one after the other in ``P (sum k_i, 3)``
    (metres) with their normals ``N`` (any length) and point counts ``sizes (k_i >= 2)``:
    the same ``P, N, T, W, H`` without splitting and joining the arrays."""
    P = np.asarray(P, float).reshape(-1, 3)
    sizes = np.asarray(sizes, np.int64).reshape(-1)
    if len(sizes) and sizes.min() < 2:
        raise InputError("strip frame: a lamella axis needs at least 2 points")
    N = _unit(np.asarray(N, float).reshape(-1, 3))
    if len(N) != len(P):
        raise InputError(f"strip frame: {len(P)} axis points but {len(N)} normals")
    first = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.int64)
    last = first + sizes - 1
    D = np.empty_like(P)
    D[1:-1] = (P[2:] - P[:-2]) / 2.0
    D[first] = P[first + 1] - P[first]
    D[last] = P[last] - P[last - 1]
    T = _unit(D)
    if tangent:
        W = _unit(np.cross(N, T))
    else:
        W = _unit(N - np.sum(N * T, axis=1, keepdims=True) * T)
    H = _unit(np.cross(T, W))
    return P, N, T, W, H


def strip_solid(axis: np.ndarray, normals: np.ndarray, width: float, thickness: float,
                tangent: bool, frame: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
                ) -> tuple[np.ndarray, np.ndarray]:
    """A closed, outward-oriented triangle mesh of the strip: the axis swept by its
    ``width x thickness`` rectangle (metres), with end caps.

    Returns ``V (4k,3)`` (the corners of the cross-section at each axis point, in the order
    ``-W-H, +W-H, +W+H, -W+H``) and ``F (8(k-1)+4, 3)``. The faces ``+-H`` are the strip's
    two wide faces, each of area ~ length x width. ``frame``: :func:`strip_frame` of these
    ``axis``, ``normals`` and ``tangent`` when the caller has it already (not computed again).
    """
    if not (np.isfinite(width) and np.isfinite(thickness) and width > 0 and thickness > 0):
        raise InputError(f"strip solid: width {width!r} and thickness {thickness!r} must be "
                         "positive lengths in metres")
    P = np.asarray(axis, float).reshape(-1, 3)
    _, W, H = frame if frame is not None else strip_frame(P, normals, tangent)
    w, h = 0.5 * float(width) * W, 0.5 * float(thickness) * H
    V = np.stack([P - w - h, P + w - h, P + w + h, P - w + h], axis=1).reshape(-1, 3)
    return V, strip_solid_faces(len(P))


def strip_solid_faces(k: int) -> np.ndarray:
    """The faces ``(8(k-1)+4, 3)`` (int64, vertex indices) of :func:`strip_solid` of an axis of
    ``k >= 2`` points: they depend on ``k`` alone (vertex ``4i + c`` is corner ``c`` of the
    cross-section at axis point ``i``)."""
    i = np.arange(k - 1)[:, None] * 4
    faces = []
    for a in range(4):                       # the four long sides, each a quad per segment
        b = (a + 1) % 4
        q = np.hstack([i + a, i + b, i + 4 + b, i + 4 + a])
        faces.append(np.stack([q[:, [0, 1, 2]], q[:, [0, 2, 3]]], axis=1).reshape(-1, 3))
    last = 4 * (k - 1)
    faces.append(np.array([[0, 2, 1], [0, 3, 2],
                           [last, last + 1, last + 2], [last, last + 2, last + 3]]))
    return np.concatenate(faces).astype(np.int64)


def ring_tolerance(thickness: float) -> float:
    """How far (metres) a corner edge of a strip solid with fewer rings may deviate from the
    full-resolution one (:func:`solid_rings`): 1 % of the strip's real ``thickness``
    (metres) or 0.05 mm (5e-5 m) at real size, whichever is smaller."""
    return min(0.01 * float(thickness), 5e-5)


def _segment_distance(X: np.ndarray, A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """Distances ``(...)`` of the points ``X (...,3)`` to the segments ``A B (...,3)``."""
    D = B - A
    dd = np.einsum("...i,...i->...", D, D)
    u = np.einsum("...i,...i->...", X - A, D)
    u = np.clip(np.divide(u, dd, out=np.zeros_like(u), where=dd > 0), 0.0, 1.0)
    return np.linalg.norm(X - A - u[..., None] * D, axis=-1)


def solid_rings(axis: np.ndarray, W: np.ndarray, H: np.ndarray, width: float,
                thickness: float, tol: float | None = None) -> np.ndarray:
    """The indices (ascending, ``int64``) of the axis samples a strip solid needs: the
    cross-sections at the other samples lie, within ``tol`` metres, on the solid through
    these ones.

    Ramer-Douglas-Peucker on the four corner polylines at once (``axis +- width/2 W +-
    thickness/2 H``, metres, the order of :func:`strip_solid`), vectorized level by level: a
    span between two kept samples is split at its sample farthest from the chords of the
    span (the largest of the four corners' distances) while that distance exceeds ``tol``.
    So every full-resolution corner point lies within ``tol`` of the simplified corner
    polyline, and the ends are always kept. ``tol``: default :func:`ring_tolerance`
    (``thickness``).
    """
    return solid_rings_many([axis], [W], [H], width, thickness, tol)[0]


def solid_rings_many(axes: list[np.ndarray], Ws: list[np.ndarray], Hs: list[np.ndarray],
                     width: float, thickness: float, tol: float | None = None
                     ) -> list[np.ndarray]:
    """:func:`solid_rings` of each axis ``(k_i,3)`` (metres) with its frame ``W, H (k_i,3)``,
    all in one vectorized pass: the same indices as one call per axis (the axes' samples
    concatenated, the ends of every axis kept, so that no span reaches from one axis into the
    next; each span is split as it would be alone, every step per sample the same
    arithmetic). One pass costs the deepest axis' levels, not the sum of all."""
    sizes = np.array([len(np.asarray(a).reshape(-1, 3)) for a in axes], dtype=np.int64)
    if not sizes.sum():
        return [np.zeros(0, np.int64) for _ in sizes]
    P = np.concatenate([np.asarray(a, float).reshape(-1, 3) for a in axes])
    k = len(P)
    tol = ring_tolerance(thickness) if tol is None else float(tol)
    w = 0.5 * float(width) * np.concatenate([np.asarray(x, float).reshape(-1, 3) for x in Ws])
    h = 0.5 * float(thickness) * np.concatenate([np.asarray(x, float).reshape(-1, 3)
                                                  for x in Hs])
    X = np.stack([P - w - h, P + w - h, P + w + h, P - w + h], axis=1)      # (k,4,3)
    first = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.int64)
    keep = np.zeros(k, bool)
    some = sizes > 0                                   # an axis without samples keeps none
    keep[first[some]] = True
    keep[(first + sizes - 1)[some]] = True
    # the samples still in a span that may split (a span within tol is settled for good:
    # its samples leave, and every later level computes what it computed, for the others)
    at = np.flatnonzero(~keep)
    while len(at):
        idx = np.flatnonzero(keep)
        seg = np.searchsorted(idx, at, side="right") - 1     # the span of each sample
        d = _segment_distance(X[at], X[idx[seg]], X[idx[seg + 1]]).max(axis=1)
        start = np.flatnonzero(np.r_[True, seg[1:] != seg[:-1]])   # runs of one span
        worst = np.maximum.reduceat(d, start)
        split = worst > tol
        if not split.any():
            break
        # the first sample of each span that needs a split where its distance is the span's
        run = np.repeat(np.arange(len(start)), np.diff(np.r_[start, len(at)]))
        far = (d == worst[run]) & split[run]
        _, first_far = np.unique(run[far], return_index=True)
        keep[at[np.flatnonzero(far)[first_far]]] = True
        at = at[split[run] & ~keep[at]]
    idx = np.flatnonzero(keep).astype(np.int64)
    cut = np.searchsorted(idx, np.concatenate([first, [k]]))
    return [idx[cut[i]:cut[i + 1]] - first[i] for i in range(len(sizes))]


def real_section_m(width_mm: float, thickness_mm: float, scale: float) -> tuple[float, float]:
    """The strip's real width and thickness in metres of the design, from the cut strip's
    width and thickness in mm of a model at ``scale`` (model / design, ``1:10`` -> 0.1)."""
    if not (scale > 0 and width_mm > 0 and thickness_mm > 0):
        raise InputError(f"section: width {width_mm} mm, thickness {thickness_mm} mm and scale "
                         f"{scale} must be positive")
    return 1e-3 * width_mm / scale, 1e-3 * thickness_mm / scale
