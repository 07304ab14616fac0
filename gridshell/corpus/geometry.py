"""Differential geometry of a parametric patch ``f(a, b) -> (..., 3)`` by central differences,
and the meshes of a sampled patch (quads of its grid, or two triangles per quad).

The differences use a step of ``1e-4`` of the unit parameter square on analytic functions:
second derivatives to about ``1e-8`` relative, enough to classify the sign of K and to check
the closed forms of :mod:`gridshell.corpus.surfaces`.
"""
from __future__ import annotations

from typing import Callable

import numpy as np

from gridshell.geometry.grid import grid_quads

__all__ = ["curvatures", "fundamental_forms", "grid_faces", "sample_grid"]

Fn = Callable[[np.ndarray, np.ndarray], np.ndarray]

_H = 1e-4


def fundamental_forms(f: Fn, a: np.ndarray, b: np.ndarray, h: float = _H
                      ) -> tuple[np.ndarray, ...]:
    """``(E, F, G, L, M, N)`` of ``f`` at ``(a, b)`` (eqs. 4.2-4.3), normal ``f_a x f_b``."""
    a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
    f0 = f(a, b)
    fa = (f(a + h, b) - f(a - h, b)) / (2 * h)
    fb = (f(a, b + h) - f(a, b - h)) / (2 * h)
    faa = (f(a + h, b) - 2 * f0 + f(a - h, b)) / h**2
    fbb = (f(a, b + h) - 2 * f0 + f(a, b - h)) / h**2
    fab = (f(a + h, b + h) - f(a + h, b - h) - f(a - h, b + h) + f(a - h, b - h)) / (4 * h * h)
    n = np.cross(fa, fb)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)

    def dot(x, y):
        return np.einsum("...k,...k->...", x, y)
    return dot(fa, fa), dot(fa, fb), dot(fb, fb), dot(faa, n), dot(fab, n), dot(fbb, n)


def curvatures(f: Fn, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray,
                                                               np.ndarray]:
    """Gaussian curvature ``K``, and the principal curvatures ``k1 <= k2`` (eqs. 4.4-4.6;
    signs w.r.t. the normal ``f_a x f_b``) of ``f`` at ``(a, b)``, in ``1 / unit^2`` and
    ``1 / unit``."""
    E, F, G, L, M, N = fundamental_forms(f, a, b)
    det = E * G - F * F
    K = (L * N - M * M) / det
    H = (E * N - 2 * F * M + G * L) / (2 * det)
    d = np.sqrt(np.maximum(H * H - K, 0.0))
    return K, H - d, H + d


def sample_grid(f: Fn, rows: int, cols: int) -> np.ndarray:
    """``P (rows, cols, 3)``: ``f`` at ``a = i / (rows - 1)``, ``b = j / (cols - 1)``."""
    a, b = np.meshgrid(np.linspace(0.0, 1.0, rows), np.linspace(0.0, 1.0, cols), indexing="ij")
    return f(a, b)


def grid_faces(rows: int, cols: int, kind: str = "quad", diagonal: str = "alternate"
               ) -> np.ndarray:
    """Faces of a ``rows x cols`` vertex grid (vertex ``i * cols + j``), oriented as
    :func:`gridshell.geometry.grid.grid_quads`: ``"quad"`` ``(m, 4)``, or ``"tri"`` ``(2m, 3)`` with the
    diagonal of each quad ``"alternate"`` (checkerboard) or ``"same"`` (all one way)."""
    Q = grid_quads(rows, cols)
    if kind == "quad":
        return Q
    if kind != "tri":
        raise ValueError(f"kind must be 'quad' or 'tri', got {kind!r}")
    i, j = np.divmod(np.arange(len(Q)), cols - 1)
    even = ((i + j) % 2 == 0) if diagonal == "alternate" else np.ones(len(Q), bool)
    T1 = np.where(even[:, None], Q[:, [0, 1, 2]], Q[:, [0, 1, 3]])
    T2 = np.where(even[:, None], Q[:, [0, 2, 3]], Q[:, [1, 2, 3]])
    # interleave so that the two triangles of a quad are neighbours in the file
    return np.stack([T1, T2], axis=1).reshape(-1, 3)
