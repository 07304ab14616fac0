"""Snow on a deployed gridshell (issue 28, item 6): the nodal snow forces against the plan
area in closed form (a flat square, a spherical cap: pi a^2), the rod model's deflection
against Euler-Bernoulli (a simply supported beam under a central point load: P L^3 / 48 EI),
the per-lamella node forces against finite differences of the lamella's own energy, and the
demo dome at full scale in spruce under 1 kN/m2: reactions carry self-weight plus snow."""
from __future__ import annotations

import numpy as np
import pytest

from gridshell.structure import loads, rod
from gridshell.structure.equilibrium import simulate, solve
from gridshell.structure.jet import Jet
from gridshell.structure.rodnet import RodNetwork, RodSpec, _bend_plus_twist


def _grid(n: int, side: float):
    t = np.linspace(0, side, n)
    X, Y = np.meshgrid(t, t, indexing="ij")
    J = np.stack([X.ravel(), Y.ravel(), 0.3 * np.sin(X.ravel())], 1)
    idx = np.arange(n * n).reshape(n, n)
    loops = np.stack([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]], -1).reshape(-1, 4)
    return J, loops


def test_snow_on_a_square_is_q_times_its_plan_area():
    J, loops = _grid(7, 4.0)
    F = loads.snow_forces(J, loops, 1.5)
    assert F[:, :2].max() == 0 and F[:, 2].sum() == pytest.approx(-1.5e3 * 16.0, rel=1e-12)
    assert loads.plan_areas(J, loops).sum() == pytest.approx(16.0, rel=1e-12)


def test_snow_on_a_spherical_cap_is_q_pi_a_squared():
    R, a, nr, nt = 5.0, 3.0, 24, 256
    r = np.linspace(0, a, nr + 1)[1:]
    th = np.linspace(0, 2 * np.pi, nt, endpoint=False)
    P = [np.array([[0.0, 0.0, R]])]
    for ri in r:
        x, y = ri * np.cos(th), ri * np.sin(th)
        P.append(np.stack([x, y, np.sqrt(R ** 2 - ri ** 2) * np.ones_like(x)], 1))
    J = np.concatenate(P)
    ring = lambda i: 1 + i * nt + np.arange(nt)                       # noqa: E731
    tris = np.stack([np.zeros(nt, int), ring(0), np.roll(ring(0), -1), -np.ones(nt, int)], 1)
    quads = [np.stack([ring(i), ring(i + 1), np.roll(ring(i + 1), -1), np.roll(ring(i), -1)], 1)
             for i in range(nr - 1)]
    loops = np.concatenate([tris, *quads])
    F = loads.snow_forces(J, loops, 1.0)
    exact = np.pi * a ** 2 * 1e3
    inscribed = 0.5 * nt * np.sin(2 * np.pi / nt) * a ** 2 * 1e3      # the polygon's own
    assert -F[:, 2].sum() == pytest.approx(inscribed, rel=1e-10)
    assert -F[:, 2].sum() == pytest.approx(exact, rel=2e-4)


def _beam(k: int = 41, L: float = 1.0, EI: float = 2.0):
    X = np.stack([np.linspace(0, L, k), np.zeros(k), np.zeros(k)], 1)
    e = k - 1
    spec = RodSpec(nodes=np.arange(k), lbar=np.full(e, L / e), EA=np.full(e, 1e7),
                   B1=np.full(e, EI), B2=np.full(e, EI), GJ=np.full(e, 1.0),
                   wbar=np.zeros((k - 2, 2)), mbar=np.zeros(k - 2), mass=np.zeros(e))
    net = RodNetwork(X, [spec], np.zeros(e), np.tile([0.0, 1.0, 0.0], (e, 1)))
    fixed = np.zeros(net.n, bool)
    fixed[net.pos_dofs(0)] = True                       # a pin
    fixed[net.pos_dofs(k - 1)[1:]] = True               # a roller: free along the beam
    fixed[net.theta_dofs(np.array([0]))] = True
    net.fixed = fixed
    return net


def test_a_simply_supported_beam_deflects_as_euler_bernoulli():
    L, EI, P = 1.0, 2.0, 0.2
    net = _beam(41, L, EI)
    mid = 20
    net.forces[mid, 2] = -P
    res = solve(net)
    assert res.converged
    w = -net.positions(res.q)[mid, 2]
    assert w == pytest.approx(P * L ** 3 / (48 * EI), rel=0.02)      # 2.08 mm
    # the reactions carry the load, half each
    g = net.energy(res.q, 1)[1]
    R = g[net.pos_dofs(np.array([0, 40]))].reshape(-1, 3)
    assert R[:, 2].sum() == pytest.approx(P, rel=1e-8)


def test_node_forces_of_each_lamella_are_minus_its_energy_gradient():
    net = _beam(9)
    rng = np.random.default_rng(3)
    q = net.q0() + 1e-3 * rng.normal(size=net.n)
    nodes = np.array([2, 4, 5])
    F = loads.rod_node_forces(net, q, nodes)[0]

    def energy(qq):
        s = rod.stretch_energy(Jet.variables(qq[net.stretch_idx], 0),
                               rod.StretchData(net.lbar, net.EA)).v.sum()
        return s + _bend_plus_twist(Jet.variables(qq[net.bend_idx], 0), net.bend_data()).v.sum()

    h = 1e-7
    for j, nd in enumerate(nodes):
        for c in range(3):
            d = np.zeros(net.n)
            d[3 * nd + c] = h
            fd = (energy(q + d) - energy(q - d)) / (2 * h)
            assert F[j, c] == pytest.approx(-fd, rel=1e-5, abs=1e-6 * np.abs(F).max())


@pytest.fixture(scope="module")
def dome_1to1():
    from gridshell import data
    from gridshell.gg.pipeline import design_gg

    bundle, _ = design_gg(data.path("dome.obj"), grid=(12, 12), n_lamellae=8, frames=0)
    return bundle


def test_the_dome_at_full_scale_in_spruce_under_snow(dome_1to1):
    from gridshell.structure import Section, get_material

    spruce = get_material("spruce")
    eq = simulate(dome_1to1, spruce, Section(80, 20, 1.0), snow=1.0)
    f = eq.figures
    assert eq.result.converged and f["gravity"].startswith("self-weight + snow 1")
    plan = loads.plan_areas(dome_1to1.net.joints, dome_1to1.net.loops).sum()
    on = eq.model.joint_node >= 0
    applied = -loads.snow_forces(dome_1to1.net.joints, dome_1to1.net.loops, 1.0)[on, 2].sum()
    assert f["snow_total_kN"] == pytest.approx(applied / 1e3, rel=1e-12)
    assert applied == pytest.approx(plan * 1e3, rel=0.05)
    assert f["reaction_sum_N"][2] == pytest.approx(f["weight_N"] + applied, rel=1e-6)
    assert 0 < f["deflection_vertical_max_mm"] <= f["deflection_max_mm"]
    assert f["span_over_deflection"] == pytest.approx(
        1e3 * f["span_m"] / f["deflection_max_mm"], rel=1e-12)
    assert f["bolt_shear_max_N"] > 0 and np.isfinite(f["bolt_shear_max_N"])
    assert f["bolt_shear_max_N"] >= f["bolt_shear_mean_N"]
