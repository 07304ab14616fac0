"""The sparse least-squares solver on problems with known answers."""
import numpy as np
import pytest
import scipy.optimize as so
import scipy.sparse as sp

from gridshell.errors import ConvergenceError, InputError
from gridshell.solver import Layout, Problem, result, solve
from gridshell.solver import terms as T


# -- test-only terms (not registered: they are fixtures, not project terms) -------------------
def circle_term(x, layout, pts):
    """r_i = |p_i - c| - R."""
    c = layout.view(x, "c")
    R = layout.view(x, "R")[0]
    d = pts - c
    nrm = np.linalg.norm(d, axis=1)
    r = nrm - R
    k = len(pts)
    rows = np.repeat(np.arange(k), pts.shape[1] + 1)
    d_ = pts.shape[1]
    cols = np.concatenate([np.tile(layout.indices("c"), (k, 1)),
                           np.full((k, 1), layout.indices("R")[0])], axis=1).ravel()
    vals = np.concatenate([-d / nrm[:, None], -np.ones((k, 1))], axis=1).ravel()
    return result(r, rows, cols, vals)


def planarity_term(x, layout, F):
    """Per quad f with unit normal n_f: <V_b - V_a, n_f> = 0 on its 4 edges; |n_f|^2 = 1."""
    V = layout.view(x, "V")
    N = layout.view(x, "N")
    Vi, Ni = layout.indices("V"), layout.indices("N")
    a = F.ravel()
    b = np.roll(F, -1, axis=1).ravel()
    f = np.repeat(np.arange(len(F)), 4)
    e = V[b] - V[a]
    n = N[f]
    r1 = np.einsum("ij,ij->i", e, n)
    m = len(r1)
    rows1 = np.repeat(np.arange(m), 9)
    cols1 = np.concatenate([Vi[b], Vi[a], Ni[f]], axis=1).ravel()
    vals1 = np.concatenate([n, -n, e], axis=1).ravel()
    r2 = np.einsum("ij,ij->i", N, N) - 1.0
    rows2 = m + np.repeat(np.arange(len(N)), 3)
    return result(np.concatenate([r1, r2]), np.concatenate([rows1, rows2]),
                  np.concatenate([cols1, Ni.ravel()]), np.concatenate([vals1, 2 * N.ravel()]))


def _grid(rows, cols):
    i, j = np.meshgrid(np.arange(rows - 1), np.arange(cols - 1), indexing="ij")
    v0 = (i * cols + j).ravel()
    return np.stack([v0, v0 + 1, v0 + cols + 1, v0 + cols], axis=1)


def test_layout_views_and_pack():
    lay = Layout({"V": (4, 3), "n": 2})
    x = lay.pack({"V": np.arange(12.0), "n": [7, 8]})
    assert lay.view(x, "V").shape == (4, 3)
    assert lay.view(x, "n").tolist() == [7, 8]
    lay.view(x, "V")[1, 2] = -1
    assert x[5] == -1
    assert lay.indices("n").tolist() == [12, 13]
    with pytest.raises(InputError, match="no variable block"):
        lay.slice("W")
    with pytest.raises(InputError, match="shape"):
        lay.pack({"n": [1, 2, 3]})


def test_circle_fit_reaches_zero_residual():
    rng = np.random.default_rng(0)
    th = rng.uniform(0, 2 * np.pi, 30)
    c, R = np.array([1.0, -2.0]), 3.0
    pts = c + R * np.stack([np.cos(th), np.sin(th)], axis=1)
    lay = Layout({"c": 2, "R": 1})
    prob = Problem(lay).add("circle", 1.0, circle_term, pts)
    x0 = lay.pack({"c": [0.0, 0.0], "R": [1.0]})
    res = solve(prob, x0, method="lm")
    assert res.converged, res.message
    assert res.energy < 1e-20
    assert np.allclose(lay.view(res.x, "c"), c, atol=1e-9)
    assert abs(lay.view(res.x, "R")[0] - R) < 1e-9


@pytest.mark.parametrize("method", ["lm", "guided"])
def test_planarizes_a_perturbed_planar_quad_grid(method):
    rng = np.random.default_rng(1)
    rows, cols = 8, 9
    F = _grid(rows, cols)
    u, v = np.meshgrid(np.linspace(0, 1, rows), np.linspace(0, 1, cols), indexing="ij")
    V0 = np.stack([u.ravel(), v.ravel(), 0.2 * u.ravel() + 0.1 * v.ravel()], axis=1)
    V = V0 + rng.normal(scale=0.02, size=V0.shape)
    N = np.tile([0.0, 0.0, 1.0], (len(F), 1))
    lay = Layout({"V": V.shape, "N": N.shape})
    prob = Problem(lay).add("planarity", 1.0, planarity_term, F)
    corners = lay.indices("V")[[0, cols - 1, len(V) - cols, len(V) - 1]].ravel()
    res = solve(prob, lay.pack({"V": V, "N": N}), fixed=corners, method=method, max_iter=100,
                damping=1e-6)
    assert res.converged, res.message
    rep = res.report
    assert rep["planarity"]["max"] < 1e-8
    # damped steps are small: the planar result stays near the perturbed input
    assert np.abs(lay.view(res.x, "V") - V).max() < 0.1
    E = [h["energy"] for h in res.history if h["accepted"]]
    if method == "lm":
        assert all(b <= a * (1 + 1e-12) for a, b in zip([res.energy0] + E, E)), \
            "LM energy increased"


def test_fixed_variables_do_not_move():
    rng = np.random.default_rng(2)
    lay = Layout({"V": (10, 3)})
    target = rng.normal(size=(10, 3))
    prob = Problem(lay).add("close", 1.0, T.closeness, T.Closeness("V", target))
    x0 = np.zeros(lay.size)
    fixed = lay.indices("V")[:3].ravel()
    res = solve(prob, x0, fixed=fixed)
    X = lay.view(res.x, "V")
    assert np.all(X[:3] == 0)
    assert np.allclose(X[3:], target[3:], atol=1e-10)


def test_agrees_with_scipy_least_squares_on_noisy_circle():
    rng = np.random.default_rng(3)
    th = rng.uniform(0, np.pi, 25)
    pts = np.stack([2 + 1.5 * np.cos(th), 1 + 1.5 * np.sin(th)], axis=1)
    pts += rng.normal(scale=0.05, size=pts.shape)
    lay = Layout({"c": 2, "R": 1})
    prob = Problem(lay).add("circle", 1.0, circle_term, pts)
    x0 = lay.pack({"c": [1.5, 0.5], "R": [1.0]})
    ours = solve(prob, x0, tol_rel=1e-14, max_iter=200)

    def fun(x):
        return prob.residuals(x)

    def jac(x):
        return prob.assemble(x).J

    ref = so.least_squares(fun, x0, jac=jac, method="trf", xtol=1e-15, ftol=1e-15, gtol=1e-15)
    assert np.allclose(ours.x, ref.x, atol=1e-7)
    assert abs(ours.energy - 2 * ref.cost) < 1e-10


def test_linear_laplacian_term_smooths_to_a_plane():
    rows, cols = 6, 6
    F = _grid(rows, cols)
    e = np.unique(np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 3]],
                                          F[:, [3, 0]]]), axis=1), axis=0)
    u, v = np.meshgrid(np.linspace(0, 1, rows), np.linspace(0, 1, cols), indexing="ij")
    V = np.stack([u.ravel(), v.ravel(), np.zeros(rows * cols)], axis=1)
    interior = ((u > 0) & (u < 1) & (v > 0) & (v < 1)).ravel()
    V[interior, 2] = np.random.default_rng(4).normal(size=interior.sum())
    boundary = np.flatnonzero(~interior)
    L = T.laplacian_matrix(len(V), e, fixed_rows=boundary)
    lay = Layout({"V": V.shape})
    prob = Problem(lay).add("fair", 1.0, T.linear, T.Linear("V", L))
    fixed = lay.indices("V")[boundary].ravel()
    res = solve(prob, lay.pack({"V": V}), fixed=fixed, method="gn")
    assert np.abs(lay.view(res.x, "V")[:, 2]).max() < 1e-9


def test_honest_non_convergence():
    pts = np.array([[np.cos(t), np.sin(t)] for t in np.linspace(0, 6, 40)])
    lay = Layout({"c": 2, "R": 1})
    prob = Problem(lay).add("circle", 1.0, circle_term, pts)
    res = solve(prob, lay.pack({"c": [5.0, 5], "R": [0.1]}), max_iter=2)
    assert not res.converged
    assert "iteration limit" in res.message
    with pytest.raises(ConvergenceError, match="did not converge"):
        res.raise_if_failed("circle fit")


def test_bad_arguments_are_named():
    lay = Layout({"c": 3})
    prob = Problem(lay).add("close", 1.0, T.closeness, T.Closeness("c", np.zeros((1, 3))))
    with pytest.raises(InputError, match="x0 has shape"):
        solve(prob, np.zeros(4))
    with pytest.raises(InputError, match="NaN"):
        solve(prob, np.array([np.nan, 0, 0]))
    with pytest.raises(InputError, match="unknown method"):
        solve(prob, np.zeros(3), method="newton")
    with pytest.raises(InputError, match="twice"):
        prob.add("close", 1.0, T.closeness, None)
    with pytest.raises(InputError, match="weight"):
        prob.add("neg", -1.0, T.closeness, None)


def test_report_lists_every_term():
    lay = Layout({"c": 3})
    prob = (Problem(lay).add("a", 2.0, T.closeness, T.Closeness("c", np.ones((1, 3))))
            .add("b", 0.5, T.closeness, T.Closeness("c", np.zeros((1, 3)))))
    rep = prob.report(np.zeros(3))
    assert rep["a"]["energy"] == pytest.approx(6.0)
    assert rep["b"]["energy"] == 0.0
    a = prob.assemble(np.zeros(3))
    assert a.energies()["a"] == pytest.approx(6.0)
    assert sp.isspmatrix_csr(a.J)
