"""FD cases of the GG surface-design terms (gridshell.gg.constraints, paper 4.1.1).

A 5 x 4 grid on a perturbed saddle with random auxiliary lengths, so that every angle and
length is generic (no angle near 0 or pi, where atan2's gradient is singular).
"""
import numpy as np

from gridshell.gg import constraints as D
from gridshell.solver import Layout

R, C = 5, 4


def _setup(rng):
    u, v = np.meshgrid(np.linspace(0, 1, R), np.linspace(0, 0.8, C), indexing="ij")
    P = np.stack([u, v, 0.3 * (u ** 2 - v ** 2)], axis=-1) + 0.03 * rng.normal(size=(R, C, 3))
    lay = Layout({"a": 2, "P": (R * C, 3), "l": R, "h": R - 1})
    x = lay.pack({"a": rng.normal(size=2), "P": P.reshape(-1, 3),
                  "l": rng.uniform(0.2, 0.4, R), "h": rng.uniform(0.2, 0.4, R - 1)})
    return lay, x


def _geodesic(rng):
    lay, x = _setup(rng)
    return lay, x, D.GridShape((R, C))


def _parallel_lengths(rng):
    lay, x = _setup(rng)
    return lay, x, D.edge_groups((R, C), "parallel")


CASES = {
    "gridshell.gg.constraints.geodesic_meridians": _geodesic,
    "gridshell.gg.constraints.equal_lengths": _parallel_lengths,
    "gridshell.gg.constraints.equal_diagonals": _geodesic,
}
