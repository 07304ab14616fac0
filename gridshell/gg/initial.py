"""The initial grid ``P0 (R, C, 3)`` of the GG surface design (paper 4.1.1) from a target surface.

Convention (as in :mod:`gridshell.gg.design`): ``P0[i, j]`` with ``i`` the parallel and ``j``
the meridian; meridians are ``P0[:, j]``, parallels ``P0[i, :]``.

- A **structured quad grid** target (:func:`gridshell.grid.grid_from_quads` gives its vertex
  grid ``G (R0, C0)``) is used as it is: ``meridians="cols"`` makes the grid's columns
  ``G[:, j]`` the meridians (``P0 = V[G]``), ``meridians="rows"`` its rows ``G[i, :]``
  (``P0 = V[G.T]``). For a mesh written from ``P`` with ``grid_quads(R, C)`` (vertex
  ``i*C + j``), ``"cols"`` gives back ``P``. A different ``grid=(R, C)`` resamples it
  bilinearly in the grid's index space.
- A **triangle mesh** target is parameterized (:func:`gridshell.igl_adapter.parameterize_disk`,
  LSCM); the parameter domain is turned so that the meridian ``direction`` runs along the first
  axis, the largest axis-aligned rectangle inside the domain is sampled with ``R x C`` points,
  and these are lifted to the surface by barycentric interpolation in their triangles.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import InputError, MeshError

__all__ = ["initial_grid"]

_MIN = 4


def _mesh_arrays(target: Any, F: Any) -> tuple[np.ndarray, np.ndarray]:
    if F is None:
        if not (hasattr(target, "V") and hasattr(target, "F")):
            raise InputError("pass the target as a QuadMesh / TriMesh or as (V, F) arrays; "
                             "F is missing")
        return np.asarray(target.V, float), np.asarray(target.F)
    return np.asarray(target, float), np.asarray(F)


def _check_disk(mesh: Any) -> None:
    if not mesh.is_disk:
        loops = len(mesh.boundary_loops) if mesh.is_manifold else "?"
        raise MeshError(f"the target is not a disk (Euler characteristic "
                        f"{mesh.euler_characteristic}, {loops} boundary loop(s)); a GG surface is "
                        "designed on one disk-like patch - cut the surface open (e.g. a cylinder "
                        "along a generator) or fill its holes")


def _check_size(R: int, C: int, what: str) -> None:
    from ..quadmesh import MAX_ELEMENTS

    if R < _MIN or C < _MIN:
        raise InputError(f"{what} is too coarse ({R} x {C} vertices); the GG design needs at "
                         f"least {_MIN} x {_MIN} - refine it or ask for a larger grid=(R, C)")
    if R * C > MAX_ELEMENTS:
        raise InputError(f"{what} is too fine ({R} x {C} vertices, limit {MAX_ELEMENTS}); a GG "
                         "mesh of 10 to 100 vertices per side is plenty - ask for a smaller "
                         "grid=(R, C)")


def _resample(P: np.ndarray, R: int, C: int) -> np.ndarray:
    """Bilinear resampling of a grid ``P (R0, C0, 3)`` to ``(R, C)`` in index space."""
    R0, C0 = P.shape[:2]
    s, t = np.linspace(0, R0 - 1, R), np.linspace(0, C0 - 1, C)
    i = np.minimum(np.floor(s).astype(int), R0 - 2)
    j = np.minimum(np.floor(t).astype(int), C0 - 2)
    a, b = (s - i)[:, None, None], (t - j)[None, :, None]
    I, J = i[:, None], j[None, :]
    return ((1 - a) * (1 - b) * P[I, J] + a * (1 - b) * P[I + 1, J]
            + (1 - a) * b * P[I, J + 1] + a * b * P[I + 1, J + 1])


def _largest_rectangle(inside: np.ndarray) -> tuple[int, int, int, int]:
    """Largest all-True axis-aligned rectangle ``(r0, r1, c0, c1)`` (inclusive) of a boolean
    raster, by the histogram-stack method."""
    nr, nc = inside.shape
    height = np.zeros(nc, dtype=int)
    best, box = 0, (0, 0, 0, 0)
    for r in range(nr):
        height = np.where(inside[r], height + 1, 0)
        stack: list[int] = []
        for c in range(nc + 1):
            hc = height[c] if c < nc else 0
            while stack and height[stack[-1]] >= hc:
                h = height[stack.pop()]
                left = stack[-1] + 1 if stack else 0
                area = h * (c - left)
                if area > best:
                    best, box = area, (r - h + 1, r, left, c - 1)
            stack.append(c)
    if best == 0:
        raise MeshError("the parameterization of the target has no interior; the mesh may be "
                        "degenerate - remove zero-area triangles")
    return box


def _direction_angle(direction: Any, V: np.ndarray, UV: np.ndarray) -> float:
    """Meridian direction as an angle (radians) in the parameter plane."""
    if direction is None:
        return 0.0
    d = np.asarray(direction, dtype=float)
    if d.ndim == 0:
        if not np.isfinite(d):
            raise InputError(f"direction must be a finite angle in degrees, got {direction!r}")
        return float(np.radians(d))
    if d.shape != (3,) or not np.all(np.isfinite(d)) or not np.linalg.norm(d) > 0:
        raise InputError(f"direction must be an angle in degrees or a non-zero 3D vector, got "
                         f"{direction!r}")
    # best linear map from space to the parameter plane, applied to the vector
    M, *_ = np.linalg.lstsq(V - V.mean(axis=0), UV - UV.mean(axis=0), rcond=None)
    du = d @ M
    if not np.linalg.norm(du) > 1e-9 * np.linalg.norm(d) * np.linalg.norm(M):
        raise InputError(f"direction {direction!r} is normal to the target; give a direction "
                         "along the surface")
    return float(np.arctan2(du[1], du[0]))


def _from_triangles(V: np.ndarray, F: np.ndarray, grid: tuple[int, int] | None,
                    direction: Any) -> np.ndarray:
    from ..igl_adapter import closest_points, closest_points_with_normals, parameterize_disk

    UV = parameterize_disk(V, F, method="lscm", normalize=False)
    UV = UV - UV.mean(axis=0)
    _, _, Vt = np.linalg.svd(UV, full_matrices=False)
    UV = UV @ Vt.T  # principal axes: angle 0 is the longest extent of the domain
    th = _direction_angle(direction, V, UV)
    d = np.array([np.cos(th), np.sin(th)])
    ST = np.stack([UV @ d, UV @ np.array([-d[1], d[0]])], axis=1)  # s along the meridians
    UV3 = np.concatenate([ST, np.zeros((len(ST), 1))], axis=1)
    # raster of the domain and the largest rectangle inside it
    n = 96
    lo, hi = ST.min(axis=0), ST.max(axis=0)
    gs, gt = np.linspace(lo[0], hi[0], n), np.linspace(lo[1], hi[1], n)
    S, Tt = np.meshgrid(gs, gt, indexing="ij")
    Q = np.stack([S.ravel(), Tt.ravel(), np.zeros(S.size)], axis=1)
    sq, _, _ = closest_points(Q, UV3, F)
    # samples up to 2 % of the extent outside the domain are accepted (clamped onto its edge)
    tol = (0.02 * max(hi - lo)) ** 2
    r0, r1, c0, c1 = _largest_rectangle((sq <= tol).reshape(n, n))
    s0, s1, t0, t1 = gs[r0], gs[r1], gt[c0], gt[c1]
    if grid is None:
        # about as many grid vertices along the longer side as sqrt(#vertices), 8..40
        Lm = float(np.mean(np.linalg.norm(np.diff(V[F[:, [0, 1, 2, 0]]], axis=1), axis=2)))
        Lp = float(np.mean(np.linalg.norm(np.diff(UV3[F[:, [0, 1, 2, 0]]], axis=1), axis=2)))
        ext = np.array([s1 - s0, t1 - t0]) * Lm / Lp
        N = int(np.clip(round(np.sqrt(len(V))), 8, 40))
        R, C = (max(_MIN, int(round(N * e / ext.max()))) for e in ext)
    else:
        R, C = grid
    s, t = np.linspace(s0, s1, R), np.linspace(t0, t1, C)
    Ss, Ts = np.meshgrid(s, t, indexing="ij")
    Q = np.stack([Ss.ravel(), Ts.ravel(), np.zeros(Ss.size)], axis=1)
    _, face, Cq = closest_points(Q, UV3, F)
    tri = F[face]
    A, B, D = ST[tri[:, 0]], ST[tri[:, 1]], ST[tri[:, 2]]
    e1, e2, p = B - A, D - A, Cq[:, :2] - A
    det = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    det = np.where(np.abs(det) > 1e-300, det, 1e-300)
    b1 = (p[:, 0] * e2[:, 1] - p[:, 1] * e2[:, 0]) / det
    b2 = (e1[:, 0] * p[:, 1] - e1[:, 1] * p[:, 0]) / det
    P = ((1 - b1 - b2)[:, None] * V[tri[:, 0]] + b1[:, None] * V[tri[:, 1]]
         + b2[:, None] * V[tri[:, 2]]).reshape(R, C, 3)
    # orient the grid's quads (i,j),(i,j+1),(i+1,j+1),(i+1,j) like the target's faces
    nq = np.cross(P[:-1, 1:] - P[:-1, :-1], P[1:, :-1] - P[:-1, :-1]).reshape(-1, 3)
    _, N = closest_points_with_normals(P[:-1, :-1].reshape(-1, 3), V, F)
    if np.nansum(np.einsum("ij,ij->i", nq, N)) < 0:
        P = P[:, ::-1].copy()
    return P


def initial_grid(target: Any, F: Any = None, *, meridians: str = "cols",
                 grid: tuple[int, int] | None = None, direction: Any = None) -> np.ndarray:
    """Initial GG grid ``P0 (R, C, 3)`` on a target surface.

    Parameters
    ----------
    target : QuadMesh, TriMesh or (n, 3) float
        The target, metres; with an array, ``F`` gives its faces.
    F : (m, 4) or (m, 3) int, optional
        Faces when ``target`` is a vertex array: quads must form a structured grid.
    meridians : {"rows", "cols"}
        Structured quad targets: the grid's rows ``G[i, :]`` or columns ``G[:, j]`` become the
        meridians (the geodesics of the designed surface); see the module docstring.
    grid : (R, C), optional
        Number of parallels ``R`` and meridians ``C``, each >= 4. Default: the target grid's
        own size (quads), about ``sqrt(n_vertices)`` (8..40) along the longer side (triangles).
    direction : float or (3,) float, optional
        Triangle targets: meridian direction, an angle in degrees in the parameter plane
        (0: the longest extent of the parameter domain) or a 3D vector, mapped into it by the
        best linear fit of the parameterization.

    Returns
    -------
    P0 : (R, C, 3) float
        Meridians ``P0[:, j]``, parallels ``P0[i, :]``, metres.

    Raises
    ------
    MeshError
        The target is not a disk, is not a structured grid (quads), or is degenerate.
    InputError
        Fewer than 4 x 4 vertices, a bad ``meridians`` / ``direction`` / ``grid``.
    """
    from ..quadmesh import QuadMesh, TriMesh

    if meridians not in ("rows", "cols"):
        raise InputError(f"meridians must be 'rows' or 'cols', got {meridians!r}")
    if grid is not None:
        try:
            R, C = (int(g) for g in grid)
        except (TypeError, ValueError):
            raise InputError(f"grid must be a pair (R, C) of integers, got {grid!r}") from None
        _check_size(R, C, f"the requested grid {grid!r}")
        grid = (R, C)
    V, Fa = _mesh_arrays(target, F)
    if Fa.ndim != 2 or Fa.shape[1] not in (3, 4):
        raise MeshError(f"target faces must have shape (m, 3) or (m, 4), got {Fa.shape}")
    if Fa.shape[1] == 4:
        if direction is not None:
            raise InputError("direction applies to triangle-mesh targets; for a quad-grid target "
                             "choose the meridians with meridians='rows' or 'cols'")
        mesh = QuadMesh(V, Fa)
        _check_disk(mesh)
        try:
            G = mesh.grid()
        except MeshError as e:
            raise MeshError(f"the quad target cannot be used as the GG grid: {e}. "
                            "Pass it as triangles (e.g. QuadMesh.to_trimesh()) so that a grid is "
                            "built by parameterization, or remesh it as a structured grid") from None
        _check_size(*G.shape, "the target grid")
        P = mesh.V[G] if meridians == "cols" else mesh.V[G.T]
        if grid is not None and grid != P.shape[:2]:
            P = _resample(P, *grid)
        return np.array(P, dtype=float)
    mesh = TriMesh(V, Fa)
    _check_disk(mesh)
    return _from_triangles(mesh.V, mesh.F, grid, direction)
