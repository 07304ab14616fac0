"""The initial grid ``P0 (R, C, 3)`` of the GG surface design (paper 4.1.1) from a target surface.

Convention (as in :mod:`gridshell.gg.design`): ``P0[i, j]`` with ``i`` the parallel and ``j``
the meridian; meridians are ``P0[:, j]``, parallels ``P0[i, :]``.

- A **structured quad grid** target (:func:`gridshell.geometry.grid.grid_from_quads` gives its vertex
  grid ``G (R0, C0)``) is used as it is: ``meridians="cols"`` makes the grid's columns
  ``G[:, j]`` the meridians (``P0 = V[G]``), ``meridians="rows"`` its rows ``G[i, :]``
  (``P0 = V[G.T]``). For a mesh written from ``P`` with ``grid_quads(R, C)`` (vertex
  ``i*C + j``), ``"cols"`` gives back ``P``. A different ``grid=(R, C)`` (by default: a grid
  longer than :data:`MAX_DEFAULT_GRID` along a side) resamples it
  bilinearly in the grid's index space.
- A **triangle mesh** target is parameterized (:func:`gridshell.geometry.igl_adapter.parameterize_disk`,
  LSCM) and the parameter domain turned so that the meridian ``direction`` runs along its first
  axis ``s``. Four boundary corners are chosen (the target's own corners if its boundary has
  four, else the extremes of ``+-s +-t``) and the target is mapped onto the unit square with
  them at its corners, by two harmonic functions (cotangent weights; Dirichlet on two opposite
  sides, free on the others): the side pair furthest apart along ``s`` bounds the meridians.
  The map is close to conformal, so its grid lines follow the target (on a helicoid they are the
  rulings and helices) and the grid spans the whole target. If that map folds, the largest
  axis-aligned rectangle inside the LSCM domain is used instead (it can miss a third of a
  target whose domain is far from a rectangle: 65 % coverage on a helicoid). ``R x C`` samples
  of the square are lifted to the smooth surface through the target's vertices (a polyharmonic
  interpolant over the square map, so that a grid finer than the triangles does not take their
  facets as odd-even ripples); those of the fallback rectangle by barycentric interpolation in
  the target's triangles.
"""
from __future__ import annotations

from typing import Any

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import spsolve

from gridshell.core.errors import InputError, MeshError

__all__ = ["initial_grid"]

_MIN = 4

#: a quad-grid target with more vertices than this along a side is resampled to this many by
#: default (proportionally fewer along the other side): the net has a few dozen lamellae, and a
#: 120 x 80 design took four times as long as a 64 x 43 one for the same figures
MAX_DEFAULT_GRID = 64

#: boundary vertices with a smaller angle (degrees) between their boundary edges are corners
_CORNER_ANGLE = 135.0


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
    from gridshell.geometry.quadmesh import MAX_ELEMENTS

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


def _harmonic(L: sp.csr_matrix, zero: np.ndarray, one: np.ndarray) -> np.ndarray:
    """Harmonic function (``L x = 0`` inside) with ``x = 0`` on ``zero``, ``x = 1`` on ``one``
    and a free (natural, zero-flux) boundary elsewhere."""
    n = L.shape[0]
    fixed = np.concatenate([zero, one])
    val = np.concatenate([np.zeros(len(zero)), np.ones(len(one))])
    free = np.setdiff1d(np.arange(n), fixed)
    x = np.zeros(n)
    x[fixed] = val
    x[free] = spsolve(L[free][:, free].tocsc(), -(L[free][:, fixed] @ val))
    return x


def _corners(V: np.ndarray, loop: np.ndarray, ST: np.ndarray) -> np.ndarray:
    """Four corners of a boundary loop (positions in ``loop``, increasing).

    The four sharpest boundary vertices (3D angle between the two boundary edges below
    :data:`_CORNER_ANGLE`, at least an eighth of the loop apart) if there are four; otherwise
    (a smooth boundary) the extremes of ``+-s +-t`` in the parameter plane ``ST``.
    """
    nb = len(loop)
    a = V[np.roll(loop, 1)] - V[loop]
    b = V[np.roll(loop, -1)] - V[loop]
    cos = np.einsum("ij,ij->i", a, b) / np.maximum(
        np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1), 1e-300)
    ang = np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))
    gap = max(1, nb // 8)
    chosen: list[int] = []
    for k in np.argsort(ang, kind="stable"):
        if ang[k] >= _CORNER_ANGLE or len(chosen) == 4:
            break
        if all(min(abs(k - c), nb - abs(k - c)) >= gap for c in chosen):
            chosen.append(int(k))
    if len(chosen) < 4:
        B = ST[loop]
        chosen = [int(np.argmax(B @ np.array(w, float)))
                  for w in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    return np.sort(np.array(chosen))


def _quad_domain(V: np.ndarray, T: np.ndarray, loop: np.ndarray,
                 ST: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """Map of the target onto the unit square with four boundary corners at its corners.

    ``s`` and ``t`` are harmonic (cotangent weights) with ``s = 0`` / ``1`` on the two opposite
    sides that lie furthest apart along the meridian direction (the first axis of ``ST``) and a
    free boundary on the other two, ``t`` likewise across; together they approximate the
    conformal map onto a rectangle, scaled to ``[0, 1]^2``, so the whole target is sampled
    (the largest rectangle inside a free-boundary parameterization can miss a third of it).

    Returns
    -------
    W : (n, 2) float or None
        ``(s, t)`` of every vertex; None if the map folds (obtuse triangles can make cotangent
        weights negative) or a side is degenerate.
    lengths : (2,) float
        Mean 3D length (metres) of the sides along ``s`` and along ``t``.
    """
    if len(loop) < 4:
        return None
    c = _corners(V, loop, ST)
    if len(np.unique(c)) < 4:
        return None
    sides = [loop[c[k]:c[k + 1] + 1] if k < 3 else np.concatenate([loop[c[3]:], loop[:c[0] + 1]])
             for k in range(4)]
    centre = np.array([ST[sd].mean(axis=0) for sd in sides])
    # the pair of opposite sides that are furthest apart along s are the ends of the meridians
    k = int(np.argmax([abs(centre[2, 0] - centre[0, 0]), abs(centre[3, 0] - centre[1, 0])]))
    s0, s1 = sides[k], sides[k + 2]
    t0, t1 = sides[k + 1], sides[(k + 3) % 4]
    if centre[k, 0] > centre[k + 2, 0]:
        s0, s1 = s1, s0
    if centre[k + 1, 1] > centre[(k + 3) % 4, 1]:
        t0, t1 = t1, t0
    from gridshell.geometry.igl_adapter import cotangent_laplacian

    L = cotangent_laplacian(V, T)
    W = np.stack([_harmonic(L, s0, s1), _harmonic(L, t0, t1)], axis=1)
    if not np.all(np.isfinite(W)):
        return None
    area = 0.5 * ((W[T[:, 1], 0] - W[T[:, 0], 0]) * (W[T[:, 2], 1] - W[T[:, 0], 1])
                  - (W[T[:, 2], 0] - W[T[:, 0], 0]) * (W[T[:, 1], 1] - W[T[:, 0], 1]))
    if not (np.all(area > 0) or np.all(area < 0)):
        return None

    def length(side: np.ndarray) -> float:
        return float(np.linalg.norm(np.diff(V[side], axis=0), axis=1).sum())

    lengths = np.array([0.5 * (length(t0) + length(t1)), 0.5 * (length(s0) + length(s1))])
    return W, lengths


def _lift(V: np.ndarray, T: np.ndarray, D: np.ndarray, Q: np.ndarray) -> np.ndarray:
    """Points ``(k, 3)`` of the target at parameters ``Q (k, 2)`` of the parameterization
    ``D (n, 2)``: barycentric interpolation in the closest parameter triangle (samples just
    outside the domain are clamped onto its edge)."""
    from gridshell.geometry.igl_adapter import closest_points

    D3 = np.concatenate([D, np.zeros((len(D), 1))], axis=1)
    Q3 = np.concatenate([Q, np.zeros((len(Q), 1))], axis=1)
    _, face, Cq = closest_points(Q3, D3, T)
    tri = T[face]
    A, B, C = D[tri[:, 0]], D[tri[:, 1]], D[tri[:, 2]]
    e1, e2, p = B - A, C - A, Cq[:, :2] - A
    det = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    det = np.where(np.abs(det) > 1e-300, det, 1e-300)
    b1 = (p[:, 0] * e2[:, 1] - p[:, 1] * e2[:, 0]) / det
    b2 = (e1[:, 0] * p[:, 1] - e1[:, 1] * p[:, 0]) / det
    return ((1 - b1 - b2)[:, None] * V[tri[:, 0]] + b1[:, None] * V[tri[:, 1]]
            + b2[:, None] * V[tri[:, 2]])


#: targets with up to this many vertices are interpolated by one global RBF system (dense,
#: about 0.2 s at 2000 vertices); larger ones by local RBFs over the nearest
#: :data:`_RBF_NEIGHBOURS` vertices of each sample
_RBF_GLOBAL = 2500
_RBF_NEIGHBOURS = 64


def _smooth_lift(V: np.ndarray, T: np.ndarray, D: np.ndarray, Q: np.ndarray) -> np.ndarray:
    """Points ``(k, 3)`` at parameters ``Q (k, 2)`` of the smooth surface through the target's
    vertices: the polyharmonic (``r^3``, C2) radial-basis interpolant of ``V`` over the
    parameters ``D (n, 2)``, plus a linear polynomial.

    A grid finer than the target's triangles samples them facet by facet if lifted
    barycentrically (:func:`_lift`): its faces inside one facet are coplanar and those across a
    facet edge take all the bending, so the dihedral angles between neighbouring grid faces
    alternate (odd-even ripples of 3-4 degrees on ``samples/dome.obj`` at 32 x 32) and the GG
    design keeps them. The interpolant passes through every vertex (corners stay exact) and
    bends evenly. Falls back to :func:`_lift` if it is singular or strays from the target by
    more than a quarter of the target's mean edge length.
    """
    from scipy.interpolate import RBFInterpolator

    from gridshell.geometry.igl_adapter import closest_points

    try:
        nb = None if len(D) <= _RBF_GLOBAL else _RBF_NEIGHBOURS
        P = RBFInterpolator(D, V, neighbors=nb, kernel="cubic", degree=1)(Q)
    except (np.linalg.LinAlgError, ValueError):
        return _lift(V, T, D, Q)
    if not np.all(np.isfinite(P)):
        return _lift(V, T, D, Q)
    edge = float(np.mean(np.linalg.norm(V[T] - V[np.roll(T, 1, axis=1)], axis=2)))
    dist, _, _ = closest_points(P, V, T)
    if np.sqrt(np.max(dist)) > 0.25 * edge:
        return _lift(V, T, D, Q)
    return P


#: fewest grid vertices along the shorter side of a default grid sampled in a triangle mesh:
#: the default 10 lamellae per family need 2-3 grid edges per side of a net loop (corpus
#: hill-04, 260 triangles: the 16 x 9 grid its vertex count gave missed Delta_a max, 3.83 %;
#: 24 x 14 passes)
MIN_SHORT_SIDE = 16


def _default_size(ext: np.ndarray, n_vertices: int) -> tuple[int, int]:
    """About ``sqrt(n_vertices)`` (8..40) grid vertices along the longer of the extents
    ``(along the meridians, along the parallels)``, proportionally fewer along the other, but
    at least :data:`MIN_SHORT_SIDE` along the shorter (the longer then grows in proportion, up
    to :data:`MAX_DEFAULT_GRID`)."""
    ext = np.asarray(ext, float)
    N = int(np.clip(round(np.sqrt(n_vertices)), 8, 40))
    ratio = float(ext.max() / max(ext.min(), 1e-300))
    N = int(min(max(N, round(MIN_SHORT_SIDE * ratio)), MAX_DEFAULT_GRID))
    R, C = (max(_MIN, int(round(N * e / ext.max()))) for e in ext)
    return R, C


def _from_triangles(V: np.ndarray, F: np.ndarray, loop: np.ndarray,
                    grid: tuple[int, int] | None, direction: Any) -> np.ndarray:
    from gridshell.geometry.igl_adapter import closest_points, closest_points_with_normals, parameterize_disk

    UV = parameterize_disk(V, F, method="lscm", normalize=False)
    UV = UV - UV.mean(axis=0)
    _, _, Vt = np.linalg.svd(UV, full_matrices=False)
    UV = UV @ Vt.T  # principal axes: angle 0 is the longest extent of the domain
    th = _direction_angle(direction, V, UV)
    d = np.array([np.cos(th), np.sin(th)])
    ST = np.stack([UV @ d, UV @ np.array([-d[1], d[0]])], axis=1)  # s along the meridians
    quad = _quad_domain(V, F, loop, ST)
    if quad is not None:
        W, ext = quad
        R, C = grid if grid is not None else _default_size(ext, len(V))
        # the square stretched to the target's side lengths: close to conformal, so that the
        # (isotropic) smooth interpolant bends alike in both directions
        s, t = np.linspace(0.0, ext[0], R), np.linspace(0.0, ext[1], C)
        D = W * ext
    else:
        # fallback: the largest axis-aligned rectangle inside a raster of the LSCM domain
        UV3 = np.concatenate([ST, np.zeros((len(ST), 1))], axis=1)
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
            Lm = float(np.mean(np.linalg.norm(np.diff(V[F[:, [0, 1, 2, 0]]], axis=1), axis=2)))
            Lp = float(np.mean(np.linalg.norm(np.diff(UV3[F[:, [0, 1, 2, 0]]], axis=1),
                                              axis=2)))
            R, C = _default_size(np.array([s1 - s0, t1 - t0]) * Lm / Lp, len(V))
        else:
            R, C = grid
        s, t = np.linspace(s0, s1, R), np.linspace(t0, t1, C)
        D = ST
    Ss, Ts = np.meshgrid(s, t, indexing="ij")
    lift = _smooth_lift if quad is not None else _lift
    P = lift(V, F, D, np.stack([Ss.ravel(), Ts.ravel()], axis=1)).reshape(R, C, 3)
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
        own size (quads; resampled to :data:`MAX_DEFAULT_GRID` along its longer side if it is
        larger), about ``sqrt(n_vertices)`` (8..40) along the longer side and at least
        ``MIN_SHORT_SIDE`` along the shorter (triangles).
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
    from gridshell.geometry.quadmesh import QuadMesh, TriMesh

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
        if grid is None and max(P.shape[:2]) > MAX_DEFAULT_GRID:
            k = MAX_DEFAULT_GRID / max(P.shape[:2])
            grid = tuple(max(_MIN, int(round(n * k))) for n in P.shape[:2])
        if grid is not None and grid != P.shape[:2]:
            P = _resample(P, *grid)
        return np.array(P, dtype=float)
    mesh = TriMesh(V, Fa)
    _check_disk(mesh)
    return _from_triangles(mesh.V, mesh.F, mesh.boundary_loops[0], grid, direction)
