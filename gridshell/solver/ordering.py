"""Fill-reducing ordering for CHOLMOD: dense columns last, nested dissection for the rest.

The auxiliary variables of the GG design (one length per parallel or meridian, coupled to
every vertex of its curve) are columns of ``J^T J`` with ~10-25x the median degree. They cross
every separator of the mesh, so METIS / nested dissection on the whole matrix fills badly
(section 1 of benchmarks/solver.py at 1e5 unknowns: 50 Gflop per factorization against 31 for
AMD), while ordering them last and the mesh part by METIS takes 20 Gflop and 20 % less time than
AMD (benchmarks/README.md, "One LM iteration at 1e5 unknowns"). Without such columns, or
below :data:`MIN_SIZE` unknowns, CHOLMOD's AMD is kept: it is the fastest there (1e4 unknowns:
0.54 Gflop, METIS 0.76).
"""
from __future__ import annotations

from typing import Any

import numpy as np
import scipy.sparse as sp

#: a column is dense when its degree exceeds this multiple of the median degree (and 16)
DENSE_RATIO = 10.0

#: at most this fraction of the columns is ordered last (more: no dense/sparse split)
DENSE_MAX_FRACTION = 0.05

#: unknowns from which the split is used: METIS's analysis costs ~4x AMD's (1e5: 0.8 s against
#: 0.2 s CPU), repaid after two factorizations at 1e5; below, on the GG pipeline at 100 x 100
#: (30k unknowns, ~11 factorizations per pattern) the factorizations were no faster and the
#: analyses made the stage 30 % slower
MIN_SIZE = 50_000

#: orderings tried for the sparse part, first available first ("metis" needs a CHOLMOD
#: built with METIS, as Debian's is; "amd" always exists)
SPARSE_ORDERINGS = ("metis", "amd")


def dense_columns(A: sp.csc_matrix) -> np.ndarray:
    """Indices of the dense columns of the symmetric ``A`` (empty if none or too many)."""
    deg = np.diff(A.indptr)
    if len(deg) == 0:
        return np.zeros(0, dtype=np.int64)
    limit = max(16.0, DENSE_RATIO * float(np.median(deg)))
    dense = np.flatnonzero(deg > limit)
    if len(dense) > DENSE_MAX_FRACTION * len(deg):
        return np.zeros(0, dtype=np.int64)
    return dense


def dense_last(A: sp.csc_matrix, cholmod: Any) -> tuple[np.ndarray, str] | None:
    """A fill-reducing permutation of ``A`` (``A[p][:, p]`` is factored in natural order)
    with the dense columns last and the rest ordered by the first of
    :data:`SPARSE_ORDERINGS` that this CHOLMOD has; and that ordering's name.
    None when ``A`` has no dense column or fewer than :data:`MIN_SIZE` unknowns (let CHOLMOD
    order it with AMD)."""
    if A.shape[0] < MIN_SIZE:
        return None
    dense = dense_columns(A)
    if len(dense) == 0:
        return None
    keep = np.ones(A.shape[0], dtype=bool)
    keep[dense] = False
    rest = np.flatnonzero(keep)
    S = A[rest][:, rest].tocsc()
    S.sort_indices()
    for method in SPARSE_ORDERINGS:
        try:
            p = cholmod.analyze(S, mode="simplicial", ordering_method=method).P()
        except cholmod.CholmodError:  # not in this build (CHOLMOD without METIS)
            continue
        return np.concatenate([rest[p], dense]).astype(np.int64), method
    return None


def permuted(A: sp.csc_matrix, perm: np.ndarray) -> tuple[sp.csc_matrix, np.ndarray]:
    """``A[perm][:, perm]`` (CSC, sorted) and the gather ``g`` with which its values are
    ``A.data[g]`` for any matrix of ``A``'s pattern (a refill without re-permuting)."""
    slots = sp.csc_matrix((np.arange(1, A.nnz + 1, dtype=float), A.indices, A.indptr),
                          shape=A.shape)  # 1-based: no slot is a zero that could be dropped
    P = slots[perm][:, perm].tocsc()
    P.sort_indices()
    gather = P.data.astype(np.int64) - 1
    return sp.csc_matrix((A.data[gather], P.indices, P.indptr), shape=A.shape), gather
