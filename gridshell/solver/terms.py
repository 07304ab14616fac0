"""Residual terms: pure functions ``term(x, layout, data) -> TermResult``, and their registry.

A term returns its *unweighted* residual ``r (m,)`` and its Jacobian as COO triplets. Weights
live in the :class:`~gridshell.solver.problem.Problem`. Every term is registered with
:func:`term` so that one finite-difference test covers all of them.
"""
from __future__ import annotations

from typing import Any, Callable, NamedTuple

import numpy as np
import scipy.sparse as sp

from gridshell.solver.layout import Layout


class TermResult(NamedTuple):
    """Residual ``r (m,)`` and Jacobian triplets: ``J[rows[k], cols[k]] += vals[k]``."""

    r: np.ndarray
    rows: np.ndarray
    cols: np.ndarray
    vals: np.ndarray


TermFn = Callable[[np.ndarray, Layout, Any], TermResult]

#: every registered term, by qualified name ``module.function``
TERMS: dict[str, TermFn] = {}


def term(fn: TermFn) -> TermFn:
    """Register ``fn`` as a solver term (needed for the finite-difference test)."""
    TERMS[f"{fn.__module__}.{fn.__name__}"] = fn
    return fn


def registered_name(fn: Any) -> str | None:
    """The qualified name under which ``fn`` itself is registered in :data:`TERMS`, or None
    (not a function, never decorated with :func:`term`, or a different function of that name)."""
    name = f"{getattr(fn, '__module__', None)}.{getattr(fn, '__name__', None)}"
    return name if TERMS.get(name) is fn else None


def result(r: np.ndarray, rows: np.ndarray, cols: np.ndarray, vals: np.ndarray) -> TermResult:
    """Build a :class:`TermResult`, flattening and typing the arrays."""
    return TermResult(np.asarray(r, float).reshape(-1),
                      np.asarray(rows, np.int64).reshape(-1),
                      np.asarray(cols, np.int64).reshape(-1),
                      np.asarray(vals, float).reshape(-1))


def concat(parts: list[TermResult]) -> TermResult:
    """Stack several results into one (rows of later parts are offset)."""
    rs, rows, cols, vals, off = [], [], [], [], 0
    for p in parts:
        rs.append(p.r)
        rows.append(p.rows + off)
        cols.append(p.cols)
        vals.append(p.vals)
        off += len(p.r)
    if not parts:
        z = np.zeros(0)
        return result(z, z, z, z)
    return result(np.concatenate(rs), np.concatenate(rows), np.concatenate(cols),
                  np.concatenate(vals))


def linear_result(A: sp.spmatrix, cols: np.ndarray, r: np.ndarray) -> TermResult:
    """Triplets of a residual that is linear, ``J = A`` on global columns ``cols``."""
    A = sp.coo_matrix(A)
    return result(r, A.row, np.asarray(cols).reshape(-1)[A.col], A.data)


# ---------------------------------------------------------------------------------------------
# Generic terms shared by the pipelines
# ---------------------------------------------------------------------------------------------

class Closeness(NamedTuple):
    """Data of :func:`closeness`: ``block`` rows ``index`` (None: all) near ``target (k,d)``."""

    block: str
    target: np.ndarray
    index: np.ndarray | None = None


@term
def closeness(x: np.ndarray, layout: Layout, data: Closeness) -> TermResult:
    """``r = X[index] - target``: closeness of points to fixed targets (metres)."""
    X = layout.view(x, data.block)
    X = X.reshape(len(X), -1)
    idx = np.arange(len(X)) if data.index is None else np.asarray(data.index)
    tgt = np.asarray(data.target, float).reshape(len(idx), -1)
    d = X.shape[1]
    r = X[idx] - tgt
    cols = layout.indices(data.block).reshape(len(X), d)[idx]
    rows = np.arange(r.size)
    return result(r, rows, cols, np.ones(r.size))


class Gliding(NamedTuple):
    """Data of :func:`gliding`: points ``block[index]`` glide on tangent planes ``(foot, normal)``."""

    block: str
    foot: np.ndarray
    normal: np.ndarray
    index: np.ndarray | None = None


@term
def gliding(x: np.ndarray, layout: Layout, data: Gliding) -> TermResult:
    """``r = <X[index] - foot, normal>``: distance to the tangent plane at the closest point."""
    X = layout.view(x, data.block)
    X = X.reshape(len(X), -1)
    idx = np.arange(len(X)) if data.index is None else np.asarray(data.index)
    N = np.asarray(data.normal, float).reshape(len(idx), -1)
    r = np.einsum("ij,ij->i", X[idx] - np.asarray(data.foot, float).reshape(len(idx), -1), N)
    d = X.shape[1]
    cols = layout.indices(data.block).reshape(len(X), d)[idx]
    rows = np.repeat(np.arange(len(idx)), d)
    return result(r, rows, cols, N)


class Linear(NamedTuple):
    """Data of :func:`linear`: ``r = A @ X.reshape(-1 if flat)`` applied per coordinate minus ``b``.

    ``A (m, k)`` acts on the ``k`` rows of block ``block`` (shape ``(k, d)``), coordinate-wise;
    ``b (m, d)``.
    """

    block: str
    A: sp.spmatrix
    b: np.ndarray | None = None


@term
def linear(x: np.ndarray, layout: Layout, data: Linear) -> TermResult:
    """``r = A X - b`` with a fixed sparse ``A`` acting row-wise on block ``X (k,d)``: Laplacian
    fairness, B-spline sample closeness and every other linear term."""
    X = layout.view(x, data.block)
    X = X.reshape(X.shape[0], -1)
    d = X.shape[1]
    A = sp.csr_matrix(data.A)
    R = A @ X
    if data.b is not None:
        R = R - np.asarray(data.b, float).reshape(R.shape)
    # r is R flattened row-major: r[i*d + c] = sum_k A[i,k] X[k,c]
    Ac = A.tocoo()
    cols_blk = layout.indices(data.block).reshape(X.shape[0], d)
    rows = (Ac.row[:, None] * d + np.arange(d)[None, :])
    cols = cols_blk[Ac.col]
    vals = np.repeat(Ac.data[:, None], d, axis=1)
    return result(R, rows, cols, vals)


def laplacian_matrix(n: int, edges: np.ndarray, fixed_rows: np.ndarray | None = None
                     ) -> sp.csr_matrix:
    """Graph Laplacian ``(n,n)``: row i is ``x_i - mean of neighbours``; rows listed in
    ``fixed_rows`` (e.g. boundary) are dropped from the result (returned matrix has fewer rows)."""
    e = np.asarray(edges, np.int64)
    i = np.concatenate([e[:, 0], e[:, 1]])
    j = np.concatenate([e[:, 1], e[:, 0]])
    W = sp.csr_matrix((np.ones(len(i)), (i, j)), shape=(n, n))
    W.data[:] = 1.0
    deg = np.asarray(W.sum(axis=1)).ravel()
    deg[deg == 0] = 1.0
    L = sp.eye(n, format="csr") - sp.diags(1.0 / deg) @ W
    if fixed_rows is not None and len(fixed_rows):
        keep = np.setdiff1d(np.arange(n), fixed_rows)
        L = L[keep]
    return sp.csr_matrix(L)
