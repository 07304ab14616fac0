"""Jacobi-preconditioned conjugate gradients for large, well-conditioned SPD systems.

On the damped normal equations of mesh problems whose terms all scale alike (closeness and
length/angle terms weighted by ``1 / L^2``, as in the GG design and section 1 of
benchmarks/solver.py), the Jacobi-scaled matrix has a condition number that does not grow
with the mesh: CG needs ~100 iterations at 1e4 and at 1e5 unknowns alike, each one matrix-
vector product (``2 nnz(A)`` flops), while a sparse Cholesky factor of a 2D mesh problem
costs ``O(n^1.5)`` (30 Gflop at 1e5 unknowns). Stiff problems (auxiliary variables with large
constraint weights, e.g. PHLW) make CG stall: :func:`pcg` then reports failure within
``maxiter`` and :class:`~.linear.LinearSolver` falls back to the direct factorization.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

#: relative residual ``|b - A x| / |b|`` at which :func:`pcg` stops (the step of LM is then
#: exact to ~1e-6 relative on the well-conditioned systems it is used for)
RTOL = 1e-8

#: iteration cap: beyond it the system is not well conditioned enough for CG to beat a
#: factorization (at 1e5 unknowns 300 iterations cost about half of one CHOLMOD factor)
MAXITER = 300


def _dot(u: np.ndarray, v: np.ndarray) -> float:
    """``u . v`` without BLAS: numpy's own loop. OpenBLAS's threaded ``ddot`` makes its
    threads spin between the matrix-vector products (measured at 1e5 unknowns with 2 threads
    on 2 cores: 3.5 s CPU against 0.84 s for the whole CG)."""
    return float(np.einsum("i,i->", u, v))


#: every this many iterations, give up if the mean rate so far would need more than
#: ``maxiter`` iterations in all (a stiff system is recognised in ~50 iterations, not 300)
CHECK_EVERY = 50


@dataclass
class PCGResult:
    """Outcome of :func:`pcg`: solution, iterations run, whether ``rtol`` was reached, and
    the final relative residual ``|b - A x| / |b|`` (recursively updated)."""

    x: np.ndarray
    iterations: int
    converged: bool
    residual: float


def pcg(A: sp.spmatrix, b: np.ndarray, rtol: float = RTOL, maxiter: int = MAXITER) -> PCGResult:
    """Solve the SPD system ``A x = b`` by CG with the Jacobi (diagonal) preconditioner.

    ``A`` is symmetric with both triangles stored (CSR or CSC); stops (not converged) on a
    non-positive curvature ``p^T A p`` (``A`` not positive definite), a non-finite value, or
    when the mean convergence rate so far cannot reach ``rtol`` within ``maxiter``.
    """
    b = np.asarray(b, dtype=float)
    n = len(b)
    A = sp.csr_matrix((A.data, A.indices, A.indptr), shape=A.shape) if sp.isspmatrix_csc(A) \
        else sp.csr_matrix(A)  # symmetric: a CSC matrix's arrays are its CSR arrays
    x = np.zeros(n)
    bn = _dot(b, b) ** 0.5
    if bn == 0.0:
        return PCGResult(x, 0, True, 0.0)
    d = A.diagonal()
    if not np.all(d > 0):
        return PCGResult(x, 0, False, 1.0)
    dinv = 1.0 / d
    r = b.copy()
    z = r * dinv
    p = z.copy()
    rz = _dot(r, z)
    tol = rtol * bn
    res = 1.0
    for k in range(1, maxiter + 1):
        q = A @ p
        pq = _dot(p, q)
        if not (pq > 0 and np.isfinite(pq)):
            return PCGResult(x, k, False, res)
        alpha = rz / pq
        x += alpha * p
        r -= alpha * q
        rn = _dot(r, r) ** 0.5
        res = rn / bn
        if rn <= tol:
            return PCGResult(x, k, True, res)
        if k % CHECK_EVERY == 0 and (res >= 1.0 or k * np.log(rtol) / np.log(res) > maxiter):
            return PCGResult(x, k, False, res)  # at this rate rtol is out of reach
        np.multiply(r, dinv, out=z)
        rz_new = _dot(r, z)
        p *= rz_new / rz
        p += z
        rz = rz_new
    return PCGResult(x, maxiter, False, res)
