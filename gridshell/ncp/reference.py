"""The initial B-spline of the PHLW design (paper 4.2.1) from a reference mesh.

A structured quad grid is fitted directly: its rows give ``u`` and its columns ``v``
(:func:`gridshell.geometry.grid.grid_from_quads`). Any other disk-like mesh (triangles, or quads that
do not form a grid) is parameterized with libigl first
(:func:`gridshell.geometry.igl_adapter.parameterize_disk`) and fitted as scattered points.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from gridshell.geometry.bspline import BSplineSurface, fit_grid, fit_points
from gridshell.core.errors import InputError, MeshError


@dataclass
class InitialFit:
    """Outcome of :func:`initial_surface`.

    surface : the fitted BSplineSurface (open uniform knots on [0, 1]^2)
    rms : root mean square fitting residual, metres
    method : "grid" (structured quad grid, rows -> u) or "parameterized" (libigl LSCM + scattered fit)
    grid_shape : (R, C) of the vertex grid for "grid", else None
    principal : the principal angle of the first fit's parameter plane
        (:class:`gridshell.ncp.principal_frame.PrincipalAngle`), None if not measured
    rotated_deg : the angle the parameter plane was turned by before the final fit (0: kept)
    """

    surface: BSplineSurface
    rms: float
    method: str
    grid_shape: tuple[int, int] | None = None
    principal: Any = None
    rotated_deg: float = 0.0


def _arrays(mesh: Any, F: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    if F is None:
        if not (hasattr(mesh, "V") and hasattr(mesh, "F")):
            raise InputError("pass the reference as (V, F) arrays or a mesh with V and F")
        mesh, F = mesh.V, mesh.F
    V = np.asarray(mesh, dtype=float)
    F = np.asarray(F)
    if V.ndim != 2 or V.shape[1] != 3 or len(V) == 0:
        raise MeshError(f"reference vertices must have shape (n, 3), got {V.shape}")
    if F.ndim != 2 or F.shape[1] not in (3, 4) or len(F) == 0:
        raise MeshError(f"reference faces must have shape (m, 3) or (m, 4), got {F.shape}")
    return V, F.astype(np.int64)


def initial_surface(mesh: Any, F: np.ndarray | None = None, *, n_ctrl: tuple[int, int] = (9, 9),
                    degree: tuple[int, int] = (4, 4), smoothing: float = 1e-6,
                    transpose: bool = False, align: bool = False) -> InitialFit:
    """Least-squares B-spline of a reference mesh (paper defaults: bi-degree 4, 9 x 9 control
    points).

    Parameters
    ----------
    mesh : (n, 3) float vertices, metres, with ``F``; or a QuadMesh / TriMesh
    F : (m, 4) or (m, 3) int faces
    n_ctrl : control points in u and v
    degree : degrees in u and v
    smoothing : relative thin-plate weight of the fit (see :func:`gridshell.geometry.bspline.fit_grid`);
        scattered data (triangle meshes) use at least 1e-4
    transpose : swap u and v (grid rows -> v); the PHLW rows then follow the other family
    align : turn the parameter plane onto the mean principal directions of the first fit
        (:mod:`gridshell.ncp.principal_frame`) when they are more than
        :data:`~gridshell.ncp.principal_frame.ALIGN_MIN_DEG` off the parameter lines, as far
        as coverage and deviation allow, and refit; otherwise the first fit is returned
        unchanged. Off by default: on 10 corpus runs (associates, saddles) the turn traded
        the PHLW relation figure for coverage (11-23 % against 10 %) and never made the PHLW
        step pass where it failed (benchmarks/README.md, "principal frame")

    Returns
    -------
    InitialFit
    """
    V, F = _arrays(mesh, F)
    nu, nv = (int(k) for k in n_ctrl)
    du, dv = (int(k) for k in degree)
    if F.shape[1] == 4:
        from gridshell.geometry.grid import grid_from_quads

        try:
            G = grid_from_quads(F, len(V))
        except MeshError:
            G = None
        if G is not None:
            P = V[G]
            if transpose:
                P = P.transpose(1, 0, 2)
            if P.shape[0] < nu or P.shape[1] < nv:
                raise InputError(f"the reference grid has {P.shape[0]} x {P.shape[1]} vertices, "
                                 f"fewer than the {nu} x {nv} control points; use fewer control "
                                 "points or a denser grid")
            surf, rms = fit_grid(P, nu, nv, du, dv, smoothing=smoothing)
            fit = InitialFit(surf, rms, "grid", (P.shape[0], P.shape[1]))
            if not align:
                return fit
            from gridshell.geometry.bspline import _chord_params

            pu, pv = np.meshgrid(_chord_params(P), _chord_params(P.transpose(1, 0, 2)),
                                 indexing="ij")
            return _aligned(fit, P.reshape(-1, 3), pu.ravel(), pv.ravel(), (nu, nv), (du, dv),
                            max(smoothing, 1e-4), V, F)
    from gridshell.geometry.igl_adapter import parameterize_disk

    UV = parameterize_disk(V, F)
    if transpose:
        UV = UV[:, ::-1]
    if len(V) < nu * nv:
        raise InputError(f"the reference has {len(V)} vertices, fewer than the {nu} x {nv} "
                         "control points; use fewer control points or a denser mesh")
    surf, rms = fit_points(V, UV[:, 0], UV[:, 1], nu, nv, du, dv,
                           smoothing=max(smoothing, 1e-4))
    fit = InitialFit(surf, rms, "parameterized", None)
    if not align:
        return fit
    return _aligned(fit, V, UV[:, 0], UV[:, 1], (nu, nv), (du, dv), max(smoothing, 1e-4), V, F)


def _aligned(fit: InitialFit, P: np.ndarray, u: np.ndarray, v: np.ndarray,
             n_ctrl: tuple[int, int], degree: tuple[int, int], smoothing: float,
             V: np.ndarray, F: np.ndarray) -> InitialFit:
    """``fit`` with its principal angle measured, refitted in the turned parameter plane when
    the misalignment is at least ALIGN_MIN_DEG (:mod:`gridshell.ncp.principal_frame`).

    A rectangle turned against the reference's boundary either leaves part of it uncovered or
    overhangs it; the turn is the largest of 1, 3/4, 1/2, 1/4 times the principal angle whose
    refit keeps both within :data:`~gridshell.ncp.principal_frame.ALIGN_BUDGET` of the PHLW
    step's coverage and deviation tolerances (the first fit's own deviation if larger), else
    none (measured: a full 44 degree turn of corpus associate-07 left coverage 16 % before
    and 28 % after the PHLW step, tolerance 10 %)."""
    from gridshell.ncp.phlw.figures import COVERAGE_TOL, DEVIATION_TOL, coverage_percent, deviation_percent
    from gridshell.ncp.principal_frame import ALIGN_BUDGET, ALIGN_MIN_DEG, principal_angle, rotated_fit

    pa = principal_angle(fit.surface)
    fit.principal = pa
    if abs(pa.angle_deg) < ALIGN_MIN_DEG or not pa.residual_deg < pa.misalignment_deg:
        return fit
    dev0 = deviation_percent(fit.surface, V, F, (40, 40))
    for frac in (1.0, 0.75, 0.5, 0.25):
        angle = frac * pa.angle_deg
        if abs(angle) < ALIGN_MIN_DEG:
            break
        surf, rms = rotated_fit(P, u, v, pa, n_ctrl, degree, smoothing, angle_deg=angle)
        if (coverage_percent(surf, V, F, (40, 40)) <= ALIGN_BUDGET * COVERAGE_TOL
                and deviation_percent(surf, V, F, (40, 40))
                <= max(ALIGN_BUDGET * DEVIATION_TOL, dev0)):
            return InitialFit(surf, rms, fit.method, fit.grid_shape, pa, angle)
    return fit


def boundary_segments(F: np.ndarray, return_faces: bool = False
                      ) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """Boundary edges of a polygon mesh: ``(m, 2)`` vertex indices of the edges used by one
    face only (faces ``(f, 3|4)``), and with ``return_faces`` the ``(m,)`` face of each."""
    F = np.asarray(F, np.int64)
    E = np.stack([F, np.roll(F, -1, axis=1)], -1).reshape(-1, 2)
    n = int(E.max()) + 1 if E.size else 1
    key = E.min(axis=1) * n + E.max(axis=1)          # one int64 per undirected edge
    _, inv, cnt = np.unique(key, return_inverse=True, return_counts=True)
    keep = cnt[inv.reshape(-1)] == 1
    if return_faces:
        return E[keep], np.repeat(np.arange(len(F)), F.shape[1])[keep]
    return E[keep]


def closest_on_segments(P: np.ndarray, A: np.ndarray, B: np.ndarray
                        ) -> tuple[np.ndarray, np.ndarray]:
    """Closest points of ``P (k, 3)`` on the segments ``A (m, 3) -> B (m, 3)``: the foot points
    ``(k, 3)`` and the index ``(k,)`` of the segment each lies on (brute force, ``k * m``)."""
    P, A, B = (np.asarray(X, float) for X in (P, A, B))
    D = B - A
    dd = np.maximum(np.einsum("ij,ij->i", D, D), 1e-300)
    s = np.clip(np.einsum("kmj,mj->km", P[:, None, :] - A[None], D) / dd, 0.0, 1.0)
    Q = A[None] + s[..., None] * D[None]
    j = np.argmin(np.einsum("kmj,kmj->km", Q - P[:, None, :], Q - P[:, None, :]), axis=1)
    return Q[np.arange(len(P)), j], j
