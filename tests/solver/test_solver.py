"""The sparse least-squares solver on problems with known answers."""
import numpy as np
import pytest
import scipy.optimize as so
import scipy.sparse as sp

from tests.helpers.fd_cases.fixtures import circle_term, grid_quads, planarity_term, rosenbrock_term

from gridshell.core.errors import ConvergenceError, InputError
from gridshell.solver import Layout, Problem, result, solve, term
from gridshell.solver import terms as T
from gridshell.solver.fdcheck import jacobian_error


def lm_solve(prob, x0, **kw):
    """``solve`` with method "lm" (the default), checking what every LM run must satisfy: the
    energy never increases, from ``energy0`` through every history record, and the per-term
    energies of every accepted record sum to its energy."""
    assert kw.get("method", "lm") == "lm"
    res = solve(prob, x0, **kw)
    E = [res.energy0] + [h["energy"] for h in res.history]
    rises = [(k, a, b) for k, (a, b) in enumerate(zip(E, E[1:])) if b > a]
    assert not rises, f"LM energy increased at (iteration, before, after) {rises}"
    assert res.energy == pytest.approx(E[-1], rel=1e-14, abs=0)
    assert_terms_sum_to_energy(res)
    return res


def assert_terms_sum_to_energy(res):
    """The per-term energies of every accepted history record sum to its energy, and the
    final report's to the final energy."""
    for h in res.history:
        if h["accepted"]:
            assert sum(h["terms"].values()) == pytest.approx(h["energy"], rel=1e-12, abs=1e-300)
    assert sum(r["energy"] for r in res.report.values()) == pytest.approx(res.energy, rel=1e-12,
                                                                         abs=1e-300)


def _grid(rows, cols):
    return grid_quads(rows, cols)


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
    res = lm_solve(prob, x0, method="lm")
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
    run = lm_solve if method == "lm" else solve
    res = run(prob, lay.pack({"V": V, "N": N}), fixed=corners, method=method, max_iter=100,
              damping=1e-6)
    assert_terms_sum_to_energy(res)
    assert res.converged, res.message
    rep = res.report
    assert rep["planarity"]["max"] < 1e-8
    # damped steps are small: the planar result stays near the perturbed input
    assert np.abs(lay.view(res.x, "V") - V).max() < 0.1


def test_fixed_variables_do_not_move():
    rng = np.random.default_rng(2)
    lay = Layout({"V": (10, 3)})
    target = rng.normal(size=(10, 3))
    prob = Problem(lay).add("close", 1.0, T.closeness, T.Closeness("V", target))
    x0 = np.zeros(lay.size)
    fixed = lay.indices("V")[:3].ravel()
    res = lm_solve(prob, x0, fixed=fixed)
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
    ours = lm_solve(prob, x0, tol_rel=1e-14, max_iter=200)
    assert ours.converged, ours.message
    # scipy differentiates the residual itself (2-point differences), so a wrong analytic
    # Jacobian of ours cannot be shared by the reference
    ref = so.least_squares(prob.residuals, x0, jac="2-point", method="trf", xtol=1e-15,
                           ftol=1e-15, gtol=1e-15)
    assert ref.success, ref.message
    assert np.allclose(ours.x, ref.x, atol=1e-8)
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
    assert_terms_sum_to_energy(res)
    assert np.abs(lay.view(res.x, "V")[:, 2]).max() < 1e-9


def test_honest_non_convergence():
    pts = np.array([[np.cos(t), np.sin(t)] for t in np.linspace(0, 6, 40)])
    lay = Layout({"c": 2, "R": 1})
    prob = Problem(lay).add("circle", 1.0, circle_term, pts)
    res = lm_solve(prob, lay.pack({"c": [5.0, 5], "R": [0.1]}), max_iter=2)
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


# -- the test-only terms' Jacobians, at the configurations the tests above solve from ---------

def _noisy_circle_points():
    rng = np.random.default_rng(3)
    th = rng.uniform(0, np.pi, 25)
    pts = np.stack([2 + 1.5 * np.cos(th), 1 + 1.5 * np.sin(th)], axis=1)
    return pts + rng.normal(scale=0.05, size=pts.shape)


def _perturbed_grid():
    rng = np.random.default_rng(1)
    rows, cols = 8, 9
    u, v = np.meshgrid(np.linspace(0, 1, rows), np.linspace(0, 1, cols), indexing="ij")
    V = np.stack([u.ravel(), v.ravel(), 0.2 * u.ravel() + 0.1 * v.ravel()], axis=1)
    F = _grid(rows, cols)
    N = rng.normal(size=(len(F), 3))
    lay = Layout({"V": V.shape, "N": N.shape})
    return lay, lay.pack({"V": V + rng.normal(scale=0.02, size=V.shape), "N": N}), F


@pytest.mark.parametrize("case", ["circle", "planarity", "rosenbrock"])
def test_test_terms_match_finite_differences(case):
    if case == "circle":
        lay = Layout({"c": 2, "R": 1})
        fn, x, data = circle_term, lay.pack({"c": [1.5, 0.5], "R": [1.0]}), _noisy_circle_points()
    elif case == "planarity":
        fn, (lay, x, data) = planarity_term, _perturbed_grid()
    else:
        lay = Layout({"p": 2})
        fn, x, data = rosenbrock_term, np.array([-1.2, 1.0]), None
    err = jacobian_error(fn, x, lay, data)
    assert err < 1e-6, f"{case}: relative Jacobian error {err:.2e}"


def test_finite_difference_check_catches_a_wrong_jacobian():
    lay = Layout({"c": 2, "R": 1})
    x, pts = lay.pack({"c": [1.5, 0.5], "R": [1.0]}), _noisy_circle_points()

    def wrong(x, layout, data):  # d/dR should be -1
        res = circle_term(x, layout, data)
        return res._replace(vals=np.where(res.cols == layout.indices("R")[0], 1.0, res.vals))

    assert jacobian_error(wrong, x, lay, pts) > 0.1


# -- registration --------------------------------------------------------------------------

def unregistered_term(x, layout, data=None):
    return result(x, np.arange(len(x)), np.arange(len(x)), np.ones(len(x)))


def test_problem_takes_only_registered_terms():
    prob = Problem(Layout({"c": 3}))
    for fn, what in ((unregistered_term, "unregistered_term"), (lambda x, lay, d: None, "lambda"),
                     (print, "print"), (42, "int")):
        with pytest.raises(InputError, match=f"'bad'.*{what}.*not a registered solver term.*@"):
            prob.add("bad", 1.0, fn)
    assert prob.entries == []

    # a function that merely shares the qualified name of a registered term is not it
    def closeness(x, layout, data):
        return T.closeness(x, layout, data)
    closeness.__module__ = T.closeness.__module__
    with pytest.raises(InputError, match="not a registered solver term"):
        prob.add("impostor", 1.0, closeness)

    # once registered (and given a case in tests/fd_cases), it is accepted
    prob.add("ok", 1.0, T.closeness, T.Closeness("c", np.zeros((1, 3))))
    assert [e.name for e in prob.entries] == ["ok"]



# -- what x is, and why a solve stopped --------------------------------------------------------

@pytest.mark.parametrize("method", ["gn", "guided"])
def test_gn_and_guided_return_the_last_iterate_even_if_the_energy_rose(method):
    """A full Gauss-Newton step on the Rosenbrock residual from (-1.2, 1) lands on (1, -3.84):
    the energy rises from 24.2 to 2342; the next step reaches the minimum (1, 1)."""
    lay = Layout({"p": 2})
    prob = Problem(lay).add("rosenbrock", 1.0, rosenbrock_term)
    x0 = np.array([-1.2, 1.0])
    one = solve(prob, x0, method=method, max_iter=1, damping=1e-12)
    assert one.energy0 == pytest.approx(24.2)
    assert np.allclose(one.x, [1.0, -3.84], atol=1e-6)    # the last iterate, not the best (x0)
    assert one.energy == pytest.approx(prob.energy(one.x)) and one.energy > 2000
    assert one.history[-1]["accepted"] and not one.converged
    assert_terms_sum_to_energy(one)
    two = solve(prob, x0, method=method, max_iter=20, damping=1e-12)
    assert two.converged and np.allclose(two.x, [1.0, 1.0], atol=1e-8)


def test_lm_on_the_same_problem_never_rises():
    lay = Layout({"p": 2})
    prob = Problem(lay).add("rosenbrock", 1.0, rosenbrock_term)
    res = lm_solve(prob, np.array([-1.2, 1.0]), max_iter=200)
    assert res.converged, res.message
    assert np.allclose(res.x, [1.0, 1.0], atol=1e-6)
    assert all(h["energy"] <= 24.2 for h in res.history)


@pytest.mark.parametrize("method", ["lm", "gn", "guided"])
def test_a_singular_system_is_named_as_such(method):
    """A point at the circle's centre: |p - c| is not differentiable there, its Jacobian row is
    NaN and the damped system cannot be factored at any damping."""
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [-1.0, 0.2]])
    lay = Layout({"c": 2, "R": 1})
    prob = Problem(lay).add("circle", 1.0, circle_term, pts)
    x0 = lay.pack({"c": [0.0, 0.0], "R": [1.0]})
    res = solve(prob, x0, method=method)
    assert not res.converged
    assert "singular at every damping" in res.message, res.message
    assert "non-finite" not in res.message.split("(")[0]
    assert np.array_equal(res.x, x0) and res.energy == res.energy0
    with pytest.raises(ConvergenceError, match="singular"):
        res.raise_if_failed("circle fit")
