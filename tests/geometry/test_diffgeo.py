"""Fundamental forms, curvatures (eqs. 4.2-4.6) and polyline curvatures vs closed forms."""
from __future__ import annotations

import numpy as np
import pytest

from gridshell.geometry.bspline import fit_grid
from gridshell.geometry.diffgeo import (curvatures, fundamental_forms, normal_geodesic_curvature,
                               polyline_curvature, principal_curvatures_along_params,
                               principal_directions, surface_curvature)
from gridshell.core.errors import InputError

#: Interior sample parameters (away from the patch boundary), paired.
_G = np.linspace(0.1, 0.9, 13)
U_IN, V_IN = (a.ravel() for a in np.meshgrid(_G, _G, indexing="ij"))


@pytest.fixture(scope="module")
def sphere_fit():
    R = 2.0
    th, ph = np.meshgrid(np.linspace(0.4, 1.2, 40), np.linspace(0.0, 1.2, 40), indexing="ij")
    P = R * np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], axis=-1)
    surf, rms = fit_grid(P, 9, 9, 4, 4)
    return R, surf, rms


@pytest.fixture(scope="module")
def torus_fit():
    R, r = 3.0, 1.0
    # v spans the outer (elliptic, cos v > 0) and inner (hyperbolic, cos v < 0) sides.
    a, b = np.meshgrid(np.linspace(0.0, 1.5, 40), np.linspace(0.6, 2.6, 40), indexing="ij")
    P = np.stack([(R + r * np.cos(b)) * np.cos(a), (R + r * np.cos(b)) * np.sin(a),
                  r * np.sin(b)], axis=-1)
    surf, rms = fit_grid(P, 9, 9, 4, 4)
    return R, r, surf, rms


# ----------------------------------------------------------------------------- closed forms


def skew_paraboloid_derivatives(a: float, b: float, c: float):
    """Derivatives at the origin of S(u,v) = (x, y, (a x^2 + b y^2)/2), x = u + c v, y = v."""
    k = 1
    Su = np.array([[1.0, 0, 0]] * k)
    Sv = np.array([[c, 1.0, 0]] * k)
    Suu = np.array([[0, 0, a]] * k)
    Suv = np.array([[0, 0, a * c]] * k)
    Svv = np.array([[0, 0, a * c * c + b]] * k)
    return Su, Sv, Suu, Suv, Svv


def test_forms_and_curvatures_of_skew_paraboloid():
    """F != 0 here, so a wrong sign of the NE term in eq. 4.6 would show."""
    a, b, c = 0.7, -1.9, 0.5
    Su, Sv, Suu, Suv, Svv = skew_paraboloid_derivatives(a, b, c)
    ff = fundamental_forms(Su, Sv, Suu, Suv, Svv)
    np.testing.assert_allclose([ff["E"][0], ff["F"][0], ff["G"][0]], [1, c, 1 + c * c])
    np.testing.assert_allclose(ff["delta"], 1.0)
    np.testing.assert_allclose(ff["n"], [[0, 0, 1]])
    np.testing.assert_allclose(ff["u"], [[0, 0, 1]])
    np.testing.assert_allclose([ff["L"][0], ff["M"][0], ff["N"][0]], [a, a * c, a * c * c + b])
    K, H, k1, k2 = curvatures(ff["E"], ff["F"], ff["G"], ff["L"], ff["M"], ff["N"])
    np.testing.assert_allclose([K[0], H[0], k1[0], k2[0]], [a * b, (a + b) / 2, b, a])
    k1, k2, d1, d2 = principal_directions(Su, Sv, ff["E"], ff["F"], ff["G"], ff["L"], ff["M"],
                                          ff["N"])
    np.testing.assert_allclose([k1[0], k2[0]], [b, a])
    np.testing.assert_allclose(np.abs(d1), [[0, 1, 0]], atol=1e-14)   # k1 = b along y
    np.testing.assert_allclose(np.abs(d2), [[1, 0, 0]], atol=1e-14)
    np.testing.assert_allclose(np.cross(d1, d2), ff["n"], atol=1e-14)  # right-handed frame


def test_umbilic_directions_are_an_orthonormal_frame():
    Su, Sv, Suu, Suv, Svv = skew_paraboloid_derivatives(1.3, 1.3, 0.4)
    ff = fundamental_forms(Su, Sv, Suu, Suv, Svv)
    k1, k2, d1, d2 = principal_directions(Su, Sv, *(ff[k] for k in "EFGLMN"))
    np.testing.assert_allclose([k1[0], k2[0]], [1.3, 1.3])
    np.testing.assert_allclose(d1, [[1, 0, 0]])
    np.testing.assert_allclose(d2, [[0, 1, 0]])


def test_singular_parameterization_gives_nan_not_error():
    z = np.zeros((1, 3))
    ff = fundamental_forms(np.array([[1.0, 0, 0]]), np.array([[2.0, 0, 0]]), z, z, z)
    assert ff["delta"][0] == 0 and np.all(np.isnan(ff["n"]))


def test_shape_errors():
    with pytest.raises(InputError, match="same shape"):
        fundamental_forms(np.ones((2, 3)), np.ones((3, 3)), np.ones((2, 3)), np.ones((2, 3)),
                          np.ones((2, 3)))


# ----------------------------------------------------------------------------- fitted surfaces


def test_fitted_sphere_patch_curvature(sphere_fit):
    R, surf, rms = sphere_fit
    assert rms < 1e-5 * R
    geo = surface_curvature(surf, U_IN, V_IN)
    assert np.abs(geo["K"] * R * R - 1).max() < 5e-3
    assert np.abs(np.abs(geo["H"]) * R - 1).max() < 5e-3
    # Normal Su x Sv points outward here, so the sphere bends away from it: k = -1/R.
    outward = np.einsum("ij,ij->i", geo["n"], geo["S"] / R)
    assert outward.min() > 0.999
    np.testing.assert_allclose(geo["k1"] * R, -1, atol=5e-3)
    np.testing.assert_allclose(geo["k2"] * R, -1, atol=5e-3)
    # On a sphere every parameter direction is principal: kI = kII = -1/R.
    np.testing.assert_allclose(np.c_[geo["kI"], geo["kII"]] * R, -1, atol=5e-3)


def test_fitted_torus_principal_curvatures_and_directions(torus_fit):
    R, r, surf, _ = torus_fit
    geo = surface_curvature(surf, U_IN, V_IN)
    S = geo["S"]
    rho = np.hypot(S[:, 0], S[:, 1])
    v = np.arctan2(S[:, 2], rho - R)                     # tube angle of the fitted point
    outward = np.c_[np.cos(v) * S[:, 0] / rho, np.cos(v) * S[:, 1] / rho, np.sin(v)]
    sign = np.sign(np.einsum("ij,ij->i", outward, geo["n"]))
    assert np.all(sign == sign[0])
    # Closed form w.r.t. the outward normal: tube -1/r, parallel -cos v / (R + r cos v).
    k_tube = -np.ones_like(v) / r
    k_par = -np.cos(v) / (R + r * np.cos(v))
    exact = np.sort(np.c_[k_tube, k_par], axis=1)
    got = np.sort(sign[0] * np.c_[geo["k1"], geo["k2"]], axis=1)
    rel = np.abs(got - exact) / np.maximum(np.abs(exact), 0.05)
    assert rel.max() < 5e-3, rel.max()
    assert (k_par > 0).any() and (k_par < 0).any()         # both hyperbolic and elliptic parts
    # u and v lines of a torus are curvature lines: the tube direction is S_v's.
    is_tube_k1 = np.isclose(sign[0] * geo["k1"], -1 / r, rtol=1e-2)
    d_tube = np.where(is_tube_k1[:, None], geo["d1"], geo["d2"])
    sv = geo["Sv"] / np.linalg.norm(geo["Sv"], axis=1)[:, None]
    assert np.abs(np.einsum("ij,ij->i", d_tube, sv)).min() > 0.999
    # ... so the normal curvatures along the parameters are the principal ones (paper e5, e6).
    np.testing.assert_allclose(sign[0] * geo["kII"], k_tube, rtol=5e-3)
    np.testing.assert_allclose(sign[0] * geo["kI"], k_par, atol=5e-3 * 0.25)


def test_params_curvatures_are_L_over_E():
    kI, kII = principal_curvatures_along_params(np.array([4.0]), np.array([9.0]),
                                                np.array([2.0]), np.array([-3.0]))
    np.testing.assert_allclose([kI[0], kII[0]], [0.5, -1 / 3])


# ----------------------------------------------------------------------------- polylines


def test_polyline_curvature_of_circle_is_exact():
    """Points on a circle lie on their circumscribed circle: 1/R exactly, towards the centre."""
    R = 0.75
    t = np.sort(np.random.default_rng(0).uniform(0, 2 * np.pi, 50))   # non-uniform sampling
    P = np.c_[R * np.cos(t), R * np.sin(t), np.full_like(t, 2.0)]
    kvec, kappa = polyline_curvature(P, closed=True)
    np.testing.assert_allclose(kappa, 1 / R, rtol=1e-10)
    np.testing.assert_allclose(kvec, -(P - [0, 0, 2]) / R ** 2, atol=1e-9)
    kvec, kappa = polyline_curvature(P, closed=False)
    assert np.isnan(kappa[[0, -1]]).all() and np.isfinite(kappa[1:-1]).all()


def test_polyline_curvature_straight_and_errors():
    P = np.c_[np.linspace(0, 1, 5), np.zeros(5), np.zeros(5)]
    _, kappa = polyline_curvature(P)
    np.testing.assert_array_equal(kappa[1:-1], 0)
    with pytest.raises(InputError, match="zero-length"):
        polyline_curvature(np.vstack([P, P[-1:]]))
    with pytest.raises(InputError, match="do not repeat the first point"):
        polyline_curvature(np.vstack([P[:3] + [[0, 1, 0]], P[:1] + [0, 1, 0]]), closed=True)


def test_helix_on_cylinder_normal_and_geodesic_curvature():
    a, b = 1.5, 0.4                                    # radius, pitch / (2 pi)
    s = np.linspace(0, 4 * np.pi, 2001)
    P = np.c_[a * np.cos(s), a * np.sin(s), b * s]
    n_out = np.c_[np.cos(s), np.sin(s), np.zeros_like(s)]
    kn, kg = normal_geodesic_curvature(P, n_out)
    kappa = a / (a * a + b * b)
    inner = slice(1, -1)
    # The helix bends towards the axis, away from the outward normal: kn = -kappa; a geodesic.
    np.testing.assert_allclose(kn[inner], -kappa, rtol=1e-2)
    assert np.abs(kg[inner]).max() < 1e-2 * kappa
    assert np.isnan(kn[[0, -1]]).all()
    kn_in, _ = normal_geodesic_curvature(P, -n_out)     # the sign follows the normal
    np.testing.assert_allclose(kn_in[inner], kappa, rtol=1e-2)


def test_latitude_circle_geodesic_curvature():
    R, theta = 2.0, 0.7
    phi = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    P = R * np.c_[np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi),
                  np.full_like(phi, np.cos(theta))]
    n_out = P / R
    kn, kg = normal_geodesic_curvature(P, n_out, closed=True)
    np.testing.assert_allclose(kn, -1 / R, rtol=1e-2)
    # Going east (phi increasing) seen from outside, the circle turns left (towards the pole).
    np.testing.assert_allclose(kg, 1 / (R * np.tan(theta)), rtol=1e-2)
    _, kg_rev = normal_geodesic_curvature(P[::-1], n_out[::-1], closed=True)
    np.testing.assert_allclose(kg_rev, -1 / (R * np.tan(theta)), rtol=1e-2)
