"""The one solver: damped normal equations over the free variables.

``(J^T J + lambda D) dx = -J^T r`` with fixed damping ("guided projection", Tang et al. 2014)
or adaptive damping with accept/reject (Levenberg-Marquardt); fixed variables are removed as
columns. ``J^T J`` keeps one pattern for the whole solve (:mod:`.normal`) and the linear solver
(:mod:`.linear`) analyses that pattern once and refactors it numerically per iteration and per
rejected step.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable, Literal

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from gridshell.core.errors import ConvergenceError, InputError
from gridshell.solver.linear import LinearSolver, NotPositiveDefinite, shared_solver
from gridshell.solver.normal import NormalEquations
from gridshell.solver.problem import Problem
from gridshell.solver.threads import one_blas_thread

Method = Literal["lm", "gn", "guided"]


@dataclass
class SolveResult:
    """Outcome of :func:`solve`.

    Attributes
    ----------
    x : final variables. Method "lm" returns the last accepted iterate, which is also the
        lowest-energy one (a step is accepted only if it lowers the energy). Methods "gn" and
        "guided" take every step whose energy is finite, so ``x`` is the last iterate even if
        the energy rose on the way (see ``history``); ``energy`` is the energy at ``x``.
    converged : whether a stopping tolerance was met (not merely the iteration cap)
    message : why it stopped
    iterations : number of iterations run
    energy, energy0 : energy at ``x`` and at ``x0``
    history : per iteration ``{"it", "energy", "terms", "step", "lambda", "accepted", "time"}``
    report : final per-term report (:meth:`Problem.report`)
    """

    x: np.ndarray
    converged: bool
    message: str
    iterations: int
    energy: float
    energy0: float
    history: list[dict] = field(default_factory=list)
    report: dict = field(default_factory=dict)

    def raise_if_failed(self, what: str = "optimization") -> "SolveResult":
        """Raise :class:`ConvergenceError` naming ``what`` unless converged."""
        if not self.converged:
            raise ConvergenceError(
                f"{what} did not converge: {self.message} (energy {self.energy0:.3e} -> "
                f"{self.energy:.3e} after {self.iterations} iterations); try more iterations, "
                "a closer initial shape, or lower weights on conflicting terms")
        return self


def _free_columns(n: int, fixed: np.ndarray | None) -> np.ndarray:
    if fixed is None:
        return np.arange(n)
    fixed = np.asarray(fixed)
    if fixed.dtype == bool:
        if fixed.shape != (n,):
            raise InputError(f"fixed mask must have shape ({n},), got {fixed.shape}")
        return np.flatnonzero(~fixed)
    mask = np.zeros(n, dtype=bool)
    mask[fixed.astype(np.int64)] = True
    return np.flatnonzero(~mask)


def factorized(A: sp.csc_matrix) -> Callable[[np.ndarray], np.ndarray]:
    """A one-shot SuperLU solver for the symmetric positive definite ``A`` (no cache).

    SuperLU in symmetric mode: MMD ordering of ``A^T + A`` and diagonal pivots only
    (``diag_pivot_thresh=0``, safe for the damped normal equations, which are SPD). With
    SuperLU's default partial pivoting, off-diagonal pivots destroy the ordering and the fill
    grows 10-20x on stiff problems; see benchmarks/solver.py for the measured choice.
    :func:`solve` uses :class:`~.linear.LinearSolver` instead (the analysis cached).
    """
    lu = spla.splu(sp.csc_matrix(A), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                   options={"SymmetricMode": True})
    return lu.solve


@one_blas_thread
def lm_update(E: float, E_new: float, g: np.ndarray, dx: np.ndarray, JTJ, lam: float,
              nu: float) -> tuple[bool, float, float]:
    """One Levenberg-Marquardt damping update (Nielsen's rule) after a trial step ``dx``:
    ``(accepted, lam, nu)``. Accepted when the energy ``E_new`` is finite and below ``E``; the
    damping then shrinks with the gain ratio (actual over predicted decrease, the prediction
    from the gradient ``g`` and ``JTJ``), else it grows by ``nu`` and ``nu`` doubles."""
    if np.isfinite(E_new) and E_new < E:
        pred = -(2 * g @ dx + dx @ (JTJ @ dx))
        rho = (E - E_new) / pred if pred > 0 else -1.0
        return True, lam * (max(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0) ** 3) if rho > 0 else 1.0), 2.0
    return False, lam * nu, nu * 2.0


def solve(problem: Problem, x0: np.ndarray, *, fixed: np.ndarray | None = None,
          method: Method = "lm", max_iter: int = 100, damping: float = 1e-3,
          tol_energy: float = 1e-20, tol_rel: float = 1e-10, tol_step: float = 1e-12,
          tol_grad: float = 1e-14, callback: Callable[[dict], None] | None = None,
          time_limit: float | None = None,
          linear: LinearSolver | str | None = None,
          stop: Callable[[np.ndarray], bool] | None = None) -> SolveResult:
    """Minimize ``problem``'s energy from ``x0``.

    Parameters
    ----------
    problem : the weighted terms
    x0 : (n,) initial variables
    fixed : boolean mask (n,) or indices of variables kept at their ``x0`` values
    method : "lm" adaptive damping with accept/reject; "gn" Gauss-Newton (tiny fixed damping,
        steps always taken); "guided" guided projection: fixed damping ``damping``, steps
        always taken
    damping : initial (lm) or fixed (gn/guided) damping, relative to mean diag(J^T J)
    tol_energy : stop when the energy falls below this
    tol_rel : stop when an accepted step lowers the energy by less than this fraction
    tol_step : stop when |dx| <= tol_step * (|x| + tol_step)
    tol_grad : stop when max |J^T r| falls below this
    callback : called with each history record (progress reporting)
    time_limit : seconds; stop (not converged) when exceeded
    linear : the linear solver: a :class:`~.linear.LinearSolver`, a backend name
        ("cholmod", "superlu") or None for the process-wide one of the default backend
        (``$GRIDSHELL_LINEAR`` or the first available, see :mod:`.linear`)
    stop : called with ``x`` after each accepted step; stop (converged) when it returns True
        (a caller's own convergence test, e.g. the design's figures hold)
    """
    x = _checked_start(problem, x0, method)
    free = _free_columns(len(x), fixed)
    lin = linear if isinstance(linear, LinearSolver) else shared_solver(linear)
    ne = NormalEquations()
    t0 = time.perf_counter()
    a = problem.assemble(x)
    E = a.energy()
    E0 = E
    lam = damping if method != "gn" else 1e-12
    history: list[dict] = []
    nu = 2.0
    message, converged, it = "iteration limit reached", False, 0
    if not np.isfinite(E):
        raise InputError("the energy at the initial point is not finite; check the input geometry")
    for it in range(1, max_iter + 1):
        if E <= tol_energy:
            message, converged, it = "energy below tolerance", True, it - 1
            break
        J = a.J if len(free) == len(x) else a.J[:, free]  # CSR; no copy if none fixed
        g = J.T @ a.r
        if np.max(np.abs(g), initial=0.0) <= tol_grad:
            message, converged, it = "gradient below tolerance", True, it - 1
            break
        JTJ = ne.update(J)
        accepted, singular, dx, x_new, a_new, E_new, lam, nu = _damped_step(
            problem, x, free, g, JTJ, ne, lin, lam, nu, method, E)
        step = float(np.linalg.norm(dx)) if accepted else 0.0
        rec = {"it": it, "energy": E_new if accepted else E, "step": step, "lambda": lam,
               "accepted": accepted, "time": time.perf_counter() - t0}
        if accepted:
            rec["terms"] = a_new.energies()
            rel = (E - E_new) / max(E, 1e-300)
            x, a, E = x_new, a_new, E_new
        history.append(rec)
        if callback is not None:
            callback(rec)
        if not accepted:
            message, converged = _rejected(method, singular, g, tol_grad, E)
            break
        why = _stopped(x, stop, method, rel, tol_rel, step, tol_step, time_limit, t0)
        if why is not None:
            message, converged = why
            break
    else:
        it = max_iter
    if E <= tol_energy:
        message, converged = "energy below tolerance", True
    return SolveResult(x=x, converged=converged, message=message, iterations=it, energy=E,
                       energy0=E0, history=history, report=a.report())  # a is at x


_SINGULAR = ("linear system singular at every damping (non-finite Jacobian entries: a term "
             "is not differentiable at the current point)")


def _checked_start(problem: Problem, x0: np.ndarray, method: str) -> np.ndarray:
    """``x0`` as a float copy, checked: a known ``method``, the layout's size, finite."""
    if method not in ("lm", "gn", "guided"):
        raise InputError(f"unknown method {method!r}; use 'lm', 'gn' or 'guided'")
    x = np.array(x0, dtype=float)
    if x.shape != (problem.layout.size,):
        raise InputError(f"x0 has shape {x.shape}, the layout needs ({problem.layout.size},)")
    if not np.all(np.isfinite(x)):
        raise InputError("x0 has NaN or infinite entries; check the initial geometry")
    return x


def _damped_step(problem: Problem, x: np.ndarray, free: np.ndarray, g: np.ndarray, JTJ,
                 ne: NormalEquations, lin: LinearSolver, lam: float, nu: float, method: str,
                 E: float):
    """One step ``dx`` of ``(J^T J + lam s D) dx = -g`` (``s`` the mean of diag ``J^T J``)
    from ``x`` over the ``free`` columns: the damping raised tenfold while the system is
    singular; "lm" retries with :func:`lm_update`'s damping until the energy ``E`` falls,
    the other methods take the first finite step. Returns ``(accepted, singular, dx,
    x_new, a_new, E_new, lam, nu)``; ``singular`` when no damping up to 1e16 factors."""
    diag = ne.diagonal()
    scale = float(np.mean(diag)) if diag.size and np.mean(diag) > 0 else 1.0
    accepted = singular = False
    dx = x_new = a_new = E_new = None
    while True:
        try:
            dx = -lin.factor(ne.damped(lam * scale), ne.key)(g)
        except NotPositiveDefinite:  # singular: raise damping
            lam *= 10.0
            if lam > 1e16:
                singular = True
                break
            continue
        x_new = x.copy()
        x_new[free] += dx
        a_new = problem.assemble(x_new)
        E_new = a_new.energy()
        if method != "lm":
            accepted = np.isfinite(E_new)
            break
        accepted, lam, nu = lm_update(E, E_new, g, dx, JTJ, lam, nu)
        if accepted or lam > 1e16:
            break
    return accepted, singular, dx, x_new, a_new, E_new, lam, nu


def _rejected(method: str, singular: bool, g: np.ndarray, tol_grad: float,
              E: float) -> tuple[str, bool]:
    """``(message, converged)`` when no step was taken: "lm" has converged when the gradient
    ``g`` is small against the energy ``E``; a non-finite energy is never convergence."""
    if method == "lm":
        message = _SINGULAR if singular else \
            "no step lowers the energy (local minimum or inconsistent terms)"
        return message, bool(np.max(np.abs(g)) <= max(tol_grad, 1e-8 * max(E, 1e-300) ** 0.5))
    return (_SINGULAR if singular else "energy became non-finite"), False


def _stopped(x: np.ndarray, stop, method: str, rel: float, tol_rel: float, step: float,
             tol_step: float, time_limit: float | None, t0: float) -> tuple[str, bool] | None:
    """``(message, converged)`` after an accepted step when a stopping test holds (the
    caller's ``stop``, the relative decrease ``rel`` for "lm", the step length, the time
    limit in seconds since ``t0``), else None."""
    if stop is not None and stop(x):
        return "the caller's stop condition holds", True
    if method == "lm" and 0 <= rel < tol_rel:
        return "relative energy decrease below tolerance", True
    if step <= tol_step * (np.linalg.norm(x) + tol_step):
        return "step below tolerance", True
    if time_limit is not None and time.perf_counter() - t0 > time_limit:
        return f"time limit of {time_limit:g} s reached", False
    return None
