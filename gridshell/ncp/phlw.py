"""B-spline surface design towards PHLW, CNC and PK surfaces (paper 3.4, 4.2.1).

Theorem 2 of the paper: a normal-curvature-preserving alignable net exists exactly on surfaces
where ``aK + bH + c = 0`` (``b^2 - 4ac <= 0``) holds with coefficients constant along one
family of principal curvature lines (PHLW surfaces). With ``a = 1`` this is eq. 4.8,
``K - 2 n H + n^2 + t^2 = 0`` with one ``(n, t)`` per principal line, ``b = -2n``,
``c = n^2 + t^2``, and the net's normal curvature is ``n``.

Conventions
-----------
- Rows: the optimization samples a uniform ``rows x cols`` grid ``(u_i, v_j)`` of the domain.
  A *u-row* is the curve ``u = u_i`` (a principal line along ``S_v`` once ``F = M = 0``,
  eq. 4.7); ``n_u, t_u`` are constant along it. Sample ``s = i * cols + j``.
- Normal and signs follow :mod:`gridshell.diffgeo`: ``U = S_u x S_v`` (eq. 4.2), curvatures
  are positive when the surface bends towards ``U``, ``H = (LG - 2MF + NE) / (2 delta)``
  (eq. 4.6 with ``+ NE``: the paper's ``- NE`` is a typo). Flipping ``u`` and ``v`` flips
  ``U``, ``H`` and ``n`` together; ``K`` and ``t^2`` are unaffected.
- Units: the optimization runs on geometry scaled to a unit bounding-box diagonal of the
  reference (so that the weights mean the same on any model); everything returned is in
  metres (curvatures 1/m, ``K`` 1/m^2).

Variables (one :class:`~gridshell.solver.Layout`)
--------------------------------------------------
``C (nc, 3)`` control points; per sample ``U (k, 3)``, ``E, F, G, delta, w, L, M, N, K, H
(k,)`` with ``w = sqrt(delta)`` (keeps eq. 4.5 quadratic: ``L w = <S_uu, U>``, ``w^2 =
delta``); ``n`` (``rows`` values in mode ``phlw``, one value in ``cnc``, absent in ``aa``
where ``n = 0``) and ``t (rows,)``.

Energy (paper): ``E_PHLW + E_beta + E_c + E_g`` with ``E_PHLW = sum chi_i^2 + omega_t chi_t^2``
(constraints 4.2-4.7 weight 1, target 4.8 weight ``omega_t = 0.1``), ``E_beta = omega_beta
sum (n_u - H)^2`` (``omega_beta = 5e-4``), closeness ``E_c`` and gliding ``E_g`` to the
reference surface with closest points refreshed every outer round. Added here (issue 13):
guards of the parametrization (``E, G, w`` may not collapse) and of umbilics (the half-gap of
the principal curvatures stays above a margin), and a one-sided boundary term.

Rounds: the solver works with relaxed auxiliary variables; each round is judged by the
surface's *true* energy (auxiliaries re-projected from the control points, same problem) and
halved or rejected if that rose (:func:`_round`). ``converged`` means the figures hold
(:func:`acceptance_figures`), not that a solver tolerance was met; the iterations and the rounds
end as soon as they hold (issue 17: a round's iterations with a margin, :data:`STOP_MARGIN`),
and a dense sampling is reached from a coarser one (:func:`sample_levels`).

Module layout: the terms live in :mod:`.phlw_terms`, row fits and checks in
:mod:`.phlw_checks`; their public names are re-exported here.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any, Callable, NamedTuple

import numpy as np

from ..bspline import BSplineSurface, uniform_params
from ..errors import ConvergenceError, InputError
from ..solver import Layout, Problem, solve
from ..solver import terms as T
from .phlw_checks import (FLAT_CURVATURE, NEAR_UMBILIC, NetCheck, RowFit, _grid_geometry,
                          _regions, check_reference_net, fit_rows, net_direction_check,
                          phlw_energy, principal_angle_error, row_relation_residual,
                          start_rows)
from .phlw_terms import (MODES, Mode, Regularity, SampleGliding, Samples, UmbilicMargin,
                         _check_mode, beta_fairness, boundary_inward, curvature_eq, delta_eq,
                         first_form_eq, init_auxiliary, init_curvature, init_delta,
                         init_first_form, init_normal, init_second_form, make_layout,
                         make_samples, normal_eq, parametrization_guard, phlw_target,
                         principal_eq, sample_gliding, second_form_eq, sqrt_delta_eq,
                         umbilic_guard)
from .phlw_output import result_summary, write_phlw  # noqa: F401  (re-exported)
from .reference import boundary_segments, closest_on_segments

#: Default weights, on geometry scaled to a unit bounding-box diagonal. ``target`` and ``beta``
#: are the paper's omega_t = 0.1 and omega_beta = 5e-4. The paper gives no omega_c, omega_g:
#: closeness 1e-2 (it mostly holds the samples tangentially, while the parameter lines rotate
#: onto the principal directions over the outer rounds) and gliding 10 (it keeps the shape on
#: the reference against E_beta, which otherwise pulls H towards n_u, i.e. towards a minimal
#: surface in mode aa). The paper weights its constraints 4.2-4.7 by 1; on unit-diagonal
#: geometry that makes them only ~10x stiffer than the target, and Levenberg-Marquardt then
#: trades constraint violation for target (the auxiliary K, H drift from the surface's true
#: curvature: measured E_PHLW of the true surface 1e4x above the solver's). Weighting them
#: 100 keeps the auxiliaries on the surface (re-projected exactly every outer round as well).
#: ``boundary`` (one-sided: boundary samples may not move inside the reference's boundary) is
#: a trade: a principal patch cannot both cover a rectangle whose edges are not principal
#: lines and stay on it. Measured on a 10 x 10 m hyperbolic paraboloid (phlw): weight 0 trims
#: the corners (coverage 4.5 %, deviation 0.08 %, 38 s), 0.1 overhangs (2.1 %, 1.2 %, 11 s),
#: 0.01 between (0.6 %, 2.9 %, 18 s). ``umbilic`` weights :func:`umbilic_guard`, a hinge of
#: size 1 per sample: 100 pulled a hill's umbilics away at the cost of E_PHLW rising.
DEFAULT_WEIGHTS: dict[str, float] = {
    "constraints": 100.0,  # eqs. 4.2-4.7
    "target": 0.1,         # omega_t, eq. 4.8
    "beta": 5e-4,          # omega_beta
    "closeness": 1e-2,     # omega_c
    "gliding": 10.0,       # omega_g
    "boundary": 0.01,      # boundary samples not inside the reference's boundary (not in the paper)
    "umbilic": 1.0,        # half-gap of the principal curvatures >= a margin (not in the paper)
}

#: Levenberg-Marquardt settings of every round: initial damping (relative to the mean of
#: diag(J^T J)) and the relative energy decrease per step that ends a round. Measured on the
#: demo's torus zone (18 x 18 samples, 4 rounds): the default damping of 1e-3 over-damps the
#: first ~10 steps of every round and tol_rel = 1e-7 is never met (160 iterations, 19 s);
#: these take 57 iterations to an energy within 10 % of that run's, the same deviation and
#: row relation (benchmarks/README.md).
SOLVER_DAMPING = 1e-9
SOLVER_TOL_REL = 1e-3

#: Floor of ``E``, ``G`` and ``w = sqrt(delta)`` per sample, as a fraction of their values on
#: the initial surface (:func:`~gridshell.ncp.phlw_terms.parametrization_guard`): the
#: parameter speeds may halve, the area element fall to a quarter, never collapse.
REGULAR_FLOOR = 0.25

#: The optimized surface keeps ``(kappa_2 - kappa_1) / 2 >= UMBILIC_MARGIN *`` the reference's
#: curvature scale (RMS over the samples of ``max |kappa_i|``) at every sample
#: (:func:`~gridshell.ncp.phlw_terms.umbilic_guard`).
UMBILIC_MARGIN = 0.05

#: An outer round that lowers the true energy by less than this fraction ends the loop
#: (stagnation); a solver step that raises it is halved up to BACKTRACK times, then rejected.
ROUND_TOL_REL = 1e-3
BACKTRACK = 6

#: Acceptance (``converged``): max relative residual of eq. 4.8 at the samples, max angle of
#: the parameter lines to the principal directions (degrees), max deviation from the reference
#: (% of its bounding-box diagonal). E_PHLW at or below E_PHLW_FLOOR (unit-diagonal units)
#: counts as held even when it did not fall: a reference that already is PHLW (a torus zone in
#: cnc starts at 1.9e-7 and ends at 1.4e-6 with relation 1.6e-4, while the total energy fell).
RELATION_TOL = 1e-2
ANGLE_TOL_DEG = 1.0
DEVIATION_TOL = 5.0
#: Acceptance: max distance of the reference to the surface (% of its diagonal). Looser than
#: DEVIATION_TOL: a principal patch is bounded by principal lines and trims the corners of a
#: reference whose edges are not principal lines; a shrunk surface (a 12 x 8 m hill returned
#: 7.7 x 5.3 m: 15 %) fails.
COVERAGE_TOL = 10.0
E_PHLW_FLOOR = 1e-4


@dataclass
class PHLWResult:
    """Outcome of :func:`optimize_phlw` (metres, 1/m, 1/m^2).

    surface : optimized BSplineSurface
    mode : "phlw" | "cnc" | "aa"
    u_rows : (rows,) u of every optimization row; ``v_samples (cols,)``
    n_rows, t_rows : (rows,) eq. 4.8 per u-row (n equal in cnc, zero in aa), 1/m
    abc : (rows, 3) ``a = 1, b = -2 n, c = n^2 + t^2`` of ``aK + bH + c = 0``
    history : per outer round ``{"round", "iterations", "energy0", "energy", "message",
        "terms", "time"}``
    report_before, report_after : per term ``{"weight", "energy", "rms", "max"}`` (scaled units),
        plus ``"E_PHLW"`` (:func:`phlw_energy`) and the acceptance figures
    converged : every acceptance figure holds (:func:`acceptance_figures`): the energy and
        E_PHLW fell, relation, principal angle and deviation within their tolerances and a
        real net direction at every sample
    figures : :func:`acceptance_figures`
    energy_initial, energy_final : energy of the whole problem (auxiliaries exact) at the start
        and at the end, on unit-diagonal geometry
    deviation : max distance of the surface (check sampling) to the reference, % of the
        reference's bounding-box diagonal
    diagnostics : human-readable lines (clamped rows, umbilic / no-net regions)
    net_check : :class:`NetCheck` at the optimization samples
    """

    surface: BSplineSurface
    mode: str
    u_rows: np.ndarray
    v_samples: np.ndarray
    n_rows: np.ndarray
    t_rows: np.ndarray
    abc: np.ndarray
    history: list[dict] = field(default_factory=list)
    report_before: dict = field(default_factory=dict)
    report_after: dict = field(default_factory=dict)
    converged: bool = False
    deviation: float = float("nan")
    diagnostics: list[str] = field(default_factory=list)
    net_check: NetCheck | None = None
    weights: dict = field(default_factory=dict)
    reference_diagonal: float = float("nan")
    figures: dict = field(default_factory=dict)
    energy_initial: float = float("nan")
    energy_final: float = float("nan")


def _scaled_surface(surf: BSplineSurface, center: np.ndarray, scale: float) -> BSplineSurface:
    return BSplineSurface(surf.degree_u, surf.degree_v, surf.knots_u.copy(), surf.knots_v.copy(),
                          (surf.ctrl - center) / scale)


def _reference_arrays(reference: Any) -> tuple[np.ndarray, np.ndarray]:
    if hasattr(reference, "V") and hasattr(reference, "F"):
        V, F = reference.V, reference.F
    else:
        try:
            V, F = reference
        except (TypeError, ValueError):
            raise InputError("reference must be a mesh (V, F) or an object with V and F") from None
    V = np.asarray(V, float)
    F = np.asarray(F)
    if V.ndim != 2 or V.shape[1] != 3 or len(V) < 3:
        raise InputError(f"reference vertices must have shape (n, 3), n >= 3; got {V.shape}")
    return V, F


def deviation_percent(surf: BSplineSurface, V: np.ndarray, F: np.ndarray,
                      samples: tuple[int, int] = (60, 60)) -> float:
    """Max distance of the surface (sampled ``samples``) to the mesh ``(V, F)``, in % of the
    mesh's bounding-box diagonal."""
    from ..igl_adapter import closest_points

    u, v = uniform_params(surf, samples)
    P = surf.evaluate_grid(u, v).reshape(-1, 3)
    d2, _, _ = closest_points(P, V, F)
    diag = float(np.linalg.norm(V.max(0) - V.min(0)))
    return float(100.0 * np.sqrt(d2.max()) / diag)


def coverage_percent(surf: BSplineSurface, V: np.ndarray, F: np.ndarray,
                     samples: tuple[int, int] = (60, 60)) -> float:
    """Max distance of the mesh ``(V, F)``'s vertices to the surface (sampled ``samples`` and
    triangulated), in % of the mesh's bounding-box diagonal: how much of the reference the
    surface fails to cover (a shrunk surface scores high, :func:`deviation_percent` not)."""
    from ..igl_adapter import closest_points

    m = surf.sample(*samples)
    d2, _, _ = closest_points(np.asarray(V, float), m.V, m.F)
    diag = float(np.linalg.norm(V.max(0) - V.min(0)))
    return float(100.0 * np.sqrt(d2.max()) / diag)


def _acceptance(surf: BSplineSurface, n: np.ndarray, t: np.ndarray, u: np.ndarray, v: np.ndarray,
                mode: str, omega_t: float, diag: float) -> dict[str, float]:
    rel = row_relation_residual(surf, u, v, n, t)
    return {"E_PHLW": phlw_energy(surf, n, t, (len(u), len(v)), omega_t=omega_t, scale=diag),
            "relation_max_rel": float(np.nanmax(rel)),
            "angle_max_deg": float(np.nanmax(principal_angle_error(surf, u, v)))}


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
    from ..igl_adapter import closest_points_with_normals

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


def principal_range_notes(K: np.ndarray, H: np.ndarray, u: np.ndarray, mode: str,
                          scale: float = 1.0) -> list[str]:
    """Lines saying where the reference admits no net of ``mode`` as it is: ``cnc``, the
    principal ranges ``[kappa_1, kappa_2]`` of all samples have no common ``n``; ``phlw``, those
    of a row have none (``K, H (rows, cols)`` on unit-diagonal geometry, ``scale`` metres)."""
    if mode == "aa":
        return []
    r = np.sqrt(np.maximum(H * H - K, 0.0))
    k1, k2 = (H - r) / scale, (H + r) / scale
    if mode == "cnc":
        lo, hi = float(k1.max()), float(k2.min())
        if lo <= hi:
            return []
        return [f"no single n lies in [kappa_1, kappa_2] at every sample of the reference: "
                f"max kappa_1 = {lo:.4g} 1/m > min kappa_2 = {hi:.4g} 1/m; no CNC net exists on "
                "it as it is, so the optimization has to move the surface (deviation)"]
    bad = np.flatnonzero(k1.max(axis=1) > k2.min(axis=1))
    if not len(bad):
        return []
    return [f"on {len(bad)} of {len(u)} rows (u in [{u[bad].min():.3f}, {u[bad].max():.3f}]) no "
            "n_u lies in [kappa_1, kappa_2] at every sample of the row; no PHLW net exists "
            "there as the reference is, so the optimization has to move the surface"]


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
    """Data of the boundary term (:func:`~gridshell.ncp.phlw_terms.boundary_inward`): the
    surface's boundary samples ``op @ ctrl``, their closest points on the reference's
    boundary edges and the outward in-surface normal there (``T x n``, pointing away from
    the edge's face). Without it the optimizer may shrink the surface away from the regions
    where no net exists (a 12 x 8 m hill came back 7.7 x 5.3 m); closeness and gliding hold
    the samples only where they are, and the patch of a principal parametrization is bounded
    by principal lines, which a rectangle's edges are not (so the boundary may overhang)."""
    from ..igl_adapter import closest_points_with_normals

    V, F = reference
    bd = reference_boundary(V, F) if boundary is None else boundary
    Sb = np.asarray(op @ ctrl)
    foot, j = closest_on_segments(Sb, bd.A, bd.B)
    _, nrm = closest_points_with_normals(foot, V, F)
    m = np.cross(bd.B[j] - bd.A[j], nrm)
    m /= np.maximum(np.linalg.norm(m, axis=1), 1e-300)[:, None]
    m *= np.where(np.einsum("ij,ij->i", m, bd.inner[j] - foot) > 0, -1.0, 1.0)[:, None]
    return SampleGliding(op, foot, m)


#: Continuation in the sampling: rounds run first on at most this many samples per direction
#: (the paper's 18) when more are asked for, then on the asked sampling, started from the
#: coarse level's control points (:func:`sample_levels`). The figures are always measured at
#: the asked sampling, so the fine level runs only when the coarse one cannot make them hold.
COARSE_SAMPLES = 18
#: Rounds on the coarse level: the first round makes the large move (on the saddle of
#: benchmarks/phlw.py the energy falls 4e4-fold in it, later rounds by < 10 % each), the
#: later ones refine what only the asked sampling can judge.
COARSE_ROUNDS = 1
#: The in-round stop (:meth:`_Judge.holds`): a round's Levenberg-Marquardt iterations end as
#: soon as every acceptance figure holds, with the relation and the principal angle this many
#: times within their tolerances (the figures the iterations drive; a margin for what the
#: NCP stages after the PHLW step build on).
STOP_MARGIN = 10.0


def sample_levels(samples: tuple[int, int]) -> list[tuple[int, int]]:
    """The sampling levels of the rounds, coarse to fine, the last one ``samples``: a coarse
    level of ``max(COARSE_SAMPLES, ceil(s / 2))`` per direction when that is fewer."""
    fine = tuple(int(s) for s in samples)
    coarse = tuple(min(s, max(COARSE_SAMPLES, -(-s // 2))) for s in fine)
    return [fine] if coarse == fine else [coarse, fine]


class _Level:
    """One sampling level of the rounds: its samples, terms and start (unit-diagonal units)."""

    def __init__(self, s0: BSplineSurface, samples: tuple[int, int], w: dict[str, float],
                 reference: tuple[np.ndarray, np.ndarray], mode: Mode, diag: float) -> None:
        self.samples, self.mode, self.reference = tuple(samples), mode, reference
        self.u, self.v = uniform_params(s0, self.samples)
        R = len(self.u)
        self.data = make_samples(s0, self.u, self.v, mode)
        self.lay = make_layout(s0.n_ctrl, R * len(self.v), R, mode)
        self.prob, self.x0, self.fit = phlw_problem(s0, self.data, self.lay, w, reference, mode,
                                                    scale=diag)
        self.op_b = boundary_operator(s0, self.data)
        self.bd = reference_boundary(*reference)

    def start(self, ctrl: np.ndarray) -> np.ndarray:
        """The state of this level on the control points ``ctrl (nc, 3)``: auxiliaries exact,
        row coefficients fitted to the rows' curvatures (:func:`start_rows`)."""
        with np.errstate(divide="ignore", invalid="ignore"):
            aux = init_auxiliary(ctrl, self.data)
        R = len(self.u)
        fit = start_rows(aux["K"].reshape(R, -1), aux["H"].reshape(R, -1), self.mode)
        vals = {"C": ctrl, **aux, "t": fit.t}
        if self.mode != "aa":
            vals["n"] = fit.n if self.mode == "phlw" else fit.n[:1]
        return self.lay.pack(vals)

    def refresh(self, x: np.ndarray) -> None:
        """Closest points on the reference (closeness, gliding, boundary) at the state ``x``."""
        from ..igl_adapter import closest_points_with_normals

        C = self.lay.view(x, "C")
        S = np.asarray(self.data.ops["S"] @ C)
        foot, nrm = closest_points_with_normals(S, *self.reference)
        self.prob.set_data("closeness", T.Linear("C", self.data.ops["S"], foot))
        self.prob.set_data("gliding", SampleGliding(self.data.ops["S"], foot, nrm))
        if any(e.name == "boundary" for e in self.prob.entries):
            self.prob.set_data("boundary", boundary_gliding(C, self.op_b, self.reference,
                                                            self.bd))


class _State(NamedTuple):
    """A state of the fine level with its figures (:class:`_Judge`); metres in ``surface``."""

    x: np.ndarray
    energy: float
    surface: BSplineSurface
    n_rows: np.ndarray
    t_rows: np.ndarray
    after: dict
    check: NetCheck
    deviation: float
    figures: dict


class _Judge:
    """The acceptance figures of a state of the fine level (what ``converged`` means)."""

    def __init__(self, fine: _Level, surf: BSplineSurface, center: np.ndarray, diag: float,
                 before: dict, energy_initial: float, reference: tuple[np.ndarray, np.ndarray],
                 mode: Mode, omega_t: float, check_samples: tuple[int, int]) -> None:
        self.fine, self.surf, self.center, self.diag = fine, surf, center, diag
        self.before, self.energy_initial, self.reference = before, energy_initial, reference
        self.mode, self.omega_t, self.check_samples = mode, omega_t, check_samples

    def _surface_rows(self, x: np.ndarray) -> tuple[BSplineSurface, np.ndarray, np.ndarray]:
        lv, diag, s = self.fine, self.diag, self.surf
        ctrl = lv.lay.view(x, "C").reshape(s.ctrl.shape) * diag + self.center
        out = BSplineSurface(s.degree_u, s.degree_v, s.knots_u.copy(), s.knots_v.copy(), ctrl)
        R = len(lv.u)
        t_rows = np.abs(lv.lay.view(x, "t")) / diag
        if self.mode == "phlw":
            n_rows = lv.lay.view(x, "n") / diag
        elif self.mode == "cnc":
            n_rows = np.full(R, lv.lay.view(x, "n")[0] / diag)
        else:
            n_rows = np.zeros(R)
        return out, n_rows, t_rows

    def _check(self, out: BSplineSurface, n_rows: np.ndarray) -> NetCheck:
        lv, mode = self.fine, self.mode
        return net_direction_check(out, n_rows if mode == "phlw" else
                                   (n_rows[:1] if mode == "cnc" else None),
                                   u_rows=lv.u, u_samples=lv.u, v_samples=lv.v)

    def __call__(self, x: np.ndarray, unchanged: bool, refresh: bool = True) -> _State:
        """Every figure of the fine level's state ``x`` (auxiliaries exact); ``refresh``: the
        energy with closest points at ``x`` (else those of the problem as it is)."""
        lv = self.fine
        if refresh and not unchanged:
            lv.refresh(x)
        energy = float(lv.prob.energy(x))
        out, n_rows, t_rows = self._surface_rows(x)
        after = _acceptance(out, n_rows, t_rows, lv.u, lv.v, self.mode, self.omega_t, self.diag)
        check = self._check(out, n_rows)
        dev = deviation_percent(out, *self.reference, self.check_samples)
        cov = coverage_percent(out, *self.reference, self.check_samples)
        figures = acceptance_figures(self.before, after, dev, check, self.energy_initial, energy,
                                     cov, unchanged=unchanged)
        return _State(x, energy, out, n_rows, t_rows, after, check, dev, figures)

    def holds(self, x: np.ndarray) -> bool:
        """Whether every figure holds at ``x``, relation and angle :data:`STOP_MARGIN` times
        within their tolerances: the in-round stop (:func:`_round`). Cheapest figures first;
        the energy with the closest points the problem has now (a running round's own)."""
        lv = self.fine
        out, n_rows, t_rows = self._surface_rows(x)
        after = _acceptance(out, n_rows, t_rows, lv.u, lv.v, self.mode, self.omega_t, self.diag)
        if not (after["relation_max_rel"] < RELATION_TOL / STOP_MARGIN
                and after["angle_max_deg"] < ANGLE_TOL_DEG / STOP_MARGIN):
            return False
        check = self._check(out, n_rows)
        if np.any(check.umbilic | check.out_of_range):
            return False
        dev = deviation_percent(out, *self.reference, self.check_samples)
        if not dev < DEVIATION_TOL:
            return False
        cov = coverage_percent(out, *self.reference, self.check_samples)
        if not cov < COVERAGE_TOL:
            return False
        figures = acceptance_figures(self.before, after, dev, check, self.energy_initial,
                                     float(lv.prob.energy(x)), cov)
        return all(f["ok"] for f in figures.values())


def optimize_phlw(surf: BSplineSurface, reference: Any, *, mode: Mode = "phlw",
                  samples: tuple[int, int] = (18, 18), weights: dict[str, float] | None = None,
                  outer: int = 4, max_iter: int = 40, check_samples: tuple[int, int] = (60, 60),
                  early_stop: bool = True,
                  progress: Callable[[str], None] | None = None) -> PHLWResult:
    """Optimize a B-spline towards a PHLW (``phlw``), CNC (``cnc``) or PK (``aa``) surface
    close to a reference mesh (paper 4.2.1).

    Parameters
    ----------
    surf : initial BSplineSurface (e.g. from :func:`gridshell.ncp.reference.initial_surface`)
    reference : the reference surface as ``(V (n,3), F (m,3|4))`` or a mesh with ``V``, ``F``;
        closest points on it are refreshed each outer round (libigl)
    mode : "phlw" one ``(n_u, t_u)`` per u-row; "cnc" one ``n`` for the whole surface;
        "aa" ``n = 0`` (PK surface, asymptotic net)
    samples : (rows, cols) optimization samples (paper: 18 x 18)
    weights : overrides of :data:`DEFAULT_WEIGHTS` (keys ``constraints``, ``target``, ``beta``,
        ``closeness``, ``gliding``, ``boundary``, ``umbilic``); in mode ``aa`` ``beta``
        defaults to 0 (see the code)
    outer : at most this many rounds of (refresh closest points, Levenberg-Marquardt solve,
        accept / halve / reject by the true energy) per sampling level
        (:func:`sample_levels`); a level ends early when a round is rejected or lowers the
        energy by less than :data:`ROUND_TOL_REL`
    max_iter : solver iterations per round
    check_samples : sampling for the deviation figure
    early_stop : end the rounds as soon as every figure of :func:`acceptance_figures` holds
        at ``samples`` (measured after every accepted round); False runs the rounds until
        they stagnate, as before
    progress : called with one line per round

    Returns
    -------
    PHLWResult : ``converged`` when every figure of :func:`acceptance_figures` holds

    Raises
    ------
    InputError : bad arguments or a singular initial parametrization
    NoNetError : no net of ``mode`` can exist near the reference (umbilic everywhere; ``aa``
        with ``K > 0`` everywhere), before any optimization
    ConvergenceError : no round could improve the surface and its figures fail, or the
        energy became non-finite
    """
    _check_mode(mode)
    w = dict(DEFAULT_WEIGHTS)
    if mode == "aa":
        # n = 0 is fixed: E_beta has no net variable left to regularize and only pulls H -> 0
        # (towards a minimal surface); measured on a pseudosphere it moves K off row-constancy
        # by 1 %. Off by default in aa; pass weights={"beta": 5e-4} for the paper's setting.
        w["beta"] = 0.0
    for key, val in (weights or {}).items():
        if key not in w:
            raise InputError(f"unknown weight {key!r}; weights are {', '.join(w)}")
        w[key] = float(val)
    if int(outer) < 1 or int(max_iter) < 1:
        raise InputError(f"outer and max_iter must be >= 1, got {outer} and {max_iter}")
    V, Fr = _reference_arrays(reference)
    center = V.mean(axis=0)
    diag = float(np.linalg.norm(V.max(0) - V.min(0)))
    if not diag > 0:
        raise InputError("the reference mesh has zero extent; pass a real surface")
    Vs = (V - center) / diag
    s0 = _scaled_surface(surf, center, diag)
    plan = sample_levels(samples)
    fine = _Level(s0, plan[-1], w, (Vs, Fr), mode, diag)
    u, v, R = fine.u, fine.v, len(fine.u)
    x, fit = fine.x0, fine.fit
    diagnostics: list[str] = []
    if len(fit.clamped):
        diagnostics.append(f"initial fit: rows {fit.clamped.tolist()} had t_u^2 < 0 (b^2 - 4ac > 0) "
                           "or n_u outside [kappa_1, kappa_2]; started there from n_u inside "
                           "the principal range")
    diagnostics += principal_range_notes(fine.lay.view(x, "K").reshape(R, -1),
                                         fine.lay.view(x, "H").reshape(R, -1), u, mode, diag)

    before = {"terms": fine.prob.report(x), **_acceptance(surf, fit.n / diag, fit.t / diag, u,
                                                          v, mode, w["target"], diag)}
    energy_initial = fine.prob.energy(x)
    judge = _Judge(fine, surf, center, diag, before, float(energy_initial), (V, Fr), mode,
                   w["target"], check_samples)
    history: list[dict] = []
    t0 = time.perf_counter()
    level = fine if len(plan) == 1 else _Level(s0, plan[0], w, (Vs, Fr), mode, diag)
    xl = x if level is fine else level.x0     # the state at the current level
    state = judge(x, unchanged=True)          # the figures of the fine level's state
    at_level, total = 0, 0
    while True:
        if total > 0:
            level.refresh(xl)                 # closest points at the accepted state
        to_fine = (lambda xr: xr) if level is fine else \
            (lambda xr, lv=level: fine.start(lv.lay.view(xr, "C")))
        step = _round(level.prob, level.lay, level.data, xl, int(max_iter),
                      stop=(lambda xr: judge.holds(to_fine(xr))) if early_stop else None)
        at_level += 1
        total += 1
        rec = {"round": total, "samples": list(level.samples),
               **{k: v_ for k, v_ in step.items() if k != "x"}}
        gain_small = step["energy0"] - step["energy"] <= ROUND_TOL_REL * step["energy0"]
        if step["accepted"]:
            xl = step["x"]
            state = judge(to_fine(xl), unchanged=False)
            rec["figures_failing"] = [k for k, f in state.figures.items() if not f["ok"]]
        rec["time"] = time.perf_counter() - t0
        history.append(rec)
        held = step["accepted"] and not rec["figures_failing"]
        if progress is not None:
            where = (f"round {at_level}/{outer}" if level is fine else
                     f"coarse round {at_level}/{COARSE_ROUNDS} ({level.samples[0]} x "
                     f"{level.samples[1]} samples)")
            progress(f"{where}: energy {step['energy0']:.3e} -> {step['energy']:.3e} in "
                     f"{step['iterations']} iterations ({step['message']})"
                     + ("; the figures hold" if held else ""))
        if held and early_stop:
            break
        if not step["accepted"] or gain_small or at_level >= (
                int(outer) if level is fine else COARSE_ROUNDS):
            if level is fine:
                break
            # continuation: the next sampling level starts from this level's control points
            level, xl, at_level = fine, fine.start(level.lay.view(xl, "C")), 0
    x = state.x
    energy_final = state.energy
    if not np.isfinite(energy_final):
        raise ConvergenceError(f"the {mode.upper()} optimization produced a non-finite energy; "
                               "refit the reference with fewer control points or more smoothing")
    unchanged = not any(h["accepted"] for h in history)
    if unchanged:
        state = judge(x, unchanged=True)
    figures, check = state.figures, state.check
    diagnostics += check.messages
    if unchanged and not all(f["ok"] for f in figures.values()):
        raise ConvergenceError(
            f"the {mode.upper()} optimization could not lower its energy from "
            f"{energy_initial:.4g}: every round made the surface worse (true energy "
            f"{history[0]['energy_true']:.4g} after round 1) and was rejected; try more control "
            "points, a denser reference or another mode")
    n_rows, t_rows = state.n_rows, state.t_rows
    abc = np.column_stack([np.ones(R), -2 * n_rows, n_rows ** 2 + t_rows ** 2])
    after = {"terms": fine.prob.report(x), **state.after}
    return PHLWResult(surface=state.surface, mode=mode, u_rows=u, v_samples=v, n_rows=n_rows,
                      t_rows=t_rows, abc=abc, history=history, report_before=before,
                      report_after=after, converged=all(f["ok"] for f in figures.values()),
                      deviation=state.deviation, diagnostics=diagnostics, net_check=check,
                      weights=w, reference_diagonal=diag, figures=figures,
                      energy_initial=float(energy_initial), energy_final=float(energy_final))


def _reprojected(lay: Layout, data: Samples, x: np.ndarray) -> np.ndarray:
    """``x`` with every auxiliary variable exact on its control points (:func:`init_auxiliary`)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return lay.pack({**lay.unpack(x), **init_auxiliary(lay.view(x, "C"), data)})


def _true_energy(prob: Problem, lay: Layout, data: Samples, x: np.ndarray
                 ) -> tuple[float, np.ndarray]:
    """Energy of ``prob`` at ``x`` re-projected (auxiliaries exact: what the surface itself
    scores, not the solver's relaxed auxiliaries); ``inf`` where it is not finite."""
    xr = _reprojected(lay, data, x)
    if not np.all(np.isfinite(xr)):
        return math.inf, xr
    E = float(prob.energy(xr))
    return (E if math.isfinite(E) else math.inf), xr


def _round(prob: Problem, lay: Layout, data: Samples, x: np.ndarray, max_iter: int,
           stop: Callable[[np.ndarray], bool] | None = None) -> dict:
    """One outer round from the accepted state ``x`` (auxiliaries exact).

    The solver's end point is judged by its *true* energy (auxiliaries re-projected from the
    control points, same problem, same closest points): the solver minimizes with relaxed
    auxiliaries, and its energy can fall while the surface's own rises (the 1e12 jumps of
    issue 13). If the true energy did not fall, the step in ``C, n, t`` is halved up to
    :data:`BACKTRACK` times; if none of these lowers it, the round is rejected and ``x`` kept.
    ``stop(x_exact)`` (auxiliaries re-projected) may end the solver's iterations early.
    """
    E0, x = _true_energy(prob, lay, data, x)
    sol = solve(prob, x, method="lm", max_iter=max_iter, damping=SOLVER_DAMPING,
                tol_rel=SOLVER_TOL_REL,
                stop=None if stop is None else (lambda xs: stop(_reprojected(lay, data, xs))))
    E1, x1 = _true_energy(prob, lay, data, sol.x)
    out = {"iterations": sol.iterations, "energy0": E0, "energy_solver": float(sol.energy),
           "energy_true": E1, "step": 1.0, "message": sol.message}
    alpha = 1.0
    for _ in range(BACKTRACK):
        if E1 < E0:
            break
        alpha *= 0.5
        E1, x1 = _true_energy(prob, lay, data, x + alpha * (sol.x - x))
    if E1 < E0:
        out.update(energy=E1, step=alpha, accepted=True, x=x1)
        if alpha < 1.0:
            out["message"] += f"; step cut to {alpha:g} (the full step raised the true energy)"
    else:
        out.update(energy=E0, step=0.0, accepted=False, x=x,
                   message=sol.message + f"; rejected (true energy {E0:.3e} -> {out['energy_true']:.3e})")
    return out


def acceptance_figures(before: dict, after: dict, deviation: float, check: NetCheck | None,
                       energy_initial: float, energy_final: float,
                       coverage: float = 0.0, unchanged: bool = False) -> dict[str, dict]:
    """The figures that decide ``converged``: ``{name: {"value", "limit", "ok"}}``.

    ``energy``: final / initial energy of the whole problem (< 1); ``E_PHLW``: after / before
    (< 1, or already below :data:`E_PHLW_FLOOR`); ``relation``: max relative residual of eq. 4.8
    at the samples; ``angle``: max principal angle error (degrees); ``deviation``: % of the
    reference's diagonal; with ``unchanged`` (no round accepted: the reference already is as
    good as the optimizer gets it) the energy figures hold if they did not rise;
    ``coverage``: max distance of the reference to the surface, same
    units (a shrunk surface); ``net``: samples without a real net direction or umbilic (0).
    """
    def fig(value: float, limit: float, ok: bool | None = None) -> dict:
        value = float(value)
        return {"value": value, "limit": float(limit),
                "ok": bool(math.isfinite(value) and (value < limit if ok is None else ok))}

    e0, e1 = before["E_PHLW"]["total"], after["E_PHLW"]["total"]
    bad = int(np.sum(check.umbilic | check.out_of_range)) if check is not None else 0
    return {
        "energy": fig(energy_final / energy_initial if energy_initial > 0 else 0.0, 1.0,
                      energy_final < energy_initial or (unchanged and
                                                        energy_final <= energy_initial)),
        "E_PHLW": fig(e1 / e0 if e0 > 0 else 0.0, 1.0,
                      e1 < e0 or e1 <= E_PHLW_FLOOR or (unchanged and e1 <= e0)),
        "relation": fig(after["relation_max_rel"], RELATION_TOL),
        "angle": fig(after["angle_max_deg"], ANGLE_TOL_DEG),
        "deviation": fig(deviation, DEVIATION_TOL),
        "coverage": fig(coverage, COVERAGE_TOL),
        "net": fig(bad, 0.5),
    }
