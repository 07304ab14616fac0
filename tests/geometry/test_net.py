"""Curve nets (gridshell.geometry.net): lamella records and moving joints with their axes."""
import numpy as np
import pytest

from gridshell.core.errors import InputError
from gridshell.geometry.net import Lamella, Net, move_joints, polyline_arclength


def _point_at(lam: Lamella, s: np.ndarray) -> np.ndarray:
    t = polyline_arclength(lam.axis)
    return np.stack([np.interp(s, t, lam.axis[:, c]) for c in range(3)], axis=1)


def _arc_net(R=2.0, n=401, at=(0.1, 0.35, 0.6, 0.9)):
    """One lamella along a circle of radius R (angle 0 .. 1 rad) with joints at fractions
    ``at`` of its length (arc length along the polyline), not at axis vertices."""
    a = np.linspace(0.0, 1.0, n)
    X = np.stack([R * np.cos(a), R * np.sin(a), 0 * a], axis=1)
    s = polyline_arclength(X)
    js = np.asarray(at) * s[-1]
    ang = np.interp(js, s, a)  # the joints on the circle itself
    J = np.stack([R * np.cos(ang), R * np.sin(ang), 0 * js], axis=1)
    lam = Lamella(0, 1, np.arange(len(js)), js, X)
    return Net(J, np.zeros((0, 4), int), [lam])


def test_moved_axis_passes_through_the_moved_joints():
    net = _arc_net()
    rng = np.random.default_rng(1)
    J = net.joints + 1e-3 * rng.normal(size=net.joints.shape)
    out = move_joints(net, J)
    lam = out.lamellae[0]
    np.testing.assert_allclose(_point_at(lam, lam.joint_s), J, atol=1e-12)
    # joint_s is arc length along the new axis, consistent with Lamella.length
    assert lam.joint_s[0] >= 0 and lam.joint_s[-1] <= lam.length + 1e-12
    assert np.all(np.diff(lam.joint_s) > 0)


def test_unmoved_and_translated_joints_keep_the_arc_lengths():
    net = _arc_net()
    same = move_joints(net, net.joints).lamellae[0]
    # joints on the circle, the axis a polygon inscribed in it: nothing moves but the joints'
    # chord sag (R da^2 / 8 = 1.6e-6 m here)
    np.testing.assert_allclose(same.joint_s, net.lamellae[0].joint_s, atol=1e-8)
    np.testing.assert_allclose(same.length, net.lamellae[0].length, rtol=1e-12)
    moved = move_joints(net, net.joints + [0.3, -0.2, 0.1]).lamellae[0]
    np.testing.assert_allclose(moved.joint_s, net.lamellae[0].joint_s, atol=1e-9)
    np.testing.assert_allclose(moved.axis, same.axis + [0.3, -0.2, 0.1], atol=1e-12)


def test_small_joint_motion_keeps_the_axis_smooth():
    # joints moved radially by a smooth 1 mm field: the carried axis stays a smooth curve whose
    # curvature differs from the circle's 1/R by far less than a kink at a joint would give
    R = 2.0
    net = _arc_net(R)
    J = net.joints * (1 + 5e-4 * np.cos(np.arange(len(net.joints))))[:, None]
    lam = move_joints(net, J).lamellae[0]
    X = lam.axis
    e = np.diff(X, axis=0)
    ln = np.linalg.norm(e, axis=1)
    turn = np.arccos(np.clip(np.sum(e[1:] * e[:-1], axis=1) / (ln[1:] * ln[:-1]), -1, 1))
    kappa = turn / (0.5 * (ln[1:] + ln[:-1]))
    s = polyline_arclength(X)[1:-1]
    inside = (s > lam.joint_s[0]) & (s < lam.joint_s[-1])
    assert np.max(np.abs(kappa[inside] * R - 1.0)) < 0.05


def test_move_joints_rejects_wrong_shapes():
    net = _arc_net()
    with pytest.raises(InputError, match="joint positions"):
        move_joints(net, net.joints[:2])
    with pytest.raises(InputError, match="finite"):
        move_joints(net, np.full_like(net.joints, np.nan))


def test_states_moved_at_once_equal_each_moved_alone():
    """move_joints_states carries several joint states through one spline with all states'
    columns; each state's net equals that state moved alone (the columns do not mix)."""
    from gridshell.geometry.net import move_joints_states

    net = _arc_net()
    rng = np.random.default_rng(7)
    states = [net.joints + 0.05 * rng.normal(size=net.joints.shape) for _ in range(4)]
    together = move_joints_states(net, states)
    for J, got in zip(states, together):
        alone = move_joints(net, J)
        assert np.array_equal(got.joints, J)
        for a, b in zip(alone.lamellae, got.lamellae):
            assert np.allclose(a.axis, b.axis, rtol=0, atol=1e-13)
            assert np.allclose(a.joint_s, b.joint_s, rtol=0, atol=1e-13)
    assert move_joints_states(net, []) == []
