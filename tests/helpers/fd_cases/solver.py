"""FD cases of the generic terms in gridshell.solver.terms."""
import numpy as np
import scipy.sparse as sp

from gridshell.solver import Layout
from gridshell.solver import terms as T


def _closeness(rng):
    lay = Layout({"V": (6, 3), "s": 2})
    x = rng.normal(size=lay.size)
    return lay, x, T.Closeness("V", rng.normal(size=(3, 3)), np.array([0, 2, 5]))


def _gliding(rng):
    lay = Layout({"a": 3, "V": (5, 3)})
    x = rng.normal(size=lay.size)
    n = rng.normal(size=(5, 3))
    return lay, x, T.Gliding("V", rng.normal(size=(5, 3)), n / np.linalg.norm(n, axis=1)[:, None])


def _linear(rng):
    lay = Layout({"V": (7, 3)})
    x = rng.normal(size=lay.size)
    A = sp.random(4, 7, density=0.5, random_state=1)
    return lay, x, T.Linear("V", A, rng.normal(size=(4, 3)))


CASES = {
    "gridshell.solver.terms.closeness": _closeness,
    "gridshell.solver.terms.gliding": _gliding,
    "gridshell.solver.terms.linear": _linear,
}
