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
model; the geodesic residual is in radians.
"""
from __future__ import annotations

import time
from dataclasses import asdict, dataclass, field, fields
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

__all__ = ["GGDesign", "GGWeights", "design_gg_surface", "edge_groups", "equal_lengths",
           "fairness_matrix", "geodesic_meridians", "geodesic_residual", "GridShape",
           "EdgeGroups", "init_group_lengths", "length_residual_rel", "equal_diagonals",
           "diagonal_residual_rel"]

Progress = Callable[[str], None] | None


# ============================================================================ weights, result

@dataclass
class GGWeights:
    """Weights of the GG surface design; dimensionless (length residuals are divided by the
    mean edge length of the initial grid, the geodesic residual is in radians).

    Attributes
    ----------
    geodesic : float
        Geodesic meridians (angle sums), 1.
    lengths : float
        Equal edge lengths along parallels and across meridian strips, 1.
    orthogonal : float
        Equal diagonals in every quad (meridians orthogonal to the parallels, see
        :mod:`gridshell.gg.constraints`), 1; in the rounds and the polish like the others.
    closeness : float
        Gliding on the target (distance to the tangent plane at the closest point), 0.1:
        below the constraints so that they dominate.
    boundary : float
        Boundary vertices glide on the initial boundary polylines, 0.1.
    fairness : float
        Second differences along meridians and parallels in the first round, 1e-4;
        multiplied by ``fairness_decay`` every round (smooths noise in the target).
    fairness_decay : float
        Factor of the fairness weight per round, 0.3.
    elastic : float
        Change of the second differences from their values at the start of each round, 3:
        resists folding (without it the constraints fold the mesh over itself on targets far
        from a GG surface - on a dome parallels pile up and meridians reverse while every
        constraint holds) and leaves a GG mesh a fixed point.
    elastic_decay : float
        Factor of the elastic weight per round, 0.6.
    proximity : float
        Closeness to the positions at the start of each round, 1e-2: resists the tangential
        drift nothing else resists (and the fairness' pull along the surface).
    soften : float
        Factor per round on ``closeness``, ``boundary`` and ``proximity``, 0.5: a penalty
        continuation, so the constraints dominate more every round and the final polish only
        has round-off-sized work left.
    polish_proximity : float
        Proximity weight of the final projection onto the constraints (to the start of each
        iteration, so a metric term too), 1e-4: holds the smooth modes that the elastic term
        leaves nearly free (with 1e-8 a noisy 12 x 10 catenoid drifted to 7.6 % of the
        diagonal from its target, with 1e-4 it stays at 1.5 %).
    polish_elastic : float
        Change of the second differences in each step of the final projection, 3e-3. Its
        reference is refreshed every iteration, so it never pulls back (a GG mesh stays a
        fixed point): it only makes the projection take the least-bending correction instead
        of the least-motion one. The least-motion correction is an odd-even zig-zag (the
        constraints are most sensitive to it); the edge lengths and angle sums then hold while
        the smooth surface through the vertices, on which the net is traced, is not isometric
        to the surface of revolution: with the former 1e-5 halved every iteration, 20 polish
        iterations took a 40 x 40 height field from Delta_a max 0.52 % to 5.2 % and a
        rotated 60 x 40 hill from 2.3 % to 5.9 % (7 % with 40 iterations); with 3e-3 kept
        (and ``polish_proximity`` 1e-4) they reach 0.09 % and 0.62 %. 0: the plain
        projection.
    polish_elastic_decay : float
        Factor of ``polish_elastic`` alone per projection iteration, 1 (kept: a metric whose
        elastic part decays against the proximity ends in the zig-zag projection above).
    polish_decay : float
        Factor of ``polish_proximity`` and ``polish_elastic`` together per projection
        iteration, 0.3 (on top of their shrinking with the constraint energy, see the module
        docstring); 1: fixed weights, a linearly converging polish.
    """

    geodesic: float = 1.0
    lengths: float = 1.0
    orthogonal: float = 1.0
    closeness: float = 0.1
    boundary: float = 0.1
    fairness: float = 1e-4
    fairness_decay: float = 0.3
    elastic: float = 3.0
    elastic_decay: float = 0.6
    proximity: float = 1e-2
    soften: float = 0.5
    polish_proximity: float = 1e-4
    polish_elastic: float = 3e-3
    polish_elastic_decay: float = 1.0
    polish_decay: float = 0.3

    @classmethod
    def coerce(cls, weights: "GGWeights | Mapping[str, float] | None") -> "GGWeights":
        """``GGWeights`` from ``None`` (defaults), an instance, or a mapping of some fields."""
        if weights is None:
            return cls()
        if isinstance(weights, cls):
            w = weights
        elif isinstance(weights, Mapping):
            names = {f.name for f in fields(cls)}
            bad = sorted(set(weights) - names)
            if bad:
                raise InputError(f"unknown GG design weight(s) {bad}; valid names are "
                                 f"{sorted(names)}")
            w = cls(**{k: float(v) for k, v in weights.items()})
        else:
            raise InputError(f"weights must be a GGWeights, a dict or None, got {type(weights)}")
        for k, v in asdict(w).items():
            if not np.isfinite(v) or v < 0:
                raise InputError(f"GG design weight {k!r} must be finite and >= 0, got {v}")
        return w


@dataclass
class GGDesign:
    """Outcome of :func:`design_gg_surface`.

    Attributes
    ----------
    P : (R, C, 3) float
        The designed mesh, metres; meridians ``P[:, j]``, parallels ``P[i, :]``.
    l : (R,) float
        Parallel edge length of each parallel, metres.
    h : (R-1,) float
        Meridian edge length between consecutive parallels, metres.
    history : list of dict
        Per round (and the polish): weights used, energies, solver iterations and message,
        geodesic and length residuals, deviation, time.
    report : dict
        ``{"before": ..., "after": ...}``: per term (base weights) weight, energy, RMS, max of
        the unweighted residual at ``P0`` and at ``P``.
    converged : bool
        Geodesic residual <= ``tol_geodesic`` and relative length spread <= ``tol_length``
        (the residuals are at round-off; a design is *accepted* on its figures, see
        :func:`gridshell.gg.pipeline.design_gg`).
    stop : str
        Why the polish ended: ``"tolerance"``, ``"stagnation"``, ``"figures"`` (the score is
        acceptable and stagnates), ``"no descent"``, ``"iteration limit"``, ``"no polish"``.
    score : float or None
        ``evaluate(P)`` of the returned mesh (None without ``evaluate``).
    checkpoint : str
        Which iterate is returned: ``"rounds"`` (the end of the rounds) or ``"polish k"``.
    deviation : dict
        ``max``, ``mean`` distance of the vertices of ``P`` to the target, % of the target's
        bounding-box diagonal; ``diagonal`` in metres.
    geodesic_residual_max : float
        Largest |angle-sum difference|, radians.
    length_residual_rel_max : float
        Largest relative spread of edge lengths within a parallel or a meridian strip, or
        relative difference of the two diagonals of a quad.
    """

    P: np.ndarray
    l: np.ndarray
    h: np.ndarray
    history: list[dict] = field(default_factory=list)
    report: dict = field(default_factory=dict)
    converged: bool = False
    deviation: dict = field(default_factory=dict)
    geodesic_residual_max: float = float("nan")
    length_residual_rel_max: float = float("nan")
    stop: str = ""
    score: float | None = None
    checkpoint: str = ""


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
    (paper 4.1.1, Fig. 12a; Wang et al. 2019).

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
        Most solver iterations per round (a round ends sooner once a step gains less than
        :data:`ROUND_TOL_REL` of its energy).
    polish_iter : int
        Most iterations of the final projection onto the constraints (0: no polish); it
        stops earlier on stagnation (see the module docstring).
    tol_geodesic : float
        Round-off tolerance on the geodesic residual, radians: the polish stops below it.
    tol_length : float
        Round-off tolerance on the relative spread of edge lengths (dimensionless).
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
        Coarse to fine (unless ``P0`` already meets the constraints to :data:`ROUNDS_TOL`):
        a grid with a side above :data:`COARSE_ABOVE` vertices is first
        designed at half the resolution (recursively), and the result, interpolated back to
        ``R x C``, starts the last :data:`FINE_ROUNDS` rounds (see :func:`_coarse_start`).
    progress : callable, optional
        Receives one line per round.

    Returns
    -------
    GGDesign
        ``converged=False`` (never an exception) when the tolerances are not met: the caller
        decides.
    """
    from gridshell.geometry.igl_adapter import triangulate
    from gridshell.measure.metrics import deviation

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
    t0 = time.perf_counter()
    R, C = P0.shape[:2]
    P0flat = P0.reshape(-1, 3)
    L = float(np.mean(np.concatenate([np.linalg.norm(np.diff(P0, axis=a), axis=2).ravel()
                                      for a in (0, 1)])))
    s2 = 1.0 / L ** 2

    lay = Layout({"P": (R * C, 3), "l": R, "h": R - 1})
    par, mer = edge_groups((R, C), "parallel"), edge_groups((R, C), "meridian")
    x = lay.pack({"P": P0flat, "l": init_group_lengths(P0flat, par),
                  "h": init_group_lengths(P0flat, mer)})
    sides = boundary_sides(R, C)
    D = fairness_matrix((R, C))

    def refreshed(X: np.ndarray) -> dict[str, Any]:
        """The data of the terms that follow the mesh, at vertices ``X``."""
        return {"closeness": surface_gliding(X, V, Ft),
                "boundary": boundary_gliding(X, P0flat, sides),
                "elastic": T.Linear("P", D, D @ X), "proximity": T.Closeness("P", X.copy())}

    def build(X: np.ndarray) -> Problem:
        """The problem with base weights and data refreshed at vertices ``X``."""
        d = refreshed(X)
        return (_constraints_only(lay, (R, C), w, par, mer, s2)
                .add("closeness", w.closeness * s2, T.gliding, d["closeness"])
                .add("boundary", w.boundary * s2, T.gliding, d["boundary"])
                .add("fairness", w.fairness * s2, T.linear, T.Linear("P", D))
                .add("elastic", w.elastic * s2, T.linear, d["elastic"])
                .add("proximity", w.proximity * s2, T.closeness, d["proximity"]))

    prob = build(P0flat)
    before = prob.report(x)
    history: list[dict] = []
    k0 = 0
    g0, l0 = _figures(P0)
    # (a P0 that meets the constraints, e.g. a helicoid grid, ends the rounds after one)
    if (coarse and max(R, C) > COARSE_ABOVE and int(outer) > FINE_ROUNDS
            and max(g0, l0) > ROUNDS_TOL):
        Pc = _coarse_start(V, Ft, P0, w, int(outer), int(max_iter), progress)
        x = lay.pack({"P": Pc.reshape(-1, 3), "l": init_group_lengths(Pc.reshape(-1, 3), par),
                      "h": init_group_lengths(Pc.reshape(-1, 3), mer)})
        k0 = int(outer) - FINE_ROUNDS
        history.append({"round": "coarse", "shape": list(_coarse_shape(R, C)),
                        "time": time.perf_counter() - t0})
    _say(progress, f"GG design {R} x {C}: geodesic residual {g0:.2e} rad, length spread "
                   f"{l0:.2e} at the start")
    lam = ROUND_DAMPING  # carried from round to round (see ROUND_DAMPING_FLOOR)
    for k in range(k0, int(outer)):
        X = lay.view(x, "P")
        if k > 0:  # (after a coarse start: refreshed at the interpolated coarse design)
            # the same problem with new data (every weight is set below): it keeps its
            # Jacobian's structure, whose triplets do not move from round to round
            for name, data in refreshed(X).items():
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
        x = res.x
        if res.history:
            lam = max(float(res.history[-1]["lambda"]), ROUND_DAMPING_FLOOR)
        g, lr = _figures(lay.view(x, "P").reshape(R, C, 3))
        history.append({"round": k, "fairness": wf, "soften": soft, "energy0": res.energy0, "energy": res.energy,
                        "iterations": res.iterations, "message": res.message,
                        "terms": {n: v["energy"] for n, v in res.report.items()},
                        "geodesic_max": g, "length_rel_max": lr,
                        "time": time.perf_counter() - t0})
        _say(progress, f"round {k + 1}/{outer}: energy {res.energy0:.3e} -> {res.energy:.3e}, "
                       f"geodesic {g:.2e} rad, length spread {lr:.2e}")
        moved = float(np.max(np.linalg.norm(lay.view(x, "P") - X, axis=1)))
        if g <= ROUNDS_TOL and lr <= ROUNDS_TOL and moved <= STILL * L:
            # the constraints hold and the round left the mesh where it was: the remaining
            # rounds (lower fairness and closeness) would change nothing (an exact GG mesh, such
            # as a helicoid grid, stops after round 1: 100 x 100 in 6 s instead of 55 s)
            _say(progress, f"stopping after round {k + 1}: the mesh moved {moved / L:.1e} edge "
                           "lengths in it and meets the constraints")
            break
    x, stop, score, checkpoint = _polish(
        x, lay, (R, C), w, par, mer, D, s2, int(polish_iter), tol_geodesic, tol_length,
        evaluate, int(check_every), history, t0, progress)
    P = lay.view(x, "P").reshape(R, C, 3).copy()
    after = build(P.reshape(-1, 3)).report(x)
    g, lr = _figures(P)
    dev = deviation(P.reshape(-1, 3), V, Ft)
    converged = bool(g <= tol_geodesic and lr <= tol_length)
    _say(progress, f"GG surface ({checkpoint}, polish stopped: {stop}): geodesic {g:.2e} rad, "
                   f"length spread {lr:.2e}, deviation max {dev['max']:.3f} % mean "
                   f"{dev['mean']:.3f} % of the diagonal, {time.perf_counter() - t0:.2f} s")
    return GGDesign(P=P, l=lay.view(x, "l").copy(), h=lay.view(x, "h").copy(), history=history,
                    report={"before": before, "after": after}, converged=converged,
                    deviation=dev, geodesic_residual_max=g, length_residual_rel_max=lr,
                    stop=stop, score=score, checkpoint=checkpoint)


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


def _polish(x: np.ndarray, lay: Layout, shape: tuple[int, int], w: GGWeights,
            par: EdgeGroups, mer: EdgeGroups, D: sp.csr_matrix, s2: float, polish_iter: int,
            tol_geodesic: float, tol_length: float,
            evaluate: Callable[[np.ndarray], float] | None, check_every: int,
            history: list[dict], t0: float,
            progress: Progress) -> tuple[np.ndarray, str, float | None, str]:
    """The final projection onto the constraints (see the module docstring).

    Returns the variables (the best-scoring checkpoint with ``evaluate``, else the last
    iterate), why the polish stopped, the score and the checkpoint's name.
    """
    R, C = shape
    best: list[Any] = [None, None, ""]  # score, x, name

    def check(name: str, xc: np.ndarray, early: bool = False) -> float:
        sc = float(evaluate(lay.view(xc, "P").reshape(R, C, 3).copy()))
        sc = sc if np.isfinite(sc) else float("inf")
        if (best[0] is None or sc < best[0]) and (not early or sc <= SCORE_DONE):
            best[:] = [sc, xc.copy(), name]
        _say(progress, f"{name}: score {sc:.3g} (largest figure / threshold of the traced net)")
        return sc

    # the end of the rounds is scored only when its score matters (a trace less per design):
    # as the first check's reference for SCORE_STALL, and as a candidate unless a polish
    # checkpoint is far inside the thresholds (SCORE_DONE)
    x_rounds = x.copy() if evaluate is not None else None
    sc_rounds: list[float] = []

    def rounds_score() -> float:
        if not sc_rounds:
            sc_rounds.append(check("rounds", x_rounds))
        return sc_rounds[0]

    if evaluate is not None and polish_iter == 0:
        rounds_score()
    sc_prev = None
    last_checked = 0
    lam = POLISH_DAMPING  # raised where a step would not descend
    stop = "iteration limit" if polish_iter > 0 else "no polish"
    done = 0
    g, lr = _figures(lay.view(x, "P").reshape(R, C, 3))
    ec_prev = (_constraint_energy(_constraints_only(lay, (R, C), w, par, mer, s2).report(x))
               if polish_iter > 0 else 0.0)
    while done < polish_iter:
        if g <= tol_geodesic and lr <= tol_length:
            stop = "tolerance"
            break
        # the references are the start of every step: the proximity and elastic terms change
        # the metric of the step only (a stale reference would pull back and stall it); both
        # shrink together (same metric shape, vanishing size) by polish_decay per step and in
        # proportion to the constraint energy below POLISH_EREF
        Xs = lay.view(x, "P").copy()
        dk = max(min(w.polish_decay ** done, ec_prev / POLISH_EREF), POLISH_FLOOR)
        pol = (_constraints_only(lay, (R, C), w, par, mer, s2)
               .add("proximity", w.polish_proximity * dk * s2, T.closeness,
                    T.Closeness("P", Xs)))
        if w.polish_elastic > 0:
            pol.add("elastic", w.polish_elastic * dk * w.polish_elastic_decay ** done * s2,
                    T.linear, T.Linear("P", D, D @ Xs))
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
        g, lr = _figures(lay.view(x, "P").reshape(R, C, 3))
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
        regular = done % check_every == 0 or slow
        if evaluate is not None and not regular and done == SCORE_EARLY:
            # an early look: a score far inside the thresholds ends the polish here; any other
            # is forgotten (the checkpoints and the stagnation test stay those of check_every)
            if check(f"polish {done}", x, early=True) <= SCORE_DONE:
                last_checked = done
                stop = "figures"
                break
        elif evaluate is not None and regular:
            sc = check(f"polish {done}", x)
            last_checked = done
            if sc_prev is None and SCORE_DONE < sc < 1.0 and not slow:
                sc_prev = rounds_score()
            stalled = slow or (sc_prev is not None and sc_prev - sc < SCORE_STALL * sc_prev)
            if sc <= SCORE_DONE or (sc < 1.0 and stalled):
                stop = "figures"
                break
            sc_prev = sc
        if rel < POLISH_STALL:
            stop = "stagnation"
            break
    if evaluate is None:
        return x, stop, None, f"polish {done}" if done else "rounds"
    if done > last_checked:
        check(f"polish {done}", x)
    if best[0] is None or best[0] > SCORE_DONE:
        rounds_score()
    return best[1], stop, best[0], best[2]
