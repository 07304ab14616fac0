"""Net directions of NCP nets (gridshell.ncp.directions, paper 4.2.2, eqs. 4.10-4.11)."""
import numpy as np
import pytest

from gridshell.core.errors import InputError, NoNetError
from gridshell.geometry.bspline import uniform_params
from gridshell.ncp.directions import net_angle, net_directions, row_normal_curvature

from tests.helpers.ncp_cases import pseudosphere, torus


def _normal_curvature_along(d, family):
    """II(e) / I(e) of the net direction from the fundamental forms (Euler, eq. 2.9)."""
    a1, b1, _, _ = d.coefficients(family)       # dxi(e) = a xi_u + b xi_v: e = a S_u + b S_v
    # a = cos b / |S_u| etc.: kn = kI (a |S_u|)^2 + kII (b |S_v|)^2 on a principal parametrization
    return d.kI * (a1 * d.norm_u) ** 2 + d.kII * (b1 * d.norm_v) ** 2


def test_torus_frame_angle_and_euler_relation():
    surf = torus()
    u, v = uniform_params(surf, (9, 7))
    d = net_directions(surf, u, v, mode="phlw")
    # principal curvatures of the torus zone (R = 3, r = 1); the outward normal convention of
    # the fit may flip signs, so compare magnitudes
    th = np.linspace(-0.6, 0.6, 9)
    assert np.allclose(np.abs(d.kI), 1.0, atol=1e-4)
    assert np.allclose(np.abs(d.kII), (np.cos(th) / (3 + np.cos(th)))[:, None], atol=1e-4)
    # constant H along parallels: n_u = H (net angle pi/4)
    assert np.allclose(d.beta, np.pi / 4, atol=1e-3)
    for f in (1, 3):
        assert np.allclose(_normal_curvature_along(d, f), d.n_rows[:, None], rtol=1e-9)
    e1, e2, e3, e4, e5 = (d.e[k] for k in (1, 2, 3, 4, 5))
    dot = lambda a, b: np.einsum("...i,...i->...", a, b)  # noqa: E731
    assert np.allclose(dot(e1, e1), 1) and np.allclose(dot(e3, e3), 1)
    assert np.allclose(dot(e1, e2), 0, atol=1e-6) and np.allclose(dot(e3, e4), 0, atol=1e-6)
    assert np.allclose(dot(e1, e5), dot(e3, e5))            # symmetric to e5
    assert np.allclose(dot(e1, e5), np.cos(d.beta), atol=1e-6)


def test_cnc_and_aa_use_one_normal_curvature():
    surf = torus()
    u, v = uniform_params(surf, (8, 8))
    d = net_directions(surf, u, v, mode="cnc", n=0.5 * np.sign(net_directions(
        surf, u, v, mode="phlw").n_rows[0]))
    assert np.ptp(d.n_rows) == 0 and abs(d.n_rows[0]) == 0.5
    assert np.allclose(_normal_curvature_along(d, 1), d.n_rows[0], rtol=1e-9)
    ps = net_directions(pseudosphere(), *uniform_params(pseudosphere(), (8, 8)), mode="aa")
    assert np.all(ps.n_rows == 0) and ps.valid.all()
    assert np.allclose(_normal_curvature_along(ps, 3), 0, atol=1e-6)


def test_no_real_net_direction_is_named():
    surf = torus()
    u, v = uniform_params(surf, (6, 6))
    with pytest.raises(NoNetError, match="eq. 4.10"):
        net_directions(surf, u, v, mode="cnc", n=50.0)
    d = net_directions(surf, u, v, mode="cnc", n=50.0, require=False)
    assert not d.valid.any()
    beta, valid = net_angle(np.array([1.0, 1.0]), np.array([1.0, 3.0]), np.array([1.0, 2.0]))
    assert not valid[0] and valid[1] and np.isclose(beta[1], np.pi / 4)
    with pytest.raises(InputError):
        row_normal_curvature(np.zeros((2, 2)), np.zeros((2, 2)), "xyz")
