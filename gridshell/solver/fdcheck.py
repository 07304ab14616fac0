"""Finite-difference check of a term's Jacobian."""
from __future__ import annotations

from typing import Any

import numpy as np
import scipy.sparse as sp

from gridshell.solver.layout import Layout
from gridshell.solver.terms import TermFn


def term_jacobian(fn: TermFn, x: np.ndarray, layout: Layout, data: Any) -> sp.csr_matrix:
    """The analytic Jacobian of ``fn`` at ``x`` as CSR ``(m, n)``."""
    res = fn(x, layout, data)
    return sp.csr_matrix((res.vals, (res.rows, res.cols)), shape=(len(res.r), layout.size))


def fd_jacobian(fn: TermFn, x: np.ndarray, layout: Layout, data: Any,
                h: float = 1e-6) -> np.ndarray:
    """Central finite-difference Jacobian ``(m, n)`` of ``fn`` at ``x`` (dense)."""
    x = np.asarray(x, float)
    m = len(fn(x, layout, data).r)
    Jfd = np.zeros((m, len(x)))
    for k in range(len(x)):
        step = h * max(1.0, abs(x[k]))
        xp, xm = x.copy(), x.copy()
        xp[k] += step
        xm[k] -= step
        Jfd[:, k] = (fn(xp, layout, data).r - fn(xm, layout, data).r) / (2 * step)
    return Jfd


def jacobian_error(fn: TermFn, x: np.ndarray, layout: Layout, data: Any,
                   h: float = 1e-6) -> float:
    """Relative Frobenius error ``|J - J_fd| / max(|J_fd|, 1)`` of a term's Jacobian."""
    J = term_jacobian(fn, x, layout, data).toarray()
    Jfd = fd_jacobian(fn, x, layout, data, h)
    return float(np.linalg.norm(J - Jfd) / max(np.linalg.norm(Jfd), 1.0))
