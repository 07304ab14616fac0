"""Tests of gridshell.measure.metrics on configurations with known values (paper 5.1)."""
from __future__ import annotations

import numpy as np
import pytest
from tests.helpers.gg_cases import catenoid, revolution_grid

from gridshell.core.errors import InputError
from gridshell.gg.clairaut import geodesic_net
from gridshell.gg.mapback import map_to_revolution
from gridshell.gg.revolution import rebuild_revolution
from gridshell.geometry.grid import grid_quads
from gridshell.measure.metrics import (alignability_error, alignability_error_arc, coverage, delta_l,
                               delta_n, deviation, geodesic_turning, smooth_grid_normals,
                               surface_area, target_deviation)
from gridshell.geometry.net import Lamella, Net


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


# ----------------------------------------------------------------------------- GG figures


def _helicoid_mesh(u, v, c=0.5):
    U, W = np.meshgrid(u, v, indexing="ij")
    P = np.stack([U * np.cos(W), U * np.sin(W), c * W], axis=-1)
    return P.reshape(-1, 3), grid_quads(len(u), len(v))


def _helicoid_area(u0, u1, v_len, c=0.5):
    """Closed form: int int sqrt(u^2 + c^2) du dv."""
    F = lambda u: 0.5 * (u * np.sqrt(u * u + c * c) + c * c * np.arcsinh(u / c))  # noqa: E731
    return v_len * (F(u1) - F(u0))


def test_coverage_and_target_deviation_of_a_shrunken_patch():
    # target: helicoid u in [-1, 1]; design: its middle u in [-0.5, 0.5], same v range
    v = np.linspace(0.0, 2.0, 81)
    tV, tF = _helicoid_mesh(np.linspace(-1, 1, 41), v)
    V, F = _helicoid_mesh(np.linspace(-0.5, 0.5, 21), v)
    assert surface_area(tV, tF) == pytest.approx(_helicoid_area(-1, 1, 2.0), rel=1e-3)
    expected = 100 * _helicoid_area(-0.5, 0.5, 2.0) / _helicoid_area(-1, 1, 2.0)
    assert coverage(V, F, tV, tF) == pytest.approx(expected, rel=2e-3)
    assert coverage(tV, tF, tV, tF) == pytest.approx(100.0)
    diag = np.linalg.norm(tV.max(0) - tV.min(0))
    # the one-way deviation sees nothing: the design lies on the target
    assert deviation(V, tV, tF)["max"] < 1e-9
    # the far rulings' ends are 0.5 m from the design's edge (straight rulings through the axis)
    d = target_deviation(V, F, tV, tF)
    assert d["diagonal"] == pytest.approx(diag)
    assert d["max"] == pytest.approx(100 * 0.5 / diag, rel=1e-3)
    # mean over the target's area: distance max(|u| - 0.5, 0) weighted by sqrt(u^2 + c^2)
    u = np.linspace(-1, 1, 20001)
    w = np.sqrt(u * u + 0.25)
    mean = np.sum(np.maximum(np.abs(u) - 0.5, 0) * w) / np.sum(w)
    assert d["mean"] == pytest.approx(100 * mean / diag, rel=2e-2)
    assert target_deviation(tV, tF, tV, tF)["max"] < 1e-9


def _catenoid_geodesics(n_phi=6):
    """Exact geodesics of the catenoid r = cosh z (arc length s = sinh z), traced with
    Clairaut's relation on the closed-form profile and mapped with the closed-form surface."""
    from tests.helpers.gg_cases import profile

    from gridshell.gg.clairaut import trace_geodesic

    r, _, z = catenoid(1.0)
    axes = []
    for phi0 in np.linspace(0.3, 1.7, n_phi):
        for xi in (0.7, -0.7, 1.2):
            s, phi, _ = trace_geodesic(profile(catenoid(1.0), -1.0, 1.0), 0.0, phi0, xi)
            ok = (phi > 0) & (phi < 2)
            axes.append(np.stack([r(s[ok]) * np.cos(phi[ok]), r(s[ok]) * np.sin(phi[ok]),
                                  z(s[ok])], 1))
    return axes


def test_smooth_grid_normals_match_the_catenoid():
    n = 13
    P = revolution_grid(catenoid(1.0), np.linspace(-1.0, 1.0, n), np.linspace(0.0, 2.0, n))
    V, F = P.reshape(-1, 3), grid_quads(n, n)
    rng = np.random.default_rng(1)
    s, phi = rng.uniform(-1, 1, 200), rng.uniform(0, 2, 200)
    r, _, z = catenoid(1.0)
    X = np.stack([r(s) * np.cos(phi), r(s) * np.sin(phi), z(s)], 1)
    exact = np.stack([np.cos(phi), np.sin(phi), -s], 1) / np.sqrt(1 + s * s)[:, None]
    N = smooth_grid_normals(X, V, F)
    err = np.degrees(np.arccos(np.minimum(np.abs(np.einsum("ij,ij->i", N, exact)), 1.0)))
    assert err.max() < 0.1                       # degrees, on a 13 x 13 grid
    assert smooth_grid_normals(X, V, np.concatenate([F[:, :3], F[:, [0, 2, 3]]])) is None


def test_geodesic_turning_of_exact_geodesics_with_smooth_normals():
    # exact geodesics on a coarse catenoid grid: the interpolated mesh normals (first order)
    # read about 1 %, the normals of the smooth surface through the grid < 0.2 %
    axes = _catenoid_geodesics()
    n = 13
    P = revolution_grid(catenoid(1.0), np.linspace(-1.0, 1.0, n), np.linspace(0.0, 2.0, n))
    V, F = P.reshape(-1, 3), grid_quads(n, n)
    smooth = geodesic_turning(axes, V, F)
    assert smooth["normals"] == "smooth" and smooth["ratio"] < 2e-3
    mesh = geodesic_turning(axes, V, F, normals="mesh")
    assert mesh["normals"] == "mesh" and mesh["ratio"] > 5 * smooth["ratio"]
    # the other extreme: a helix u = 0.7 of the helicoid (u cos v, u sin v, c v) has the radial
    # principal normal (-cos v, -sin v, 0), tangent to the surface (normal ~ (c sin v,
    # -c cos v, u)): it bends in the surface only, ratio 1
    Vh, Fh = _helicoid_mesh(np.linspace(-1, 1, 13), np.linspace(0, 2, 13))
    t = np.linspace(0.05, 1.95, 300)
    helix = np.stack([0.7 * np.cos(t), 0.7 * np.sin(t), 0.5 * t], 1)
    assert geodesic_turning([helix], Vh, Fh)["ratio"] == pytest.approx(1.0, abs=2e-3)
    with pytest.raises(InputError, match="structured quad grid"):
        geodesic_turning(axes, V, np.concatenate([F[:, :3], F[:, [0, 2, 3]]]), normals="smooth")
    with pytest.raises(InputError, match="normals must be"):
        geodesic_turning(axes, V, F, normals="exact")


def _kn_one_by_one(net, normals, jidx):
    """The straightforward kn at the joints: normal_geodesic_curvature of each whole axis."""
    from gridshell.measure.metrics import kn_at_joints_per_axis

    return kn_at_joints_per_axis(net, normals, jidx)


def test_kn_at_joints_equals_the_whole_axes_one_by_one():
    """crossing_normal_curvature's kn at the joint samples of all lamellae at once gives, bit
    for bit, what normal_geodesic_curvature of each whole axis gives there (wavy axes, normals
    of any length, joints at the ends and inside, short lamellae skipped); a polyline it
    refuses still raises its error."""
    from gridshell.measure.metrics import _kn_at_joints, crossing_normal_curvature

    rng = np.random.default_rng(2)
    lams, normals, jidx = [], [], []
    for i, k in enumerate([40, 2, 3, 17, 120, 9]):
        s = np.linspace(0.0, 2.0, k)
        P = np.c_[s, 0.2 * np.sin(3 * s + i) + 1e-3 * rng.standard_normal(k),
                  0.3 * s * s + 0.1 * i]
        N = np.c_[0.2 * rng.standard_normal((k, 2)), rng.uniform(0.5, 3.0, k)]
        vi = np.unique(np.r_[0, k - 1, rng.integers(0, k, 4)])
        joints = (np.arange(len(vi)) + 3 * i) % 12
        lams.append(Lamella(id=i, family=1 if i % 2 else 3, joints=joints,
                            joint_s=np.zeros(len(vi)), axis=P))
        normals.append(N)
        jidx.append(vi)
    net = Net(joints=rng.standard_normal((12, 3)), loops=np.zeros((0, 4), np.int64),
              lamellae=lams)
    ref = _kn_one_by_one(net, normals, jidx)
    got = _kn_at_joints(net, normals, jidx)
    assert got == ref and len(ref) >= 6
    res = crossing_normal_curvature(net, normals, jidx, np.full(12, 0.1))
    assert len(res["joints"]) == sum(len(d) == 2 for d in ref.values())
    bad = [N.copy() for N in normals]
    bad[4][7] = 0.0                                  # a zero normal: its own error
    assert _kn_at_joints(net, bad, jidx) is None
    with pytest.raises(InputError, match="zero vectors"):
        crossing_normal_curvature(net, bad, jidx, np.full(12, 0.1))
    lams[0].axis[5] = lams[0].axis[4]               # a repeated point: its own error
    assert _kn_at_joints(net, normals, jidx) is None
    with pytest.raises(InputError, match="zero-length"):
        crossing_normal_curvature(net, normals, jidx, np.full(12, 0.1))
