"""A least-squares problem: a list of weighted terms over one :class:`Layout`."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.sparse as sp

from gridshell.core.errors import InputError
from gridshell.solver.layout import Layout
from gridshell.solver.terms import TermFn, TermResult, registered_name


@dataclass
class Entry:
    """One weighted term of a problem: energy ``weight * |term(x)|^2``."""

    name: str
    weight: float
    fn: TermFn
    data: Any = None


def _term_report(weight: float, r: np.ndarray) -> dict[str, float]:
    """Weight, energy, unweighted RMS and max |r| of one term's unweighted residual ``r``."""
    return {"weight": weight, "energy": weight * float(r @ r),
            "rms": float(np.sqrt(np.mean(r ** 2))) if r.size else 0.0,
            "max": float(np.max(np.abs(r))) if r.size else 0.0}


@dataclass
class Assembled:
    """Weighted residual ``r``, CSR Jacobian ``J`` and each term's rows in them; ``terms``:
    each active term's weight and unweighted residual, for :meth:`report`."""

    r: np.ndarray
    J: sp.csr_matrix
    slices: dict[str, slice]
    terms: dict[str, tuple[float, np.ndarray]] = field(default_factory=dict)

    def energy(self) -> float:
        return float(self.r @ self.r)

    def energies(self) -> dict[str, float]:
        return {k: float(self.r[s] @ self.r[s]) for k, s in self.slices.items()}

    def report(self) -> dict[str, dict[str, float]]:
        """:meth:`Problem.report` at the assembled point (the same values, no evaluation)."""
        return {k: _term_report(w, r) for k, (w, r) in self.terms.items()}


@dataclass
class Problem:
    """Sum of weighted squared residuals over the variables of ``layout``."""

    layout: Layout
    entries: list[Entry] = field(default_factory=list)
    _csr: Any = field(default=None, init=False, repr=False, compare=False)

    def add(self, name: str, weight: float, fn: TermFn, data: Any = None) -> "Problem":
        """Add term ``fn`` with ``data`` and ``weight`` under ``name``; returns ``self``.

        ``fn`` must be registered with :func:`~gridshell.solver.terms.term`, so that the
        finite-difference test (``tests/solver/test_jacobians.py``) covers every term a problem uses.
        """
        if registered_name(fn) is None:
            what = getattr(fn, "__qualname__", None) or type(fn).__name__
            raise InputError(f"term {name!r}: {what!r} is not a registered solver term; decorate "
                             "it with @gridshell.solver.term and add a finite-difference case "
                             "for it in tests/fd_cases/")
        if any(e.name == name for e in self.entries):
            raise InputError(f"term {name!r} is added twice")
        if not np.isfinite(weight) or weight < 0:
            raise InputError(f"term {name!r}: weight must be finite and >= 0, got {weight}")
        self.entries.append(Entry(name, float(weight), fn, data))
        return self

    def set_weight(self, name: str, weight: float) -> None:
        """Change the weight of term ``name``."""
        for e in self.entries:
            if e.name == name:
                e.weight = float(weight)
                return
        raise InputError(f"no term {name!r}; terms are {[e.name for e in self.entries]}")

    def set_data(self, name: str, data: Any) -> None:
        """Replace the data of term ``name`` (e.g. new closest points)."""
        for e in self.entries:
            if e.name == name:
                e.data = data
                return
        raise InputError(f"no term {name!r}; terms are {[e.name for e in self.entries]}")

    def evaluate(self, x: np.ndarray) -> list[tuple[Entry, TermResult]]:
        """Every active term's unweighted result at ``x``."""
        return [(e, e.fn(x, self.layout, e.data)) for e in self.entries if e.weight > 0]

    def residuals(self, x: np.ndarray) -> np.ndarray:
        """The weighted residual vector only (no Jacobian assembly cost saved)."""
        return self.assemble(x, jacobian=False).r

    def assemble(self, x: np.ndarray, jacobian: bool = True) -> Assembled:
        """Weighted residual and CSR Jacobian at ``x``."""
        rs, rows, cols, vals, slices, off, terms = [], [], [], [], {}, 0, {}
        for e, res in self.evaluate(x):
            w = np.sqrt(e.weight)
            m = len(res.r)
            terms[e.name] = (e.weight, res.r)
            rs.append(w * res.r)
            if jacobian:
                rows.append(res.rows + off)
                cols.append(res.cols)
                vals.append(w * res.vals)
            slices[e.name] = slice(off, off + m)
            off += m
        r = np.concatenate(rs) if rs else np.zeros(0)
        if jacobian and rows:
            J = self._to_csr(np.concatenate(rows), np.concatenate(cols), np.concatenate(vals),
                             (off, self.layout.size))
        else:
            J = sp.csr_matrix((off, self.layout.size))
        return Assembled(r, J, slices, terms)

    def _to_csr(self, rows: np.ndarray, cols: np.ndarray, vals: np.ndarray,
                shape: tuple[int, int]) -> sp.csr_matrix:
        """CSR from COO triplets (duplicates summed, explicit zeros kept). The structure and
        each triplet's slot are kept while the triplets' rows and columns stay the same (every
        iteration of a solve), so later calls only sum the values into place."""
        c = self._csr
        if c is None or c[0] != shape or not (np.array_equal(c[1], rows)
                                              and np.array_equal(c[2], cols)):
            key = rows.astype(np.int64) * shape[1] + cols
            # np.unique(key, return_inverse=True), through a stable sort: the terms emit
            # their triplets in sorted runs, which timsort merges (1e5 unknowns: 4x faster)
            order = np.argsort(key, kind="stable")
            ks = key[order]
            new = np.ones(len(ks), dtype=bool)
            np.not_equal(ks[1:], ks[:-1], out=new[1:])
            uniq = ks[new]
            slot = np.empty(len(ks), dtype=np.int64)
            slot[order] = np.cumsum(new) - 1
            indptr = np.zeros(shape[0] + 1, dtype=np.int64)
            np.cumsum(np.bincount(uniq // shape[1], minlength=shape[0]), out=indptr[1:])
            c = self._csr = (shape, rows.copy(), cols.copy(), indptr, uniq % shape[1], slot)
        _, _, _, indptr, indices, slot = c
        data = np.bincount(slot, weights=vals, minlength=len(indices))
        return sp.csr_matrix((data, indices.copy(), indptr.copy()), shape=shape)

    def energy(self, x: np.ndarray) -> float:
        """Total energy ``sum_k w_k |r_k|^2``."""
        r = self.residuals(x)
        return float(r @ r)

    def report(self, x: np.ndarray) -> dict[str, dict[str, float]]:
        """Per term: weight, energy, unweighted RMS and max |r|."""
        return {e.name: _term_report(e.weight, res.r) for e, res in self.evaluate(x)}
