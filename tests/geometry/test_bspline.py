"""B-spline basis, operators (eq. 4.1), fitting and JSON io, checked against closed forms."""
from __future__ import annotations

import json

import numpy as np
import pytest
import scipy.interpolate as si

from gridshell.geometry.bspline import (BSplineSurface, basis_matrix, fit_grid, fit_points,
                               open_uniform_knots)
from gridshell.core.errors import InputError

DERIVS = {"Su": (1, 0), "Sv": (0, 1), "Suu": (2, 0), "Suv": (1, 1), "Svv": (0, 2)}


def random_surface(du: int, dv: int, nu: int = 7, nv: int = 8, seed: int = 0) -> BSplineSurface:
    rng = np.random.default_rng(seed)
    gu, gv = np.meshgrid(np.linspace(0, 3, nu), np.linspace(0, 2, nv), indexing="ij")
    ctrl = np.stack([gu, gv, np.zeros_like(gu)], axis=-1) + 0.3 * rng.normal(size=(nu, nv, 3))
    return BSplineSurface.from_control_grid(ctrl, du, dv)


def away_from_knots(knots: np.ndarray, k: int, margin: float, rng) -> np.ndarray:
    t = rng.uniform(margin, 1 - margin, 4 * k)
    dist = np.abs(t[:, None] - np.unique(knots)[None, :]).min(axis=1)
    return t[dist > margin][:k]


# ----------------------------------------------------------------------------- basis


def test_open_uniform_knots():
    np.testing.assert_array_equal(open_uniform_knots(5, 2), [0, 0, 0, 1 / 3, 2 / 3, 1, 1, 1])
    assert len(open_uniform_knots(9, 4)) == 14
    with pytest.raises(InputError, match="at least degree"):
        open_uniform_knots(3, 4)


@pytest.mark.parametrize("degree", [1, 2, 3, 4, 5])
def test_basis_matches_scipy_and_partition_of_unity(degree):
    knots = open_uniform_knots(9, degree)
    t = np.r_[np.linspace(0, 1, 57), knots[degree:-degree]]     # includes every knot and t = 1
    B = basis_matrix(knots, degree, t)
    assert B.shape == (len(t), 9)
    np.testing.assert_allclose(np.asarray(B.sum(axis=1)).ravel(), 1.0, atol=1e-14)
    ref = si.BSpline(knots, np.eye(9), degree)
    for d in range(degree + 1):
        np.testing.assert_allclose(basis_matrix(knots, degree, t, d).toarray(), ref(t, nu=d),
                                   atol=1e-10 * 10 ** d)
    for d in range(1, degree + 1):   # derivatives of a partition of unity sum to zero
        np.testing.assert_allclose(basis_matrix(knots, degree, t, d).sum(axis=1), 0, atol=1e-8)
    assert basis_matrix(knots, degree, t, degree + 1).count_nonzero() == 0


def test_basis_end_of_domain_interpolates_last_control_point():
    knots = open_uniform_knots(6, 3)
    row = basis_matrix(knots, 3, [1.0]).toarray()[0]
    np.testing.assert_array_equal(row, [0, 0, 0, 0, 0, 1])


def test_basis_nonuniform_knots_with_multiplicity():
    knots = np.array([0, 0, 0, 0, 0.2, 0.5, 0.5, 0.7, 1, 1, 1, 1.0])
    t = np.r_[np.linspace(0, 1, 41), 0.5]
    ref = si.BSpline(knots, np.eye(8), 3)
    for d in range(4):
        np.testing.assert_allclose(basis_matrix(knots, 3, t, d).toarray(), ref(t, nu=d),
                                   atol=1e-9)


def test_basis_rejects_bad_input():
    knots = open_uniform_knots(6, 3)
    with pytest.raises(InputError, match="outside the knot domain"):
        basis_matrix(knots, 3, [1.2])
    with pytest.raises(InputError, match="non-decreasing"):
        basis_matrix(knots[::-1], 3, [0.5])
    with pytest.raises(InputError, match="non-negative"):
        basis_matrix(knots, 3, [0.5], deriv=-1)


# ----------------------------------------------------------------------------- operators


@pytest.mark.parametrize("du,dv", [(4, 4), (3, 3), (2, 5)])
def test_derivative_operators_match_central_differences(du, dv):
    surf = random_surface(du, dv)
    rng = np.random.default_rng(1)
    h = 1e-5
    u = away_from_knots(surf.knots_u, 25, 2 * h, rng)
    v = away_from_knots(surf.knots_v, 25, 2 * h, rng)
    k = min(len(u), len(v))
    u, v = u[:k], v[:k]
    D = surf.derivatives(u, v)
    fd = {
        "Su": (surf.evaluate(u + h, v) - surf.evaluate(u - h, v)) / (2 * h),
        "Sv": (surf.evaluate(u, v + h) - surf.evaluate(u, v - h)) / (2 * h),
        "Suu": (surf.evaluate(u + h, v, 1, 0) - surf.evaluate(u - h, v, 1, 0)) / (2 * h),
        "Suv": (surf.evaluate(u, v + h, 1, 0) - surf.evaluate(u, v - h, 1, 0)) / (2 * h),
        "Svv": (surf.evaluate(u, v + h, 0, 1) - surf.evaluate(u, v - h, 0, 1)) / (2 * h),
    }
    for key in DERIVS:
        rel = np.abs(fd[key] - D[key]).max() / np.abs(D[key]).max()
        assert rel < 1e-6, (key, rel)


@pytest.mark.parametrize("du,dv", [(4, 4), (2, 5)])
def test_paired_and_grid_operators_agree(du, dv):
    surf = random_surface(du, dv)
    u = np.linspace(0, 1, 7)
    v = np.linspace(0, 1, 5)
    C = surf.ctrl.reshape(-1, 3)
    U, V = np.meshgrid(u, v, indexing="ij")
    for (a, b) in [(0, 0), *DERIVS.values()]:
        G = surf.operator_grid(u, v, a, b)
        A = surf.operator(U.ravel(), V.ravel(), a, b)
        assert G.shape == A.shape == (35, surf.n_ctrl)
        np.testing.assert_allclose((A - G).toarray(), 0, atol=1e-12)
        np.testing.assert_allclose(surf.evaluate_grid(u, v, a, b).reshape(-1, 3), G @ C,
                                   atol=1e-12)
    # A row touches exactly (du+1)(dv+1) control points, the row-wise Kronecker product.
    assert np.all(np.diff(surf.operator(U.ravel(), V.ravel()).indptr) == (du + 1) * (dv + 1))


def test_surface_corners_interpolate_control_points():
    surf = random_surface(3, 4)
    S = surf.evaluate([0, 0, 1, 1], [0, 1, 0, 1])
    np.testing.assert_allclose(S, surf.ctrl[[0, 0, -1, -1], [0, -1, 0, -1]], atol=1e-14)


def test_bilinear_patch_is_exact():
    """A degree-(1,1) surface is the bilinear interpolant: S_uv is the twist vector."""
    ctrl = np.array([[[0, 0, 0], [0, 1, 0]], [[1, 0, 0], [1, 1, 1.0]]])
    surf = BSplineSurface.from_control_grid(ctrl, 1, 1)
    u, v = np.array([0.3, 0.8]), np.array([0.6, 0.1])
    np.testing.assert_allclose(surf.evaluate(u, v), np.c_[u, v, u * v], atol=1e-15)
    np.testing.assert_allclose(surf.evaluate(u, v, 1, 1), [[0, 0, 1]] * 2, atol=1e-15)


# ----------------------------------------------------------------------------- fitting


def test_fit_reproduces_polynomial_surface_exactly():
    """A bi-quartic polynomial lies in the spline space, so the fit is exact."""
    s = np.linspace(0, 1, 20)
    U, V = np.meshgrid(s, s, indexing="ij")
    P = np.stack([U, V, U ** 4 - 2 * U * V ** 3 + 0.5 * V ** 2], axis=-1)
    surf, rms = fit_grid(P, 6, 6, params="uniform", smoothing=0.0)
    assert rms < 1e-12
    uu = np.linspace(0, 1, 11)
    Q = surf.evaluate_grid(uu, uu)
    Uq, Vq = np.meshgrid(uu, uu, indexing="ij")
    np.testing.assert_allclose(Q[..., 2], Uq ** 4 - 2 * Uq * Vq ** 3 + 0.5 * Vq ** 2, atol=1e-10)


def test_fit_points_scattered():
    rng = np.random.default_rng(3)
    u, v = rng.random(400), rng.random(400)
    P = np.c_[u, v, np.sin(u) * np.cos(v)]
    surf, rms = fit_points(P, u, v, 7, 7, 3, 3)
    assert rms < 1e-5
    with pytest.raises(InputError, match="one \\(u, v\\) per point"):
        fit_points(P, u[:-1], v)


def test_fit_rejects_bad_input():
    P = np.zeros((10, 10, 3))
    P[..., 0], P[..., 1] = np.meshgrid(np.arange(10.0), np.arange(10.0), indexing="ij")
    with pytest.raises(InputError, match="shape \\(a, b, 3\\)"):
        fit_grid(P.reshape(-1, 3))
    with pytest.raises(InputError, match="params"):
        fit_grid(P, params="centripetal")
    with pytest.raises(InputError, match="smoothing"):
        fit_grid(P, smoothing=-1)


# ----------------------------------------------------------------------------- io


def test_json_round_trip_is_exact(tmp_path):
    surf = random_surface(2, 5, nu=6, nv=9, seed=7)
    again = BSplineSurface.from_json(json.loads(json.dumps(surf.to_json())))
    path = tmp_path / "sub" / "surface.json"
    surf.save(path)
    loaded = BSplineSurface.load(path)
    for other in (again, loaded):
        assert (other.degree_u, other.degree_v) == (2, 5)
        np.testing.assert_array_equal(other.knots_u, surf.knots_u)
        np.testing.assert_array_equal(other.knots_v, surf.knots_v)
        np.testing.assert_array_equal(other.ctrl, surf.ctrl)
    d = json.loads(path.read_text())
    assert (d["format"], d["version"], d["units"]) == ("gridshell.bspline", 1, "m")
    assert not list(tmp_path.joinpath("sub").glob(".*tmp*"))   # no temporary left behind


@pytest.mark.parametrize("edit,match", [
    (lambda d: d.update(format="gridshell.mesh"), "not a B-spline file"),
    (lambda d: d.update(version=2), "unsupported"),
    (lambda d: d.update(units="mm"), "units"),
    (lambda d: d.pop("knots_v"), "misses knots_v"),
    (lambda d: d.update(ctrl=d["ctrl"][:-1]), "knots_u has 9 entries but 4 control points"),
    (lambda d: d.update(degree_u=0), "degree_u must be an integer >= 1"),
    (lambda d: d["ctrl"][0][0].__setitem__(0, float("nan")), "NaN"),
    (lambda d: d.update(knots_v=d["knots_v"][::-1]), "non-decreasing"),
    (lambda d: d.update(ctrl=[[1, 2], [3, 4]]), "shape \\(nu, nv, 3\\)"),
])
def test_load_errors_name_the_problem(tmp_path, edit, match):
    d = random_surface(3, 3, nu=5, nv=4).to_json()
    edit(d)
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(d))
    with pytest.raises(InputError, match=match):
        BSplineSurface.load(path)


def test_load_unreadable_files(tmp_path):
    with pytest.raises(InputError, match="cannot read"):
        BSplineSurface.load(tmp_path / "missing.json")
    (tmp_path / "broken.json").write_text("{not json")
    with pytest.raises(InputError, match="not valid JSON"):
        BSplineSurface.load(tmp_path / "broken.json")


# ----------------------------------------------------------------------------- sampling


def test_sample_quad_mesh():
    pytest.importorskip("gridshell.geometry.quadmesh")
    pytest.importorskip("gridshell.geometry.grid")
    surf = random_surface(3, 3)
    mesh = surf.sample(5, 4)
    V, F = np.asarray(mesh.V), np.asarray(mesh.F)
    assert V.shape == (20, 3) and F.shape == (12, 4)
    np.testing.assert_allclose(V.reshape(5, 4, 3),
                               surf.evaluate_grid(np.linspace(0, 1, 5), np.linspace(0, 1, 4)))
    with pytest.raises(InputError):
        surf.sample(1, 4)


@pytest.mark.parametrize("knots,degree", [([0, 0, 1, 1, 1], 1), ([0, 0, 0, 1, 1, 1, 1], 2),
                                          ([0, 0, 0.5, 1, 1, 1], 1)])
def test_basis_at_the_right_end_with_a_repeated_end_knot(knots, degree):
    # an interior knot equal to the end knot leaves an empty last span; the right end must
    # still be evaluated (partition of unity) as the limit from the left (scipy gives 0 there)
    from scipy.interpolate import BSpline
    t = np.linspace(knots[degree], knots[len(knots) - degree - 1], 7)
    B = basis_matrix(np.asarray(knots, float), degree, t).toarray()
    np.testing.assert_allclose(B.sum(axis=1), 1.0, atol=1e-14)
    n = len(knots) - degree - 1
    for i in range(n):
        c = np.zeros(n)
        c[i] = 1.0
        ref = BSpline(np.asarray(knots, float), c, degree)(np.minimum(t, t[-1] - 1e-13))
        np.testing.assert_allclose(B[:, i], ref, atol=1e-11)
