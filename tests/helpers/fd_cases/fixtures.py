"""Test-only solver terms (problems with known answers for tests/solver/test_solver.py) and their
FD cases.

They live here, not in test_solver.py, because :meth:`gridshell.solver.Problem.add` takes only
terms registered with ``@term`` and every registered term needs a case in this package
(tests/solver/test_jacobians.py); defining them beside their cases keeps that check complete
whichever test files a pytest run collects.
"""
import numpy as np

from gridshell.solver import Layout, result, term


@term
def circle_term(x, layout, pts):
    """``r_i = |p_i - c| - R`` for points ``pts (k, d)``; blocks ``c (d,)``, ``R (1,)``."""
    c = layout.view(x, "c")
    R = layout.view(x, "R")[0]
    d = pts - c
    nrm = np.linalg.norm(d, axis=1)
    r = nrm - R
    k, dim = pts.shape
    rows = np.repeat(np.arange(k), dim + 1)
    cols = np.concatenate([np.tile(layout.indices("c"), (k, 1)),
                           np.full((k, 1), layout.indices("R")[0])], axis=1).ravel()
    with np.errstate(invalid="ignore", divide="ignore"):  # a point at c: NaN row, on purpose
        vals = np.concatenate([-d / nrm[:, None], -np.ones((k, 1))], axis=1).ravel()
    return result(r, rows, cols, vals)


@term
def planarity_term(x, layout, F):
    """Per quad ``f`` of ``F (m, 4)`` with normal ``n_f``: ``<V_b - V_a, n_f> = 0`` on its 4
    edges and ``|n_f|^2 = 1``; blocks ``V (nv, 3)``, ``N (m, 3)``."""
    V = layout.view(x, "V")
    N = layout.view(x, "N")
    Vi, Ni = layout.indices("V"), layout.indices("N")
    a = F.ravel()
    b = np.roll(F, -1, axis=1).ravel()
    f = np.repeat(np.arange(len(F)), 4)
    e = V[b] - V[a]
    n = N[f]
    r1 = np.einsum("ij,ij->i", e, n)
    m = len(r1)
    rows1 = np.repeat(np.arange(m), 9)
    cols1 = np.concatenate([Vi[b], Vi[a], Ni[f]], axis=1).ravel()
    vals1 = np.concatenate([n, -n, e], axis=1).ravel()
    r2 = np.einsum("ij,ij->i", N, N) - 1.0
    rows2 = m + np.repeat(np.arange(len(N)), 3)
    return result(np.concatenate([r1, r2]), np.concatenate([rows1, rows2]),
                  np.concatenate([cols1, Ni.ravel()]), np.concatenate([vals1, 2 * N.ravel()]))


@term
def rosenbrock_term(x, layout, data=None):
    """``r = (10 (y - x^2), 1 - x)`` on block ``p = (x, y)``: a full Gauss-Newton step from
    ``(-1.2, 1)`` raises the energy from 24.2 to about 2342 before the next reaches 0."""
    px, py = layout.view(x, "p")
    i, j = layout.indices("p")
    return result([10 * (py - px * px), 1 - px], [0, 0, 1], [i, j, i], [-20 * px, 10, -1])


def grid_quads(rows, cols):
    """Quads ``(m, 4)`` of a ``rows x cols`` vertex grid (vertex ``i * cols + j``)."""
    i, j = np.meshgrid(np.arange(rows - 1), np.arange(cols - 1), indexing="ij")
    v0 = (i * cols + j).ravel()
    return np.stack([v0, v0 + 1, v0 + cols + 1, v0 + cols], axis=1)


def _circle(rng):
    lay = Layout({"c": 2, "R": 1})
    return lay, rng.normal(size=lay.size), rng.normal(size=(7, 2))


def _planarity(rng):
    F = grid_quads(3, 4)
    lay = Layout({"V": (12, 3), "N": (len(F), 3)})
    return lay, rng.normal(size=lay.size), F


def _rosenbrock(rng):
    lay = Layout({"pad": 1, "p": 2})
    return lay, rng.normal(size=lay.size), None


CASES = {
    "tests.helpers.fd_cases.fixtures.circle_term": _circle,
    "tests.helpers.fd_cases.fixtures.planarity_term": _planarity,
    "tests.helpers.fd_cases.fixtures.rosenbrock_term": _rosenbrock,
}
