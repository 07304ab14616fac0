"""Benchmark of the sparse least-squares solver (``gridshell.solver``): seconds per iteration
and peak memory at ~1e3, 1e4 and 1e5 unknowns, the side-by-side run against
``scipy.optimize.least_squares`` and the choice of the linear solver.

The problem has mesh-like sparsity and is built from the project's own terms: an ``n x n``
quad grid on the elliptic dome ``z = -(x^2/2 + y^2/2.2)`` perturbed by Gaussian noise of 0.1
edge lengths, pulled back towards the dome (``closeness``, weight 1) while being made a GG mesh
(``geodesic_meridians``: angle sums, radians; ``equal_lengths`` on parallels and meridians
with the auxiliary lengths ``l, h``), with second-difference fairness (``linear``, 1e-3).
Length-like residuals are divided by the mean edge length, as in ``design_gg_surface``. The
dome is not a GG surface, so the minimum has a non-zero energy. Unknowns ``3 n^2 + 2 n - 1``:
n = 18, 57, 182 give 1 007, 9 860 and 99 735.

Sections (units: seconds, MB = 2^20 bytes, peak resident memory above the start of the run,
see ``_measure.py``):

1. ``iterations``: Levenberg-Marquardt (``solve(method="lm")``) from the noisy grid; seconds
   per iteration, peak memory, and one iteration's cost split into assembly
   (``Problem.assemble``), normal equations (``J^T J`` on its kept pattern) and the linear
   solve as ``solve()`` does it (CG first from ``linear.ITERATIVE_MIN`` unknowns), next to
   the linear solve with the factorization forced, in the same run.
2. ``least_squares``: on three problems - section 1's; round 1 of the GG surface design
   (``design_gg_surface``'s terms and default weights on the dome, from the grid itself); and
   round 1 of the PHLW optimization (``optimize_phlw``'s terms and weights on the saddle of
   ``phlw.py``, 8 / 27 samples per side for 1e3 / 1e4 unknowns; not at 1e5) - the same residual and sparse Jacobian (both from ``Problem.assemble``, cached per ``x``)
   are given to ``scipy.optimize.least_squares(method="trf", tr_solver="lsmr")`` with the
   default ``x_scale`` and with ``x_scale="jac"`` (not at 1e5 nor PHLW 1e4). The target is the energy our
   solver converges to (``tol_rel=1e-10``) times ``1 + 1e-6``; each run is timed until its
   energy first falls below it (least_squares through its ``callback``). Ours also runs with
   ``damping=1e-6`` instead of the default 1e-3. Ratio = least_squares' best time over ours
   (> 1: ours is faster; the issue's goal is >= 5 at 1e4+ unknowns); ``>=`` where
   least_squares was stopped at ``--lsq-cap`` seconds before reaching the target.
3. ``linear``: the damped normal equations ``J^T J + 1e-3 mean(diag) I`` at the start point
   solved by SuperLU with our options (MMD on ``A^T + A``, ``SymmetricMode``,
   ``diag_pivot_thresh=0``), SuperLU's default (COLAMD, partial pivoting), MMD with default
   pivoting, COLAMD with diagonal pivots, ``qdldl`` (AMD + LDL^T, only if installed; it is
   not a dependency) and, for reference, Jacobi-preconditioned CG to a relative residual of
   1e-8 (inexact, iterative). Figures: factor + solve seconds, fill ``nnz(L) + nnz(U)``
   (``2 nnz(L) + n`` for LDL^T), relative residual, peak MB. Each runs in its own process
   with a time limit.
4. ``pipelines``: the project's own problems at 1e4+ unknowns. One run of each pipeline step
   that optimizes (``design_gg_surface`` on the 60x60 dome, ``optimize_phlw`` at 28x28
   samples, ``post_optimize`` at 45 and ``simulate_alignment`` at 41 curves per family) is
   recorded: every ``solve`` call, with a copy of its problem, start point and settings. Each
   call is replayed with our solver and with ``least_squares(trf, lsmr)`` on the free
   variables, which runs until its energy is within 1e-6 of what ours reached in that call or
   until it has used ``--budget`` (6) times our seconds. Figures per pipeline and per call
   site: seconds summed over the calls, how many calls least_squares finished, the ratio of
   the sums (``>=`` if some call was stopped) and the worst single call's ratio.

    .venv/bin/python benchmarks/solver.py [--sizes 1e3 1e4 1e5] [--lsq-sizes 1e3 1e4 1e5]
        [--lsq-problems dome gg_round phlw_round] [--lsq-1e5-problems dome gg_round]
        [--linear-sizes 1e3 1e4] [--iter-1e5 3]
        [--pipelines gg_design phlw ncp_postopt ncp_simulation] [--budget 6]
        [--section iterations least_squares linear pipelines] [--json FILE]
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Any, Callable

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _measure import measure, run_worker  # noqa: E402

from gridshell.gg.design import (GridShape, edge_groups, equal_lengths,  # noqa: E402
                                 fairness_matrix, geodesic_meridians, init_group_lengths)
from gridshell.solver import Layout, Problem, solve  # noqa: E402
from gridshell.solver import terms as T  # noqa: E402
from gridshell.solver.solve import factorized  # noqa: E402

#: grid side per size label: 3 n^2 + 2 n - 1 unknowns
SIZES = {"1e3": 18, "1e4": 57, "1e5": 182}
SECTIONS = ("iterations", "least_squares", "linear", "backends", "pipelines")
DAMPING = 1e-3  # relative to mean diag(J^T J), as solve()'s default
TARGET_REL = 1e-6
SCRIPT = Path(__file__).resolve()


def grid_problem(n: int, noise: float = 0.1, seed: int = 0, closeness: float = 1.0,
                 fairness: float = 1e-3) -> tuple[Problem, np.ndarray]:
    """The benchmark problem on an ``n x n`` grid and its start point ``x0``."""
    x, y = np.meshgrid(np.linspace(-1, 1, n), np.linspace(-0.8, 0.8, n), indexing="ij")
    P = np.stack([x, y, -(x ** 2 / 2.0 + y ** 2 / 2.2)], axis=-1).reshape(-1, 3)
    L = 2.0 / (n - 1)
    P0 = P + noise * L * np.random.default_rng(seed).standard_normal(P.shape)
    lay = Layout({"P": (n * n, 3), "l": n, "h": n - 1})
    par, mer = edge_groups((n, n), "parallel"), edge_groups((n, n), "meridian")
    x0 = lay.pack({"P": P0, "l": init_group_lengths(P0, par), "h": init_group_lengths(P0, mer)})
    s2 = 1.0 / L ** 2
    D = fairness_matrix((n, n))
    prob = (Problem(lay)
            .add("geodesic", 1.0, geodesic_meridians, GridShape((n, n)))
            .add("parallel_lengths", s2, equal_lengths, par)
            .add("meridian_lengths", s2, equal_lengths, mer)
            .add("closeness", closeness * s2, T.closeness, T.Closeness("P", P))
            .add("fairness", fairness * s2, T.linear, T.Linear("P", D)))
    return prob, x0


def normal_equations(prob: Problem, x: np.ndarray) -> tuple[sp.csc_matrix, np.ndarray]:
    """``A = J^T J + DAMPING mean(diag) I`` (CSC) and ``b = -J^T r`` at ``x``, as in solve()."""
    a = prob.assemble(x)
    J = a.J.tocsc()
    JTJ = (J.T @ J).tocsc()
    A = (JTJ + sp.identity(JTJ.shape[0], format="csc") * (DAMPING * JTJ.diagonal().mean())).tocsc()
    return A, -(J.T @ a.r)


# ============================================================================ 1. iterations

def _timed(fn: Callable[[], Any]) -> tuple[float, Any]:
    t0 = time.perf_counter()
    out = fn()
    return time.perf_counter() - t0, out


def iteration_split(prob: Problem, x: np.ndarray) -> dict[str, float]:
    """Seconds of one iteration's parts at ``x`` (the steps of solve()), wall and CPU:
    assembly, normal equations on their kept pattern (a second update, as in every iteration
    after the first), then the linear solve as solve() does it (``LinearSolver()``: CG first
    at ``ITERATIVE_MIN`` unknowns and more) - the first solve and one again at another damping
    (a rejected step) - and the same two with the factorization forced (``iterative_min=0``:
    analysis + factor + solve, then refactor + solve), side by side in one run."""
    from gridshell.solver.linear import LinearSolver
    from gridshell.solver.normal import NormalEquations

    ne = NormalEquations()
    out: dict[str, Any] = {}

    def timed(name: str, fn: Callable[[], Any]) -> Any:
        t0, c0 = time.perf_counter(), time.process_time()
        v = fn()
        out[name], out[name + "_cpu"] = time.perf_counter() - t0, time.process_time() - c0
        return v

    prob.assemble(x)  # the first assembly also sets up J's structure, kept for later ones
    a = timed("assemble", lambda: prob.assemble(x))
    ne.update(a.J)
    timed("normal_eq", lambda: ne.update(a.J))
    g = a.J.T @ a.r
    mu = DAMPING * float(np.mean(ne.diagonal()))
    for path, lin in (("", LinearSolver()), ("direct_", LinearSolver(iterative_min=0))):
        timed(path + "first", lambda: lin.factor(ne.damped(mu), ne.key)(g))
        timed(path + "again", lambda: lin.factor(ne.damped(2 * mu), ne.key)(g))
        out[path + "how"] = ("CG" if lin.iterative == 2 else "CG, then factor"
                             if lin.iterative else "factor")
    out["backend"] = LinearSolver().backend
    return out


def work_iterations(size: str, max_iter: int) -> dict:
    prob, x0 = grid_problem(SIZES[size])
    split = iteration_split(prob, x0)
    m = measure(lambda: solve(prob, x0, method="lm", max_iter=max_iter, tol_rel=1e-10))
    res = m.value
    its = max(res.iterations, 1)
    split["backend"] = split.get("backend", "")
    A, _ = normal_equations(prob, x0)
    return {"size": size, "unknowns": int(len(x0)), "rows": int(len(prob.residuals(x0))),
            "nnz_J": int(prob.assemble(x0).J.nnz), "nnz_A": int(A.nnz),
            "seconds": m.seconds, "cpu_seconds": m.cpu_seconds, "iterations": res.iterations,
            "s_per_it": m.seconds / its, "cpu_per_it": m.cpu_seconds / its,
            "peak_mb": m.peak_mb, "rss_peak_mb": m.rss_peak_mb, "energy0": res.energy0,
            "energy": res.energy, "message": res.message, "split": split}


# ============================================================================ 2. least_squares

def gg_round_problem(n: int) -> tuple[Problem, np.ndarray]:
    """Round 1 of ``design_gg_surface`` on the dome grid of ``gg_design.py``: the same terms
    and default weights (geodesic, lengths, gliding on the target's tangent planes, fairness
    1e-4, elastic 3, proximity 1e-2; boundary gliding left out), from the grid itself."""
    from gridshell.geometry.grid import grid_quads
    from gridshell.geometry.igl_adapter import closest_points_with_normals, triangulate

    x, y = np.meshgrid(np.linspace(-1, 1, n), np.linspace(-0.8, 0.8, n), indexing="ij")
    P0 = np.stack([x, y, -(x ** 2 / 2.0 + y ** 2 / 2.2)], axis=-1)
    X = P0.reshape(-1, 3)
    V, Ft, _ = triangulate(X, grid_quads(n, n))
    foot, normal = closest_points_with_normals(X, V, Ft)
    L = float(np.mean(np.concatenate([np.linalg.norm(np.diff(P0, axis=a), axis=2).ravel()
                                      for a in (0, 1)])))
    s2 = 1.0 / L ** 2
    lay = Layout({"P": (n * n, 3), "l": n, "h": n - 1})
    par, mer = edge_groups((n, n), "parallel"), edge_groups((n, n), "meridian")
    x0 = lay.pack({"P": X, "l": init_group_lengths(X, par), "h": init_group_lengths(X, mer)})
    D = fairness_matrix((n, n))
    prob = (Problem(lay)
            .add("geodesic", 1.0, geodesic_meridians, GridShape((n, n)))
            .add("parallel_lengths", s2, equal_lengths, par)
            .add("meridian_lengths", s2, equal_lengths, mer)
            .add("closeness", 0.1 * s2, T.gliding, T.Gliding("P", foot, normal))
            .add("fairness", 1e-4 * s2, T.linear, T.Linear("P", D))
            .add("elastic", 3.0 * s2, T.linear, T.Linear("P", D, D @ X))
            .add("proximity", 1e-2 * s2, T.closeness, T.Closeness("P", X.copy())))
    return prob, x0


#: PHLW samples per side for a size label: 243 + 13 m^2 + m unknowns (9 x 9 control points)
PHLW_SAMPLES = {"1e3": 8, "1e4": 27, "1e5": 87}


def phlw_round_problem(n: int) -> tuple[Problem, np.ndarray]:
    """Round 1 of ``optimize_phlw`` (mode ``phlw``, default weights, 9 x 9 control points,
    bi-degree 4) on the saddle ``z = 0.3 (x^2 - y^2)`` of ``phlw.py``, with ``n`` samples
    per side: its own terms (eqs. 4.2-4.8 with auxiliary variables, E_beta, closeness,
    gliding), built by ``phlw_problem``."""
    from gridshell.geometry.bspline import uniform_params
    from gridshell.geometry.grid import grid_quads
    from gridshell.ncp import phlw as P
    from gridshell.ncp.reference import initial_surface

    x, y = np.meshgrid(np.linspace(-1, 1, 30), np.linspace(-1, 1, 30), indexing="ij")
    V = np.stack([x, y, 0.3 * (x ** 2 - y ** 2)], -1).reshape(-1, 3)
    F = grid_quads(30, 30)
    surf = initial_surface(V, F, n_ctrl=(9, 9), degree=(4, 4)).surface
    center, diag = V.mean(axis=0), float(np.linalg.norm(V.max(0) - V.min(0)))
    s0 = P._scaled_surface(surf, center, diag)
    u, v = uniform_params(s0, (n, n))
    data = P.make_samples(s0, u, v, "phlw")
    lay = P.make_layout(s0.n_ctrl, n * n, n, "phlw")
    prob, x0, _ = P.phlw_problem(s0, data, lay, dict(P.DEFAULT_WEIGHTS),
                                 ((V - center) / diag, F), "phlw")
    return prob, x0


#: problems of the least_squares section: name -> (builder, side per size label, note)
PROBLEMS: dict[str, tuple[Callable[[int], tuple[Problem, np.ndarray]], dict[str, int], str]] = {
    "dome": (grid_problem, SIZES, "noisy dome grid (section 1's problem)"),
    "gg_round": (gg_round_problem, SIZES, "GG design round 1 on the dome (design_gg_surface's "
                                          "terms and weights)"),
    "phlw_round": (phlw_round_problem, PHLW_SAMPLES, "PHLW round 1 on the saddle "
                                                     "(optimize_phlw's terms and weights)"),
}


def _time_to_target(res: Any, target: float, total: float) -> dict[str, Any]:
    reach = [h for h in res.history if h["accepted"] and h["energy"] <= target]
    return {"reached": bool(reach), "seconds": reach[0]["time"] if reach else total,
            "iterations": reach[0]["it"] if reach else res.iterations, "energy": res.energy,
            "seconds_total": total, "iterations_total": res.iterations}


def lsq_to_target(prob: Problem, x0: np.ndarray, fixed: Any, target: float, budget: float,
                  *, x_scale: str = "default", max_nfev: int = 100000,
                  tol: float = 1e-15) -> dict[str, Any]:
    """``least_squares(trf, lsmr)`` on the free variables from ``x0`` (the residual and
    Jacobian of ``Problem.assemble``, cached per point) until its energy is <= ``target``,
    ``budget`` seconds have passed or it stops by itself (``max_nfev``, tolerances ``tol``)."""
    from scipy.optimize import least_squares

    from gridshell.solver.solve import _free_columns

    free = _free_columns(len(x0), fixed)
    cache: dict[str, Any] = {}

    def assembled(xf: np.ndarray) -> Any:
        if "x" not in cache or not np.array_equal(cache["x"], xf):
            x = x0.copy()
            x[free] = xf
            cache["x"], cache["a"] = xf.copy(), prob.assemble(x)
        return cache["a"]

    state: dict[str, Any] = {"nit": 0}
    t0 = time.perf_counter()

    def callback(intermediate_result: Any) -> None:  # the name selects the result form
        state["nit"] += 1
        if 2.0 * float(intermediate_result.cost) <= target:
            state["seconds"] = time.perf_counter() - t0
            raise StopIteration
        if time.perf_counter() - t0 > budget:
            raise StopIteration

    r = least_squares(lambda xf: assembled(xf).r, x0[free],
                      jac=lambda xf: assembled(xf).J[:, free], method="trf", tr_solver="lsmr",
                      x_scale=None if x_scale == "default" else x_scale, ftol=tol, xtol=tol,
                      gtol=tol, max_nfev=max_nfev, callback=callback)
    total = time.perf_counter() - t0
    if "seconds" not in state and 2.0 * float(r.cost) <= target:
        state["seconds"] = total
    return {"reached": "seconds" in state, "seconds": state.get("seconds", total),
            "iterations": state["nit"], "nfev": int(r.nfev), "energy": 2.0 * float(r.cost),
            "message": str(r.message), "capped": total > budget and "seconds" not in state}


def work_least_squares(problem: str, size: str, x_scales: list[str], cap: float) -> dict:
    build, sides, _ = PROBLEMS[problem]
    prob, x0 = build(sides[size])
    t_ours, res = _timed(lambda: solve(prob, x0, method="lm", max_iter=100, tol_rel=1e-10))
    target = res.energy * (1.0 + TARGET_REL)
    out: dict[str, Any] = {"problem": problem, "size": size, "unknowns": int(len(x0)),
                           "target": target, "energy0": res.energy0,
                           "ours": _time_to_target(res, target, t_ours), "least_squares": {}}
    # the same solver with a lower initial damping (the default is 1e-3 of mean diag(J^T J))
    t_low, low = _timed(lambda: solve(prob, x0, method="lm", max_iter=100, tol_rel=1e-10,
                                      damping=1e-6))
    out["ours_damping_1e-6"] = _time_to_target(low, target, t_low)
    for xs in x_scales:
        out["least_squares"][xs] = lsq_to_target(prob, x0, None, target, cap, x_scale=xs,
                                                 max_nfev=500, tol=1e-12)
    return out


# ============================================================================ 4. pipelines

#: pipeline -> (builder in run_all.py or here, its size, what); sizes chosen for 1e4+ unknowns
PIPELINES: dict[str, tuple[str, int, str]] = {
    "gg_design": ("_gg_design", 60, "design_gg_surface on the 60x60 dome grid"),
    "phlw": ("_phlw", 28, "optimize_phlw on the saddle, 28x28 samples"),
    "ncp_postopt": ("_postopt", 45, "post_optimize, pseudosphere AA net, 45 curves per family"),
    "ncp_simulation": ("_simulation_frames", 41, "simulate_alignment, 41 curves per family, "
                                                 "4 frames"),
}
#: least_squares gets this many times our seconds on each call before it is stopped
BUDGET = 6.0


def _simulation_frames(curves: int) -> Callable[[], Any]:
    from run_all import _traced_net

    from gridshell.ncp.postopt import post_optimize
    from gridshell.ncp.alignment import collapse_direction, simulate_alignment

    surf, tn, col = _traced_net(curves)
    post = post_optimize(surf, tn.net, tn.joint_uv, col)
    E, d = tn.net.edges(), collapse_direction(surf)
    return lambda: simulate_alignment(post.V, post.r, E, d, aligned=(post.Vt, post.rt), frames=4)


def captured_solves(run: Callable[[], Any]) -> list[dict]:
    """Run ``run`` and return every ``solve`` call the library made in it: a copy of its
    problem and start point, its keyword arguments and the calling module."""
    import copy
    import importlib

    mod = importlib.import_module("gridshell.solver.solve")
    original = mod.solve
    calls: list[dict] = []

    def recorder(name: str) -> Callable[..., Any]:
        def rec(problem: Problem, x0: np.ndarray, **kw: Any) -> Any:
            calls.append({"where": name.removeprefix("gridshell."), "problem":
                          copy.deepcopy(problem), "x0": np.array(x0, dtype=float), "kw": kw})
            return original(problem, x0, **kw)
        return rec

    users = [(k, m) for k, m in list(sys.modules.items())
             if k.startswith("gridshell.") and getattr(m, "solve", None) is original]
    for k, m in users:
        m.solve = recorder(k)
    try:
        run()
    finally:
        for _, m in users:
            m.solve = original
    return calls


def work_pipeline(name: str, budget: float) -> dict:
    import copy

    import run_all

    builder, size, what = PIPELINES[name]
    build = globals()[builder] if builder in globals() else getattr(run_all, builder)
    run = build(size)
    t0 = time.perf_counter()
    calls = captured_solves(run)
    t_run = time.perf_counter() - t0
    rows = []
    for c in calls:
        prob = copy.deepcopy(c["problem"])
        t_ours, res = _timed(lambda: solve(prob, c["x0"], **c["kw"]))
        target = res.energy * (1.0 + TARGET_REL)
        ls = lsq_to_target(c["problem"], c["x0"], c["kw"].get("fixed"), target,
                           max(budget * t_ours, 0.05))
        kind = f"{c['where']} {c['kw'].get('method', 'lm')}"
        rows.append({"kind": kind, "unknowns": int(len(c["x0"])), "ours": t_ours,
                     "ours_iterations": res.iterations, "energy": res.energy,
                     "least_squares": ls})
    return {"pipeline": name, "what": what, "seconds_run": t_run, "calls": rows}


def section_pipelines(names: list[str], timeout: float, budget: float) -> list[dict]:
    print(f"4. the pipelines' own solves at 1e4+ unknowns: every solve() call of one run, "
          f"replayed with ours and with least_squares(trf, lsmr) until E <= E_ours * (1 + "
          f"{TARGET_REL:g}); least_squares is stopped at {budget:g}x our time per call")
    print(f"  {'pipeline: calls':<44} {'n':>6} {'calls':>5} {'ours s':>8} {'lsq s':>8} "
          f"{'reached':>7} {'ratio':>9} {'min ratio':>9}")
    out = []
    for name in names:
        d = run_worker(SCRIPT, ["pipeline", name, str(budget)], timeout)
        if d is None or "error" in d:
            print(f"  {name:<44} {'timed out' if d is None else d['error']} "
                  f"(limit {timeout:.0f} s)")
            continue
        groups: dict[str, list[dict]] = {}
        for r in d["calls"]:
            groups.setdefault(r["kind"], []).append(r)
        d["groups"] = {}
        print(f"  {name}: {d['what']}")
        for label, rows in [("  all calls", d["calls"])] + \
                [(f"    {k}", v) for k, v in groups.items()]:
            whole = label == "  all calls"
            ours = sum(r["ours"] for r in rows)
            lsq = sum(r["least_squares"]["seconds"] for r in rows)
            reached = sum(r["least_squares"]["reached"] for r in rows)
            ratios = [r["least_squares"]["seconds"] / r["ours"] for r in rows]
            lower = reached < len(rows)
            fig = {"n_calls": len(rows), "ours": ours, "least_squares": lsq, "reached": reached,
                   "ratio": lsq / ours, "ratio_lower_bound": lower, "ratio_min": min(ratios),
                   "unknowns": max(r["unknowns"] for r in rows)}
            if not whole:
                d["groups"][label.strip()] = fig
            else:
                d.update(fig)
            pre = ">=" if lower else ""
            print(f"  {label:<44} {fig['unknowns']:>6} {len(rows):>5} {ours:>8.2f} {lsq:>8.2f} "
                  f"{reached:>3}/{len(rows):<3} {pre + format(lsq / ours, '.1f') + 'x':>9} "
                  f"{min(ratios):>8.1f}x")
        out.append(d)
    print(f"  (ratio = least_squares / ours summed over the calls, >= when least_squares was "
          f"stopped at {budget:g}x our time on some call; min ratio: the worst single call)")
    return out


# ============================================================================ 3. linear solvers

def _superlu(**kw: Any) -> Callable[[sp.csc_matrix, np.ndarray], tuple[np.ndarray, int]]:
    def run(A: sp.csc_matrix, b: np.ndarray) -> tuple[np.ndarray, int]:
        lu = spla.splu(A, **kw)
        return lu.solve(b), int(lu.L.nnz + lu.U.nnz)
    return run


def _qdldl(A: sp.csc_matrix, b: np.ndarray) -> tuple[np.ndarray, int]:
    import qdldl

    s = qdldl.Solver(sp.triu(A, format="csc"), upper=True)
    L, d, _ = s.factors()
    return s.solve(b), int(2 * L.nnz + len(d))


def _cg(A: sp.csc_matrix, b: np.ndarray) -> tuple[np.ndarray, int]:
    x, info = spla.cg(A, b, rtol=1e-8, maxiter=20000, M=sp.diags(1.0 / A.diagonal()))
    return x, 0


LINEAR: dict[str, tuple[str, Callable[[sp.csc_matrix, np.ndarray], tuple[np.ndarray, int]]]] = {
    "ours": ("SuperLU MMD(A^T+A), SymmetricMode, diag_pivot_thresh=0 (factorized)",
             _superlu(permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                      options={"SymmetricMode": True})),
    "colamd": ("SuperLU COLAMD, partial pivoting (scipy default)", _superlu()),
    "mmd_pivot": ("SuperLU MMD(A^T+A), partial pivoting", _superlu(permc_spec="MMD_AT_PLUS_A")),
    "colamd_sym": ("SuperLU COLAMD, SymmetricMode, diag_pivot_thresh=0",
                   _superlu(permc_spec="COLAMD", diag_pivot_thresh=0.0,
                            options={"SymmetricMode": True})),
    "qdldl": ("qdldl AMD + LDL^T (optional package)", _qdldl),
    "cg": ("CG + Jacobi to rel. residual 1e-8 (iterative, inexact)", _cg),
}


def qdldl_available() -> bool:
    try:
        import qdldl  # noqa: F401
    except ImportError:
        return False
    return True


def work_linear(size: str, method: str) -> dict:
    prob, x0 = grid_problem(SIZES[size])
    A, b = normal_equations(prob, x0)
    fn = LINEAR[method][1]
    m = measure(lambda: fn(A, b))
    x, fill = m.value
    rel = float(np.linalg.norm(A @ x - b) / np.linalg.norm(b))
    return {"size": size, "method": method, "n": int(A.shape[0]), "nnz_A": int(A.nnz),
            "seconds": m.seconds, "fill": fill, "residual": rel, "peak_mb": m.peak_mb}


# ============================================================================ 3b. backends

def _pardiso_available() -> bool:
    try:
        import pymklpardiso  # noqa: F401
    except ImportError:
        return False
    return True


def _backend_runs(name: str) -> tuple[Callable, Callable] | None:
    """``(first(A, b), again(A, b))`` of a candidate backend: ``first`` analyses and factors,
    ``again`` refactors the same pattern with new values (the analysis reused)."""
    from gridshell.solver.linear import LinearSolver, available

    if name in ("cholmod", "superlu"):
        if not available(name):
            return None
        lin = LinearSolver(name)
        return (lambda A, b: lin.factor(A)(b)), (lambda A, b: lin.factor(A)(b))
    if name == "pardiso" and _pardiso_available():
        import pymklpardiso as pm

        state: dict[str, Any] = {}

        def first(A: sp.csc_matrix, b: np.ndarray) -> np.ndarray:
            U = sp.triu(A, format="csr")
            U.sort_indices()
            state["s"] = pm.PardisoSolver(U, pm.MTYPE_REAL_SYM_POSDEF)
            return state["s"].solve(b)

        def again(A: sp.csc_matrix, b: np.ndarray) -> np.ndarray:
            U = sp.triu(A, format="csr")
            U.sort_indices()
            state["s"].refactor(U.data)
            return state["s"].solve(b)

        return first, again
    return None


#: candidates of the "analyse once, factor many" interface (gridshell.solver.linear)
BACKEND_LABELS = {
    "superlu": "SuperLU (scipy; MMD ordering cached, then NATURAL on the permuted matrix)",
    "cholmod": "CHOLMOD supernodal (scikit-sparse 0.4.16, Debian libsuitesparse 5.12, OpenBLAS)",
    "pardiso": "MKL PARDISO SPD (py-mkl-pardiso, optional: not a dependency)",
}


def work_backend(size: str, name: str) -> dict:
    prob, x0 = grid_problem(SIZES[size])
    A, b = normal_equations(prob, x0)
    runs = _backend_runs(name)
    if runs is None:
        return {"size": size, "backend": name, "missing": True}
    first, again = runs
    m1 = measure(lambda: first(A, b))
    A2 = A.copy()
    A2.setdiag(A2.diagonal() * (1 + 1e-2))  # new values, same pattern (a rejected LM step)
    b2 = A2 @ np.ones(len(b))
    m2 = measure(lambda: again(A2, b2))
    return {"size": size, "backend": name, "n": int(A.shape[0]), "nnz_A": int(A.nnz),
            "first_s": m1.seconds, "first_cpu": m1.cpu_seconds,
            "again_s": m2.seconds, "again_cpu": m2.cpu_seconds,
            "residual": float(np.linalg.norm(A @ m1.value - b) / np.linalg.norm(b)),
            "residual_again": float(np.linalg.norm(A2 @ m2.value - b2) / np.linalg.norm(b2)),
            "peak_mb": max(m1.peak_mb, m2.peak_mb)}


def section_backends(sizes: list[str], timeout: float) -> list[dict]:
    print("3b. backends of gridshell.solver.linear on the same systems (each size and backend in "
          "its own process): first = analysis + factorization + solve, again = numeric "
          "refactorization of the same pattern + solve; wall s (CPU s, all threads)")
    print(f"  {'size':>4} {'n':>7}  {'backend':<82} {'first':>16} {'again':>16} "
          f"{'residual':>9} {'peak MB':>8}")
    rows = []
    for s in sizes:
        for name, label in BACKEND_LABELS.items():
            d = run_worker(SCRIPT, ["backend", s, name], timeout)
            if d is None or "error" in d:
                why = f"> {timeout:.0f} s (stopped)" if d is None else d["error"]
                print(f"  {s:>4} {'':>7}  {label:<82} {why}")
                continue
            if d.get("missing"):
                print(f"  {s:>4} {'':>7}  {label:<82} not installed")
                continue
            print(f"  {s:>4} {d['n']:>7}  {label:<82} "
                  f"{d['first_s']:>7.3f} ({d['first_cpu']:>6.3f}) "
                  f"{d['again_s']:>7.3f} ({d['again_cpu']:>6.3f}) "
                  f"{max(d['residual'], d['residual_again']):>9.1e} {d['peak_mb']:>8.0f}")
            rows.append(d)
    return rows


# ============================================================================ printing

def section_iterations(sizes: list[str], iter_big: int, timeout: float) -> list[dict]:
    from gridshell.solver.linear import default_backend

    print("1. Levenberg-Marquardt iterations (solve(method='lm')), GG-dome grid problem, linear "
          f"solver {default_backend()}; wall s (CPU s, all threads)")
    print(f"  {'size':>4} {'unknowns':>9} {'nnz(J)':>9} {'nnz(JTJ)':>9} {'its':>4} "
          f"{'s/it':>16} {'total s':>8} {'peak MB':>8}   one iteration: assemble / J^T J / "
          "linear solve, first / again (how) | factorization forced: first / again "
          "[s wall (CPU)]")
    rows = []
    for s in sizes:
        max_iter = 100 if SIZES[s] < 100 else iter_big
        d = run_worker(SCRIPT, ["iterations", s, str(max_iter)], timeout)
        if d is None or "error" in d:
            print(f"  {s:>4}  {'timed out' if d is None else d['error']} (limit {timeout:.0f} s)")
            continue
        sp_ = d["split"]
        def part(k: str) -> str:
            return f"{sp_[k]:.3f} ({sp_[k + '_cpu']:.3f})"

        parts = (" / ".join(part(k) for k in ("assemble", "normal_eq", "first", "again"))
                 + f" ({sp_['how']}) | {part('direct_first')} / {part('direct_again')}")
        print(f"  {s:>4} {d['unknowns']:>9} {d['nnz_J']:>9} {d['nnz_A']:>9} {d['iterations']:>4} "
              f"{d['s_per_it']:>7.3f} ({d['cpu_per_it']:>6.3f}) {d['seconds']:>8.2f} "
              f"{d['peak_mb']:>8.0f}   {parts}"
              + (f"  (capped at {max_iter} iterations)" if max_iter < 100 else ""))
        rows.append(d)
    return rows


def section_least_squares(problems: list[str], sizes: list[str], timeout: float,
                          cap: float, big_problems: list[str] | None = None) -> list[dict]:
    print("2. ours (LM, SuperLU) vs scipy.optimize.least_squares(trf, lsmr), same r and J; "
          f"seconds (iterations) to energy <= E_ours * (1 + {TARGET_REL:g}); ratio = best "
          "least_squares / ours (> 1: ours faster)")
    print(f"  {'problem':<9} {'size':>4} {'unknowns':>9} {'target E':>10} {'ours':>12} "
          f"{'ours damp 1e-6':>15} {'lsq default':>14} {'lsq x_scale=jac':>16} {'ratio':>8} "
          f"{'ratio 1e-6':>10}")
    rows = []
    for prob in problems:
        for s in sizes:
            if SIZES[s] >= 100 and big_problems is not None and prob not in big_problems:
                continue
            # x_scale="jac" only where a run takes seconds (it never beat the default where
            # measured: the 1e5 runs and PHLW at 1e4, whose runs reach the cap)
            slow = SIZES[s] >= 100 or (prob == "phlw_round" and s != "1e3")
            xs = ["default"] if slow else ["default", "jac"]
            d = run_worker(SCRIPT, ["least_squares", prob, s, ",".join(xs), str(cap)], timeout)
            if d is None or "error" in d:
                print(f"  {prob:<9} {s:>4}  {'timed out' if d is None else d['error']} "
                      f"(limit {timeout:.0f} s)")
                continue

            def cell(v: dict | None) -> str:
                if v is None:
                    return "-"
                mark = "" if v["reached"] else ("!" if not v.get("capped") else " capped")
                return f"{v['seconds']:.2f} ({v['iterations']}){mark}"

            ls = d["least_squares"]
            best = min(ls.values(), key=lambda v: v["seconds"])
            lower = not best["reached"]
            d["ratio"] = best["seconds"] / d["ours"]["seconds"]
            d["ratio_damping_1e-6"] = best["seconds"] / d["ours_damping_1e-6"]["seconds"]
            d["ratio_lower_bound"] = lower
            pre = ">=" if lower else ""
            print(f"  {prob:<9} {s:>4} {d['unknowns']:>9} {d['target']:>10.6g} "
                  f"{cell(d['ours']):>12} {cell(d['ours_damping_1e-6']):>15} "
                  f"{cell(ls.get('default')):>14} {cell(ls.get('jac')):>16} "
                  f"{pre + format(d['ratio'], '.2f') + 'x':>8} "
                  f"{pre + format(d['ratio_damping_1e-6'], '.2f') + 'x':>10}")
            rows.append(d)
    print("  (!: stopped before the target; the time is then its whole run)")
    return rows


def section_linear(sizes: list[str], timeout: float) -> list[dict]:
    print(f"3. linear solver of the damped normal equations (each in its own process, limit "
          f"{timeout:.0f} s)")
    methods = [m for m in LINEAR if m != "qdldl" or qdldl_available()]
    if not qdldl_available():
        print("  (qdldl not installed: skipped; pip install qdldl to include it)")
    print(f"  {'size':>4} {'n':>7} {'nnz(A)':>9}  {'method':<68} {'s':>7} {'fill':>10} "
          f"{'residual':>9} {'peak MB':>8}")
    rows = []
    for s in sizes:
        for meth in methods:
            d = run_worker(SCRIPT, ["linear", s, meth], timeout)
            label = LINEAR[meth][0]
            if d is None or "error" in d:
                why = f"> {timeout:.0f} s (stopped)" if d is None else d["error"]
                print(f"  {s:>4} {'':>7} {'':>9}  {label:<68} {why}")
                rows.append({"size": s, "method": meth, "seconds": None})
                continue
            fill = f"{d['fill']:>10}" if d["fill"] else f"{'-':>10}"
            print(f"  {s:>4} {d['n']:>7} {d['nnz_A']:>9}  {label:<68} {d['seconds']:>7.3f} "
                  f"{fill} {d['residual']:>9.1e} {d['peak_mb']:>8.0f}")
            rows.append(d)
    return rows


def main(argv: list[str] | None = None) -> dict[str, list[dict]]:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", nargs="+", default=list(SIZES), choices=list(SIZES),
                    help="sizes of the iteration section")
    ap.add_argument("--lsq-sizes", nargs="+", default=["1e3", "1e4", "1e5"], choices=list(SIZES))
    ap.add_argument("--lsq-problems", nargs="+", default=list(PROBLEMS), choices=list(PROBLEMS))
    ap.add_argument("--lsq-1e5-problems", nargs="+", default=["dome", "gg_round"],
                    choices=list(PROBLEMS), help="problems also compared at 1e5 (~2 min each)")
    ap.add_argument("--linear-sizes", nargs="+", default=["1e3", "1e4"], choices=list(SIZES))
    ap.add_argument("--backend-sizes", nargs="+", default=["1e3", "1e4", "1e5"],
                    choices=list(SIZES))
    ap.add_argument("--iter-1e5", type=int, default=3,
                    help="iteration cap of the 1e5 run of section 1 (about 12 s each)")
    ap.add_argument("--lsq-cap", type=float, default=300.0,
                    help="seconds after which least_squares is stopped (reported as capped)")
    ap.add_argument("--linear-timeout", type=float, default=30.0)
    ap.add_argument("--pipelines", nargs="+", default=list(PIPELINES), choices=list(PIPELINES))
    ap.add_argument("--budget", type=float, default=BUDGET,
                    help="least_squares is stopped at this many times our seconds per call")
    ap.add_argument("--section", nargs="+", default=list(SECTIONS), choices=SECTIONS)
    ap.add_argument("--json", help="also write the figures to this JSON file")
    a = ap.parse_args(argv)
    out: dict[str, list[dict]] = {}
    if "iterations" in a.section:
        out["iterations"] = section_iterations(a.sizes, a.iter_1e5, timeout=600)
    if "least_squares" in a.section:
        out["least_squares"] = section_least_squares(a.lsq_problems, a.lsq_sizes, timeout=900,
                                                     cap=a.lsq_cap,
                                                     big_problems=a.lsq_1e5_problems)
    if "linear" in a.section:
        out["linear"] = section_linear(a.linear_sizes, a.linear_timeout)
    if "backends" in a.section:
        out["backends"] = section_backends(a.backend_sizes, timeout=300)
    if "pipelines" in a.section:
        out["pipelines"] = section_pipelines(a.pipelines, timeout=1800, budget=a.budget)
    if a.json:
        Path(a.json).write_text(json.dumps(out, indent=1, default=float))
    return out


def worker(args: list[str]) -> None:
    kind, size = args[0], args[1]
    if kind == "iterations":
        d = work_iterations(size, int(args[2]))
    elif kind == "least_squares":
        d = work_least_squares(args[1], args[2], args[3].split(","), float(args[4]))
    elif kind == "linear":
        d = work_linear(size, args[2])
    elif kind == "backend":
        d = work_backend(size, args[2])
    elif kind == "pipeline":
        d = work_pipeline(args[1], float(args[2]))
    else:
        raise SystemExit(f"unknown worker {kind!r}")
    print(json.dumps(d, default=float))


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--worker":
        worker(sys.argv[2:])
    else:
        main()
