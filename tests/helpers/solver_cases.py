"""Solver problems shared by the linear-solver tests: the GG design's own terms on a dome."""
import numpy as np

from gridshell.gg.design import (GridShape, edge_groups, equal_lengths, fairness_matrix,
                                 geodesic_meridians, init_group_lengths)
from gridshell.solver import Layout, Problem
from gridshell.solver import terms as T


def gg_problem(n=9, seed=0):
    """A GG design problem on a noisy n x n dome grid (the design's own terms)."""
    x, y = np.meshgrid(np.linspace(-1, 1, n), np.linspace(-0.8, 0.8, n), indexing="ij")
    P = np.stack([x, y, -(x ** 2 / 2.0 + y ** 2 / 2.2)], axis=-1).reshape(-1, 3)
    L = 2.0 / (n - 1)
    P0 = P + 0.1 * L * np.random.default_rng(seed).standard_normal(P.shape)
    lay = Layout({"P": (n * n, 3), "l": n, "h": n - 1})
    par, mer = edge_groups((n, n), "parallel"), edge_groups((n, n), "meridian")
    x0 = lay.pack({"P": P0, "l": init_group_lengths(P0, par), "h": init_group_lengths(P0, mer)})
    s2 = 1.0 / L ** 2
    prob = (Problem(lay)
            .add("geodesic", 1.0, geodesic_meridians, GridShape((n, n)))
            .add("parallel_lengths", s2, equal_lengths, par)
            .add("meridian_lengths", s2, equal_lengths, mer)
            .add("closeness", s2, T.closeness, T.Closeness("P", P))
            .add("fairness", 1e-3 * s2, T.linear, T.Linear("P", fairness_matrix((n, n)))))
    return prob, x0
