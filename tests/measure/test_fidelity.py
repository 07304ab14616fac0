"""The net's fidelity to its target against closed forms: a net on its flat target (0, all
covered), lifted by h (every joint h / D, covered while h < 2 % of D), covering the left part
of a square (the covered share is that part plus the 2 % band beside it), and the gate."""
from __future__ import annotations

import numpy as np
import pytest

from gridshell.core.errors import ConvergenceError
from gridshell.geometry.grid import grid_quads
from gridshell.measure.fidelity import COVER_TOL, net_fidelity, require_fidelity


def _square(n: int, x1: float = 1.0, z: float = 0.0):
    x, y = np.linspace(0, x1, n), np.linspace(0, 1, n)
    X, Y = np.meshgrid(x, y, indexing="ij")
    V = np.stack([X.ravel(), Y.ravel(), np.full(X.size, z)], 1)
    return V, grid_quads(n, n)


def test_a_net_on_its_flat_target_deviates_nothing_and_covers_all():
    tV, tF = _square(41)
    J, L = _square(9)
    f = net_fidelity(J, L, tV, tF)
    assert f["deviation_max"] == pytest.approx(0.0, abs=1e-12)
    assert f["coverage"] == pytest.approx(100.0, abs=1e-9)
    assert f["diagonal"] == pytest.approx(np.sqrt(2.0), rel=1e-12)


@pytest.mark.parametrize("h_pct", [0.5, 1.5, 3.0])
def test_a_lifted_net_deviates_by_its_lift(h_pct):
    tV, tF = _square(41)
    D = np.sqrt(2.0)
    J, L = _square(9, z=h_pct / 100 * D)
    f = net_fidelity(J, L, tV, tF)
    for k in ("deviation_mean", "deviation_p95", "deviation_max"):
        assert f[k] == pytest.approx(h_pct, rel=1e-9)
    assert f["coverage"] == pytest.approx(100.0 if h_pct < COVER_TOL else 0.0, abs=1e-9)


def test_a_net_on_part_of_the_target_covers_that_part_and_the_band_beside_it():
    tV, tF = _square(201)
    J, L = _square(11, x1=0.5)
    f = net_fidelity(J, L, tV, tF)
    band = COVER_TOL / 100 * np.sqrt(2.0)         # points within 2 % of D beside the net
    assert f["coverage"] == pytest.approx(100 * (0.5 + band), abs=0.3)
    # the far edge, as near as the samples inside its triangles reach it (1/6 of a step)
    assert f["reach_max"] == pytest.approx(50 / np.sqrt(2.0), rel=3e-3)


def test_the_gate_refuses_a_mean_deviation_above_the_limit():
    m = {"fidelity": {"deviation_mean": 1.2, "deviation_p95": 2.0}}
    require_fidelity(m, None)
    require_fidelity(m, 1.5)
    with pytest.raises(ConvergenceError, match="--max-deviation 1 %"):
        require_fidelity(m, 1.0)
