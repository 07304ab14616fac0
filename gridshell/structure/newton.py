"""Newton's method on a total energy with exact gradient and Hessian (static equilibrium).

The energy need not be a sum of squares (self-weight is linear in the positions), so the step
solves ``(H + mu D) dq = -g`` over the free variables with the smallest shift ``mu`` that makes
the matrix positive definite (inertia read off the symmetric LU factor's pivots), followed by a
backtracking (Armijo) line search on the energy itself. Converged when the largest free
gradient component (a force in N or a moment in N m) falls below ``gtol``.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

EnergyFn = Callable[[np.ndarray, int], tuple]


@dataclass
class NewtonResult:
    """Outcome of :func:`minimize`: final ``q``, whether ``gtol`` was met, why it stopped, the
    iterations, the energy at ``q`` (J), the largest free gradient component and a history of
    ``{"it", "energy", "grad", "shift", "alpha", "time"}``."""

    q: np.ndarray
    converged: bool
    message: str
    iterations: int
    energy: float
    grad: float
    history: list[dict] = field(default_factory=list)


def _factor_pd(A: sp.csc_matrix):
    """A solver for ``A`` if its symmetric LU (diagonal pivots) shows it positive definite,
    else None."""
    try:
        lu = spla.splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                       options={"SymmetricMode": True})
    except RuntimeError:
        return None
    d = lu.U.diagonal()
    if not np.all(np.isfinite(d)) or np.any(d <= 0):
        return None
    return lu.solve


def _shifted_factor(Hf: sp.csc_matrix, mu: float) -> tuple[Any, float]:
    """A factorization of ``Hf + shift D`` (``D`` the Hessian's diagonal) that is positive
    definite, the shift growing from ``mu`` tenfold (from 1e-8); ``(None, shift)`` if none."""
    diag = np.abs(Hf.diagonal())
    scale = float(np.mean(diag)) if diag.size and np.mean(diag) > 0 else 1.0
    D = sp.diags(np.maximum(diag, 1e-12 * scale)).tocsc()
    solve = None
    shift = mu
    for _ in range(60):
        solve = _factor_pd((Hf + shift * D).tocsc() if shift > 0 else Hf)
        if solve is not None:
            break
        shift = max(10.0 * shift, 1e-8)
    return solve, shift


def _line_search(fun: EnergyFn, q: np.ndarray, idx: np.ndarray, dq: np.ndarray, E: float,
                 slope: float) -> tuple[np.ndarray, float, bool]:
    """Backtracking (Armijo) along ``dq`` from ``q``: ``(q_new, alpha, taken)``."""
    alpha = 1.0
    qn = q
    for _ in range(40):
        qn = q.copy()
        qn[idx] += alpha * dq
        En = fun(qn, 0)[0]
        if np.isfinite(En) and En <= E + 1e-4 * alpha * slope:
            return qn, alpha, True
        # near the minimum of a prestressed structure the decrease is below the energy's
        # round-off: the full step of the (accurate) quadratic model is taken
        if alpha == 1.0 and np.isfinite(En) and -slope <= 1e-11 * abs(E) \
                and En <= E + 1e-11 * abs(E):
            return qn, alpha, True
        alpha *= 0.5
    return qn, alpha, False


def minimize(fun: EnergyFn, q0: np.ndarray, free: np.ndarray, *, gtol: float,
             etol: float = 1e-13, max_iter: int = 200,
             accept: Callable[[np.ndarray], None] | None = None,
             time_limit: float | None = None) -> NewtonResult:
    """Minimize ``fun`` from ``q0`` over the variables ``free`` (boolean mask).

    ``fun(q, order)`` returns ``(E, g, H)``: the energy, its gradient ``(n,)`` (order >= 1) and
    its sparse Hessian ``(n, n)`` (order 2). ``accept(q)`` is called after every accepted step
    (the rods re-base their reference frames there). Converged when the largest free gradient
    component is at most ``gtol`` (in the gradient's units), or when the Newton decrement
    ``g^T H^-1 g / 2`` (the energy still to gain) is at most ``etol |E|`` with an unshifted,
    positive definite Hessian (the gradient's round-off floor is reached first on stiff,
    lightly loaded rods).
    """
    q = np.array(q0, float)
    idx = np.flatnonzero(free)
    t0 = time.perf_counter()
    E, g, H = fun(q, 2)
    mu = 0.0
    hist: list[dict] = []
    message, converged, it = "iteration limit reached", False, 0
    for it in range(1, max_iter + 1):
        gf = g[idx]
        gmax = float(np.max(np.abs(gf), initial=0.0))
        if gmax <= gtol:
            message, converged, it = "gradient below tolerance", True, it - 1
            break
        solve, shift = _shifted_factor(sp.csc_matrix(H[idx][:, idx]), mu)
        if solve is None:
            message = "no positive definite shift of the Hessian found"
            break
        dq = -solve(gf)
        slope = float(gf @ dq)
        if shift == 0.0 and -0.5 * slope <= etol * max(abs(E), 1e-300):
            # Newton decrement: the energy is within etol of its minimum (relative)
            message, converged = "Newton decrement below tolerance", True
            break
        qn, alpha, taken = _line_search(fun, q, idx, dq, E, slope)
        if not taken:
            if shift > 0 and shift >= 1e6:
                message = "line search failed (no descent along the Newton direction)"
                break
            mu = max(10.0 * shift, 1e-6)
            hist.append({"it": it, "energy": E, "grad": gmax, "shift": shift, "alpha": 0.0,
                         "time": time.perf_counter() - t0})
            continue
        q = qn
        if accept is not None:
            accept(q)
        E, g, H = fun(q, 2)
        mu = shift * 0.1 if alpha == 1.0 else shift
        if mu < 1e-10:
            mu = 0.0
        hist.append({"it": it, "energy": E, "grad": gmax, "shift": shift, "alpha": alpha,
                     "decrement": -0.5 * slope, "time": time.perf_counter() - t0})
        if time_limit is not None and time.perf_counter() - t0 > time_limit:
            message = f"time limit of {time_limit:g} s reached"
            break
    else:
        it = max_iter
    gmax = float(np.max(np.abs(g[idx]), initial=0.0))
    if gmax <= gtol and not converged:
        converged, message = True, "gradient below tolerance"
    return NewtonResult(q=q, converged=converged, message=message, iterations=it, energy=E,
                        grad=gmax, history=hist)
