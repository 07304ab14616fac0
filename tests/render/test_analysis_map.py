"""render.analysis_map: cell corners of a sample grid and the PNG of the maps."""
from __future__ import annotations

import numpy as np

from gridshell.render.analysis_map import analysis_png, cell_corners, plan_coordinates


def test_cell_corners_of_a_regular_grid_are_the_midpoints():
    x, y = np.meshgrid(np.arange(4.0), 2.0 * np.arange(3.0), indexing="ij")
    C = cell_corners(np.stack([x, y], -1))
    assert C.shape == (5, 4, 2)
    assert np.allclose(C[:, 0, 0], np.arange(5) - 0.5)
    assert np.allclose(C[0, :, 1], 2.0 * (np.arange(4) - 0.5))


def test_plan_coordinates_keep_distances_of_a_planar_grid():
    rng = np.random.default_rng(1)
    P = np.column_stack([rng.random(30) * 3, rng.random(30), np.zeros(30)])
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    XY = plan_coordinates(P @ Q.T + 5.0)
    d = lambda A: np.linalg.norm(A[:, None] - A[None], axis=-1)
    assert np.allclose(d(XY), d(P[:, :2]))


def test_analysis_png_is_a_png_of_the_maps():
    n = 12
    u = np.linspace(-1, 1, n)
    X, Y = np.meshgrid(u, u, indexing="ij")
    S = np.stack([X, Y, X * X - Y * Y], -1)
    sign = -np.ones((n, n))
    png = analysis_png(S, sign, np.ones((n, n)), np.zeros((n, n), bool), np.ones((n, n), bool),
                       {"phlw": (1, 8, 2, 9), "aa": None}, title="t")
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 10000
