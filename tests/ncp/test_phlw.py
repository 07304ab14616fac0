"""PHLW / CNC / PK surface design (gridshell.ncp.phlw, paper 3.4 and 4.2.1).

Reference surfaces are analytic and built here (their formulas are the reference data):
- pseudosphere x = (sech s cos phi, sech s sin phi, s - tanh s), s in [0.5, 1.5], phi in [0, 1.5]:
  K = -1, parameter lines principal (rows = s = const: parallels);
- a torus zone (R = 2, r = 1), rows = parallels: a surface of revolution is PHLW with the
  parallels as rows;
- the saddle z = 0.3 (x^2 - y^2) over [-1, 1]^2, whose grid lines are up to 15 degrees off
  the principal directions.
Sizes are below the paper's (7 x 7 control points, 12 x 12 samples) to keep the file fast;
benchmarks/phlw.py runs the paper's 9 x 9 / 18 x 18.
"""
import numpy as np
import pytest

from gridshell.geometry.bspline import BSplineSurface, fit_grid, uniform_params
from gridshell.core.errors import InputError
from gridshell.geometry.grid import grid_quads
from gridshell.ncp import phlw as P
from gridshell.ncp.reference import initial_surface

DENSE = np.linspace(0.0, 1.0, 60)


def pseudosphere(a=20, b=20):
    s, p = np.meshgrid(np.linspace(0.5, 1.5, a), np.linspace(0, 1.5, b), indexing="ij")
    return np.stack([np.cos(p) / np.cosh(s), np.sin(p) / np.cosh(s), s - np.tanh(s)], -1)


def torus(a=20, b=20, R=2.0, r=1.0):
    th, ph = np.meshgrid(np.linspace(-0.8, 0.8, a), np.linspace(0, 1.2, b), indexing="ij")
    rho = R + r * np.cos(th)
    return np.stack([rho * np.cos(ph), rho * np.sin(ph), r * np.sin(th)], -1)


def saddle(a=20, b=20):
    x, y = np.meshgrid(np.linspace(-1, 1, a), np.linspace(-1, 1, b), indexing="ij")
    return np.stack([x, y, 0.3 * (x ** 2 - y ** 2)], -1)


def mesh_of(Pg):
    return Pg.reshape(-1, 3), grid_quads(*Pg.shape[:2])


def fitted(Pg, n=7):
    V, F = mesh_of(Pg)
    return initial_surface(V, F, n_ctrl=(n, n), degree=(4, 4)).surface, (V, F)


# --------------------------------------------------------------------------- building blocks

@pytest.mark.parametrize("mode", ["phlw", "cnc", "aa"])
def test_fit_rows_recovers_exact_coefficients(mode):
    rng = np.random.default_rng(0)
    R, m = 5, 9
    n = {"phlw": rng.uniform(-1, 1, R), "cnc": np.full(R, 0.3), "aa": np.zeros(R)}[mode]
    t = rng.uniform(0.2, 1.0, R)
    H = rng.uniform(-1, 1, (R, m))
    K = 2 * n[:, None] * H - (n * n + t * t)[:, None]
    fit = P.fit_rows(K, H, mode)
    assert np.allclose(fit.n, n) and np.allclose(fit.t, t)
    assert len(fit.clamped) == 0


def test_fit_rows_phlw_equals_a_line_fit_per_row():
    """The rows' lines are fitted all at once: the same coefficients as np.polyfit row by row
    (noisy rows, and a row whose H is constant, which gets n = mean H)."""
    rng = np.random.default_rng(7)
    H = rng.normal(0.3, 0.2, size=(40, 25))
    n0, t0 = rng.normal(size=(40, 1)), rng.uniform(0.5, 1.0, size=(40, 1))
    K = 2 * n0 * H - (n0 ** 2 + t0 ** 2) + 1e-3 * rng.normal(size=H.shape)
    H[5] = 0.7
    fit = P.fit_rows(K, H, "phlw")
    for i in range(len(H)):
        if i == 5:
            n, beta = H[i].mean(), np.mean(K[i] - 2 * H[i].mean() * H[i])
        else:
            alpha, beta = np.polyfit(H[i], K[i], 1)
            n = alpha / 2
        assert -beta - n * n > 0 and len(fit.clamped) == 0
        assert fit.n[i] == pytest.approx(n, rel=1e-10, abs=1e-12)
        assert fit.t[i] == pytest.approx(np.sqrt(-beta - n * n), rel=1e-9)


def test_fit_rows_reports_secant_rows():
    H = np.linspace(-1, 1, 7)[None, :]
    K = 0.5 * H + 0.8               # a line crossing K = H^2: t^2 < 0
    fit = P.fit_rows(K, H, "phlw")
    assert fit.clamped.tolist() == [0] and fit.t[0] >= 0


def test_auxiliaries_satisfy_every_constraint_exactly():
    surf, _ = fitted(saddle())
    u, v = uniform_params(surf, (6, 5))
    data = P.make_samples(surf, u, v, "phlw")
    lay = P.make_layout(surf.n_ctrl, 30, 6, "phlw")
    aux = P.init_auxiliary(surf.ctrl.reshape(-1, 3), data)
    x = lay.pack({"C": surf.ctrl.reshape(-1, 3), **aux, "n": np.zeros(6), "t": np.ones(6)})
    for fn in (P.normal_eq, P.first_form_eq, P.delta_eq, P.sqrt_delta_eq, P.second_form_eq,
               P.curvature_eq):
        assert np.max(np.abs(fn(x, lay, data).r)) < 1e-10, fn.__name__


def test_unknown_mode_and_weight_are_named():
    surf, ref = fitted(torus(8, 8), 5)
    with pytest.raises(InputError, match="mode"):
        P.optimize_phlw(surf, ref, mode="xyz")
    with pytest.raises(InputError, match="omega_x"):
        P.optimize_phlw(surf, ref, weights={"omega_x": 1.0})


def test_triangle_mesh_reference_is_parameterized_with_libigl():
    V, Fq = mesh_of(torus(15, 15))
    Ft = np.concatenate([Fq[:, [0, 1, 2]], Fq[:, [0, 2, 3]]])
    fit = initial_surface(V, Ft, n_ctrl=(7, 7))
    assert fit.method == "parameterized"
    assert fit.rms < 2e-3 * np.linalg.norm(V.max(0) - V.min(0))
    grid = initial_surface(V, Fq, n_ctrl=(7, 7))
    assert grid.method == "grid" and grid.grid_shape == (15, 15)


def test_net_direction_check_names_umbilic_and_no_net_regions():
    # sphere patch: all umbilic
    th, ph = np.meshgrid(np.linspace(0.6, 1.2, 12), np.linspace(0, 0.8, 12), indexing="ij")
    S = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], -1)
    sphere, _ = fit_grid(S, 6, 6, 3, 3)
    chk = P.net_direction_check(sphere, np.zeros(8), samples=(8, 8), umbilic_tol=0.05)
    assert chk.umbilic.all() and chk.regions[0]["kind"] == "umbilic"
    assert "umbilic" in chk.messages[0] and not chk.ok
    # pseudosphere with n far outside [kappa_I, kappa_II]: no real net direction
    ps, _ = fit_grid(pseudosphere(12, 12), 6, 6, 3, 3)
    chk = P.net_direction_check(ps, np.full(8, 50.0), samples=(8, 8))
    assert chk.out_of_range.all() and chk.regions[0]["kind"] == "no-net"
    assert chk.regions[0]["u"] == (0.0, 1.0)
    # asymptotic net (n = 0) on K < 0: fine everywhere
    assert P.net_direction_check(ps, None, samples=(8, 8)).ok


# --------------------------------------------------------------------------- acceptance

def test_aa_keeps_the_pseudosphere_with_constant_K_per_row(tmp_path):
    surf, ref = fitted(pseudosphere())
    res = P.optimize_phlw(surf, ref, mode="aa", samples=(10, 10), outer=2, max_iter=15)
    assert res.deviation < 0.5
    assert np.all(res.n_rows == 0)
    g = P._grid_geometry(res.surface, res.u_rows, res.v_samples)
    K_row = -res.t_rows[:, None] ** 2
    assert np.max(np.abs(g["K"] - K_row) / np.abs(g["K"])) < 1e-3
    # between the samples too (Fig. 14): K refitted per row on a 60 x 60 grid
    assert np.max(P.row_relation_residual(res.surface, DENSE, DENSE, mode="aa")) < 1e-3
    # with the optimized K_row themselves, at the optimization rows and dense along them
    assert np.max(P.row_relation_residual(res.surface, res.u_rows, DENSE, res.n_rows,
                                          res.t_rows, mode="aa")) < 1e-3
    assert res.net_check.ok
    files = P.write_phlw(tmp_path / "out", res, sample_grid=(20, 20))
    for f in files.values():
        assert (tmp_path / "out" / f.split("/")[-1]).stat().st_size > 0
    rows = np.loadtxt(files["rows"], delimiter=",", skiprows=1)
    assert rows.shape == (10, 6) and np.allclose(rows[:, 3], 1.0)
    assert np.allclose(rows[:, 5], rows[:, 1] ** 2 + rows[:, 2] ** 2)
    assert BSplineSurface.load(files["surface"]).shape == (7, 7)
    with open(files["curvature_diagram"], "rb") as fh:
        assert fh.read(8) == b"\x89PNG\r\n\x1a\n"


def test_phlw_converges_on_a_surface_of_revolution():
    surf, ref = fitted(torus())
    res = P.optimize_phlw(surf, ref, mode="phlw", samples=(10, 10), outer=2, max_iter=15)
    assert res.converged, res.history
    assert res.report_after["relation_max_rel"] < 1e-4
    assert np.max(P.row_relation_residual(res.surface, DENSE, DENSE)) < 1e-4
    assert np.max(P.row_relation_residual(res.surface, res.u_rows, DENSE, res.n_rows,
                                          res.t_rows)) < 1e-4
    assert res.deviation < 0.5
    # E_beta picks the net angle pi/4: n_u = H on a parallel, t_u = sqrt(H^2 - K)
    assert res.net_check.ok
    assert np.allclose(res.net_check.sin2beta, 0.5, atol=2e-2)


def test_phlw_on_a_saddle_aligns_parameter_lines_with_principal_directions():
    surf, ref = fitted(saddle())
    res = P.optimize_phlw(surf, ref, mode="phlw", samples=(12, 12), outer=3, max_iter=20)
    assert res.converged, res.history
    before, after = res.report_before, res.report_after
    assert before["angle_max_deg"] > 10
    assert after["E_PHLW"]["total"] * 100 <= before["E_PHLW"]["total"]
    assert after["angle_max_deg"] < 1.0
    assert res.deviation < 5.0
    assert after["relation_max_rel"] < 2e-3
    # denser than the optimization sampling (Fig. 14)
    assert np.max(P.principal_angle_error(res.surface, DENSE, DENSE)) < 1.0
    assert np.max(P.row_relation_residual(res.surface, DENSE, DENSE)) < 2e-3
    # each optimization row on its own fitted line (n_u, t_u), densely along the row
    assert np.max(P.row_relation_residual(res.surface, res.u_rows, DENSE, res.n_rows,
                                          res.t_rows)) < 2e-3
