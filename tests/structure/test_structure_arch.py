"""A single arch in closed form (issue 28, item 6): the rod model of a two-hinged semicircular
arch (radius R, bending stiffness EI, laterally braced, axial stiffness large) against the
classical results of the force method (Castigliano, bending energy only):

- a point load P at the crown: thrust H = P / pi, crown deflection
  (3 pi / 8 - 1 - 1 / (2 pi)) P R^3 / EI;
- snow, q kN/m2 on the plan area of a strip of loops of width b along the arch (the loads
  module's own plan areas, half of each loop on the arch's joints: w = q b / 2 per metre of
  plan): thrust H = 4 w R / (3 pi), crown bending moment (1/2 - 4 / (3 pi)) w R^2, crown
  deflection ((pi/4 - 1/3) / 2 - 2 / (3 pi)) w R^4 / EI.
Each within 5 %."""
from __future__ import annotations

import numpy as np
import pytest

from gridshell.structure import loads, rod
from gridshell.structure.equilibrium import solve
from gridshell.structure.rodnet import RodNetwork, RodSpec

R, EI, K = 2.0, 50.0, 121


def _arch():
    """The arch as one rod of ``K`` nodes, stress-free as built (rest curvatures its own),
    pinned at both ends, braced out of its plane (y and the frame angles held)."""
    th = np.linspace(0.0, np.pi, K)
    X = np.stack([-R * np.cos(th), np.zeros(K), R * np.sin(th)], 1)
    e = K - 1
    d1 = np.tile([0.0, 1.0, 0.0], (e, 1))
    wbar, mbar = rod.material_curvatures(X, d1)
    lbar = np.linalg.norm(np.diff(X, axis=0), axis=1)
    spec = RodSpec(nodes=np.arange(K), lbar=lbar, EA=np.full(e, 1e4 * EI / R ** 2),
                   B1=np.full(e, EI), B2=np.full(e, EI), GJ=np.full(e, EI),
                   wbar=wbar, mbar=mbar, mass=np.zeros(e))
    a1 = rod.bishop_frame(X, np.array([0.0, 1.0, 0.0]))
    T = rod.unit(np.diff(X, axis=0))
    net = RodNetwork(X, [spec], rod.frame_angle(a1, T, d1), a1)
    fixed = np.zeros(net.n, bool)
    fixed[net.pos_dofs(np.array([0, K - 1])).reshape(-1)] = True
    fixed[net.pos_dofs(np.arange(K))[:, 1]] = True
    fixed[net.theta_dofs(np.arange(e))] = True
    net.fixed = fixed
    return net, X


def _thrust(net, q) -> float:
    g = net.energy(q, 1)[1]
    Rx = g[net.pos_dofs(np.array([0, K - 1]))][:, 0]
    assert Rx.sum() == pytest.approx(0.0, abs=1e-8 * np.abs(Rx).max())   # equal and opposite
    return float(abs(Rx[0]))


def test_a_point_load_at_the_crown_of_a_two_hinged_semicircular_arch():
    net, X = _arch()
    P, crown = 0.5, K // 2
    net.forces[crown, 2] = -P
    res = solve(net)
    assert res.converged
    assert _thrust(net, res.q) == pytest.approx(P / np.pi, rel=0.05)
    w = X[crown, 2] - net.positions(res.q)[crown, 2]
    exact = (3 * np.pi / 8 - 1 - 1 / (2 * np.pi)) * P * R ** 3 / EI      # 3.03 mm
    assert w == pytest.approx(exact, rel=0.05)


def test_snow_on_a_two_hinged_semicircular_arch():
    net, X = _arch()
    b, q_kN = 0.5, 0.002
    J = np.concatenate([X, X + [0.0, b, 0.0]])
    i = np.arange(K - 1)
    loops = np.stack([i, i + 1, K + i + 1, K + i], 1)
    F = loads.snow_forces(J, loops, q_kN)
    net.forces[:] = F[:K]
    w = q_kN * 1e3 * b / 2                                            # N per metre of plan
    assert -F[:K, 2].sum() == pytest.approx(w * 2 * R, rel=1e-12)
    res = solve(net)
    assert res.converged
    assert _thrust(net, res.q) == pytest.approx(4 * w * R / (3 * np.pi), rel=0.05)
    crown = K // 2
    Xq = net.positions(res.q)
    deflection = X[crown, 2] - Xq[crown, 2]
    exact = ((np.pi / 4 - 1 / 3) / 2 - 2 / (3 * np.pi)) * w * R ** 4 / EI     # 2.2 mm
    assert deflection == pytest.approx(exact, rel=0.05)
    # the crown moment from the change of curvature there: EI (kappa - kappa_rest)
    wq, _ = rod.material_curvatures(Xq, np.tile([0.0, 1.0, 0.0], (K - 1, 1)))
    wr, _ = rod.material_curvatures(X, np.tile([0.0, 1.0, 0.0], (K - 1, 1)))
    ds = 0.5 * (net.lbar[crown - 1] + net.lbar[crown])
    M = EI * np.abs(wq - wr)[crown - 1].max() / ds
    assert M == pytest.approx((0.5 - 4 / (3 * np.pi)) * w * R ** 2, rel=0.05)
