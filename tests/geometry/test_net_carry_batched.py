"""The lamella axes carried to joint states with the displacement splines of all lamellae
solved at once (gridshell.geometry.net._carry_axes, gridshell.geometry.spline_batch) are the axes carried lamella
by lamella with scipy's CubicSpline, bit for bit."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import CubicSpline

from gridshell.geometry.net import Lamella, Net, _smooth_at, carried_axes, move_joints_states
from gridshell.geometry.spline_batch import cubic_splines_at


def _bits(a) -> np.ndarray:
    return np.ascontiguousarray(np.asarray(a, float)).view(np.int64)


def _same(a, b) -> bool:
    a, b = np.asarray(a, float), np.asarray(b, float)
    return a.shape == b.shape and np.array_equal(_bits(a), _bits(b))


# ---- the reference: one lamella at a time, scipy's CubicSpline (net._carry_axis before) -------

def _norms(V):
    return np.sqrt(V[..., 0] * V[..., 0] + V[..., 1] * V[..., 1] + V[..., 2] * V[..., 2])


def _ref_arclengths(X):
    seg = _norms(np.diff(X, axis=1))
    return np.concatenate([np.zeros((len(X), 1)), np.cumsum(seg, axis=1)], axis=1)


def _ref_carry_axis(lam: Lamella, Js: np.ndarray):
    X, js = lam.axis, lam.joint_s
    if len(X) < 2 or len(js) == 0:
        Xs = np.stack([X + (J[lam.joints[0]] - X[0] if len(js) else 0) for J in Js])
        return Xs, _ref_arclengths(Xs), js, None
    X = X[np.concatenate([[True], _norms(np.diff(X, axis=0)) > 0])]
    s = _ref_arclengths(X[None])[0]
    js = np.clip(js, 0.0, s[-1])
    seg = np.diff(s)
    near = 0.2 * np.interp(s, 0.5 * (s[:-1] + s[1:]), seg) if len(seg) else s
    keep = np.min(np.abs(s[:, None] - js[None, :]), axis=1) > near
    at = _smooth_at(s, X, js)
    order = np.argsort(np.concatenate([s[keep], js]), kind="stable")
    s_all = np.concatenate([s[keep], js])[order]
    X = np.concatenate([X[keep], at])[order]
    D = Js[:, lam.joints] - at[None]
    m = len(Js)
    if len(js) == 1 or js[-1] - js[0] <= 1e-12 * s[-1]:
        disp = np.broadcast_to(D.mean(axis=1)[:, None, :], (m,) + X.shape)
    else:
        Dc = np.moveaxis(D, 0, 1).reshape(len(js), 3 * m)
        cs = CubicSpline(js, Dc, axis=0, bc_type="natural" if len(js) > 2 else "not-a-knot")
        t = np.clip(s_all, js[0], js[-1])
        slope0, slope1 = cs(js[[0, -1]], 1)
        d = cs(t) + (s_all - t)[:, None] * np.where((s_all < js[0])[:, None], slope0, slope1)
        disp = np.moveaxis(d.reshape(len(s_all), m, 3), 1, 0)
    Xs = X[None] + disp
    return Xs, _ref_arclengths(Xs), js, s_all


# ---- random nets ------------------------------------------------------------------------------

def _signed_zeros(rng, A, share=0.15):
    """``A`` with a share of its entries set to 0.0 and a share to -0.0."""
    A = A.copy()
    A[rng.random(A.shape) < share] = 0.0
    A[rng.random(A.shape) < share] = -0.0
    return A


def _random_axis(rng) -> np.ndarray:
    p = int(rng.integers(1, 40))
    steps = rng.normal(size=(p, 3)) * rng.choice([1e-3, 0.1, 1.0, 5.0], size=(p, 1))
    steps[rng.random(p) < 0.1] = 0.0                       # repeated axis points
    X = np.cumsum(_signed_zeros(rng, steps), axis=0) + rng.normal(size=3)
    return _signed_zeros(rng, X, 0.05)


def _random_joint_s(rng, X: np.ndarray, k: int) -> np.ndarray:
    s = np.concatenate([[0.0], np.cumsum(_norms(np.diff(X, axis=0)))])
    how = rng.integers(0, 4)
    if how == 0 and len(np.unique(s)) >= k:                # at axis vertices
        return np.sort(rng.choice(np.unique(s), size=k, replace=False))
    if how == 1 and len(s) > 1 and k > 1:                  # a span too short for a spline
        return np.full(k, s[-1] * rng.random())
    js = np.sort(rng.uniform(-0.05, 1.05, size=k)) * s[-1]  # some beyond the ends (clipped)
    return js


def _random_net(rng) -> Net:
    n = int(rng.integers(3, 40))
    joints = _signed_zeros(rng, rng.normal(size=(n, 3)))
    lams = []
    for i in range(int(rng.integers(1, 12))):
        X = _random_axis(rng)
        k = int(rng.choice([0, 1, 2, 3, int(rng.integers(1, 13))]))
        js = _random_joint_s(rng, X, k) if len(X) > 1 or k <= 1 else np.zeros(k)
        lams.append(Lamella(i, 1 + 2 * (i % 2), rng.integers(0, n, size=k), js, X))
    return Net(joints, np.zeros((0, 4), int), lams)


def _random_states(rng, net: Net) -> list[np.ndarray]:
    m = int(rng.integers(1, 14))
    states = [net.joints + rng.normal(size=net.joints.shape)
              * rng.choice([0.0, 1e-6, 0.01, 1.0]) for _ in range(m)]
    return [_signed_zeros(rng, J, 0.05) for J in states]


def _plain_error(lam: Lamella, Js: np.ndarray) -> str | None:
    """The error the reference raises for ``lam``, if any (the batch must raise it too)."""
    try:
        _ref_carry_axis(lam, Js)
    except ValueError as e:
        return str(e)
    return None


@pytest.mark.parametrize("seed", range(60))
def test_batched_carry_is_scipys_per_lamella_carry_bit_for_bit(seed):
    rng = np.random.default_rng(seed)
    net = _random_net(rng)
    states = _random_states(rng, net)
    Js = np.stack(states)
    if any(_plain_error(lam, Js) for lam in net.lamellae):  # equal joint_s: scipy refuses
        with pytest.raises(ValueError, match="strictly increasing"):
            carried_axes(net, states)
        return
    want = [_ref_carry_axis(lam, Js) for lam in net.lamellae]
    got = carried_axes(net, states)
    assert len(got) == len(want)
    for (X, S), (wX, wS, _, _) in zip(got, want):
        assert _same(X, wX) and _same(S, wS)
    for k, moved in enumerate(move_joints_states(net, states)):
        assert _same(moved.joints, states[k])
        for lam, (wX, wS, js, s_all) in zip(moved.lamellae, want):
            assert _same(lam.axis, wX[k])
            assert _same(lam.joint_s, js if s_all is None else np.interp(js, s_all, wS[k]))


def test_the_random_nets_take_every_path():
    """The nets above have lamellae of one, two and three joints, splines over joints at axis
    vertices and between them, short spans, single-vertex axes and unjointed lamellae."""
    kinds = set()
    for seed in range(60):
        rng = np.random.default_rng(seed)
        net = _random_net(rng)
        for lam in net.lamellae:
            k, p = len(lam.joint_s), len(lam.axis)
            kinds.add(("joints", min(k, 4)))
            kinds.add(("axis", min(p, 2)))
            if p > 1 and k > 1:
                span = lam.joint_s[-1] - lam.joint_s[0]
                kinds.add(("short span", bool(span <= 1e-12 * lam.length)))
    assert {("joints", k) for k in range(5)} <= kinds
    assert {("axis", 1), ("axis", 2), ("short span", True), ("short span", False)} <= kinds


def test_equal_joint_arc_lengths_raise_scipys_error():
    X = np.stack([np.linspace(0, 3, 7), np.zeros(7), np.zeros(7)], axis=1)
    lam = Lamella(0, 1, [0, 1, 2], [0.5, 1.0, 1.0], X)
    net = Net(np.eye(3), np.zeros((0, 4), int), [lam])
    with pytest.raises(ValueError) as plain:
        _ref_carry_axis(lam, net.joints[None] + 0.1)
    with pytest.raises(ValueError) as batched:
        carried_axes(net, [net.joints + 0.1])
    assert str(batched.value) == str(plain.value)


@pytest.mark.parametrize("seed", range(20))
def test_cubic_splines_at_are_scipys_splines(seed):
    """Knots spaced over four decades (LAPACK pivots), values with signed zeros, points inside,
    at the knots and beyond both ends (continued linearly with the end slopes)."""
    rng = np.random.default_rng(100 + seed)
    q = 3 * int(rng.integers(1, 14))
    xs, ys, ss = [], [], []
    for _ in range(int(rng.integers(1, 30))):
        k = int(rng.integers(2, 14))
        x = np.cumsum(rng.choice([1e-3, 0.1, 1.0, 10.0], size=k) * (0.1 + rng.random(k)))
        x = x - rng.random() * x[-1]
        xs.append(x)
        ys.append(_signed_zeros(rng, rng.normal(size=(k, q)) * rng.choice([0.0, 1.0, 1e-3])))
        ss.append(np.sort(np.concatenate([x, rng.uniform(x[0] - 1, x[-1] + 1, 20)])))
    got = cubic_splines_at(xs, ys, ss)
    r = 0
    for x, y, s in zip(xs, ys, ss):
        cs = CubicSpline(x, y, axis=0, bc_type="natural" if len(x) > 2 else "not-a-knot")
        t = np.clip(s, x[0], x[-1])
        slope0, slope1 = cs(x[[0, -1]], 1)
        want = cs(t) + (s - t)[:, None] * np.where((s < x[0])[:, None], slope0, slope1)
        assert _same(got[r:r + len(s)], want)
        r += len(s)
    assert r == len(got)
