"""The linear-solver interface (gridshell.solver.linear): analyse once per pattern, factor many.

Every backend against a dense solve (random SPD systems and a real GG normal matrix), the
analysis cache (counted, reused, invalidated), the fixed-pattern normal equations
(gridshell.solver.normal) and the forced SuperLU fallback (GRIDSHELL_LINEAR)."""
import numpy as np
import pytest
import scipy.sparse as sp

from gridshell.cli.main import main
from gridshell.core.errors import InputError
from gridshell.solver import solve
from gridshell.solver import linear as lin
from gridshell.solver.normal import NormalEquations
from tests.helpers.solver_cases import gg_problem

BACKENDS = [pytest.param(b, marks=pytest.mark.skipif(not lin.available(b),
                                                     reason=f"{b} not installed"))
            for b in lin.BACKENDS]


def random_spd(n, density, seed):
    """``B B^T + 1e-3 I`` with sparse random ``B``: SPD, full diagonal, random pattern."""
    B = sp.random(n, n, density, random_state=seed, format="csc")
    return (B @ B.T + 1e-3 * sp.identity(n)).tocsc()


def gg_normal_matrix(n=9):
    prob, x0 = gg_problem(n)
    a = prob.assemble(x0)
    JTJ = (a.J.T @ a.J).tocsc()
    A = (JTJ + 1e-3 * JTJ.diagonal().mean() * sp.identity(JTJ.shape[0])).tocsc()
    return A, -(a.J.T @ a.r)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("n, density, seed", [(1, 1.0, 0), (40, 0.1, 1), (300, 0.01, 2)])
def test_random_spd_matches_dense_solve(backend, n, density, seed):
    A = random_spd(n, density, seed)
    b = np.random.default_rng(seed).standard_normal((n,))
    s = lin.LinearSolver(backend)
    x = s.factor(A)(b)
    ref = np.linalg.solve(A.toarray(), b)
    assert np.allclose(x, ref, rtol=1e-9, atol=1e-9 * np.abs(ref).max())
    # new values on the same pattern: refactored numerically, the analysis reused
    A2 = A.copy()
    A2.data = A2.data * 2.0
    A2.setdiag(A2.diagonal() + 0.5)
    x2 = s.factor(A2)(b)
    ref2 = np.linalg.solve(A2.toarray(), b)
    assert np.allclose(x2, ref2, rtol=1e-9, atol=1e-9 * np.abs(ref2).max())
    assert (s.analyses, s.factorizations) == (1, 2)


@pytest.mark.parametrize("backend", BACKENDS)
def test_gg_normal_matrix_matches_dense_solve(backend):
    A, b = gg_normal_matrix()
    x = lin.LinearSolver(backend).factor(A)(b)
    ref = np.linalg.solve(A.toarray(), b)
    assert np.linalg.norm(x - ref) <= 1e-8 * np.linalg.norm(ref)
    assert np.linalg.norm(A @ x - b) <= 1e-10 * np.linalg.norm(b)


@pytest.mark.parametrize("backend", BACKENDS)
def test_analysis_cached_per_pattern_and_invalidated(backend):
    s = lin.LinearSolver(backend, cache_size=2)
    A, B, C = random_spd(60, 0.05, 3), random_spd(60, 0.05, 4), random_spd(50, 0.05, 5)
    assert lin.pattern_key(A) != lin.pattern_key(B)
    b = np.ones(60)
    s.factor(A)(b)
    s.factor(A * 3.0)(b)
    assert s.analyses == 1
    xb = s.factor(B)(b)  # another pattern: analysed
    assert s.analyses == 2
    assert np.allclose(B @ xb, b)
    s.factor(A)(b)  # still cached (two patterns fit)
    assert s.analyses == 2
    s.factor(C)(np.ones(50))  # a third pattern evicts the least recently used (B)
    s.factor(A)(b)
    assert s.analyses == 3
    s.factor(B)(b)
    assert s.analyses == 4
    s.clear()
    s.factor(A)(b)
    assert (s.analyses, s.factorizations) == (5, 8)


@pytest.mark.parametrize("backend", BACKENDS)
def test_solve_analyses_once_per_solve(backend):
    """An LM solve of many iterations (and rejected steps) analyses its pattern once, and the
    next solve of a problem with the same structure not at all."""
    prob, x0 = gg_problem()
    s = lin.LinearSolver(backend)
    res = solve(prob, x0, method="lm", max_iter=15, linear=s)
    assert res.iterations >= 3
    tries = len(res.history)
    assert s.analyses == 1 and s.factorizations >= tries
    ref = solve(prob, x0, method="lm", max_iter=15, linear=lin.LinearSolver("superlu"))
    assert res.energy == pytest.approx(ref.energy, rel=1e-6)
    assert np.allclose(res.x, ref.x, atol=1e-7)
    solve(prob, res.x, method="lm", max_iter=2, linear=s)
    assert s.analyses == 1


def test_normal_equations_keep_their_pattern():
    """J^T J on a fixed pattern: values match a fresh product, an entry that cancels exactly
    stays in the pattern (explicit zero), the damping lands on the diagonal only."""
    rng = np.random.default_rng(0)
    J = sp.random(30, 12, 0.3, random_state=1, format="csr")
    ne = NormalEquations()
    M = ne.update(J)
    assert np.allclose(M.toarray(), (J.T @ J).toarray())
    assert np.all(np.diff(M.indptr) > 0) and ne.patterns == 1
    key, nnz = ne.key, M.nnz
    J2 = J.copy()
    J2.data = rng.standard_normal(J2.nnz)
    M2 = ne.update(J2)
    assert np.allclose(M2.toarray(), (J2.T @ J2).toarray())
    assert (ne.key, M2.nnz, ne.patterns) == (key, nnz, 1)
    J3 = J.copy()
    J3.data[:] = 0.0  # every product cancels: scipy drops the entries, the pattern stays
    M3 = ne.update(J3)
    assert (M3.nnz, ne.key, ne.patterns) == (nnz, key, 1) and not np.any(M3.data)
    A = ne.damped(2.5)
    assert np.allclose(A.toarray(), 2.5 * np.eye(12))
    assert not np.any(ne.JTJ.data)  # damped() copies
    J4 = sp.random(30, 12, 0.5, random_state=2, format="csr")  # a larger pattern: new one
    ne.update(J4)
    assert ne.patterns == 2 and ne.key != key
    assert np.allclose(ne.JTJ.toarray(), (J4.T @ J4).toarray())
    J5 = J4.tolil()
    J5[:, 3] = 0.0  # a variable no residual uses: its diagonal entry joins the pattern anyway
    J5 = J5.tocsr()
    J5.eliminate_zeros()
    assert ne.update(J5).nnz == ne.JTJ.nnz and ne.patterns == 2  # a sub-pattern: kept
    ne = NormalEquations()
    M5 = ne.update(J5)
    assert ne.patterns == 1 and M5.nnz == (J5.T @ J5).nnz + 1
    assert np.allclose(M5.toarray(), (J5.T @ J5).toarray())
    assert np.allclose(ne.damped(1.0).diagonal(), M5.diagonal() + 1.0)


@pytest.mark.parametrize("backend", BACKENDS)
def test_non_finite_or_indefinite_matrix_is_refused(backend):
    A = random_spd(20, 0.2, 6)
    bad = A.copy()
    bad.data[0] = np.nan
    with pytest.raises(lin.NotPositiveDefinite, match="NaN"):
        lin.LinearSolver(backend).factor(bad)
    if backend == "cholmod":  # SuperLU with diagonal pivots factors indefinite matrices too
        with pytest.raises(lin.NotPositiveDefinite):
            lin.LinearSolver(backend).factor((A - 10.0 * sp.identity(20)).tocsc())


def test_forced_superlu_by_environment(monkeypatch, capsys):
    monkeypatch.setenv(lin.ENV, "superlu")
    assert lin.default_backend() == "superlu"
    assert lin.shared_solver().backend == "superlu"
    assert "superlu" in lin.describe() and lin.ENV in lin.describe()
    assert main(["--version"]) == 0
    out = capsys.readouterr().out
    assert "gridshell" in out and "linear solver: superlu" in out
    prob, x0 = gg_problem(6)
    res = solve(prob, x0, method="lm", max_iter=5)
    assert res.energy < res.energy0
    monkeypatch.setenv(lin.ENV, "umfpack")
    with pytest.raises(InputError, match="unknown linear solver 'umfpack'"):
        lin.default_backend()
    with pytest.raises(InputError, match="GRIDSHELL_LINEAR"):
        solve(prob, x0, method="lm", max_iter=1)


def test_default_backend_is_the_first_available(monkeypatch, capsys):
    monkeypatch.delenv(lin.ENV, raising=False)
    first = next(b for b in lin.BACKENDS if lin.available(b))
    assert lin.default_backend() == first
    assert main(["--version"]) == 0
    assert f"linear solver: {first}" in capsys.readouterr().out
