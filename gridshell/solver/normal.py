"""The damped normal equations ``J^T J + lambda I`` on one fixed sparsity pattern.

Within a solve the Jacobian's structure does not change, so neither does the pattern of
``J^T J``. :class:`NormalEquations` keeps that pattern (with the whole diagonal in it) and
its :func:`~.linear.pattern_key`, refills the values every iteration and adds the damping to
the stored diagonal positions in place; a rejected Levenberg-Marquardt step changes the
diagonal only. The linear solver then recognises the pattern and reuses its analysis.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .linear import pattern_key


class NormalEquations:
    """``J^T J`` of successive Jacobians with one pattern, and its damped copies.

    Attributes
    ----------
    JTJ : scipy.sparse.csc_matrix
        ``J^T J`` of the last :meth:`update`, on the kept pattern (explicit zeros included).
    key : tuple
        :func:`~.linear.pattern_key` of the pattern (computed once per pattern).
    patterns : int
        How many patterns were set up (1 for a solve whose structure never changes).
    """

    def __init__(self) -> None:
        self.JTJ: sp.csc_matrix | None = None
        self.key: tuple = ()
        self.patterns = 0
        self._diag: np.ndarray = np.zeros(0, dtype=np.int64)

    def update(self, J: sp.spmatrix) -> sp.csc_matrix:
        """Set ``J^T J`` for the Jacobian ``J (m, n)``; returns it ``(n, n)``, CSC."""
        J = J.tocsr()
        M = (J.T.tocsr() @ J).tocsr()  # symmetric: its CSR arrays are its CSC arrays
        M.sort_indices()
        P = self.JTJ
        if P is not None and P.shape == M.shape and np.array_equal(P.indptr, M.indptr) \
                and np.array_equal(P.indices, M.indices):
            P.data[:] = M.data  # the usual case: the same pattern as before
            return P
        if P is not None and P.shape == M.shape:
            pos = self._positions(M)
            if pos is not None:  # M lost entries that cancelled exactly: keep the pattern
                P.data[:] = 0.0
                P.data[pos] = M.data
                return P
        self._new_pattern(M)
        return self.JTJ

    def _positions(self, M: sp.csr_matrix) -> np.ndarray | None:
        """Where ``M``'s entries sit in the kept pattern, or None if one is not in it."""
        P = self.JTJ
        n = P.shape[0]
        kp = np.repeat(np.arange(n, dtype=np.int64), np.diff(P.indptr)) * n + P.indices
        km = np.repeat(np.arange(n, dtype=np.int64), np.diff(M.indptr)) * n + M.indices
        pos = np.searchsorted(kp, km)
        pos = np.minimum(pos, len(kp) - 1)
        return pos if np.array_equal(kp[pos], km) else None

    def _new_pattern(self, M: sp.csr_matrix) -> None:
        n = M.shape[0]
        rows = np.repeat(np.arange(n), np.diff(M.indptr))
        diag = np.flatnonzero(rows == M.indices)
        if len(diag) == n:  # the usual case: M holds its whole diagonal, its pattern is the one
            self.JTJ = sp.csc_matrix((M.data.copy(), M.indices, M.indptr), shape=M.shape)
            self._diag = diag
            self.key = pattern_key(self.JTJ)
            self.patterns += 1
            return
        ones = sp.csr_matrix((np.ones(M.nnz), M.indices, M.indptr), shape=M.shape)
        S = (ones + sp.identity(n, format="csr")).tocsr()  # M's pattern plus the diagonal
        S.sort_indices()
        self.JTJ = sp.csc_matrix((np.zeros(S.nnz), S.indices.copy(), S.indptr.copy()),
                                 shape=M.shape)
        pos = self._positions(M)
        self.JTJ.data[pos] = M.data
        rows = np.repeat(np.arange(n), np.diff(S.indptr))
        self._diag = np.flatnonzero(rows == S.indices)
        self.key = pattern_key(self.JTJ)
        self.patterns += 1

    def diagonal(self) -> np.ndarray:
        """``diag(J^T J)`` (n,)."""
        return self.JTJ.data[self._diag]

    def damped(self, mu: float) -> sp.csc_matrix:
        """``J^T J + mu I`` on the same pattern (a new matrix; ``JTJ`` is untouched)."""
        data = self.JTJ.data.copy()
        data[self._diag] += mu
        return sp.csc_matrix((data, self.JTJ.indices, self.JTJ.indptr), shape=self.JTJ.shape)
