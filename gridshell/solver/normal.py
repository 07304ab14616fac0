"""The damped normal equations ``J^T J + lambda I`` on one fixed sparsity pattern.

Within a solve the Jacobian's structure does not change, so neither does the pattern of
``J^T J``. :class:`NormalEquations` keeps that pattern (with the whole diagonal in it) and
its :func:`~.linear.pattern_key`, refills the values every iteration and adds the damping to
the stored diagonal positions in place; a rejected Levenberg-Marquardt step changes the
diagonal only. The linear solver then recognises the pattern and reuses its analysis.

The values are filled in place: the transpose of ``J`` is a fixed gather of ``J``'s values
(its structure computed once per pattern of ``J``), and the product ``J^T J`` (scipy's
sparse product, whose output order depends only on its inputs' patterns) is scattered into
the kept pattern through positions computed once, with no sorting and no search. At 1e5
unknowns this halves the cost of an update (benchmarks/README.md).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from gridshell.solver.linear import pattern_key


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
        self.fast = 0  # updates that took the in-place path
        self._diag: np.ndarray = np.zeros(0, dtype=np.int64)
        self._T: tuple | None = None  # J's pattern, J^T's pattern and the gather J -> J^T
        self._M: tuple | None = None  # the product's (unsorted) pattern and its positions

    def update(self, J: sp.spmatrix) -> sp.csc_matrix:
        """Set ``J^T J`` for the Jacobian ``J (m, n)``; returns it ``(n, n)``, CSC."""
        J = J.tocsr()
        M = self._transpose(J) @ J  # symmetric: its CSR arrays are its CSC arrays
        P, m = self.JTJ, self._M
        if P is not None and m is not None and m[0] == M.shape \
                and np.array_equal(m[1], M.indptr) and np.array_equal(m[2], M.indices):
            if m[4]:  # the product covers the kept pattern (the usual case)
                P.data[m[3]] = M.data
            else:
                P.data[:] = 0.0
                P.data[m[3]] = M.data
            self.fast += 1
            return P
        pos = self._positions(M) if P is not None and P.shape == M.shape else None
        if pos is None:  # a new pattern (or an entry outside the kept one)
            km = _keys(M)
            order = np.argsort(km, kind="stable")  # M's slots in sorted (CSR) order
            S = sp.csr_matrix((M.data[order], M.indices[order], M.indptr), shape=M.shape)
            self._new_pattern(S)
            P = self.JTJ
            pos = np.empty(len(order), dtype=np.int64)
            if P.nnz == M.nnz:  # S's pattern is the kept one: slot order[k] goes to k
                pos[order] = np.arange(len(order))
            else:  # the diagonal was added
                pos = np.searchsorted(_keys(P), km)
        P.data[:] = 0.0  # entries of the pattern that cancelled exactly stay explicit zeros
        P.data[pos] = M.data
        self._M = (M.shape, M.indptr.copy(), M.indices.copy(), pos, len(pos) == P.nnz)
        return P

    def _transpose(self, J: sp.csr_matrix) -> sp.csr_matrix:
        """``J^T`` in CSR, its values gathered from ``J``'s through a kept permutation."""
        t = self._T
        if t is None or t[0] != J.shape or not (np.array_equal(t[1], J.indptr)
                                                and np.array_equal(t[2], J.indices)):
            slots = sp.csr_matrix((np.arange(1, J.nnz + 1, dtype=float), J.indices, J.indptr),
                                  shape=J.shape).T.tocsr()  # 1-based: no slot is a zero
            t = self._T = (J.shape, J.indptr.copy(), J.indices.copy(), slots.indptr,
                           slots.indices, slots.data.astype(np.int64) - 1)
        return sp.csr_matrix((J.data[t[5]], t[4], t[3]), shape=J.shape[::-1])

    def _positions(self, M: sp.csr_matrix) -> np.ndarray | None:
        """Where ``M``'s entries sit in the kept pattern, or None if one is not in it."""
        kp, km = _keys(self.JTJ), _keys(M)
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


def _keys(M: sp.spmatrix) -> np.ndarray:
    """``row * n + column`` of every stored entry of the compressed matrix ``M``, in storage
    order (for CSC read row as column: symmetric patterns only)."""
    n = M.shape[1]
    return np.repeat(np.arange(M.shape[0], dtype=np.int64), np.diff(M.indptr)) * n + M.indices
