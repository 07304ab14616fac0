"""Discrete elastic rods against closed forms (tolerances stated per test) and every energy's
gradient and Hessian against finite differences."""
import numpy as np
import pytest

from gridshell.structure import rod
from gridshell.structure.equilibrium import solve
from gridshell.structure.jet import Jet
from gridshell.structure.rodnet import JointSpec, RodNetwork, RodSpec

# a 20 x 1 mm polypropylene-like strip (SI units)
E, G, W, T = 1.5e9, 0.53e9, 0.02, 0.001
EA, EI_STRONG, EI_WEAK, GJ = E * W * T, E * T * W ** 3 / 12, E * W * T ** 3 / 12, G * W * T ** 3 / 3


# ---------------------------------------------------------------------------------------------
# finite differences of every energy (value -> gradient -> Hessian), random stencils
# ---------------------------------------------------------------------------------------------

def _frames(rng, T_):
    t_old = rod.unit(T_ + 0.1 * rng.normal(size=T_.shape))
    a = rng.normal(size=T_.shape)
    return rod.unit(a - np.sum(a * t_old, -1, keepdims=True) * t_old), t_old


def _cases(rng):
    B = 4
    x = np.cumsum(rng.normal(size=(B, 3, 3)) * 0.3 + [1.0, 0, 0], axis=1)
    a_old, t_old = _frames(rng, rod.unit(np.diff(x, axis=1)))
    bt = rod.BendTwistData(a_old, t_old, 0.2 * rng.normal(size=(B, 2)),
                           rng.uniform(1, 2, B), rng.uniform(1, 2, B),
                           rng.uniform(1, 2, B), 0.1 * rng.normal(size=B), rng.uniform(1, 2, B))
    Xbt = np.concatenate([x.reshape(B, 9), rng.normal(size=(B, 2))], 1)
    xe = np.cumsum(rng.normal(size=(B, 8, 3)) * 0.3 + [1.0, 0, 0], axis=1)
    ja, jt = _frames(rng, rod.unit(xe[:, 1::2] - xe[:, 0::2]))
    jd = rod.JointData(ja, jt, rng.normal(size=(B, 4, 3)), rng.uniform(1, 2, B))
    Xj = np.concatenate([xe.reshape(B, 24), rng.normal(size=(B, 4))], 1)
    md = rod.MomentData(rng.normal(size=B), rod.unit(rng.normal(size=(B, 3))),
                        rng.normal(size=(B, 3)))
    md = md._replace(ref=rod.unit(md.ref - np.sum(md.ref * md.axis, -1, keepdims=True) * md.axis))
    return {
        "stretch": (rod.stretch_energy, x[:, :2].reshape(B, 6),
                    rod.StretchData(rng.uniform(0.5, 1.5, B), rng.uniform(1, 2, B))),
        "bend": (rod.bend_energy, Xbt, bt),
        "twist": (rod.twist_energy, Xbt, bt),
        "joint": (rod.joint_energy, Xj, jd),
        "moment": (rod.moment_energy, x[:, :2].reshape(B, 6), md),
    }


@pytest.mark.parametrize("name", ["stretch", "bend", "twist", "joint", "moment"])
def test_energy_gradient_and_hessian_match_finite_differences(name):
    """Central differences (h = 1e-6) of the energy give the gradient, of the gradient the
    Hessian, to a relative 1e-6."""
    fn, X, d = _cases(np.random.default_rng(7))[name]
    J = fn(Jet.variables(X, 2), d)
    h = 1e-6
    G_fd, H_fd = np.zeros_like(X), np.zeros(X.shape + (X.shape[1],))
    for k in range(X.shape[1]):
        Xp, Xm = X.copy(), X.copy()
        Xp[:, k] += h
        Xm[:, k] -= h
        Jp, Jm = fn(Jet.variables(Xp, 1), d), fn(Jet.variables(Xm, 1), d)
        G_fd[:, k] = (Jp.v - Jm.v) / (2 * h)
        H_fd[:, :, k] = (Jp.g - Jm.g) / (2 * h)
    assert np.abs(J.g - G_fd).max() <= 1e-6 * np.abs(J.g).max()
    assert np.abs(J.h - H_fd).max() <= 1e-6 * np.abs(J.h).max()
    assert np.allclose(J.h, np.swapaxes(J.h, 1, 2), atol=1e-12 * np.abs(J.h).max())
    # the value-only path agrees
    assert np.allclose(fn(Jet.variables(X, 0), d).v, J.v, rtol=1e-14, atol=0)


def test_network_gradient_matches_finite_differences_across_a_frame_update():
    """The assembled network (two rods sharing a joint) after a re-based reference frame: its
    gradient is the derivative of its energy (relative 1e-6)."""
    net = _cross(8)
    rng = np.random.default_rng(3)
    q = net.q0() + 1e-3 * rng.normal(size=net.n)
    net.accept(q)
    q = q + 1e-3 * rng.normal(size=net.n)
    _, g, H = net.energy(q, 2)
    h = 1e-7
    for k in rng.choice(net.n, 12, replace=False):
        e = np.zeros(net.n)
        e[k] = h
        fd = (net.energy(q + e, 0)[0] - net.energy(q - e, 0)[0]) / (2 * h)
        assert abs(fd - g[k]) <= 1e-5 * np.abs(g).max()
        gd = (net.energy(q + e, 1)[1] - net.energy(q - e, 1)[1]) / (2 * h)
        assert np.abs(gd - H[:, [k]].toarray().ravel()).max() <= 1e-5 * abs(H).max()


# ---------------------------------------------------------------------------------------------
# builders
# ---------------------------------------------------------------------------------------------

def _strip(X, d1=None, B1=EI_STRONG, B2=EI_WEAK, gj=GJ, ea=EA, rest=None):
    """A rod through ``X (n,3)`` with width directions ``d1`` (default +y projected), rest
    straight (or ``rest``: (wbar, mbar)) and rest lengths its edge lengths."""
    X = np.asarray(X, float)
    n = len(X) - 1
    Tn = rod.unit(np.diff(X, axis=0))
    if d1 is None:
        d1 = np.tile([0.0, 1.0, 0.0], (n, 1))
    a1 = rod.bishop_frame(X)
    theta = rod.frame_angle(a1, Tn, d1)
    wbar, mbar = rest if rest is not None else (np.zeros((n - 1, 2)), np.zeros(n - 1))
    spec = RodSpec(np.arange(n + 1), np.linalg.norm(np.diff(X, axis=0), axis=1),
                   np.full(n, ea), np.full(n, B1), np.full(n, B2), np.full(n, gj), wbar, mbar,
                   np.zeros(n))
    return RodNetwork(X, [spec], theta, a1)


def _line(n, L):
    return np.stack([np.linspace(0, L, n + 1), np.zeros(n + 1), np.zeros(n + 1)], 1)


def _fix(net, nodes=(), thetas=(), comps=None):
    fixed = np.zeros(net.n, bool)
    for i in nodes:
        fixed[3 * i:3 * i + 3] = True if comps is None else [c in comps for c in range(3)]
    for e in thetas:
        fixed[3 * len(net.X) + e] = True
    net.fixed = fixed
    return net


def _cross(n):
    """Two straight rods crossing at their middle nodes (shared node), a joint between them."""
    X1 = _line(n, 1.0) - [0.5, 0, 0]
    X2 = X1[:, [1, 0, 2]]
    X2 = np.delete(X2, n // 2, axis=0)
    X = np.concatenate([X1, X2])
    nodes2 = np.insert(np.arange(n + 1, 2 * n + 1), n // 2, n // 2)
    rods, th, a1 = [], [], []
    for nodes, d in ((np.arange(n + 1), [0, 1.0, 0]), (nodes2, [1.0, 0, 0])):
        P = X[nodes]
        a = rod.bishop_frame(P)
        th.append(rod.frame_angle(a, rod.unit(np.diff(P, axis=0)), np.tile(d, (n, 1))))
        a1.append(a)
        rods.append(RodSpec(nodes, np.linalg.norm(np.diff(P, axis=0), axis=1), np.full(n, EA),
                            np.full(n, EI_STRONG), np.full(n, EI_WEAK), np.full(n, GJ),
                            0.05 * np.ones((n - 1, 2)), np.zeros(n - 1), np.zeros(n)))
    m = n // 2
    c = np.zeros((4, 3))
    c[:2, 2], c[2:, 2] = 0.5, -0.5
    # both strips' thickness directions m2 are +-z at the design: sign them alike
    c[2:, 2] *= np.sign(np.cross([0, 1.0, 0], [1.0, 0, 0])[2])
    joint = JointSpec(np.array([m - 1, m, n + m - 1, n + m]), c, 100 * EI_STRONG)
    return RodNetwork(X, rods, np.concatenate(th), np.concatenate(a1), joints=[joint])


# ---------------------------------------------------------------------------------------------
# closed forms
# ---------------------------------------------------------------------------------------------

def test_cantilever_tip_deflection_is_PL3_over_3EI():
    """A 1 m strip, 40 elements, clamped (first edge and its frame held), a tip load P across
    its thickness small enough that the deflection is 1 % of the length: delta = P L^3 / 3EI
    within 0.5 % (L from the clamp, the first edge's midpoint, to the tip)."""
    n, L = 40, 1.0
    net = _fix(_strip(_line(n, L)), nodes=(0, 1), thetas=(0,))
    Lc = L - 0.5 * L / n
    P = 0.01 * 3 * EI_WEAK / Lc ** 2
    net.forces[-1, 2] = -P
    res = solve(net)
    assert res.converged, res.message
    tip = net.positions(res.q)[-1]
    assert tip[2] == pytest.approx(-P * Lc ** 3 / (3 * EI_WEAK), rel=5e-3)
    assert abs(tip[1]) < 1e-9  # no coupling into the strong direction


def test_end_moment_bends_a_strip_into_a_circle_of_radius_EI_over_M():
    """A clamped 1 m strip (40 elements) under an end moment M about its width axis takes
    the arc of radius R = EI/M (here L/R = 1 rad): tip position within 0.3 % of L, stored
    energy M^2 L_b / 2EI within 0.5 % (L_b = L - h: the vertices' Voronoi lengths, from the
    clamped edge's midpoint to the loaded edge's), and the moment in the strip EI/R recovered
    from the energy of the bent shape (dE/dphi) within 0.5 %."""
    n, L = 40, 1.0
    net = _strip(_line(n, L))
    Lc = L - 0.5 * L / n
    R = Lc
    M = EI_WEAK / R
    net.moments = [(n - 1, M, np.array([0.0, 1.0, 0.0]), np.array([1.0, 0.0, 0.0]))]
    net.__post_init__()
    _fix(net, nodes=(0, 1), thetas=(0,))
    res = solve(net)
    assert res.converged, res.message
    P = net.positions(res.q)
    # the clamp's centre: the first edge's midpoint; moment about +y turns x towards -z
    c = 0.5 * (P[0] + P[1])
    tip = P[-1] - c
    phi = Lc / R
    expect = np.array([R * np.sin(phi), 0.0, -R * (1 - np.cos(phi))])
    assert np.linalg.norm(tip - expect) < 3e-3 * L
    Eel = net.energy(res.q, 0, parts=True)[3]
    assert Eel["bend"] == pytest.approx(M ** 2 * (L - L / n) / (2 * EI_WEAK), rel=5e-3)
    # moment = dE/d(phi): energy of the same strip on arcs of turning angle phi +- dphi
    def arc_energy(ph):  # turning angle ph over the bent length L - h
        Rr = (L - L / n) / ph
        s = np.linspace(0, L, n + 1) - 0.5 * L / n
        X = np.stack([Rr * np.sin(s / Rr), np.zeros_like(s), -Rr * (1 - np.cos(s / Rr))], 1)
        return _strip(X).energy(_strip(X).q0(), 0, parts=True)[3]["bend"]
    dphi = 1e-3
    phi_b = (L - L / n) / R
    moment = (arc_energy(phi_b + dphi) - arc_energy(phi_b - dphi)) / (2 * dphi)
    assert moment == pytest.approx(EI_WEAK / R, rel=5e-3)


def test_strip_bent_into_a_ring_stores_EI_L_over_2R2():
    """A straight strip (rest) laid on a full ring of radius R (60 elements, positions held,
    frame angles free): it turns its weak axis into the bend and stores E = EI_weak L / 2R^2
    within 0.5 % (L = 2 pi R (n-1)/n: the ring's ends meet at a node that does not bend); with
    the strong axis forced into the bend, EI_strong instead."""
    n, R = 60, 0.2
    s = np.linspace(0, 2 * np.pi * R, n + 1)
    X = np.stack([R * np.cos(s / R), R * np.sin(s / R), np.zeros_like(s)], 1)
    radial = -rod.unit(0.5 * (X[1:] + X[:-1]))
    L = 2 * np.pi * R * (n - 1) / n
    # width along z (the ring's axis): the bend is across the thickness (weak)
    net = _fix(_strip(X, d1=np.tile([0, 0, 1.0], (n, 1)) + 0.3 * radial), nodes=range(n + 1))
    res = solve(net)
    assert res.converged, res.message
    parts = net.energy(res.q, 0, parts=True)[3]
    assert parts["bend"] == pytest.approx(EI_WEAK * L / (2 * R ** 2), rel=5e-3)
    # width along the radius, every frame angle held: strong-axis bending
    net = _fix(_strip(X, d1=radial), nodes=range(n + 1), thetas=range(n))
    parts = net.energy(net.q0(), 0, parts=True)[3]
    assert parts["bend"] == pytest.approx(EI_STRONG * L / (2 * R ** 2), rel=5e-3)


def test_twisted_strip_torque_is_GJ_phi_over_L():
    """A straight strip (30 elements) with its end frames turned by phi = 0.5 rad and the
    positions held: uniform twist, torque at the ends GJ phi / L and energy GJ phi^2 / 2L to
    1e-9 (exact for the discretization; L between the end edges' midpoints)."""
    n, Lr = 30, 0.6
    net = _strip(_line(n, Lr))
    q0 = net.q0()
    phi = 0.5
    q0[3 * (n + 1) + n - 1] += phi
    _fix(net, nodes=range(n + 1), thetas=(0, n - 1))
    res = solve(net, q0)
    assert res.converged, res.message
    L = Lr * (n - 1) / n
    _, g, _, parts = net.energy(res.q, 1, parts=True)
    torque = g[3 * (n + 1) + n - 1]
    assert torque == pytest.approx(GJ * phi / L, rel=1e-9)
    assert g[3 * (n + 1)] == pytest.approx(-GJ * phi / L, rel=1e-9)
    assert parts["twist"] == pytest.approx(GJ * phi ** 2 / (2 * L), rel=1e-9)


def test_euler_buckling_load_of_a_pinned_column_is_pi2_EI_over_L2():
    """A pinned-pinned strip (40 elements) under an axial load P: the smallest eigenvalue of
    the Hessian at the straight, compressed equilibrium crosses zero at P = pi^2 EI_weak / L^2,
    found by bisection, within 2 % (and 0.5 %)."""
    n, L = 40, 1.0
    Pe = np.pi ** 2 * EI_WEAK / L ** 2

    def lowest(P):
        """Smallest free eigenvalue of the Hessian at the straight column compressed by P."""
        net = _strip(_line(n, L))
        net.forces[-1, 0] = -P
        fixed = np.zeros(net.n, bool)
        fixed[0:3] = True                       # pin
        fixed[3 * n + 1:3 * n + 3] = True       # roller: the end slides along x only
        fixed[3 * (n + 1)] = True               # the twist's rigid turn
        q = net.q0()
        q[0:3 * (n + 1):3] *= 1.0 - P / EA      # uniform compression: the equilibrium
        _, g, H = net.energy(q, 2)
        free = ~fixed
        assert np.abs(g[free]).max() < 1e-6 * P  # round-off of EA-sized terms
        return np.linalg.eigvalsh(H.toarray()[np.ix_(free, free)])[0]

    lo, hi = 0.8 * Pe, 1.2 * Pe
    assert lowest(lo) > 0 > lowest(hi)
    for _ in range(25):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if lowest(mid) > 0 else (lo, mid)
    assert 0.5 * (lo + hi) == pytest.approx(Pe, rel=0.02)
    assert 0.5 * (lo + hi) == pytest.approx(Pe, rel=5e-3)


def test_helix_bends_and_twists_like_its_frenet_frame():
    """A straight strip laid on a helix (radius r, pitch 2 pi c; 60 elements, positions held,
    end frames held along the helix's principal normal, inner frame angles free) settles with
    its thickness along the principal normal (a geodesic strip on the cylinder): curvature
    kappa = r / (r^2 + c^2) across the thickness and twist rate tau = c / (r^2 + c^2), energy
    (EI_weak kappa^2 + GJ tau^2) L_b / 2 within 1 % (L_b = L (n-1)/n, between the end edges'
    midpoints), thickness direction within 1 degree of the principal normal everywhere."""
    n, r, c = 60, 0.1, 0.03
    t = np.linspace(0, 2.0 * np.pi, n + 1)
    X = np.stack([r * np.cos(t), r * np.sin(t), c * t], 1)
    tm = 0.5 * (t[1:] + t[:-1])
    Nrm = -np.stack([np.cos(tm), np.sin(tm), np.zeros_like(tm)], 1)   # principal normal
    Tn = rod.unit(np.diff(X, axis=0))
    width = rod.unit(np.cross(Nrm, Tn))
    net = _strip(X, d1=width)
    q0 = net.q0()
    rng = np.random.default_rng(1)
    q0[3 * (n + 1) + 1:3 * (n + 1) + n - 1] += 0.2 * rng.normal(size=n - 2)
    _fix(net, nodes=range(n + 1), thetas=(0, n - 1))
    res = solve(net, q0)
    assert res.converged, res.message
    kappa, tau = r / (r * r + c * c), c / (r * r + c * c)
    L = np.sqrt(r * r + c * c) * 2 * np.pi * (n - 1) / n
    parts = net.energy(res.q, 0, parts=True)[3]
    total = parts["bend"] + parts["twist"]
    assert total == pytest.approx(0.5 * (EI_WEAK * kappa ** 2 + GJ * tau ** 2) * L, rel=1e-2)
    th = res.q[3 * (n + 1):]
    a2 = np.cross(net.tref, net.a1)
    m2 = -np.sin(th)[:, None] * net.a1 + np.cos(th)[:, None] * a2
    ang = np.degrees(np.arccos(np.clip(np.abs(np.sum(m2 * Nrm, 1)), 0, 1)))
    assert ang.max() < 1.0


def test_crossing_strips_keep_a_common_joint_axis_and_turn_about_it():
    """Two crossing strips joined at their middle: turning one strip about the joint axis
    (z) costs no joint energy, tilting it about an in-surface axis does (the pin)."""
    net = _cross(8)
    q = net.q0()
    d = net.joint_data()
    e0 = rod.joint_energy(Jet.variables(q[net.joint_idx], 0), d).v[0]
    assert e0 < 1e-20

    def turned(axis, ang):
        from scipy.spatial.transform import Rotation

        Rm = Rotation.from_rotvec(ang * np.asarray(axis, float)).as_matrix()
        qq = q.copy()
        P = net.positions(qq)
        nodes = net.rods[1].nodes
        P[nodes] = P[nodes] @ Rm.T
        edges = np.arange(net.rod_edges[1][0], net.rod_edges[1][1])
        dd = d._replace(a_old=d.a_old.copy(), t_old=d.t_old.copy())
        for q_, e in enumerate(net.joint_edges[0]):
            if e in edges:
                dd.a_old[0, q_] = Rm @ d.a_old[0, q_]
                dd.t_old[0, q_] = Rm @ d.t_old[0, q_]
        return rod.joint_energy(Jet.variables(qq[net.joint_idx], 0), dd).v[0]

    assert turned([0, 0, 1], 0.3) < 1e-20
    k = net.joints[0].k
    tilt = turned([1, 0, 0], 0.01)
    assert tilt == pytest.approx(0.5 * k * (2 * np.sin(0.005)) ** 2, rel=1e-6)
