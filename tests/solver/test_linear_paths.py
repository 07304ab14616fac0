"""Every path of the linear solver against a reference (issue 17, one LM iteration at 1e5):
CHOLMOD with AMD, with dense columns last and METIS (or AMD when this CHOLMOD has no METIS),
SuperLU, Jacobi-CG and its fallback to the factorization; the in-place J^T J against a fresh
scipy product (bit for bit); the assembly's CSR structure against scipy's COO conversion."""
from types import SimpleNamespace

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from gridshell.solver import iterative, ordering
from gridshell.solver import linear as lin
from gridshell.solver.normal import NormalEquations
from gridshell.solver.problem import Problem

BACKENDS = [pytest.param(b, marks=pytest.mark.skipif(not lin.available(b),
                                                     reason=f"{b} not installed"))
            for b in lin.BACKENDS]
needs_cholmod = pytest.mark.skipif(not lin.available("cholmod"), reason="cholmod not installed")


def mesh_jacobian(k=24, hubs=3, per_hub=150, seed=0):
    """A Jacobian with mesh sparsity (one row per edge of a k x k grid, 2 unknowns per vertex)
    plus ``hubs`` auxiliary unknowns, each in ``per_hub`` rows with random vertices (dense
    columns of J^T J, like the GG design's curve lengths)."""
    rng = np.random.default_rng(seed)
    nv = k * k
    idx = np.arange(nv).reshape(k, k)
    edges = np.concatenate([np.stack([idx[:-1].ravel(), idx[1:].ravel()], 1),
                            np.stack([idx[:, :-1].ravel(), idx[:, 1:].ravel()], 1)])
    rows, cols = [], []
    for i, (a, b) in enumerate(edges):
        rows += [i] * 4
        cols += [2 * a, 2 * a + 1, 2 * b, 2 * b + 1]
    m = len(edges)
    for h in range(hubs):
        for v in rng.choice(nv, per_hub, replace=False):
            rows += [m] * 3
            cols += [2 * nv + h, 2 * v, 2 * v + 1]
            m += 1
    J = sp.csr_matrix((rng.standard_normal(len(rows)), (rows, cols)), shape=(m, 2 * nv + hubs))
    return J


def damped(J, mu=1e-2):
    A = (J.T @ J).tocsc()
    return (A + mu * A.diagonal().mean() * sp.identity(A.shape[0])).tocsc()


def rel_residual(A, x, b):
    return np.linalg.norm(A @ x - b) / np.linalg.norm(b)


@pytest.fixture(autouse=True)
def small_dense_last(monkeypatch):
    """The dense-last ordering from any size (it starts at 5e4 unknowns), so that these small
    matrices take that path."""
    monkeypatch.setattr(ordering, "MIN_SIZE", 0)


def test_dense_columns_found_and_ordered_last():
    J = mesh_jacobian()
    A = damped(J)
    n = A.shape[0]
    assert list(ordering.dense_columns(A)) == [n - 3, n - 2, n - 1]
    assert len(ordering.dense_columns(damped(mesh_jacobian(hubs=0)))) == 0
    if lin.available("cholmod"):
        perm, method = ordering.dense_last(A, lin._cholmod())
        assert sorted(perm) == list(range(n)) and set(perm[-3:]) == {n - 3, n - 2, n - 1}
        assert method in ordering.SPARSE_ORDERINGS
        P, gather = ordering.permuted(A, perm)
        assert np.array_equal(P.toarray(), A.toarray()[np.ix_(perm, perm)])
        B = A.copy()
        B.data = np.random.default_rng(1).standard_normal(B.nnz)
        assert np.array_equal(B.data[gather], B[perm][:, perm].tocsc().sorted_indices().data)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("hubs", [0, 3])
def test_direct_paths_match_superlu_and_dense(backend, hubs):
    """Each factorization path (CHOLMOD AMD without dense columns, CHOLMOD dense-last with
    METIS with them, SuperLU) solves to a relative residual of 1e-12, refactors on new values,
    and agrees with a one-shot SuperLU and a dense solve."""
    J = mesh_jacobian(hubs=hubs)
    A = damped(J)
    b = np.random.default_rng(2).standard_normal(A.shape[0])
    s = lin.LinearSolver(backend, iterative_min=None)
    for scale in (1.0, 7.0):  # first: analysis + factor; then a refactorization
        M = (A * scale + 0.3 * sp.identity(A.shape[0])).tocsc()
        x = s.factor(M)(b)
        assert rel_residual(M, x, b) < 1e-12
        ref = spla.splu(M).solve(b)
        dense = np.linalg.solve(M.toarray(), b)
        assert np.linalg.norm(x - ref) <= 1e-9 * np.linalg.norm(ref)
        assert np.linalg.norm(x - dense) <= 1e-9 * np.linalg.norm(dense)
    assert (s.analyses, s.factorizations, s.iterative) == (1, 2, 0)
    if backend == "cholmod":
        assert s.ordering == ("amd" if hubs == 0 else "metis, dense columns last")


@needs_cholmod
def test_dense_last_only_from_its_size(monkeypatch):
    monkeypatch.setattr(ordering, "MIN_SIZE", 10_000)
    A = damped(mesh_jacobian())
    s = lin.LinearSolver("cholmod", iterative_min=None)
    s.factor(A)
    assert s.ordering == "amd"


@needs_cholmod
def test_dense_last_falls_back_to_amd_without_metis(monkeypatch):
    """A CHOLMOD built without METIS refuses the "metis" ordering: the sparse part is then
    ordered by AMD, and the solve is as exact."""
    real = lin._cholmod()
    refused = []

    def analyze(A, mode="auto", ordering_method="default", **kw):
        if ordering_method in ("metis", "nesdis"):
            refused.append(ordering_method)
            raise real.CholmodError("METIS not installed")
        return real.analyze(A, mode=mode, ordering_method=ordering_method, **kw)

    fake = SimpleNamespace(analyze=analyze, CholmodError=real.CholmodError,
                           CholmodNotPositiveDefiniteError=real.CholmodNotPositiveDefiniteError)
    monkeypatch.setattr(lin, "_cholmod", lambda: fake)
    A = damped(mesh_jacobian())
    b = np.ones(A.shape[0])
    s = lin.LinearSolver("cholmod", iterative_min=None)
    x = s.factor(A)(b)
    assert refused == ["metis"] and s.ordering == "amd, dense columns last"
    assert rel_residual(A, x, b) < 1e-12
    assert np.allclose(x, spla.splu(A).solve(b), rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("backend", BACKENDS)
def test_cg_path_and_its_fallback(backend):
    """From ``iterative_min`` unknowns CG solves well-conditioned systems to its tolerance (no
    factorization); on a system where it stalls it falls back to the factorization (exact)
    and keeps to it for that pattern."""
    J = mesh_jacobian(hubs=0)
    A = damped(J, mu=1.0)  # well conditioned
    b = np.random.default_rng(3).standard_normal(A.shape[0])
    s = lin.LinearSolver(backend, iterative_min=100)
    x = s.factor(A)(b)
    assert rel_residual(A, x, b) <= iterative.RTOL
    assert np.linalg.norm(x - spla.splu(A).solve(b)) <= 1e-6 * np.linalg.norm(x)
    assert (s.iterative, s.fallbacks, s.factorizations) == (1, 0, 0)
    # stiff: a strong chain through every unknown (Jacobi-scaled condition number ~ n^2)
    n = A.shape[0]
    D = sp.diags([np.ones(n - 1)], [1], shape=(n - 1, n)) - sp.diags([np.ones(n - 1)], [0],
                                                                     shape=(n - 1, n))
    S = (A + 1e6 * (D.T @ D)).tocsc()
    x = s.factor(S)(b)
    assert (s.fallbacks, s.factorizations) == (1, 1)
    assert rel_residual(S, x, b) < 1e-10
    s.factor(S * 2.0)(b)  # the pattern is a direct one now: no CG try
    assert (s.fallbacks, s.factorizations, s.iterative) == (1, 2, 1)
    small = lin.LinearSolver(backend, iterative_min=10 * n)  # below the size: factored
    small.factor(A)(b)
    assert (small.iterative, small.factorizations) == (0, 1)


def test_pcg_reports_failure_honestly():
    A = damped(mesh_jacobian(hubs=0), mu=1.0)
    b = np.ones(A.shape[0])
    r = iterative.pcg(A, b, maxiter=3)
    assert not r.converged and r.iterations == 3
    assert r.residual == pytest.approx(rel_residual(A, r.x, b), rel=1e-6)
    ind = (A - 1e3 * sp.identity(A.shape[0])).tocsc()  # indefinite: negative curvature
    assert not iterative.pcg(ind, b).converged
    assert iterative.pcg(A, np.zeros_like(b)).converged


def test_in_place_normal_equations_match_fresh_scipy_exactly():
    """J^T J filled in place (kept transpose gather, product scattered into the kept pattern)
    equals scipy's ``J.T @ J`` with sorted indices bit for bit, over successive values, and
    keeps its pattern when entries cancel."""
    J = mesh_jacobian()
    rng = np.random.default_rng(4)
    ne = NormalEquations()
    for it in range(4):
        J.data = rng.standard_normal(J.nnz)
        if it == 3:
            J.data[:40] = 0.0  # some products vanish: scipy drops them, we keep the slots
        M = ne.update(J)
        F = (J.T.tocsr() @ J).tocsr()
        F.sort_indices()
        if it < 3:
            assert np.array_equal(M.indptr, F.indptr) and np.array_equal(M.indices, F.indices)
            assert np.array_equal(M.data, F.data)
        else:
            assert np.array_equal(M.toarray(), F.toarray())
    assert ne.patterns == 1 and ne.fast >= 2


def test_assembly_structure_matches_scipy_coo():
    """Problem's COO -> CSR (duplicates summed, explicit zeros kept, structure kept) against
    scipy's conversion, on random triplets with many duplicates."""
    rng = np.random.default_rng(5)
    rows = rng.integers(0, 50, 2000)
    cols = rng.integers(0, 30, 2000)
    vals = rng.standard_normal(2000)
    prob = Problem.__new__(Problem)
    prob._csr = None
    for v in (vals, -vals * 3.0):
        J = prob._to_csr(rows, cols, v, (50, 30))
        ref = sp.coo_matrix((v, (rows, cols)), shape=(50, 30)).tocsr()
        ref.sort_indices()
        assert np.array_equal(J.indptr, ref.indptr) and np.array_equal(J.indices, ref.indices)
        assert np.allclose(J.data, ref.data, rtol=1e-13, atol=1e-13)


def test_lm_with_cg_steps_matches_factored_steps():
    """An LM solve whose steps come from CG (tolerance 1e-8) takes the same iterations to the
    same energy and point as one with factored steps (the GG dome problem of test_linear)."""
    from tests.helpers.solver_cases import gg_problem

    from gridshell.solver import solve

    prob, x0 = gg_problem(12)
    cg = lin.LinearSolver(iterative_min=1)
    res = solve(prob, x0, method="lm", max_iter=30, linear=cg)
    ref = solve(prob, x0, method="lm", max_iter=30, linear=lin.LinearSolver(iterative_min=None))
    assert cg.iterative >= res.iterations and cg.fallbacks == 0
    assert res.iterations == ref.iterations and res.energy < 0.5 * res.energy0
    assert res.energy == pytest.approx(ref.energy, rel=1e-9)
    assert np.allclose(res.x, ref.x, atol=1e-9)
