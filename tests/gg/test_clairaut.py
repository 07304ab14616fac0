"""Tests of gridshell.gg.clairaut against closed-form geodesics of surfaces of revolution."""
from __future__ import annotations

import numpy as np
import pytest
from tests.helpers.gg_cases import catenoid, cone, cylinder, profile, revolution_grid
from scipy.integrate import quad

from gridshell.core.errors import InputError
from gridshell.gg.clairaut import clairaut_constant_for_angle, geodesic_net, trace_geodesic
from gridshell.gg.revolution import rebuild_revolution


def test_cylinder_geodesics_are_helices():
    R, xi = 0.7, 0.6
    s, phi, sigma = trace_geodesic(profile(cylinder(R), 0.0, 2.0), 0.0, 0.3, xi)
    np.testing.assert_allclose(s, sigma * np.sin(xi), atol=1e-9)
    np.testing.assert_allclose(phi, 0.3 + s / np.tan(xi) / R, atol=1e-9)
    assert s[-1] == pytest.approx(2.0, abs=1e-12)  # stopped on the boundary parallel


def test_meridian_geodesic():
    s, phi, sigma = trace_geodesic(profile(catenoid(1.0), -1.0, 1.0), -1.0, 0.2, np.pi / 2)
    np.testing.assert_allclose(phi, 0.2, atol=1e-12)
    np.testing.assert_allclose(s, -1.0 + sigma, atol=1e-10)
    assert s[-1] == pytest.approx(1.0)


def test_cone_geodesics_are_straight_in_the_development():
    r0, beta = 0.5, 0.4
    sb = np.sin(beta)
    s0, phi0, xi0 = 1.5, 0.1, -0.35  # heading towards the apex, past a turning point
    s, phi, sigma, ds, dphi = trace_geodesic(profile(cone(r0, beta), 0.0, 2.0), s0, phi0, xi0,
                                             derivatives=True)
    rho0 = r0 / sb  # apex distance of s = 0
    # developed cone: polar (rho, theta) = (rho0 + s, phi sin(beta)); geodesics are lines
    X0 = (rho0 + s0) * np.array([np.cos(phi0 * sb), np.sin(phi0 * sb)])
    e_rho = X0 / np.linalg.norm(X0)
    e_th = np.array([-e_rho[1], e_rho[0]])
    X = X0 + sigma[:, None] * (np.sin(xi0) * e_rho + np.cos(xi0) * e_th)
    rho = np.linalg.norm(X, axis=1)
    theta = np.unwrap(np.arctan2(X[:, 1], X[:, 0]))
    np.testing.assert_allclose(s, rho - rho0, atol=1e-8)
    np.testing.assert_allclose(phi, theta / sb, atol=1e-8)
    assert np.argmin(s) not in (0, len(s) - 1)  # the turning point was passed
    r = r0 + s * sb
    c = r ** 2 * dphi
    np.testing.assert_allclose(c, c[0], rtol=1e-8)
    np.testing.assert_allclose(ds ** 2 + (r * dphi) ** 2, 1.0, atol=1e-8)


def test_catenoid_turning_point_closed_form():
    a, c = 1.0, 1.3
    s_turn = np.sqrt(c * c - a * a)
    s0 = 2.0
    r_f, _, _ = catenoid(a)
    xi0 = -np.arccos(c / r_f(s0))  # inwards, towards the neck
    s, phi, sigma, ds, dphi = trace_geodesic(profile(catenoid(a), -2.0, 2.0), s0, 0.0, xi0,
                                             derivatives=True, step=0.01)
    k = int(np.argmin(s))
    assert s[k] == pytest.approx(s_turn, abs=1e-4)  # reached...
    assert s[-1] == pytest.approx(2.0) and k < len(s) - 10  # ...and passed, back to the rim

    def F(x):  # int_{s*}^{x} c ds / (r sqrt(r^2 - c^2)) with x = s* cosh t
        T = np.arccosh(max(x / s_turn, 1.0))
        return quad(lambda t: c / np.sqrt(a * a + (s_turn * np.cosh(t)) ** 2), 0.0, T,
                    epsabs=1e-13, epsrel=1e-13)[0]

    idx = np.arange(0, len(s), 7)
    ref = np.array([F(s0) - F(s[i]) if i <= k else F(s0) + F(s[i]) for i in idx])
    np.testing.assert_allclose(phi[idx], ref, atol=1e-7)
    r = r_f(s)
    np.testing.assert_allclose(r * r * dphi, c, rtol=1e-8)  # Clairaut: r cos(xi) = c


def test_clairaut_constant_for_angle():
    prof = profile(catenoid(1.0), -1.0, 1.0)
    c, xi = clairaut_constant_for_angle(prof, np.radians(60.0), 0.5)
    assert xi == pytest.approx(np.radians(60.0))
    assert c == pytest.approx(np.sqrt(1.25) * 0.5)
    with pytest.raises(InputError, match="between 0 and 180"):
        clairaut_constant_for_angle(prof, 0.0, 0.5)


def _catenoid_rev(R=31, C=25, total=2.0):
    s = np.linspace(-1.0, 1.0, R)
    return rebuild_revolution(revolution_grid(catenoid(1.0), s, np.linspace(0, total, C)))


def test_geodesic_net_families_are_symmetric_and_cover_the_domain():
    rev = _catenoid_rev()
    net = geodesic_net(rev, n_lamellae=6, crossing_angle=80.0)
    # the reference parallel is crossed at the same phi by C1_k and its mirror C3
    step = rev.total_angle / 5
    on_ref = np.abs(net.offsets1 / step - np.round(net.offsets1 / step)) < 1e-9
    assert on_ref.all() and np.sum((net.offsets1 >= 0) & (net.offsets1 <= rev.total_angle
                                                          + 1e-12)) == 6
    assert len(net.curves1) > 6  # extra curves reach the corners
    for cv in net.curves1:
        assert np.all(np.diff(cv[:, 1]) > 0)
        # within the domain up to its relative margin (clairaut.BOUNDARY_MARGIN = 1e-9)
        eps = 1.01e-9 * rev.total_angle
        assert np.all((cv[:, 1] >= -eps) & (cv[:, 1] <= rev.total_angle + eps))
    for cv in net.curves3:
        assert np.all(np.diff(cv[:, 1]) < 0)
    # crossing angle on the reference parallel: 2 * (90 deg - xi)
    assert np.degrees(np.pi - 2 * net.xi_star) == pytest.approx(80.0)
    # mirror symmetry: C3 with offset o is C1 with offset o reflected about phi = o
    k1 = int(np.argmin(np.abs(net.offsets1 - step)))
    k3 = int(np.argmin(np.abs(net.offsets3 - step)))
    a, b = net.curves1[k1], net.curves3[k3]
    assert np.all(np.diff(a[:, 0]) > 0) and np.all(np.diff(b[:, 0]) > 0)  # no turning point
    inside = (a[:, 0] > b[:, 0].min()) & (a[:, 0] < b[:, 0].max())
    assert inside.sum() > 50
    phi_b = np.interp(a[inside, 0], b[:, 0], b[:, 1])
    np.testing.assert_allclose(phi_b - step, -(a[inside, 1] - step), atol=1e-5)


def test_geodesic_net_spacing_and_offsets():
    rev = _catenoid_rev()
    r_star = float(rev.r_of_s(rev.s[-1] / 2))
    net = geodesic_net(rev, spacing=0.25, crossing_angle=90.0)
    d = np.diff(net.offsets1)
    np.testing.assert_allclose(d * r_star, 0.25, rtol=1e-12)
    net2 = geodesic_net(rev, crossing_angle=90.0, offsets1=[0.2, 0.5, 1.4],
                        offsets3=[0.1, 1.0])
    assert net2.offsets1.tolist() == [0.2, 0.5, 1.4] and len(net2.curves3) == 2
    with pytest.raises(InputError, match="either n_lamellae or spacing"):
        geodesic_net(rev, n_lamellae=4, spacing=0.2)
    with pytest.raises(InputError, match="wider"):
        geodesic_net(rev, spacing=100.0)
