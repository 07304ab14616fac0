"""Tests of gridshell.gg.revolution: rebuilding exact surfaces of revolution from GG meshes."""
from __future__ import annotations

import numpy as np
import pytest
from tests.helpers.gg_cases import catenoid, cone, helicoid_grid, revolution_grid, sphere

from gridshell.core.errors import InputError, NoNetError
from gridshell.gg.revolution import embeddable_range, rebuild_revolution

CASES = {
    "catenoid": (catenoid(0.8), np.linspace(-1.2, 1.5, 41)),
    "sphere_zone": (sphere(1.3), np.linspace(0.5, 3.0, 37)),
    "cone": (cone(0.5, 0.4), np.linspace(0.0, 2.0, 25)),
}


@pytest.mark.parametrize("name", CASES)
@pytest.mark.parametrize("total", [1.0, 2 * np.pi / 3])
def test_rebuild_exact_with_true_angle(name, total):
    funcs, s_true = CASES[name]
    phi = np.linspace(0.0, total, 17)
    rev = rebuild_revolution(revolution_grid(funcs, s_true, phi), angle=total)
    r, _, z = funcs
    np.testing.assert_allclose(rev.r, r(s_true), rtol=1e-6)
    np.testing.assert_allclose(rev.z, z(s_true) - z(s_true[0]), rtol=1e-6,
                               atol=1e-6 * np.ptp(z(s_true)))
    np.testing.assert_allclose(rev.phi, phi, atol=1e-12)
    # s is the chord length along the profile: the arc length up to O(h^2 kappa^2)
    np.testing.assert_allclose(rev.s, s_true - s_true[0], rtol=2e-3, atol=1e-4)
    # the discrete surface is edge-for-edge isometric (here: identical) to the input
    V, F = rev.mesh()
    np.testing.assert_allclose(V.reshape(len(s_true), len(phi), 3),
                               revolution_grid(funcs, s_true, phi) - [0, 0, z(s_true[0])],
                               atol=1e-9)
    assert F.shape == ((len(s_true) - 1) * (len(phi) - 1), 4)


@pytest.mark.parametrize("name", CASES)
def test_default_angle_recovers_the_true_angle(name):
    funcs, s_true = CASES[name]
    phi = np.linspace(0.0, 1.7, 23)
    rev = rebuild_revolution(revolution_grid(funcs, s_true, phi))
    assert rev.info["method"] == "turning"
    assert rev.dphi == pytest.approx(phi[1], rel=1e-10)
    np.testing.assert_allclose(rev.r, funcs[0](s_true), rtol=1e-9)


def test_smooth_profile_interpolates_and_differentiates():
    funcs, s_true = CASES["catenoid"]
    rev = rebuild_revolution(revolution_grid(funcs, s_true, np.linspace(0, 1, 9)), angle=1.0)
    np.testing.assert_allclose(rev.r_of_s(rev.s), rev.r, atol=1e-14)
    mid = 0.5 * (rev.s[1:] + rev.s[:-1])
    s_mid = 0.5 * (s_true[1:] + s_true[:-1]) - s_true[0]
    np.testing.assert_allclose(rev.r_of_s(mid), funcs[0](s_mid + s_true[0]), rtol=1e-4)
    np.testing.assert_allclose(rev.dr_of_s(rev.s[2:-2]), funcs[1](s_true[2:-2]), atol=1e-3)
    prof = rev.profile
    assert prof.s_range == (0.0, rev.s[-1])


def test_helicoid_is_isometric_to_a_catenoid():
    c = 0.5
    P = helicoid_grid(41, 31, c=c, v=(0.0, 2.0))
    rev = rebuild_revolution(P, angle=2.0)
    s = rev.s - rev.s[len(rev.s) // 2]
    np.testing.assert_allclose(rev.r, np.sqrt(c * c + s * s), rtol=2e-3)


def test_embeddable_range_and_errors():
    funcs, s_true = CASES["cone"]
    P = revolution_grid(funcs, s_true, np.linspace(0, 1.0, 11))
    lo, hi = embeddable_range(*_lh(P))
    assert hi == pytest.approx(np.pi)
    # the cone's slope sin(beta) at the true dphi = 0.1 must be <= 1: dphi_min below 0.1
    assert lo < 0.1
    with pytest.raises(InputError, match="unembeddable"):
        rebuild_revolution(P, angle=0.5 * lo * 10)
    # a parallel growing by more than twice the meridian edge admits no revolution (a real
    # quad cannot do that - triangle inequality - but averaged edge lengths could)
    with pytest.raises(NoNetError, match="parallels 1 and 2"):
        embeddable_range(np.array([1.0, 1.1, 3.5]), np.array([0.5, 1.0]))
    with pytest.raises(InputError, match=r"\(R, C, 3\)"):
        rebuild_revolution(np.zeros((3, 3)))


def test_default_angle_is_clamped_to_the_embeddable_range():
    # a helicoid's helices turn less than the catenoid's parallels: the estimate is clamped
    P = helicoid_grid(21, 21, c=0.2, u=(-1.0, 1.0), v=(0.0, 2.0))
    rev = rebuild_revolution(P)
    assert rev.info["method"] == "clamped"
    assert rev.dphi == pytest.approx(rev.info["dphi_min"])
    assert rev.info["max_slope"] <= 1.0 + 1e-12


def _lh(P):
    from gridshell.gg.revolution import edge_lengths
    l, h, _ = edge_lengths(P)
    return l, h
