"""Collapse curve (gridshell.ncp.collapse, paper 4.2.3, eq. 4.14, Fig. 15)."""
import numpy as np
import pytest

from gridshell.core.errors import InputError
from gridshell.ncp.collapse import (closest_on_polyline, collapse_curve, fit_circle,
                                    integrate_collapse, line_deviation)

from tests.helpers.ncp_cases import pseudosphere, torus


def _circumcurvature(P):
    a, b = P[:-2] - P[1:-1], P[2:] - P[1:-1]
    cross = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    return -2 * cross / (np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1)
                         * np.linalg.norm(a - b, axis=1))


def test_forward_integration_reproduces_the_curvatures():
    rng = np.random.default_rng(1)
    ell = rng.uniform(0.01, 0.03, 200)
    n = np.sin(np.linspace(0, 3, 201)) * 2.0
    P, N = integrate_collapse(ell, n)
    assert np.allclose(np.linalg.norm(np.diff(P, axis=0), axis=1), ell)
    # the circle through C_i-1, C_i, C_i+1 has curvature n_i (Fig. 15), signed towards n~
    assert np.allclose(_circumcurvature(P), n[1:-1], atol=1e-9)
    assert np.allclose(np.linalg.norm(N, axis=1), 1)
    # constant curvature: a circle of radius 1 / n; zero: a line
    P, _ = integrate_collapse(np.full(50, 0.02), np.full(51, 0.5))
    assert np.isclose(fit_circle(P)[1], 2.0, rtol=1e-12)
    P, N = integrate_collapse(np.full(50, 0.02), np.zeros(51))
    assert line_deviation(P) < 1e-12 and np.allclose(N, [0, 1])
    with pytest.raises(InputError):
        integrate_collapse(ell, n[:-1])


def test_closest_on_polyline_projects_onto_segments():
    Q = np.array([[0.0, 0], [1, 0], [2, 1]])
    X, _, t = closest_on_polyline(np.array([[0.5, 0.3], [2.0, 1.5]]), Q)
    assert np.allclose(X[0], [0.5, 0]) and np.isclose(t[0], 0.5)
    assert np.isclose(t[1], 2.0)


def test_cnc_torus_collapses_into_a_circle_of_radius_one_over_n():
    """Acceptance: CNC collapse radius within 1 % of 1/n at the paper's 1200 x 1200."""
    c = collapse_curve(torus(), mode="cnc", n=None, samples=(1200, 1200))
    n = c.n_rows[0]
    assert np.ptp(c.n_rows) == 0 and c.shape == "circle"
    assert np.isclose(c.radius, 1 / abs(n))
    assert c.fit["radius_error"] < 0.01
    assert abs(fit_circle(c.points)[1] * abs(n) - 1) < 0.01


def test_phlw_torus_length_is_the_meridian_over_cos_beta():
    # n = H on a surface of revolution: beta = pi/4, the net curves are sqrt(2) x the meridian
    c = collapse_curve(torus(), mode="phlw", samples=(400, 300))
    assert c.shape == "curve"
    assert np.isclose(c.s[-1], 1.2 * np.sqrt(2), rtol=1e-4)


def test_aa_pseudosphere_collapses_into_a_line_of_the_asymptotic_length():
    """The line itself is a given (``n = 0`` integrates to a line; the aligned joints of the
    simulation are checked in test_ncp_pipeline.py); its length is not: on the pseudosphere
    (K = -1) the parallel s has kappa_II = sinh s, the meridian kappa_I = -1 / sinh s and
    speed tanh s, so an asymptotic line (II = 0) has ds_curve = tanh s sqrt(1 + 1 / sinh^2 s)
    ds = ds: it is exactly as long as its s-range, 1.0 for s in [0.5, 1.5]."""
    c = collapse_curve(pseudosphere(), mode="aa", samples=(300, 300))
    assert c.shape == "line" and c.radius is None
    assert np.allclose(c.n_rows, 0)
    assert np.isclose(c.s[-1], 1.0, rtol=1e-4)            # the B-spline fit of the patch
    P, N = c.at_u(np.array([0.25, 0.75]))
    assert np.allclose(N, [0, 1]) and P[0, 0] < P[1, 0]
