"""Tests of gridshell.metrics on configurations with known values (paper 5.1)."""
from __future__ import annotations

import numpy as np
import pytest
from gg_cases import catenoid, revolution_grid

from gridshell.errors import InputError
from gridshell.gg.clairaut import geodesic_net
from gridshell.gg.mapback import map_to_revolution
from gridshell.gg.revolution import rebuild_revolution
from gridshell.grid import grid_quads
from gridshell.metrics import (alignability_error, alignability_error_arc, delta_l, delta_n,
                               deviation, geodesic_turning)
from gridshell.net import Lamella, Net


@pytest.mark.parametrize("seed", range(5))
def test_parallelogram_is_alignable(seed):
    rng = np.random.default_rng(seed)
    A, u, v = rng.normal(size=(3, 3))
    V = np.array([A, A + u, A + u + v, A + v])
    assert alignability_error(V, [[0, 1, 2, 3]])[0] == pytest.approx(0.0, abs=1e-14)


def test_kite_has_the_closed_form_error():
    # symmetric about BD: |AB| = |CB| = sqrt(2), |AD| = |CD| = sqrt(5)
    V = np.array([[-1.0, 0, 0], [0, 1, 0], [1, 0, 0], [0, -2, 0]])
    a, b = np.sqrt(2), np.sqrt(5)
    expected = 4 * abs(2 * a - 2 * b) / (2 * a + 2 * b)
    assert alignability_error(V, [[0, 1, 2, 3]])[0] == pytest.approx(expected, rel=1e-14)
    # a kite symmetric about AC is alignable (l_AB + l_BC = l_AD + l_DC)
    V2 = np.array([[0, -1.0, 0], [1, 0, 0], [0, 2, 0], [-1, 0, 0]])
    assert alignability_error(V2, [[0, 1, 2, 3]])[0] == pytest.approx(0.0, abs=1e-15)
    with pytest.raises(InputError, match=r"\(m, 4\)"):
        alignability_error(V, [[0, 1, 2]])


def test_arc_variant_uses_lamella_lengths():
    V = np.array([[-1.0, 0, 0], [0, 1, 0], [1, 0, 0], [0, -2, 0]])
    lams = [Lamella(0, 1, [0, 1], [0.0, 2.0], V[[0, 1]]),   # A -> B, arc 2
            Lamella(1, 1, [3, 2], [0.0, 1.0], V[[3, 2]]),   # D -> C, arc 1
            Lamella(2, 3, [1, 2], [0.0, 1.0], V[[1, 2]]),   # B -> C, arc 1
            Lamella(3, 3, [0, 3], [0.0, 2.0], V[[0, 3]])]   # A -> D, arc 2
    net = Net(V, [[0, 1, 2, 3]], lams)
    assert alignability_error_arc(net)[0] == pytest.approx(0.0)
    lams[0] = Lamella(0, 1, [0, 1], [0.0, 3.0], V[[0, 1]])
    assert alignability_error_arc(Net(V, [[0, 1, 2, 3]], lams))[0] == pytest.approx(4 / 7)
    with pytest.raises(InputError, match="not consecutive"):
        alignability_error_arc(Net(V, [[0, 2, 1, 3]], lams))


def test_geodesic_net_on_a_surface_of_revolution_has_no_alignability_error():
    s = np.linspace(-1.0, 1.0, 21)
    rev = rebuild_revolution(revolution_grid(catenoid(1.0), s, np.linspace(0, 2.0, 21)))
    net, _ = map_to_revolution(geodesic_net(rev, n_lamellae=8, crossing_angle=90.0), rev)
    assert np.mean(alignability_error(net.joints, net.loops)) < 1e-3
    assert np.max(alignability_error_arc(net)) < 1e-6


def test_delta_l_and_delta_n():
    rng = np.random.default_rng(0)
    V = rng.normal(size=(6, 3))
    E = np.array([[0, 1], [1, 2], [2, 3], [3, 4], [4, 5], [0, 5], [1, 4]])
    np.testing.assert_allclose(delta_l(V, 1.1 * V, E), 0.1, rtol=1e-12)
    r = rng.normal(size=(6, 3))
    r /= np.linalg.norm(r, axis=1)[:, None]
    np.testing.assert_allclose(delta_n(V, r, V, r, E), 0.0, atol=1e-14)
    # rigid motion: edges and axes move together, nothing changes
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    np.testing.assert_allclose(delta_n(V, r, V @ Q.T + 1.0, r @ Q.T, E), 0.0, atol=1e-12)
    # a star: centre 0 lifted by 1 along z over three neighbours in the plane -> den = 1
    S = np.array([[0, 0, 1.0], [1, 0, 0], [-0.5, 0.8, 0], [-0.5, -0.8, 0]])
    z = np.tile([0, 0, 1.0], (4, 1))
    Sa = S.copy()
    Sa[0, 2] = 1.5
    star = np.array([[0, 1], [0, 2], [0, 3]])
    assert delta_n(S, z, Sa, z, star)[0] == pytest.approx(0.5)


def test_deviation_in_percent_of_the_diagonal():
    i, j = np.meshgrid(np.arange(5.0), np.arange(4.0), indexing="ij")
    V = np.stack([j.ravel(), i.ravel(), np.zeros(20)], axis=1)
    F = grid_quads(5, 4)
    diag = np.hypot(3.0, 4.0)
    P = np.array([[1.0, 1.0, 0.05], [2.0, 2.5, -0.1]])
    d = deviation(P, V, F)
    assert d["max"] == pytest.approx(0.1 / diag * 100)
    assert d["mean"] == pytest.approx(0.075 / diag * 100)


def test_geodesic_turning_of_parallels_and_meridians_on_a_sphere():
    rho, theta = 1.0, 1.0
    # sphere zone as a fine quad mesh
    th = np.linspace(0.4, 2.4, 81)
    ph = np.linspace(0, 2 * np.pi, 161)[:-1]
    T, Ph = np.meshgrid(th, ph, indexing="ij")
    V = rho * np.stack([np.sin(T) * np.cos(Ph), np.sin(T) * np.sin(Ph), np.cos(T)], -1)
    V = V.reshape(-1, 3)
    G = np.arange(len(V)).reshape(len(th), len(ph))
    F = np.concatenate([grid_quads(len(th), len(ph)).reshape(len(th) - 1, len(ph) - 1, 4)
                        .reshape(-1, 4),
                        np.stack([G[:-1, -1], G[:-1, 0], G[1:, 0], G[1:, -1]], 1)])
    F = F[:, ::-1]  # outward normals do not matter: |kg| and |kappa| only
    t = np.linspace(0.3, 2.0, 200)
    parallel = rho * np.stack([np.sin(theta) * np.cos(t), np.sin(theta) * np.sin(t),
                               np.full_like(t, np.cos(theta))], 1)
    meridian = rho * np.stack([np.sin(t + 0.2) * np.cos(0.3), np.sin(t + 0.2) * np.sin(0.3),
                               np.cos(t + 0.2)], 1)
    assert geodesic_turning([parallel], V, F)["ratio"] == pytest.approx(np.cos(theta), abs=2e-3)
    assert geodesic_turning([meridian], V, F)["ratio"] < 2e-3
