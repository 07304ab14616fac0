"""Constraint terms of a rotationally isometric geodesic-parallel mesh (paper 4.1.1, Fig. 12a;
Wang et al. 2019) on a grid ``P (R, C, 3)``, metres, ``P[i, j]`` with ``i`` the parallel and ``j``
the meridian:

1. :func:`geodesic_meridians` - equal angle sums on both sides of every meridian (radians);
2. / 3. :func:`equal_lengths` - one edge length per parallel and per meridian strip (metres);
4. :func:`equal_diagonals` - in every quad the two diagonals have one length (metres): the
   discrete orthogonality of meridians and parallels.

Constraints 1-3 alone admit a uniformly sheared grid (parallelograms on a plane or a cylinder:
equal lengths, equal angle sums) whose meridians cross the parallels at any angle, while the
surface of revolution it must be isometric to is parametrized orthogonally by its meridians and
parallels. A quad of a discrete surface of revolution (parallel ``i`` a circle of chord ``l_i``,
profile chord ``h_i``) is an isosceles trapezoid, whose diagonals are equal; with equal legs
``h_i`` and equal diagonals a planar quad *is* that trapezoid (Ptolemy: ``d^2 = h_i^2 +
l_i l_{i+1}``), so the quads of the design have the metric of the surface of revolution's. In the
smooth limit ``|d1|^2 - |d2|^2 = 4 P_u . P_v du dv``: the constraint is ``P_u . P_v = 0``.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from gridshell.core.errors import InputError
from gridshell.solver import Layout, TermResult, result, term

__all__ = ["GridShape", "EdgeGroups", "geodesic_meridians", "geodesic_residual", "edge_groups",
           "equal_lengths", "init_group_lengths", "length_residual_rel", "equal_diagonals",
           "diagonal_residual_rel"]


class GridShape(NamedTuple):
    """Data of :func:`geodesic_meridians`: block ``block`` holds an ``R x C`` grid row-major."""

    shape: tuple[int, int]
    block: str = "P"


def _cross(u: np.ndarray, w: np.ndarray) -> np.ndarray:
    """``u x w`` of ``(m, 3)`` arrays: the products and differences of ``np.cross`` (the same
    values to the bit) without its axis handling, which cost 3x the arithmetic at 1e3 rows."""
    out = np.empty_like(u)
    out[:, 0] = u[:, 1] * w[:, 2] - u[:, 2] * w[:, 1]
    out[:, 1] = u[:, 2] * w[:, 0] - u[:, 0] * w[:, 2]
    out[:, 2] = u[:, 0] * w[:, 1] - u[:, 1] * w[:, 0]
    return out


def _angle(u: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``theta = atan2(|u x w|, u.w)`` ``(m,)``, radians, with ``n = u x w`` and ``|n|``."""
    n = _cross(u, w)
    s = np.linalg.norm(n, axis=1)
    return np.arctan2(s, np.einsum("ij,ij->i", u, w)), n, s


def _angle_grads(u: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``theta = atan2(|u x w|, u.w)`` ``(m,)`` and its gradients w.r.t. ``u`` and ``w`` ``(m,3)``.

    ``d theta / du = (u x n) / (|u|^2 |n|)``, ``d theta / dw = (n x w) / (|w|^2 |n|)`` with
    ``n = u x w`` (minus the unit part of ``w`` normal to ``u``, over ``|u|``).
    """
    theta, n, s = _angle(u, w)
    s_ = np.maximum(s, 1e-300)
    gu = _cross(u, n) / (np.einsum("ij,ij->i", u, u) * s_)[:, None]
    gw = _cross(n, w) / (np.einsum("ij,ij->i", w, w) * s_)[:, None]
    return theta, gu, gw


def _stencil(shape: tuple[int, int]) -> tuple[np.ndarray, ...]:
    """Flat indices of interior vertices and their neighbours ``a`` (i-1), ``b`` (i+1),
    ``l`` (j-1), ``r`` (j+1)."""
    R, C = shape
    idx = np.arange(R * C).reshape(R, C)
    return (idx[1:-1, 1:-1].ravel(), idx[:-2, 1:-1].ravel(), idx[2:, 1:-1].ravel(),
            idx[1:-1, :-2].ravel(), idx[1:-1, 2:].ravel())


@term
def geodesic_meridians(x: np.ndarray, layout: Layout, data: GridShape) -> TermResult:
    """Paper Fig. 12a: ``r = ang(a,l) + ang(l,b) - ang(a,r) - ang(r,b)`` (radians) at every
    interior vertex: the meridians ``P[:, j]`` are discrete geodesics."""
    X = layout.view(x, data.block).reshape(-1, 3)
    cols_blk = layout.indices(data.block).reshape(-1, 3)
    c0, ia, ib, il, ir = _stencil(data.shape)
    m = len(c0)
    r = np.zeros(m)
    rows, cols, vals = [], [], []
    rr = np.repeat(np.arange(m), 3)
    for sign, p, q in ((1.0, ia, il), (1.0, il, ib), (-1.0, ia, ir), (-1.0, ir, ib)):
        th, gu, gw = _angle_grads(X[p] - X[c0], X[q] - X[c0])
        r += sign * th
        for vert, g in ((p, gu), (q, gw), (c0, -(gu + gw))):
            rows.append(rr)
            cols.append(cols_blk[vert].ravel())
            vals.append(sign * g.ravel())
    if m == 0:
        z = np.zeros(0)
        return result(z, z, z, z)
    return result(r, np.concatenate(rows), np.concatenate(cols), np.concatenate(vals))


def geodesic_residual(P: np.ndarray) -> np.ndarray:
    """Residual of :func:`geodesic_meridians` on ``P (R, C, 3)``, radians, ``(R-2, C-2)``."""
    P = np.asarray(P, float)
    R, C = P.shape[:2]
    X = P.reshape(-1, 3)
    c0, ia, ib, il, ir = _stencil((R, C))
    r = np.zeros(len(c0))
    for sign, p, q in ((1.0, ia, il), (1.0, il, ib), (-1.0, ia, ir), (-1.0, ir, ib)):
        r += sign * _angle(X[p] - X[c0], X[q] - X[c0])[0]  # as in geodesic_meridians
    return r.reshape(R - 2, C - 2)


class EdgeGroups(NamedTuple):
    """Data of :func:`equal_lengths`: edges ``p[k] -> q[k]`` of block ``block`` whose lengths
    all equal the auxiliary ``aux[group[k]]``."""

    block: str
    aux: str
    p: np.ndarray
    q: np.ndarray
    group: np.ndarray


def edge_groups(shape: tuple[int, int], family: str, block: str = "P",
                aux: str | None = None) -> EdgeGroups:
    """Edge groups of an ``R x C`` grid: ``"parallel"`` (edges ``(i,j)-(i,j+1)``, group ``i``,
    aux ``"l"``) or ``"meridian"`` (edges ``(i,j)-(i+1,j)``, group ``i``, aux ``"h"``)."""
    R, C = shape
    idx = np.arange(R * C).reshape(R, C)
    if family == "parallel":
        p, q = idx[:, :-1], idx[:, 1:]
        g = np.broadcast_to(np.arange(R)[:, None], p.shape)
        aux = aux or "l"
    elif family == "meridian":
        p, q = idx[:-1, :], idx[1:, :]
        g = np.broadcast_to(np.arange(R - 1)[:, None], p.shape)
        aux = aux or "h"
    else:
        raise InputError(f"family must be 'parallel' or 'meridian', got {family!r}")
    return EdgeGroups(block, aux, p.ravel(), q.ravel(), np.ascontiguousarray(g).ravel())


@term
def equal_lengths(x: np.ndarray, layout: Layout, data: EdgeGroups) -> TermResult:
    """``r = |X[q] - X[p]| - a[group]`` (metres): the edges of a group have one length ``a``
    (parallels: isometry with a surface of revolution; meridians: geodesic parallels)."""
    X = layout.view(x, data.block).reshape(-1, 3)
    A = layout.view(x, data.aux).reshape(-1)
    cols_blk = layout.indices(data.block).reshape(-1, 3)
    cols_aux = layout.indices(data.aux).reshape(-1)
    e = X[data.q] - X[data.p]
    n = np.linalg.norm(e, axis=1)
    r = n - A[data.group]
    t = e / np.maximum(n, 1e-300)[:, None]
    m = len(r)
    rows = np.concatenate([np.repeat(np.arange(m), 3), np.repeat(np.arange(m), 3), np.arange(m)])
    cols = np.concatenate([cols_blk[data.q].ravel(), cols_blk[data.p].ravel(),
                           cols_aux[data.group]])
    vals = np.concatenate([t.ravel(), -t.ravel(), -np.ones(m)])
    return result(r, rows, cols, vals)


def init_group_lengths(X: np.ndarray, data: EdgeGroups) -> np.ndarray:
    """Initial auxiliary of :func:`equal_lengths`: the mean edge length of each group, metres."""
    X = np.asarray(X, float).reshape(-1, 3)
    n = np.linalg.norm(X[data.q] - X[data.p], axis=1)
    k = int(data.group.max()) + 1 if len(data.group) else 0
    return np.bincount(data.group, n, k) / np.maximum(np.bincount(data.group, None, k), 1)


def length_residual_rel(P: np.ndarray) -> dict[str, float]:
    """Largest relative spread of edge lengths within a parallel (``parallel``) and within a
    meridian strip (``meridian``): ``max |e - mean| / mean`` over each group."""
    P = np.asarray(P, float)
    shape = P.shape[:2]
    out = {}
    for fam in ("parallel", "meridian"):
        g = edge_groups(shape, fam)
        mean = init_group_lengths(P, g)
        n = np.linalg.norm(P.reshape(-1, 3)[g.q] - P.reshape(-1, 3)[g.p], axis=1)
        out[fam] = float(np.max(np.abs(n - mean[g.group]) / np.maximum(mean[g.group], 1e-300)))
    return out


@term
def equal_diagonals(x: np.ndarray, layout: Layout, data: GridShape) -> TermResult:
    """``r = |P[i,j] - P[i+1,j+1]| - |P[i,j+1] - P[i+1,j]|`` (metres) in every quad ``(R-1)(C-1)``:
    meridians orthogonal to the parallels (zero on a discrete surface of revolution)."""
    X = layout.view(x, data.block).reshape(-1, 3)
    cols_blk = layout.indices(data.block).reshape(-1, 3)
    R, C = data.shape
    idx = np.arange(R * C).reshape(R, C)
    a, b = idx[:-1, :-1].ravel(), idx[1:, 1:].ravel()
    c, d = idx[:-1, 1:].ravel(), idx[1:, :-1].ravel()
    e1, e2 = X[b] - X[a], X[d] - X[c]
    n1, n2 = np.linalg.norm(e1, axis=1), np.linalg.norm(e2, axis=1)
    t1 = e1 / np.maximum(n1, 1e-300)[:, None]
    t2 = e2 / np.maximum(n2, 1e-300)[:, None]
    m = len(a)
    rr = np.tile(np.repeat(np.arange(m), 3), 4)
    cols = np.concatenate([cols_blk[b].ravel(), cols_blk[a].ravel(), cols_blk[d].ravel(),
                           cols_blk[c].ravel()])
    vals = np.concatenate([t1.ravel(), -t1.ravel(), -t2.ravel(), t2.ravel()])
    return result(n1 - n2, rr, cols, vals)


def diagonal_residual_rel(P: np.ndarray) -> float:
    """Largest ``| |d1| - |d2| | / mean(|d1|, |d2|)`` over the quads of ``P (R, C, 3)``."""
    P = np.asarray(P, float)
    d1 = np.linalg.norm(P[1:, 1:] - P[:-1, :-1], axis=2)
    d2 = np.linalg.norm(P[1:, :-1] - P[:-1, 1:], axis=2)
    return float(np.max(2 * np.abs(d1 - d2) / np.maximum(d1 + d2, 1e-300))) if d1.size else 0.0
