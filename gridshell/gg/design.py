"""GG surface design (paper 4.1.1, after Wang et al. 2019): a quad mesh isometric to a surface of
revolution that approximates a target surface.

The designed mesh is ``P (R, C, 3)``, metres: ``P[i, j]`` with ``i`` the parallel and ``j`` the
meridian, so meridians are ``P[:, j]`` and parallels ``P[i, :]``. A *rotationally isometric
geodesic-parallel mesh* (Fig. 12a) satisfies

1. **geodesic meridians** - at every interior vertex the edge angles on both sides of the
   meridian have equal sums, ``ang(a,l) + ang(l,b) = ang(a,r) + ang(r,b)``
   (``a, b`` the meridian edges, ``l, r`` the parallel edges, ``ang(u,w) = atan2(|u x w|, u.w)``);
2. **isometric parallels** - every edge of parallel ``i`` has one length ``l_i``;
3. **geodesic parallels** - every meridian edge between parallels ``i`` and ``i+1`` has one
   length ``h_i`` (the parallels are at constant geodesic distance).

Such a mesh maps isometrically to a discrete surface of revolution (parallel ``i`` a circle with
chord ``l_i``, profile chords ``h_i``), see :mod:`gridshell.gg.revolution`.

Optimization (Tang et al. 2014 style, one :class:`~gridshell.solver.Layout` with blocks
``P (R*C, 3)``, ``l (R,)``, ``h (R-1,)``):

- ``outer`` rounds; round ``k`` refreshes the closest points on the target and runs at most
  ``max_iter`` Levenberg-Marquardt iterations (fewer once a step gains less than
  :data:`ROUND_TOL_REL`; the damping carries over from round to round) on
  ``E = w_g E_geo + w_l (E_par + E_mer) + s^k (w_c E_glide + w_b E_bnd + w_p E_prox)
  + w_f d^k E_fair`` (``s = soften``, ``d = fairness_decay``: a penalty continuation in which
  the constraints dominate more every round);
- a final *polish* (Levenberg-Marquardt, one iteration at a time, every step lowering the
  constraint energy) drops closeness, boundary and fairness and keeps only the constraints 1-3
  plus a tiny proximity and an elastic term to the start of the iteration: a projection onto
  the constraint set that moves the (already nearly feasible) mesh little. The elastic term,
  whose residual is zero where each step starts, changes only the metric of the projection: it
  takes the correction that bends the mesh least rather than the one that moves its vertices
  least (an odd-even zig-zag, to which the constraints are most sensitive, and which leaves a
  mesh whose edge lengths and angle sums hold but whose smooth interpolant, on which the net is
  traced, is not isometric to the surface of revolution). Both terms shrink together, by
  ``polish_decay`` per step and in proportion to the constraint energy once it is below
  :data:`POLISH_EREF` (a Levenberg-Marquardt regularisation proportional to the squared
  residual, after Yamashita & Fukushima 2001): the metric keeps its least-bending shape while
  its size vanishes, so the last steps are Gauss-Newton steps and the polish converges
  superlinearly (a bumped 40 x 40 helicoid: the constraint energy falls 1e9-fold in 6 steps;
  with the former fixed weights it fell 3-15 % per step, and 20 steps left a 120 x 120 dome
  at 3e-3 rad).
  The polish stops when the residuals reach ``tol_geodesic`` / ``tol_length`` (round-off),
  when the constraint energy stagnates (:data:`POLISH_STALL`), or - given an ``evaluate``
  score, e.g. the design's figures on the traced net - when the score is acceptable and
  stagnates (:data:`SCORE_STALL`, or a step lowered the constraint energy by less than
  :data:`POLISH_SLOW` with the regularisation below :data:`POLISH_GN`: the floor of slightly
  inconsistent constraints on a freeform target),
  or is far inside the thresholds (:data:`SCORE_DONE`); the score is computed every
  ``check_every`` steps, when the polish slows down, and once after :data:`SCORE_EARLY` steps
  (which ends the polish only on :data:`SCORE_DONE`). With a score the best-scoring
  checkpoint is returned, so a longer polish never returns a worse design (the end of the
  rounds is a candidate too, scored only when no polish checkpoint is far inside the
  thresholds, or as the reference of the first check's stagnation test).
- *coarse to fine*: a grid with a side above :data:`COARSE_ABOVE` vertices is designed at half
  the resolution first (recursively: 120 -> 60 -> 30), interpolated back (bicubic in grid
  index space), and only the last :data:`FINE_ROUNDS` rounds and the polish run at full
  resolution (at 120 x 120 one LM iteration costs ~16 at 30 x 30).
  The boundary gliding conflicts with the constraints when the target's outline is not a
  possible GG outline (e.g. a small-circle edge that must become a geodesic), which is why it
  is softened and dropped at the end rather than enforced.

Boundary handling (keeps the patch from shrinking or sliding): every vertex of the grid's four
boundary polylines glides on the *initial* boundary polyline of its side - residual = distance
to the tangent line at its closest point on that polyline, refreshed every round - so the
outline stays where ``P0`` put it (for a structured-grid target that is the target's own
boundary; for a grid sampled inside a triangle mesh it is the sampled rectangle's outline).
Corners lie on two sides and are thus pinned. On top, a proximity term to the start of each
round (``w_p``) keeps the tangential motion, which nothing else resists, from drifting.

All length-like residuals are divided by the mean edge length ``L`` of ``P0`` (their weights are
``w / L^2``), so the weights of :class:`GGWeights` are dimensionless and mean the same on any
model; the geodesic residual is in radians. :class:`GGWeights` and the outcome
:class:`GGDesign` live in :mod:`gridshell.gg.surface_types` (importable from here too).
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any, Callable, Mapping

import numpy as np
import scipy.sparse as sp

from gridshell.core.errors import InputError
from gridshell.solver import Layout, Problem, solve
from gridshell.solver import terms as T
from gridshell.gg.constraints import (EdgeGroups, GridShape, diagonal_residual_rel, edge_groups,
                          equal_diagonals, equal_lengths, geodesic_meridians, geodesic_residual,
                          init_group_lengths, length_residual_rel)
from gridshell.gg.soft_terms import boundary_gliding, boundary_sides, fairness_matrix, surface_gliding
from gridshell.gg.surface_types import GGDesign, GGWeights

__all__ = ["GGDesign", "GGWeights", "design_gg_surface", "edge_groups", "equal_lengths",
           "fairness_matrix", "geodesic_meridians", "geodesic_residual", "GridShape",
           "EdgeGroups", "init_group_lengths", "length_residual_rel", "equal_diagonals",
           "diagonal_residual_rel"]

Progress = Callable[[str], None] | None


# ============================================================================ the optimization

def _say(progress: Progress, msg: str) -> None:
    if progress is not None:
        progress(msg)


def _check_P0(P0: Any) -> np.ndarray:
    P0 = np.asarray(P0, dtype=float)
    if P0.ndim != 3 or P0.shape[2] != 3:
        raise InputError(f"the initial grid must have shape (R, C, 3), got {P0.shape}")
    R, C = P0.shape[:2]
    if R < 4 or C < 4:
        raise InputError(f"the initial grid is too coarse ({R} x {C}); a GG mesh needs at least "
                         "4 x 4 vertices - ask for a finer grid")
    if not np.all(np.isfinite(P0)):
        raise InputError("the initial grid has NaN or infinite coordinates")
    e1 = np.linalg.norm(np.diff(P0, axis=0), axis=2)
    e2 = np.linalg.norm(np.diff(P0, axis=1), axis=2)
    L = float(np.mean(np.concatenate([e1.ravel(), e2.ravel()])))
    if not L > 0 or min(e1.min(), e2.min()) <= 1e-9 * L:
        raise InputError("the initial grid has zero-length edges (coincident vertices); "
                         "build it from a non-degenerate target")
    return P0


def _figures(P: np.ndarray) -> tuple[float, float]:
    g = geodesic_residual(P)
    lr = length_residual_rel(P)
    return (float(np.max(np.abs(g))) if g.size else 0.0,
            max(max(lr.values()), diagonal_residual_rel(P)))


#: a continuation round that moves no vertex by more than this many mean edge lengths, with
#: the constraints met, ends the rounds (on an exact GG mesh such as a helicoid grid every
#: round after the first moves it by 1e-6 to 3e-5 edge lengths, a noisy catenoid by 1e-2)
STILL = 1e-5

#: residuals (radians, relative spread) below which a still round ends the rounds
ROUNDS_TOL = 5e-7

#: the polish stops when an iteration lowers the constraint energy by less than this fraction
POLISH_STALL = 1e-2

#: a polish step that lowers the constraint energy by less than this fraction has reached the
#: floor of the (slightly inconsistent) constraints: with an ``evaluate`` score the score is
#: checked, and the polish ends if it is acceptable
POLISH_SLOW = 0.5

#: the polish' steps count as Gauss-Newton steps (a slow one has met the floor of the
#: constraints) once the regularisation is below this fraction of its base weights; above,
#: a slow step is the metric's damping (the former fixed weights: 3-15 % per step)
POLISH_GN = 1e-2

#: constraint energy (dimensionless: radians^2 and relative lengths^2) below which the
#: polish' regularisation shrinks in proportion to it (see :func:`_polish`)
POLISH_EREF = 1e-4

#: initial Levenberg-Marquardt damping of a polish step (relative to the mean of diag(J^T J)),
#: scaled with the regularisation like it
POLISH_DAMPING = 1e-6

#: the polish' regularisation stops shrinking at this fraction of its base weights
POLISH_FLOOR = 1e-12

#: with an ``evaluate`` score: the polish stops when the score is acceptable (< 1) and improved
#: by less than this fraction since the previous check
SCORE_STALL = 0.05

#: with an ``evaluate`` score: a score this far inside the thresholds ends the polish at a
#: check (the figures are 1/20 of the paper's; further steps change them by noise: a 120 x 120
#: ridge went from 0.0168 to 0.0145 in 4 more steps of 1.2 s each)
SCORE_DONE = 0.05

#: Levenberg-Marquardt damping of the first round (relative to the mean of diag(J^T J))
ROUND_DAMPING = 1e-3

#: every later round starts from the damping the previous one ended with (the problem changes
#: little from round to round, so the trust the steps earned carries over), not below this
#: floor; with the first round's damping at every round the first steps of each round were
#: damped far below Gauss-Newton and 4 iterations did not reach the round's minimum
ROUND_DAMPING_FLOOR = 1e-6

#: a round ends when a step lowers its energy by less than this fraction (its minimum is
#: reached to ~1 %; the next round halves the soft weights anyway): the 30 x 30 dome of
#: benchmarks/gg_design.py took 20 instead of 40 iterations, with its deviation from the
#: target mean 0.353 % (was 0.357 %) and max 3.48 % (was 3.45 %) of the diagonal
ROUND_TOL_REL = 1e-2

#: with an ``evaluate`` score: the polish is also scored after this many steps, and ends
#: there if the score is at most SCORE_DONE (else that score is not used: the checkpoints
#: are those of ``check_every``; on the 30 x 30 dome of benchmarks/gg_design.py
#: the 3rd and 4th steps, 6 factorizations with 4 rejected steps at the floor of the
#: constraints, took the score from 0.0017 to 0.0015 and a quarter of the design's time)
SCORE_EARLY = 2

#: grids with a side above this many vertices are designed coarse to fine (at 120 x 120 the
#: rounds alone took 100+ s CPU; each LM iteration there costs ~1.7 s, 16x one at 30 x 30)
COARSE_ABOVE = 40

#: rounds run at full resolution after the coarse design (the last ones of the continuation)
FINE_ROUNDS = 2

_CONSTRAINTS = ("geodesic", "parallel_lengths", "meridian_lengths", "orthogonal")


def design_gg_surface(target_V: Any, target_F: Any, P0: Any, *,
                      weights: GGWeights | Mapping[str, float] | None = None, outer: int = 10,
                      max_iter: int = 4, polish_iter: int = 20, tol_geodesic: float = 1e-9,
                      tol_length: float = 1e-9,
                      evaluate: Callable[[np.ndarray], float] | None = None,
                      check_every: int = 4, coarse: bool = True,
                      progress: Progress = None) -> GGDesign:
    """Optimize ``P0`` into a rotationally isometric geodesic-parallel mesh near a target
    (paper 4.1.1, Fig. 12a; Wang et al. 2019): the rounds (:func:`_rounds`), then the polish
    (:func:`_polish`).

    Parameters
    ----------
    target_V : (n, 3) float
        Target surface vertices, metres (or a ``QuadMesh`` / ``TriMesh``, then ``target_F``
        is ``None``).
    target_F : (m, 3) or (m, 4) int or None
        Target faces (quads are triangulated for the closest-point queries).
    P0 : (R, C, 3) float
        Initial grid, metres (see :func:`gridshell.gg.initial.initial_grid`): meridians
        ``P0[:, j]``, parallels ``P0[i, :]``; ``R, C >= 4``.
    weights : GGWeights or dict, optional
        Term weights (defaults: :class:`GGWeights`).
    outer : int
        Rounds of (closest points -> ``max_iter`` Levenberg-Marquardt iterations).
    max_iter : int
        Most solver iterations per round (fewer once a step gains less than
        :data:`ROUND_TOL_REL` of its energy).
    polish_iter : int
        Most iterations of the final projection onto the constraints (0: no polish); it
        stops earlier on stagnation (see the module docstring).
    tol_geodesic, tol_length : float
        Round-off tolerances on the geodesic residual (radians) and on the relative spread of
        edge lengths (dimensionless): the polish stops below them.
    evaluate : callable, optional
        ``evaluate(P (R, C, 3)) -> float``, lower is better, below 1 acceptable (e.g. the
        largest ratio figure / threshold of the net traced on ``P``; ``inf`` if none can be
        traced). Called every ``check_every`` polish iterations, when the polish slows down,
        at its end, and on the end of the rounds unless a polish checkpoint scored
        :data:`SCORE_DONE` or less; the best-scoring of these meshes is returned.
    check_every : int
        Polish iterations between two calls of ``evaluate`` (and one early call after
        :data:`SCORE_EARLY` iterations, which ends the polish only on :data:`SCORE_DONE`).
    coarse : bool
        Coarse to fine (unless ``P0`` already meets the constraints to :data:`ROUNDS_TOL`): a
        grid with a side above :data:`COARSE_ABOVE` vertices is first designed at half the
        resolution (recursively), and the result, interpolated back to ``R x C``, starts the
        last :data:`FINE_ROUNDS` rounds (see :func:`_coarse_start`).
    progress : callable, optional
        Receives one line per round.

    Returns
    -------
    GGDesign
        ``converged=False`` (never an exception) when the tolerances are not met: the caller
        decides.
    """
    V, Ft, P0, w = _surface_inputs(target_V, target_F, P0, weights, outer, max_iter,
                                   polish_iter, check_every)
    t0 = time.perf_counter()
    gp = _SurfaceProblem.of(V, Ft, P0, w)
    x = gp.pack(gp.P0flat)
    prob = gp.build(gp.P0flat)
    before = prob.report(x)
    x, history = _rounds(gp, prob, x, outer, int(max_iter), coarse, t0, progress)
    polished = _polish(x, gp, int(polish_iter), tol_geodesic, tol_length, evaluate,
                       int(check_every), history, t0, progress)
    return _surface_result(gp, polished, history, before, tol_geodesic, tol_length, t0,
                           progress)


def _surface_inputs(target_V: Any, target_F: Any, P0: Any, weights: Any, outer: int,
                    max_iter: int, polish_iter: int, check_every: int
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, GGWeights]:
    """The checked inputs of :func:`design_gg_surface`: the target triangulated ``(V, Ft)``
    (metres), the initial grid ``P0 (R, C, 3)`` and the weights; InputError names a bad one."""
    from gridshell.geometry.igl_adapter import triangulate

    if target_F is None:
        if not (hasattr(target_V, "V") and hasattr(target_V, "F")):
            raise InputError("pass the target as (V, F) arrays or as a mesh object; F is missing")
        target_V, target_F = target_V.V, target_V.F
    V, Ft, _ = triangulate(target_V, target_F)  # validates the target
    P0 = _check_P0(P0)
    w = GGWeights.coerce(weights)
    if int(outer) < 1 or int(max_iter) < 1 or int(polish_iter) < 0 or int(check_every) < 1:
        raise InputError(f"outer, max_iter and check_every must be >= 1 and polish_iter >= 0, "
                         f"got {outer}, {max_iter}, {check_every}, {polish_iter}")
    return V, Ft, P0, w


@dataclass
class _SurfaceProblem:
    """The fixed data of one GG surface design: the triangulated target ``(V, Ft)`` and the
    initial grid ``P0 (R, C, 3)`` (metres), the weights, the variables' layout (blocks ``P``,
    ``l``, ``h``), the edge groups, the boundary sides, the fairness matrix ``D`` and the mean
    edge length ``L`` of ``P0`` (metres; length residuals are weighted by ``s2 = 1 / L^2``)."""

    V: np.ndarray
    Ft: np.ndarray
    P0: np.ndarray
    w: GGWeights
    L: float
    lay: Layout
    par: EdgeGroups
    mer: EdgeGroups
    sides: Any
    D: sp.csr_matrix

    @classmethod
    def of(cls, V: np.ndarray, Ft: np.ndarray, P0: np.ndarray, w: GGWeights
           ) -> "_SurfaceProblem":
        """The problem data of grid ``P0 (R, C, 3)`` on the target ``(V, Ft)``."""
        R, C = P0.shape[:2]
        L = float(np.mean(np.concatenate([np.linalg.norm(np.diff(P0, axis=a), axis=2).ravel()
                                          for a in (0, 1)])))
        return cls(V, Ft, P0, w, L, Layout({"P": (R * C, 3), "l": R, "h": R - 1}),
                   edge_groups((R, C), "parallel"), edge_groups((R, C), "meridian"),
                   boundary_sides(R, C), fairness_matrix((R, C)))

    @property
    def shape(self) -> tuple[int, int]:
        return self.P0.shape[0], self.P0.shape[1]

    @property
    def P0flat(self) -> np.ndarray:
        return self.P0.reshape(-1, 3)

    @property
    def s2(self) -> float:
        return 1.0 / self.L ** 2

    def pack(self, X: np.ndarray) -> np.ndarray:
        """The variables of vertices ``X (R*C, 3)`` with their group lengths ``l``, ``h``."""
        return self.lay.pack({"P": X, "l": init_group_lengths(X, self.par),
                              "h": init_group_lengths(X, self.mer)})

    def mesh(self, x: np.ndarray) -> np.ndarray:
        """The mesh ``P (R, C, 3)`` of the variables ``x`` (a view), metres."""
        return self.lay.view(x, "P").reshape(*self.shape, 3)

    def constraints(self) -> Problem:
        """The constraints 1-3 (and the equal diagonals), base weights."""
        return _constraints_only(self.lay, self.shape, self.w, self.par, self.mer, self.s2)

    def refreshed(self, X: np.ndarray) -> dict[str, Any]:
        """The data of the terms that follow the mesh, at vertices ``X``."""
        return {"closeness": surface_gliding(X, self.V, self.Ft),
                "boundary": boundary_gliding(X, self.P0flat, self.sides),
                "elastic": T.Linear("P", self.D, self.D @ X),
                "proximity": T.Closeness("P", X.copy())}

    def build(self, X: np.ndarray) -> Problem:
        """The problem with base weights and data refreshed at vertices ``X``."""
        d, w, s2 = self.refreshed(X), self.w, self.s2
        return (self.constraints()
                .add("closeness", w.closeness * s2, T.gliding, d["closeness"])
                .add("boundary", w.boundary * s2, T.gliding, d["boundary"])
                .add("fairness", w.fairness * s2, T.linear, T.Linear("P", self.D))
                .add("elastic", w.elastic * s2, T.linear, d["elastic"])
                .add("proximity", w.proximity * s2, T.closeness, d["proximity"]))


def _rounds(gp: _SurfaceProblem, prob: Problem, x: np.ndarray, outer: int, max_iter: int,
            coarse: bool, t0: float, progress: Progress) -> tuple[np.ndarray, list[dict]]:
    """The ``outer`` continuation rounds (closest points -> Levenberg-Marquardt, see the
    module docstring), after a coarse start on a big grid; the variables and the history."""
    history: list[dict] = []
    x, k0 = _coarse_begin(gp, x, outer, max_iter, coarse, history, t0, progress)
    lam = ROUND_DAMPING  # carried from round to round (see ROUND_DAMPING_FLOOR)
    for k in range(k0, int(outer)):
        X = gp.lay.view(x, "P")
        res, wf, soft = _round(gp, prob, x, k, lam, max_iter)
        x = res.x
        if res.history:
            lam = max(float(res.history[-1]["lambda"]), ROUND_DAMPING_FLOOR)
        g, lr = _figures(gp.mesh(x))
        history.append({"round": k, "fairness": wf, "soften": soft, "energy0": res.energy0,
                        "energy": res.energy, "iterations": res.iterations,
                        "message": res.message,
                        "terms": {n: v["energy"] for n, v in res.report.items()},
                        "geodesic_max": g, "length_rel_max": lr,
                        "time": time.perf_counter() - t0})
        _say(progress, f"round {k + 1}/{outer}: energy {res.energy0:.3e} -> {res.energy:.3e}, "
                       f"geodesic {g:.2e} rad, length spread {lr:.2e}")
        moved = float(np.max(np.linalg.norm(gp.lay.view(x, "P") - X, axis=1)))
        if g <= ROUNDS_TOL and lr <= ROUNDS_TOL and moved <= STILL * gp.L:
            # the constraints hold and the round left the mesh where it was: the remaining
            # rounds (lower fairness and closeness) would change nothing (an exact GG mesh, such
            # as a helicoid grid, stops after round 1: 100 x 100 in 6 s instead of 55 s)
            _say(progress, f"stopping after round {k + 1}: the mesh moved {moved / gp.L:.1e} "
                           "edge lengths in it and meets the constraints")
            break
    return x, history


def _coarse_begin(gp: _SurfaceProblem, x: np.ndarray, outer: int, max_iter: int,
                  coarse: bool, history: list[dict], t0: float, progress: Progress
                  ) -> tuple[np.ndarray, int]:
    """The start of the rounds: the variables and the first round, after a coarse design
    (:func:`_coarse_start`) of a big grid that does not meet the constraints yet."""
    R, C = gp.shape
    k0 = 0
    g0, l0 = _figures(gp.P0)
    # (a P0 that meets the constraints, e.g. a helicoid grid, ends the rounds after one)
    if (coarse and max(R, C) > COARSE_ABOVE and int(outer) > FINE_ROUNDS
            and max(g0, l0) > ROUNDS_TOL):
        Pc = _coarse_start(gp.V, gp.Ft, gp.P0, gp.w, int(outer), int(max_iter), progress)
        x = gp.pack(Pc.reshape(-1, 3))
        k0 = int(outer) - FINE_ROUNDS
        history.append({"round": "coarse", "shape": list(_coarse_shape(R, C)),
                        "time": time.perf_counter() - t0})
    _say(progress, f"GG design {R} x {C}: geodesic residual {g0:.2e} rad, length spread "
                   f"{l0:.2e} at the start")
    return x, k0


def _round(gp: _SurfaceProblem, prob: Problem, x: np.ndarray, k: int, lam: float,
           max_iter: int) -> tuple[Any, float, float]:
    """Round ``k``: the terms' data refreshed at the mesh of ``x``, the weights of round ``k``
    set (fairness ``w_f d^k``, softened terms ``s^k``) and at most ``max_iter``
    Levenberg-Marquardt steps from damping ``lam``; the solver's result, ``w_f d^k``, ``s^k``."""
    w, s2 = gp.w, gp.s2
    if k > 0:  # (after a coarse start: refreshed at the interpolated coarse design)
        # the same problem with new data (every weight is set below): it keeps its
        # Jacobian's structure, whose triplets do not move from round to round
        for name, data in gp.refreshed(gp.lay.view(x, "P")).items():
            prob.set_data(name, data)
    wf = w.fairness * w.fairness_decay ** k
    soft = w.soften ** k
    prob.set_weight("fairness", wf * s2)
    prob.set_weight("elastic", w.elastic * w.elastic_decay ** k * s2)
    for name, wk in (("closeness", w.closeness), ("boundary", w.boundary),
                     ("proximity", w.proximity)):
        prob.set_weight(name, wk * soft * s2)
    res = solve(prob, x, method="lm", max_iter=int(max_iter), damping=lam,
                tol_rel=ROUND_TOL_REL)
    return res, wf, soft


def _surface_result(gp: _SurfaceProblem, polished: tuple, history: list[dict], before: dict,
                    tol_geodesic: float, tol_length: float, t0: float,
                    progress: Progress) -> GGDesign:
    """The :class:`GGDesign` of the polished variables (``polished``: :func:`_polish`'s
    result): the mesh, its group lengths, residuals, deviation from the target (% of its
    diagonal) and the terms' report before and after."""
    from gridshell.measure.metrics import deviation

    x, stop, score, checkpoint = polished
    P = gp.mesh(x).copy()
    after = gp.build(P.reshape(-1, 3)).report(x)
    g, lr = _figures(P)
    dev = deviation(P.reshape(-1, 3), gp.V, gp.Ft)
    converged = bool(g <= tol_geodesic and lr <= tol_length)
    _say(progress, f"GG surface ({checkpoint}, polish stopped: {stop}): geodesic {g:.2e} rad, "
                   f"length spread {lr:.2e}, deviation max {dev['max']:.3f} % mean "
                   f"{dev['mean']:.3f} % of the diagonal, {time.perf_counter() - t0:.2f} s")
    return GGDesign(P=P, l=gp.lay.view(x, "l").copy(), h=gp.lay.view(x, "h").copy(),
                    history=history, report={"before": before, "after": after},
                    converged=converged, deviation=dev, geodesic_residual_max=g,
                    length_residual_rel_max=lr, stop=stop, score=score, checkpoint=checkpoint)


def _constraint_energy(report: Mapping[str, Mapping[str, float]]) -> float:
    """Sum of the constraint terms' energies in a :meth:`Problem.report`."""
    return float(sum(report[n]["energy"] for n in _CONSTRAINTS if n in report))


def _constraints_only(lay: Layout, shape: tuple[int, int], w: GGWeights, par: EdgeGroups,
                      mer: EdgeGroups, s2: float) -> Problem:
    """The constraints 1-3 (and the equal diagonals) of a GG mesh, base weights."""
    return (Problem(lay)
            .add("geodesic", w.geodesic, geodesic_meridians, GridShape(shape))
            .add("parallel_lengths", w.lengths * s2, equal_lengths, par)
            .add("meridian_lengths", w.lengths * s2, equal_lengths, mer)
            .add("orthogonal", w.orthogonal * s2, equal_diagonals, GridShape(shape)))


def _resample(P: np.ndarray, R: int, C: int) -> np.ndarray:
    """Grid ``P (r, c, 3)`` interpolated (bicubic per coordinate, in grid-index space) at
    ``R x C`` points spanning the same index range, metres."""
    from scipy.interpolate import RectBivariateSpline

    r, c = P.shape[:2]
    u, v = np.arange(r, dtype=float), np.arange(c, dtype=float)
    uu, vv = np.linspace(0, r - 1, R), np.linspace(0, c - 1, C)
    return np.stack([RectBivariateSpline(u, v, P[:, :, k], kx=min(3, r - 1), ky=min(3, c - 1),
                                         s=0)(uu, vv) for k in range(3)], axis=-1)


def _coarse_shape(R: int, C: int) -> tuple[int, int]:
    """The grid a coarse-to-fine design starts from: each side above ``COARSE_ABOVE / 2``
    halved (a short side of an elongated grid is kept)."""
    return tuple((n + 1) // 2 if n > COARSE_ABOVE // 2 else n for n in (R, C))


def _coarse_start(V: np.ndarray, F: np.ndarray, P0: np.ndarray, w: GGWeights, outer: int,
                  max_iter: int, progress: Progress) -> np.ndarray:
    """Start of a fine design: ``P0 (R, C, 3)`` resampled at half the resolution, designed
    there (every round, no polish; recursively coarser still if still above
    :data:`COARSE_ABOVE`), and interpolated back to ``R x C``, metres. The fine rounds then
    only refine a mesh that is near a GG surface near the target: at 120 x 120 every fine LM
    iteration costs ~16 coarse ones."""
    R, C = P0.shape[:2]
    Rc, Cc = _coarse_shape(R, C)
    _say(progress, f"coarse to fine: designing at {Rc} x {Cc} first")
    d = design_gg_surface(V, F, _resample(P0, Rc, Cc), weights=w, outer=outer,
                          max_iter=max_iter, polish_iter=0, progress=progress)
    return _resample(d.P, R, C)


def _polish(x: np.ndarray, gp: _SurfaceProblem, polish_iter: int, tol_geodesic: float,
            tol_length: float, evaluate: Callable[[np.ndarray], float] | None,
            check_every: int, history: list[dict], t0: float,
            progress: Progress) -> tuple[np.ndarray, str, float | None, str]:
    """The final projection onto the constraints (see the module docstring), one
    Levenberg-Marquardt step at a time (:func:`_polish_problem`), scored at checkpoints by
    ``evaluate`` (:class:`_Checkpoints`).

    Returns the variables (the best-scoring checkpoint with ``evaluate``, else the last
    iterate), why the polish stopped, the score and the checkpoint's name.
    """
    w = gp.w
    cp = _Checkpoints(evaluate, gp, x, progress) if evaluate is not None else None
    if cp is not None and polish_iter == 0:
        cp.rounds_score()
    lam = POLISH_DAMPING  # raised where a step would not descend
    stop = "iteration limit" if polish_iter > 0 else "no polish"
    done = 0
    g, lr = _figures(gp.mesh(x))
    ec_prev = _constraint_energy(gp.constraints().report(x)) if polish_iter > 0 else 0.0
    while done < polish_iter:
        if g <= tol_geodesic and lr <= tol_length:
            stop = "tolerance"
            break
        dk = max(min(w.polish_decay ** done, ec_prev / POLISH_EREF), POLISH_FLOOR)
        pol = _polish_problem(gp, x, dk, done)
        lam = min(lam, POLISH_DAMPING * dk)  # the LM damping must not take the metric over
        res = solve(pol, x, method="lm", max_iter=1, damping=lam, tol_energy=0.0, tol_rel=0.0,
                    tol_step=0.0, tol_grad=0.0)
        done += 1
        rec = res.history[-1] if res.history else {"accepted": False, "lambda": lam}
        lam = float(rec["lambda"])
        if not rec["accepted"]:
            stop = "no descent"
            break
        x = res.x
        ec = _constraint_energy(res.report)  # res.report is at res.x
        g, lr = _figures(gp.mesh(x))
        history.append({"round": "polish", "energy0": res.energy0, "energy": res.energy,
                        "constraint_energy": ec, "regularisation": dk,
                        "iterations": res.iterations, "message": res.message,
                        "terms": {n: v["energy"] for n, v in res.report.items()},
                        "geodesic_max": g, "length_rel_max": lr,
                        "time": time.perf_counter() - t0})
        _say(progress, f"polish {done}: constraint energy {ec:.3e}, geodesic {g:.2e} rad, "
                       f"length spread {lr:.2e}")
        rel = (ec_prev - ec) / max(ec_prev, 1e-300)
        ec_prev = ec
        slow = rel < POLISH_SLOW and dk <= POLISH_GN  # a floor, not the metric's damping
        if cp is not None and cp.after_step(done, x, slow, check_every):
            stop = "figures"
            break
        if rel < POLISH_STALL:
            stop = "stagnation"
            break
    if cp is None:
        return x, stop, None, f"polish {done}" if done else "rounds"
    return cp.finish(done, x, stop)


def _polish_problem(gp: _SurfaceProblem, x: np.ndarray, dk: float, done: int) -> Problem:
    """The problem of polish step ``done + 1`` from ``x``: the constraints plus proximity and
    elastic terms at regularisation ``dk`` (a fraction of their base weights).

    The references are the start of every step: the proximity and elastic terms change the
    metric of the step only (a stale reference would pull back and stall it); both shrink
    together (same metric shape, vanishing size) by polish_decay per step and in proportion to
    the constraint energy below POLISH_EREF.
    """
    w, s2 = gp.w, gp.s2
    Xs = gp.lay.view(x, "P").copy()
    pol = (gp.constraints()
           .add("proximity", w.polish_proximity * dk * s2, T.closeness, T.Closeness("P", Xs)))
    if w.polish_elastic > 0:
        pol.add("elastic", w.polish_elastic * dk * w.polish_elastic_decay ** done * s2,
                T.linear, T.Linear("P", gp.D, gp.D @ Xs))
    return pol


class _Checkpoints:
    """The polish' checkpoints scored by ``evaluate(P (R, C, 3))`` (lower is better, below 1
    acceptable): the best one kept, the stagnation test between regular checks, and the end
    of the rounds (``x_rounds``) scored only when its score matters (a trace less per design):
    as the first check's reference for SCORE_STALL, and as a candidate unless a polish
    checkpoint is far inside the thresholds (SCORE_DONE)."""

    def __init__(self, evaluate: Callable[[np.ndarray], float], gp: _SurfaceProblem,
                 x_rounds: np.ndarray, progress: Progress) -> None:
        self.evaluate, self.gp, self.progress = evaluate, gp, progress
        self.x_rounds = x_rounds.copy()
        self.best: list[Any] = [None, None, ""]  # score, x, name
        self.sc_rounds: list[float] = []
        self.sc_prev: float | None = None
        self.last_checked = 0

    def check(self, name: str, xc: np.ndarray, early: bool = False) -> float:
        """The score of the variables ``xc``, kept as the best if it is (an ``early`` one only
        at SCORE_DONE or below)."""
        sc = float(self.evaluate(self.gp.mesh(xc).copy()))
        sc = sc if np.isfinite(sc) else float("inf")
        if (self.best[0] is None or sc < self.best[0]) and (not early or sc <= SCORE_DONE):
            self.best[:] = [sc, xc.copy(), name]
        _say(self.progress, f"{name}: score {sc:.3g} (largest figure / threshold of the traced "
                            "net)")
        return sc

    def rounds_score(self) -> float:
        """The score of the end of the rounds, computed once."""
        if not self.sc_rounds:
            self.sc_rounds.append(self.check("rounds", self.x_rounds))
        return self.sc_rounds[0]

    def after_step(self, done: int, x: np.ndarray, slow: bool, check_every: int) -> bool:
        """Whether the polish ends on its figures after step ``done`` (at ``x``): a regular
        check (every ``check_every`` steps, or a ``slow`` step) whose score is far inside the
        thresholds or acceptable and stagnating, or the early look after SCORE_EARLY steps
        far inside them (any other early score is forgotten)."""
        regular = done % check_every == 0 or slow
        if not regular and done == SCORE_EARLY:
            if self.check(f"polish {done}", x, early=True) <= SCORE_DONE:
                self.last_checked = done
                return True
        elif regular:
            sc = self.check(f"polish {done}", x)
            self.last_checked = done
            if self.sc_prev is None and SCORE_DONE < sc < 1.0 and not slow:
                self.sc_prev = self.rounds_score()
            stalled = slow or (self.sc_prev is not None
                               and self.sc_prev - sc < SCORE_STALL * self.sc_prev)
            if sc <= SCORE_DONE or (sc < 1.0 and stalled):
                return True
            self.sc_prev = sc
        return False

    def finish(self, done: int, x: np.ndarray, stop: str
               ) -> tuple[np.ndarray, str, float | None, str]:
        """The polish' result: the last iterate checked, the end of the rounds scored unless
        a checkpoint is far inside the thresholds, and the best-scoring of them."""
        if done > self.last_checked:
            self.check(f"polish {done}", x)
        if self.best[0] is None or self.best[0] > SCORE_DONE:
            self.rounds_score()
        return self.best[1], stop, self.best[0], self.best[2]
