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
- Normal and signs follow :mod:`gridshell.geometry.diffgeo`: ``U = S_u x S_v`` (eq. 4.2), curvatures
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
halved or rejected if that rose (:func:`run_round`). ``converged`` means the figures hold
(:func:`acceptance_figures`), not that a solver tolerance was met; the iterations and the rounds
end as soon as they hold (issue 17: a round's iterations with a margin, :data:`STOP_MARGIN`),
and a dense sampling is reached from a coarser one (:func:`sample_levels`).

Module layout (the package :mod:`gridshell.ncp.phlw`): the terms live in :mod:`.terms`, row
fits and checks in :mod:`.checks`, the problem in :mod:`.problem`, the acceptance figures in
:mod:`.figures`, the rounds (levels, judge, one round) in :mod:`.rounds`, the result type in
:mod:`.result`, the output in :mod:`.output`; this module is the driver.
"""


from __future__ import annotations

import time
from typing import Any, Callable

import numpy as np

from gridshell.geometry.bspline import BSplineSurface
from gridshell.core.errors import ConvergenceError, InputError
from gridshell.ncp.phlw.result import PHLWResult
from gridshell.ncp.phlw.checks import NetCheck
from gridshell.ncp.phlw.figures import surface_figures
from gridshell.ncp.phlw.rounds import COARSE_ROUNDS, ROUND_TOL_REL, Judge, Level, run_round, sample_levels
from gridshell.ncp.phlw.terms import Mode, _check_mode

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
    w = _phlw_weights(mode, weights)
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
    fine = Level(s0, plan[-1], w, (Vs, Fr), mode, diag)
    x, fit = fine.x0, fine.fit
    diagnostics = _initial_diagnostics(fine, mode, diag)
    before = {"terms": fine.prob.report(x), **surface_figures(surf, fit.n / diag, fit.t / diag,
                                                              fine.u, fine.v, mode, w["target"],
                                                              diag)}
    energy_initial = fine.prob.energy(x)
    judge = Judge(fine, surf, center, diag, before, float(energy_initial), (V, Fr), mode,
                  w["target"], check_samples)
    t0 = time.perf_counter()
    level = fine if len(plan) == 1 else Level(s0, plan[0], w, (Vs, Fr), mode, diag)
    state, history = _rounds(fine, level, judge, x, outer=int(outer), max_iter=int(max_iter),
                             early_stop=early_stop, progress=progress, t0=t0)
    return _phlw_result(state, history, fine, judge, before=before, diagnostics=diagnostics,
                        energy_initial=float(energy_initial), mode=mode, weights=w, diag=diag)


def _phlw_weights(mode: Mode, weights: dict[str, float] | None) -> dict[str, float]:
    """:data:`DEFAULT_WEIGHTS` with the caller's overrides (unknown names refused)."""
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
    return w


def _initial_diagnostics(fine: Level, mode: Mode, diag: float) -> list[str]:
    """Notes on the initial row fit of the fine level (rows clamped into the principal range)
    and on where the reference admits no net as it is (:func:`principal_range_notes`)."""
    x, fit, R = fine.x0, fine.fit, len(fine.u)
    diagnostics: list[str] = []
    if len(fit.clamped):
        diagnostics.append(f"initial fit: rows {fit.clamped.tolist()} had t_u^2 < 0 (b^2 - 4ac > 0) "
                           "or n_u outside [kappa_1, kappa_2]; started there from n_u inside "
                           "the principal range")
    return diagnostics + principal_range_notes(fine.lay.view(x, "K").reshape(R, -1),
                                               fine.lay.view(x, "H").reshape(R, -1), fine.u,
                                               mode, diag)


def _rounds(fine: Level, level: Level, judge: Judge, x: np.ndarray, *, outer: int,
            max_iter: int, early_stop: bool, progress: Callable[[str], None] | None,
            t0: float) -> tuple[Any, list[dict]]:
    """The rounds from ``x`` (the fine level's start), on the coarse ``level`` first when it
    is not ``fine`` (continued on the fine one from its control points): ``(the judged state
    of the last accepted round, one record per round)``. A level ends when a round is
    rejected, gains less than :data:`ROUND_TOL_REL` or its round count is reached; with
    ``early_stop`` the rounds end as soon as the figures hold. ``t0``: the clock of the
    records' ``time`` (s)."""
    history: list[dict] = []
    xl = x if level is fine else level.x0     # the state at the current level
    state = judge(x, unchanged=True)          # the figures of the fine level's state
    at_level, total = 0, 0
    while True:
        if total > 0:
            level.refresh(xl)                 # closest points at the accepted state
        to_fine = (lambda xr: xr) if level is fine else \
            (lambda xr, lv=level: fine.start(lv.lay.view(xr, "C")))
        step = run_round(level.prob, level.lay, level.data, xl, max_iter,
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
            progress(_round_line(step, at_level, outer, None if level is fine else level, held))
        if held and early_stop:
            break
        if not step["accepted"] or gain_small or at_level >= (
                outer if level is fine else COARSE_ROUNDS):
            if level is fine:
                break
            # continuation: the next sampling level starts from this level's control points
            level, xl, at_level = fine, fine.start(level.lay.view(xl, "C")), 0
    return state, history


def _round_line(step: dict, at_level: int, outer: int, coarse: Level | None, held: bool) -> str:
    """The progress line of one round (``coarse``: its level when not the fine one)."""
    where = (f"round {at_level}/{outer}" if coarse is None else
             f"coarse round {at_level}/{COARSE_ROUNDS} ({coarse.samples[0]} x "
             f"{coarse.samples[1]} samples)")
    return (f"{where}: energy {step['energy0']:.3e} -> {step['energy']:.3e} in "
            f"{step['iterations']} iterations ({step['message']})"
            + ("; the figures hold" if held else ""))


def _phlw_result(state: Any, history: list[dict], fine: Level, judge: Judge, *, before: dict,
                 diagnostics: list[str], energy_initial: float, mode: Mode,
                 weights: dict[str, float], diag: float) -> PHLWResult:
    """The :class:`PHLWResult` of the rounds' last ``state``; raises
    :class:`ConvergenceError` for a non-finite energy, or when every round was rejected and
    the initial surface misses the figures."""
    x = state.x
    energy_final = state.energy
    if not np.isfinite(energy_final):
        raise ConvergenceError(f"the {mode.upper()} optimization produced a non-finite energy; "
                               "refit the reference with fewer control points or more smoothing")
    unchanged = not any(h["accepted"] for h in history)
    if unchanged:
        state = judge(x, unchanged=True)
    figures, check = state.figures, state.check
    diagnostics = [*diagnostics, *check.messages]
    if unchanged and not all(f["ok"] for f in figures.values()):
        raise ConvergenceError(
            f"the {mode.upper()} optimization could not lower its energy from "
            f"{energy_initial:.4g}: every round made the surface worse (true energy "
            f"{history[0]['energy_true']:.4g} after round 1) and was rejected; try more control "
            "points, a denser reference or another mode")
    n_rows, t_rows = state.n_rows, state.t_rows
    abc = np.column_stack([np.ones(len(fine.u)), -2 * n_rows, n_rows ** 2 + t_rows ** 2])
    after = {"terms": fine.prob.report(x), **state.after}
    return PHLWResult(surface=state.surface, mode=mode, u_rows=fine.u, v_samples=fine.v,
                      n_rows=n_rows, t_rows=t_rows, abc=abc, history=history,
                      report_before=before, report_after=after,
                      converged=all(f["ok"] for f in figures.values()),
                      deviation=state.deviation, diagnostics=diagnostics, net_check=check,
                      weights=weights, reference_diagonal=diag, figures=figures,
                      energy_initial=float(energy_initial), energy_final=float(energy_final))
