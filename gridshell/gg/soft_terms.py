"""Data of the soft terms of the GG surface design (:mod:`gridshell.gg.design`), metres: the
fairness operator (second differences along the grid lines), the gliding of the vertices on the
target's tangent planes and of the boundary vertices on the tangent lines of the initial
boundary polylines. The design refreshes the gliding data every round."""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from gridshell.solver import terms as T

__all__ = ["boundary_gliding", "boundary_sides", "fairness_matrix", "surface_gliding"]


def fairness_matrix(shape: tuple[int, int]) -> sp.csr_matrix:
    """Second differences ``X[k-1] - 2 X[k] + X[k+1]`` along meridians and along parallels of
    an ``R x C`` grid (row-major), ``((R-2) C + R (C-2), R C)``."""
    R, C = shape
    idx = np.arange(R * C).reshape(R, C)
    trip = []
    for a, b, c in ((idx[:-2, :], idx[1:-1, :], idx[2:, :]), (idx[:, :-2], idx[:, 1:-1], idx[:, 2:])):
        trip.append((a.ravel(), b.ravel(), c.ravel()))
    a = np.concatenate([t[0] for t in trip])
    b = np.concatenate([t[1] for t in trip])
    c = np.concatenate([t[2] for t in trip])
    m = len(a)
    rows = np.tile(np.arange(m), 3)
    return sp.csr_matrix((np.concatenate([np.ones(m), -2 * np.ones(m), np.ones(m)]),
                          (rows, np.concatenate([a, b, c]))), shape=(m, R * C))


def _closest_on_polyline(X: np.ndarray, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Closest points ``(k,3)`` of ``X (k,3)`` on polyline ``Q (n,3)`` and the unit tangent of
    the segment holding each."""
    A, B = Q[:-1], Q[1:]
    d = B - A
    dd = np.maximum(np.einsum("ij,ij->i", d, d), 1e-300)
    t = np.clip(np.einsum("kij,ij->ki", X[:, None, :] - A[None], d) / dd[None], 0.0, 1.0)
    F = A[None] + t[..., None] * d[None]
    s = np.argmin(np.einsum("kij,kij->ki", X[:, None] - F, X[:, None] - F), axis=1)
    k = np.arange(len(X))
    return F[k, s], d[s] / np.sqrt(dd[s])[:, None]


def boundary_sides(R: int, C: int) -> list[np.ndarray]:
    """Flat indices of the four boundary polylines of an ``R x C`` grid (row-major): first and
    last parallel, first and last meridian."""
    idx = np.arange(R * C).reshape(R, C)
    return [idx[0, :], idx[-1, :], idx[:, 0], idx[:, -1]]


def boundary_gliding(X: np.ndarray, P0flat: np.ndarray, sides: list[np.ndarray]) -> T.Gliding:
    """Gliding data keeping each boundary vertex on the tangent line of its side of ``P0``."""
    index, foot, normal = [], [], []
    for side in sides:
        F, t = _closest_on_polyline(X[side], P0flat[side])
        # two unit normals of the tangent line
        helper = np.where(np.abs(t[:, [0]]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
        n1 = np.cross(t, helper)
        n1 /= np.linalg.norm(n1, axis=1)[:, None]
        n2 = np.cross(t, n1)
        index += [side, side]
        foot += [F, F]
        normal += [n1, n2]
    return T.Gliding("P", np.concatenate(foot), np.concatenate(normal), np.concatenate(index))


def surface_gliding(X: np.ndarray, V: np.ndarray, F: np.ndarray) -> T.Gliding:
    """Gliding data keeping vertices ``X (k, 3)`` on the tangent planes of the target ``(V, F)``
    (triangles, metres) at their closest points (a zero normal where none is defined)."""
    from gridshell.geometry.igl_adapter import closest_points_with_normals

    C, N = closest_points_with_normals(X, V, F)
    bad = ~np.all(np.isfinite(N), axis=1)
    N[bad] = 0.0
    return T.Gliding("P", C, N)
