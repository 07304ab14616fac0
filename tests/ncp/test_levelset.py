"""Level-set tracing of NCP nets (gridshell.ncp.levelset, paper 4.2.2, eqs. 4.12-4.13)."""
import numpy as np
import pytest

from gridshell.core.errors import InputError
from gridshell.measure.metrics import alignability_error
from gridshell.ncp import levelset as LS
from gridshell.geometry.bspline import uniform_params
from gridshell.ncp.directions import net_directions

from tests.helpers.ncp_cases import pseudosphere, torus


def test_level_values_by_count_and_spacing():
    assert np.allclose(LS.level_values(0.0, 1.0, count=3), [0.25, 0.5, 0.75])
    assert np.allclose(LS.level_values(0.0, 1.0, spacing=0.3), [0.2, 0.5, 0.8])
    for kw in ({}, {"count": 2, "spacing": 0.1}, {"count": 0}, {"spacing": -1.0}):
        with pytest.raises(InputError):
            LS.level_values(0.0, 1.0, **kw)
    assert np.allclose(LS.level_values(0.0, 1.0, spacing=5.0), [0.5])   # the middle curve


def test_level_function_reproduces_u_and_v():
    surf = torus()
    F = LS.level_function(surf, np.arange(144.0), (12, 12), (3, 3))
    u, v = np.array([0.1, 0.73]), np.array([0.4, 0.95])
    assert np.allclose(F.evaluate(u, v)[:, :2], np.stack([u, v], 1))


@pytest.fixture(scope="module")
def torus_net():
    surf = torus()
    d = net_directions(surf, *uniform_params(surf, (24, 24)), mode="phlw")
    return surf, LS.trace(surf, d, curves=8, grid=(160, 160), axis_points=200)


def test_level_functions_follow_the_net_directions(torus_net):
    _, tn = torus_net
    for f in (1, 3):
        assert tn.fits[f].align_rms < 5e-3          # |sin| of the level set / e_f angle
        assert abs(tn.fits[f].density - 1) < 1e-2   # dxi(e_f+1) ~ 1 (eq. 4.13)


def test_traced_net_is_consistent(torus_net):
    surf, tn = torus_net
    net = tn.net
    F1, F3 = tn.fits[1].F, tn.fits[3].F
    i, j = tn.joint_ij.T
    uv = tn.joint_uv
    # joints: both levels at once, on the surface
    assert np.allclose(LS.evaluate_xi(F1, uv[:, 0], uv[:, 1]), tn.levels[1][i], atol=1e-9)
    assert np.allclose(LS.evaluate_xi(F3, uv[:, 0], uv[:, 1]), tn.levels[3][j], atol=1e-9)
    assert np.allclose(net.joints, surf.evaluate(uv[:, 0], uv[:, 1]))
    # loops: A has the least u, C the largest (A->B->C and A->D->C overlap upon alignment)
    Lu = uv[net.loops, 0]
    assert np.all(np.argmin(Lu, axis=1) == 0) and np.all(np.argmax(Lu, axis=1) == 2)
    assert len(net.loops) > 10
    # lamellae: joints are axis vertices, joint_s increases, u increases along the axis
    for lam, auv, jidx in zip(net.lamellae, tn.axis_uv, tn.axis_joint_index):
        assert np.allclose(lam.axis[jidx], net.joints[lam.joints])
        assert np.all(np.diff(lam.joint_s) > 0) and auv[-1, 0] > auv[0, 0]
        F = F1 if lam.family == 1 else F3
        lev = LS.evaluate_xi(F, auv[:, 0], auv[:, 1])
        assert np.ptp(lev) < 1e-8
    assert len(net.family(1)) == len(net.family(3)) == 8
    da = alignability_error(net.joints, net.loops)
    assert np.mean(da) < 0.005 and np.max(da) < 0.01


def test_pseudosphere_asymptotic_net_before_post_optimization():
    """Acceptance (AA, before post-optimization): mean Delta_a < 1 %, max < 3 %."""
    surf = pseudosphere()
    d = net_directions(surf, *uniform_params(surf, (48, 48)), mode="aa")
    tn = LS.trace(surf, d, curves=10)
    da = alignability_error(tn.net.joints, tn.net.loops)
    assert np.mean(da) < 0.01 and np.max(da) < 0.03


def test_xi_evaluation_matches_the_operator():
    """evaluate_xi and the gradient used by the tracing sum over the non-zero basis products
    only; they equal the sparse operator's products (eq. 4.1), ends of the domain included."""
    surf = torus()
    rng = np.random.default_rng(3)
    F = LS.level_function(surf, rng.normal(size=99), (9, 11), (3, 2))
    (u0, u1), (v0, v1) = F.domain
    u = np.concatenate([rng.uniform(u0, u1, 200), [u0, u1, u0, u1]])
    v = np.concatenate([rng.uniform(v0, v1, 200), [v0, v1, v1, v0]])
    xi = F.ctrl[..., 2].reshape(-1)
    for du, dv in ((0, 0), (1, 0), (0, 1), (1, 1), (2, 0), (0, 3)):
        ref = F.operator(u, v, du, dv) @ xi
        assert np.allclose(LS.evaluate_xi(F, u, v, du, dv), ref, rtol=1e-13, atol=1e-12)
    z, g = LS._grad_xi(F, np.stack([u, v], axis=1))
    assert np.allclose(z, F.operator(u, v) @ xi, rtol=1e-13, atol=1e-12)
    assert np.allclose(g[:, 0], F.operator(u, v, 1, 0) @ xi, rtol=1e-13, atol=1e-12)
    assert np.allclose(g[:, 1], F.operator(u, v, 0, 1) @ xi, rtol=1e-13, atol=1e-12)
    with pytest.raises(InputError):
        LS.evaluate_xi(F, u, v[:-1])
    with pytest.raises(InputError):
        LS.evaluate_xi(F, np.array([u1 + 1.0]), np.array([v0]))


def _fit_with_solve(surf, d, family, n_ctrl, omega_f, max_iter=20):
    """The level-set fit as the terms given to gridshell.solver.solve (the reference)."""
    from gridshell.solver import Layout, Problem, solve

    ops = LS.level_operators(surf, d, n_ctrl)
    a1, b1, a2, b2 = (c.reshape(-1)[ops.ok] for c in d.coefficients(family))
    k, (nu, nv) = ops.Du.shape[0], n_ctrl
    prob = Problem(Layout({"xi": nu * nv}))
    prob.add("alignment (4.12)", 1.0, LS.directional_derivative,
             LS.DirectionalDerivative(ops.Du, ops.Dv, a1, b1, np.zeros(k)))
    prob.add("density (4.13)", omega_f, LS.directional_derivative,
             LS.DirectionalDerivative(ops.Du, ops.Dv, a2, b2, np.ones(k)))
    fixed = np.zeros(nu * nv, bool)
    fixed[(nu // 2) * nv + nv // 2] = True
    return solve(prob, np.zeros(nu * nv), fixed=fixed, method="lm", max_iter=max_iter,
                 damping=1e-9, tol_rel=1e-12)


@pytest.mark.parametrize("case", [("pseudo", "aa", 48, (12, 12), 0.01),
                                  ("torus", "cnc", 24, (16, 12), 1.0),
                                  ("torus", "cnc", 6, (12, 12), 0.01)])
def test_level_fit_is_the_solvers_minimum(case):
    """fit_level_function (Jacobian and normal matrix formed once) ends where
    gridshell.solver.solve ends on the same terms: same energy to 1e-9, same control values,
    the same verdict and iterations; one iteration cannot converge; dropped samples are left
    out alike (6 x 6 samples: fewer than the 12 x 12 control values, damping holds them)."""
    name, mode, m, n_ctrl, omega_f = case
    surf = pseudosphere() if name == "pseudo" else torus()
    d = net_directions(surf, *uniform_params(surf, (m, m)), mode=mode)
    if m == 6:
        d.valid[0, :3] = False
    for f in (1, 3):
        fit = LS.fit_level_function(surf, d, f, n_ctrl=n_ctrl, omega_f=omega_f)
        ref = _fit_with_solve(surf, d, f, n_ctrl, omega_f)
        assert fit.converged and ref.converged and fit.iterations == ref.iterations
        E = sum(t["energy"] for t in fit.report.values())
        assert abs(E - ref.energy) <= 1e-9 * ref.energy + 1e-24
        for t, want in ref.report.items():
            assert np.allclose([fit.report[t][k] for k in want], list(want.values()),
                               rtol=1e-6, atol=1e-12)
        xi = fit.F.ctrl[..., 2].reshape(-1)
        assert np.max(np.abs(xi - ref.x)) <= 1e-6 * np.max(np.abs(ref.x))
        one = LS.fit_level_function(surf, d, f, n_ctrl=n_ctrl, omega_f=omega_f, max_iter=1)
        assert not one.converged and one.iterations == 1
    with pytest.raises(InputError):
        LS.fit_level_function(surf, d, 1, n_ctrl=n_ctrl, omega_f=-1.0)
    with pytest.raises(InputError):
        LS.fit_level_function(surf, d, 1, n_ctrl=(8, 8),
                              operators=LS.level_operators(surf, d, n_ctrl))
