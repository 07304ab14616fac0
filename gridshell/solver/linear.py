"""Sparse symmetric positive definite solves: analyse once per sparsity pattern, factor many.

The damped normal equations ``(J^T J + lambda D) dx = -J^T r`` of :func:`~.solve.solve` keep
one sparsity pattern for a whole solve (and for the next solve of a problem of the same
structure, e.g. the GG design's rounds and polish steps): only the values change between
iterations and between the rejected steps of Levenberg-Marquardt. A :class:`LinearSolver`
therefore does the symbolic analysis (fill-reducing ordering, elimination tree, supernodes)
once per pattern, keeps it in a small cache keyed on the pattern, and refactors numerically.

Backends (chosen by measurement, see benchmarks/README.md, "Linear solver"):

``"cholmod"``
    CHOLMOD's supernodal Cholesky through scikit-sparse 0.4.16 (built by ``make`` against
    Debian's libsuitesparse-dev; BLAS from OpenBLAS). The analysis is ``cholmod.analyze``, the
    numeric factorization ``Factor.cholesky_inplace``. Ordering: AMD, or, when the matrix has
    dense columns (auxiliary variables coupled to whole curves), those last and METIS for the
    rest (:mod:`.ordering`).
``"superlu"``
    scipy's SuperLU, the fallback that always works: the analysis is the MMD ordering of
    ``A^T + A`` (computed by a first factorization); later factorizations of the same pattern
    take the symmetrically permuted matrix in natural order with diagonal pivots
    (``diag_pivot_thresh=0``, safe for SPD matrices), so the ordering is not redone.

The default is the first available of :data:`BACKENDS`; the environment variable
``GRIDSHELL_LINEAR`` (``cholmod`` or ``superlu``) or the ``backend`` argument forces one.

Large systems (``n >= ITERATIVE_MIN`` unknowns) are first tried with Jacobi-preconditioned
CG (:mod:`.iterative`): on well-conditioned mesh problems it converges in ~100 matrix-vector
products whatever the size, 3-5x faster than the factorization at 1e5 unknowns. If CG does not
reach its tolerance within its iteration cap, the solve falls back to the backend's
factorization and the pattern is remembered as a direct one (no more CG tries on it).
"""
from __future__ import annotations

import hashlib
import os
from collections import OrderedDict
from typing import Any, Callable

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from gridshell.core.errors import InputError
from gridshell.solver.iterative import pcg
from gridshell.solver.ordering import dense_last, permuted

#: backends in order of preference (the first one that imports is the default)
BACKENDS = ("cholmod", "superlu")

#: environment variable naming the backend to use (overrides the preference order)
ENV = "GRIDSHELL_LINEAR"

#: unknowns from which CG is tried before the factorization (see benchmarks/README.md,
#: "One LM iteration at 1e5 unknowns"); below it the factorization is as fast or faster
ITERATIVE_MIN = 50_000


class NotPositiveDefinite(RuntimeError):
    """The matrix is not (numerically) positive definite: raise the damping."""


def _cholmod() -> Any:
    from sksparse import cholmod  # optional: built by `make` where libsuitesparse-dev exists

    return cholmod


def available(backend: str) -> bool:
    """Whether ``backend`` can be used here."""
    if backend == "superlu":
        return True
    if backend == "cholmod":
        try:
            _cholmod()
        except ImportError:
            return False
        return True
    return False


def default_backend() -> str:
    """The backend in use: ``$GRIDSHELL_LINEAR`` if set, else the first available one."""
    env = os.environ.get(ENV, "").strip().lower()
    if env:
        return _check(env)
    return next(b for b in BACKENDS if available(b))


def _check(backend: str) -> str:
    if backend not in BACKENDS:
        raise InputError(f"unknown linear solver {backend!r} (from {ENV} or the backend "
                         f"argument); use one of {', '.join(BACKENDS)}")
    if not available(backend):
        raise InputError(f"linear solver {backend!r} is not installed here (scikit-sparse is "
                         "built by `make` when libsuitesparse-dev is present); unset "
                         f"{ENV} or use 'superlu'")
    return backend


def describe() -> str:
    """One line naming the backend in use and why (for ``gridshell --version``)."""
    return f"{_describe_backend()}; Jacobi-CG first from {ITERATIVE_MIN} unknowns"


def _describe_backend() -> str:
    b = default_backend()
    if b == "cholmod":
        import sksparse

        ver = getattr(sksparse, "__version__", "") or _dist_version("scikit-sparse")
        how = f" (forced by {ENV})" if os.environ.get(ENV) else ""
        return f"cholmod (supernodal Cholesky, scikit-sparse {ver}){how}"
    if os.environ.get(ENV):
        return f"superlu (scipy; forced by {ENV})"
    return ("superlu (scipy; fallback: scikit-sparse/CHOLMOD is not installed - as root on "
            "Debian `make` installs it)")


def _dist_version(name: str) -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version(name)
    except PackageNotFoundError:
        return "?"


def pattern_key(A: sp.csc_matrix) -> tuple:
    """A key identifying the sparsity pattern of CSC (or CSR) ``A``: shape, nnz and a digest
    of ``indptr`` and ``indices`` (sorted indices assumed)."""
    h = hashlib.blake2b(digest_size=16)
    h.update(np.ascontiguousarray(A.indptr, dtype=np.int64).tobytes())
    h.update(np.ascontiguousarray(A.indices, dtype=np.int64).tobytes())
    return (A.shape, A.nnz, h.hexdigest())


class LinearSolver:
    """Factorizations of symmetric positive definite matrices, with the symbolic analysis
    cached per sparsity pattern (the ``cache_size`` most recent patterns).

    ``factor(A)`` returns a function ``solve(b) -> x``; it is valid until the next ``factor``
    of a matrix with the same pattern (the numeric factor is refilled in place).
    ``analyses`` and ``factorizations`` count the symbolic and numeric phases run,
    ``iterative`` the solves done by CG and ``fallbacks`` the CG tries that gave up (then the
    matrix was factored). ``iterative_min``: unknowns from which CG is tried first (default
    :data:`ITERATIVE_MIN`; ``None`` or 0 never).
    """

    def __init__(self, backend: str | None = None, cache_size: int = 2,
                 iterative_min: int | None = ITERATIVE_MIN) -> None:
        self.backend = _check(backend) if backend is not None else default_backend()
        self.cache_size = max(int(cache_size), 1)
        self.iterative_min = int(iterative_min) if iterative_min else 0
        self._cache: OrderedDict[tuple, Any] = OrderedDict()
        self._direct: set[tuple] = set()  # patterns on which CG gave up
        self.analyses = 0
        self.factorizations = 0
        self.iterative = 0
        self.fallbacks = 0
        self.ordering = ""  # the last analysis' ordering (CHOLMOD)

    def clear(self) -> None:
        """Forget every cached analysis (frees the factors) and where CG gave up."""
        self._cache.clear()
        self._direct.clear()

    def _analysis(self, A: sp.csc_matrix, key: tuple) -> tuple[Any, bool]:
        """The cached analysis of ``A``'s pattern, or ``(None, True)`` to make one."""
        if key in self._cache:
            self._cache.move_to_end(key)
            return self._cache[key], False
        return None, True

    def _store(self, key: tuple, analysis: Any) -> None:
        self._cache[key] = analysis
        self.analyses += 1
        while len(self._cache) > self.cache_size:
            self._cache.popitem(last=False)

    def factor(self, A: sp.spmatrix, key: tuple | None = None) -> Callable[[np.ndarray], np.ndarray]:
        """Factor the SPD matrix ``A`` (both triangles stored); ``key`` is its
        :func:`pattern_key` if the caller already knows it."""
        A = A if sp.isspmatrix_csc(A) else sp.csc_matrix(A)
        if not A.has_sorted_indices:
            A = A.sorted_indices()
        if not np.all(np.isfinite(A.data)):
            raise NotPositiveDefinite("the matrix has NaN or infinite entries")
        key = pattern_key(A) if key is None else key
        if self.iterative_min and A.shape[0] >= self.iterative_min and key not in self._direct:
            return self._iterative(A, key)
        return self._factor_direct(A, key)

    def _factor_direct(self, A: sp.csc_matrix, key: tuple) -> Callable:
        if self.backend == "cholmod":
            return self._factor_cholmod(A, key)
        return self._factor_superlu(A, key)

    def _iterative(self, A: sp.csc_matrix, key: tuple) -> Callable:
        """CG first; the factorization if CG gives up (and from then on for this pattern)."""
        def solve(b: np.ndarray) -> np.ndarray:
            res = pcg(A, b)
            if res.converged:
                self.iterative += 1
                return res.x
            self.fallbacks += 1
            self._direct.add(key)
            return self._factor_direct(A, key)(b)

        return solve

    # ---------------------------------------------------------------- CHOLMOD
    def _factor_cholmod(self, A: sp.csc_matrix, key: tuple) -> Callable:
        cholmod = _cholmod()
        an, new = self._analysis(A, key)
        try:
            if new:
                an = self._analyse_cholmod(A, cholmod)
                self._store(key, an)
            f, perm, gather, Ap = an
            if perm is None:
                f.cholesky_inplace(A)
            else:
                Ap.data[:] = A.data[gather]
                f.cholesky_inplace(Ap)
        except cholmod.CholmodNotPositiveDefiniteError as exc:
            raise NotPositiveDefinite(str(exc)) from None
        self.factorizations += 1
        if perm is None:
            return f

        def solve(b: np.ndarray) -> np.ndarray:
            x = np.empty_like(np.asarray(b, dtype=float))
            x[perm] = f(np.asarray(b)[perm])
            return x

        return solve

    def _analyse_cholmod(self, A: sp.csc_matrix, cholmod: Any) -> tuple:
        """``(factor, perm, gather, A[perm][:, perm])``: dense columns last when ``A`` has
        some (:mod:`.ordering`), else CHOLMOD's AMD (``perm`` None)."""
        order = dense_last(A, cholmod)
        if order is None:
            self.ordering = "amd"
            return cholmod.analyze(A, mode="supernodal", ordering_method="amd"), None, None, None
        perm, self.ordering = order[0], f"{order[1]}, dense columns last"
        Ap, gather = permuted(A, perm)
        f = cholmod.analyze(Ap, mode="supernodal", ordering_method="natural")
        return f, perm, gather, Ap

    # ---------------------------------------------------------------- SuperLU
    def _factor_superlu(self, A: sp.csc_matrix, key: tuple) -> Callable:
        perm, new = self._analysis(A, key)
        opts = {"SymmetricMode": True}
        try:
            if new:
                lu = spla.splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                               options=opts)
                self._store(key, np.argsort(lu.perm_c))  # new order: old index per position
                self.factorizations += 1
                return lu.solve
            Ap = A[perm][:, perm]
            lu = spla.splu(Ap, permc_spec="NATURAL", diag_pivot_thresh=0.0, options=opts)
        except RuntimeError as exc:  # "Factor is exactly singular"
            raise NotPositiveDefinite(str(exc)) from None
        self.factorizations += 1
        inv = np.empty_like(perm)
        inv[perm] = np.arange(len(perm))

        def solve(b: np.ndarray) -> np.ndarray:
            return lu.solve(np.asarray(b)[perm])[inv]

        return solve


_SOLVERS: dict[str, LinearSolver] = {}


def shared_solver(backend: str | None = None) -> LinearSolver:
    """The process-wide :class:`LinearSolver` of ``backend`` (default: :func:`default_backend`),
    so that consecutive solves of problems with one structure share the analysis."""
    b = _check(backend) if backend is not None else default_backend()
    if b not in _SOLVERS:
        _SOLVERS[b] = LinearSolver(b)
    return _SOLVERS[b]
