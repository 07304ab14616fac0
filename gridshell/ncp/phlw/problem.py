"""The PHLW optimization problem (paper 4.2.1): the terms of eqs. 4.2-4.8 on a B-spline's
control points and auxiliaries, the parametrization and umbilic guards, and the one-sided
boundary gliding against the reference's boundary. Geometry in units of the reference's
bounding-box diagonal.
"""
from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from gridshell.geometry.bspline import BSplineSurface, uniform_params
from gridshell.core.errors import InputError
from gridshell.solver import Layout, Problem
from gridshell.solver import terms as T
from gridshell.ncp.phlw.checks import RowFit, check_reference_net, start_rows
from gridshell.ncp.phlw.terms import (Mode, Regularity, SampleGliding, Samples, UmbilicMargin, beta_fairness,
                         boundary_inward, curvature_eq, delta_eq, first_form_eq, init_auxiliary,
                         normal_eq, parametrization_guard, phlw_target, principal_eq,
                         sample_gliding, second_form_eq, sqrt_delta_eq, umbilic_guard)
from gridshell.ncp.reference import boundary_segments, closest_on_segments


#: Floor of ``E``, ``G`` and ``w = sqrt(delta)`` per sample, as a fraction of their values on
#: the initial surface (:func:`~gridshell.ncp.phlw.terms.parametrization_guard`): the
#: parameter speeds may halve, the area element fall to a quarter, never collapse.
REGULAR_FLOOR = 0.25

#: The optimized surface keeps ``(kappa_2 - kappa_1) / 2 >= UMBILIC_MARGIN *`` the reference's
#: curvature scale (RMS over the samples of ``max |kappa_i|``) at every sample
#: (:func:`~gridshell.ncp.phlw.terms.umbilic_guard`).
UMBILIC_MARGIN = 0.05


def phlw_problem(s0: BSplineSurface, data: Samples, lay: Layout, weights: dict[str, float],
                 reference: tuple[np.ndarray, np.ndarray], mode: Mode = "phlw",
                 scale: float = 1.0) -> tuple[Problem, np.ndarray, RowFit]:
    """The PHLW problem of one round (eqs. 4.2-4.8, E_beta, closeness, gliding, boundary, the
    parametrization and umbilic guards) and its start.

    ``s0`` and ``reference = (V, F)`` are in unit-diagonal coordinates (``scale``: the
    diagonal in metres, for messages); ``weights`` are all of :data:`DEFAULT_WEIGHTS`. The
    auxiliary variables start exact on ``s0`` and the row coefficients from
    :func:`start_rows` (``n`` inside the principal range); closest points on the reference
    are computed here.
    Raises :class:`InputError` for a singular parametrization and :class:`NoNetError` where
    no net of ``mode`` exists (:func:`check_reference_net`).

    Returns
    -------
    (Problem, x0 (lay.size,), RowFit)
    """
    from gridshell.geometry.igl_adapter import closest_points_with_normals

    R = int(data.row.max()) + 1
    aux = init_auxiliary(s0.ctrl.reshape(-1, 3), data)
    if not np.all(aux["delta"] > 0):
        raise InputError("the initial surface has a singular parametrization (S_u x S_v = 0) at "
                         f"{int(np.sum(~(aux['delta'] > 0)))} samples; refit the reference")
    check_reference_net(aux["K"], aux["H"], mode, scale=scale)
    fit = start_rows(aux["K"].reshape(R, -1), aux["H"].reshape(R, -1), mode)
    vals = {"C": s0.ctrl.reshape(-1, 3), **aux, "t": fit.t}
    if mode == "phlw":
        vals["n"] = fit.n
    elif mode == "cnc":
        vals["n"] = fit.n[:1]
    x = lay.pack(vals)

    S0 = np.asarray(data.ops["S"] @ s0.ctrl.reshape(-1, 3))
    foot, nrm = closest_points_with_normals(S0, *reference)
    prob = Problem(lay)
    c = weights["constraints"]
    prob.add("normal (4.2)", c, normal_eq, data)
    prob.add("first form (4.3)", c, first_form_eq, data)
    prob.add("delta (4.4)", c, delta_eq)
    prob.add("sqrt delta", c, sqrt_delta_eq)
    prob.add("second form (4.5)", c, second_form_eq, data)
    prob.add("curvature (4.6)", c, curvature_eq)
    prob.add("principal (4.7)", c, principal_eq)
    prob.add("regularity", c, parametrization_guard,
             Regularity(REGULAR_FLOOR * aux["E"], REGULAR_FLOOR * aux["G"],
                        REGULAR_FLOOR * aux["w"]))
    prob.add("umbilic", weights["umbilic"], umbilic_guard, UmbilicMargin(umbilic_margin(aux["K"], aux["H"]) ** 2))
    prob.add("target (4.8)", weights["target"], phlw_target, data)
    prob.add("beta", weights["beta"], beta_fairness, data)
    prob.add("closeness", weights["closeness"], T.linear, T.Linear("C", data.ops["S"], foot))
    prob.add("gliding", weights["gliding"], sample_gliding,
             SampleGliding(data.ops["S"], foot, nrm))
    bd = reference_boundary(*reference)
    if weights.get("boundary", 0.0) > 0 and len(bd.A):
        prob.add("boundary", weights["boundary"], boundary_inward,
                 boundary_gliding(s0.ctrl.reshape(-1, 3), boundary_operator(s0, data), reference,
                                  bd))
    return prob, x, fit


def umbilic_margin(K: np.ndarray, H: np.ndarray) -> float:
    """Least half-gap ``(kappa_2 - kappa_1) / 2`` the optimization keeps (units of ``H``):
    :data:`UMBILIC_MARGIN` times the RMS of ``max |kappa_i|`` over the samples."""
    r = np.sqrt(np.maximum(H * H - K, 0.0))
    return float(UMBILIC_MARGIN * np.sqrt(np.mean((np.abs(H) + r) ** 2)))


def boundary_operator(surf: BSplineSurface, data: Samples) -> Any:
    """``S`` at the boundary of the domain (``u = 0, 1`` and ``v = 0, 1``, at the sample
    parameters of the other direction): COO ``(4 m, nc)`` on the control points."""
    R = int(data.row.max()) + 1
    u, v = uniform_params(surf, (R, data.row.size // R))
    ub = np.concatenate([u, u, np.zeros(len(v)), np.ones(len(v))])
    vb = np.concatenate([np.zeros(len(u)), np.ones(len(u)), v, v])
    return surf.operator(ub, vb, 0, 0).tocoo()


class ReferenceBoundary(NamedTuple):
    """The boundary edges ``A (m, 3) -> B (m, 3)`` of a reference mesh and a point inside the
    face of each, ``inner (m, 3)`` (:func:`reference_boundary`)."""

    A: np.ndarray
    B: np.ndarray
    inner: np.ndarray


def reference_boundary(V: np.ndarray, F: np.ndarray) -> ReferenceBoundary:
    """:class:`ReferenceBoundary` of the mesh ``(V, F)`` (empty arrays for a closed mesh)."""
    seg, face = boundary_segments(F, return_faces=True)
    return ReferenceBoundary(V[seg[:, 0]], V[seg[:, 1]],
                             V[np.asarray(F)[face]].mean(axis=1))


def boundary_gliding(ctrl: np.ndarray, op: Any, reference: tuple[np.ndarray, np.ndarray],
                     boundary: ReferenceBoundary | None = None) -> SampleGliding:
    """Data of the boundary term (:func:`~gridshell.ncp.phlw.terms.boundary_inward`): the
    surface's boundary samples ``op @ ctrl``, their closest points on the reference's
    boundary edges and the outward in-surface normal there (``T x n``, pointing away from
    the edge's face). Without it the optimizer may shrink the surface away from the regions
    where no net exists (a 12 x 8 m hill came back 7.7 x 5.3 m); closeness and gliding hold
    the samples only where they are, and the patch of a principal parametrization is bounded
    by principal lines, which a rectangle's edges are not (so the boundary may overhang)."""
    from gridshell.geometry.igl_adapter import closest_points_with_normals

    V, F = reference
    bd = reference_boundary(V, F) if boundary is None else boundary
    Sb = np.asarray(op @ ctrl)
    foot, j = closest_on_segments(Sb, bd.A, bd.B)
    _, nrm = closest_points_with_normals(foot, V, F)
    m = np.cross(bd.B[j] - bd.A[j], nrm)
    m /= np.maximum(np.linalg.norm(m, axis=1), 1e-300)[:, None]
    m *= np.where(np.einsum("ij,ij->i", m, bd.inner[j] - foot) > 0, -1.0, 1.0)[:, None]
    return SampleGliding(op, foot, m)
