"""Tests of gridshell.gg.alignment: the alignment sequence of a GG net keeps its lengths."""
from __future__ import annotations

import numpy as np
import pytest
from tests.helpers.gg_cases import helicoid_grid

from gridshell.core.errors import InputError
from gridshell.gg.pipeline import collapse_gg, gg_net_from_mesh
from gridshell.gg.alignment import edge_length_errors, gg_alignment_sequence, line_frame


@pytest.fixture(scope="module")
def helicoid_net():
    net = gg_net_from_mesh(helicoid_grid(21, 21, c=0.5), n_lamellae=7, crossing_angle=90.0)["net"]
    aligned, _ = collapse_gg(net)
    return net, aligned


def _second_differences(net, V):
    """Largest |J_{k-1} - 2 J_k + J_{k+1}| along the lamellae (kinks of the joint chains), m."""
    rows = np.array([lam.joints[k - 1:k + 2] for lam in net.lamellae
                     for k in range(1, len(lam.joints) - 1)])
    return float(np.linalg.norm(V[rows[:, 0]] - 2 * V[rows[:, 1]] + V[rows[:, 2]], axis=1).max())


def test_sequence_keeps_lamella_lengths_and_ends_collapsed(helicoid_net):
    net, aligned = helicoid_net
    E = net.edges()
    seq = gg_alignment_sequence(net.joints, aligned, E, frames=6)
    assert len(seq.V) == 7 and seq.t[0] == 0 and seq.t[-1] == 1
    np.testing.assert_array_equal(seq.V[0], net.joints)
    np.testing.assert_array_equal(seq.V[-1], aligned)
    # reference lengths from the lamellae themselves: deployed chords and arc lengths
    chord = np.linalg.norm(net.joints[E[:, 1]] - net.joints[E[:, 0]], axis=1)
    arc = {}
    for lam in net.lamellae:
        for a, b, d in zip(lam.joints[:-1], lam.joints[1:], np.diff(lam.joint_s)):
            arc[(min(a, b), max(a, b))] = d
    arc = np.array([arc[(a, b)] for a, b in E])
    assert np.all(arc >= chord * (1 - 1e-9))   # a curved lamella: chord <= arc
    for t, V in zip(seq.t, seq.V):
        ell = np.linalg.norm(V[E[:, 1]] - V[E[:, 0]], axis=1)
        # every state within 1 % of the deployed chords, within 0.5 % of the straightening
        # lamella's chord (1 - t) chord + t arc
        assert np.max(np.abs(ell - chord) / chord) < 0.01, t
        assert np.max(np.abs(ell - ((1 - t) * chord + t * arc)) / arc) < 5e-3, t
    np.testing.assert_allclose(seq.length_error[[0, -1]], 0.0, atol=1e-3)
    assert np.all(seq.length_error < 5e-3)
    # the collapsed state: every lamella's joints on one line at their arc lengths
    np.testing.assert_allclose(seq.V[-1][:, 1:], 0.0, atol=1e-12)
    # no folding on the way: the joint chains straighten, they do not kink
    kinks = [_second_differences(net, V) for V in seq.V]
    assert max(kinks) <= 1.2 * kinks[0]
    assert len(seq.history) == 5 and all(h["iterations"] > 0 for h in seq.history)


def test_intermediate_states_are_not_a_rigid_motion(helicoid_net):
    # the net changes shape: the angle between the two families at a joint closes
    net, aligned = helicoid_net
    seq = gg_alignment_sequence(net.joints, aligned, net.edges(), frames=4)
    lam1, lam3 = net.family(1)[2], net.family(3)[2]
    j = np.intersect1d(lam1.joints, lam3.joints)[0]

    def angle(V):
        def direction(lam):
            k = int(np.flatnonzero(lam.joints == j)[0])
            nb = lam.joints[k + 1] if k + 1 < len(lam.joints) else lam.joints[k - 1]
            d = V[nb] - V[j]
            return d / np.linalg.norm(d) * (1 if k + 1 < len(lam.joints) else -1)
        return np.degrees(np.arccos(np.clip(direction(lam1) @ direction(lam3), -1, 1)))

    angles = [angle(V) for V in seq.V]
    assert angles[0] > 45 and angles[-1] < 1e-6
    assert np.all(np.diff(angles) < 0)


def test_line_frame_places_a_line_on_the_points_it_fits():
    rng = np.random.default_rng(3)
    x = np.sort(rng.uniform(0, 5, 12))
    A = np.stack([x, np.zeros(12), np.zeros(12)], 1)
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    V = (A - A.mean(0)) @ Q.T + np.array([1.0, -2.0, 0.5])     # the same line, moved rigidly
    placed, e, axis = line_frame(V, A)
    np.testing.assert_allclose(placed, V, atol=1e-12)
    np.testing.assert_allclose(e, Q @ np.array([1.0, 0, 0]) * np.sign(axis[0]), atol=1e-12)
    # a rigidly moved line needs no optimization: every state is that line, moved
    seq = gg_alignment_sequence(V, A, np.stack([np.arange(11), np.arange(1, 12)], 1), frames=3)
    for W in seq.V:
        np.testing.assert_allclose(np.diff(W @ _unit(W[-1] - W[0])), np.diff(x), atol=1e-6)


def _unit(v):
    return v / np.linalg.norm(v)


def test_edge_length_errors_and_bad_input():
    V = np.array([[0.0, 0, 0], [1, 0, 0], [1, 2, 0]])
    E = np.array([[0, 1], [1, 2]])
    np.testing.assert_allclose(edge_length_errors(V, E, [1.0, 2.5]), [0.0, 0.2])
    A = np.array([[0.0, 0, 0], [1, 0, 0], [3, 0, 0]])
    with pytest.raises(InputError, match="frames"):
        gg_alignment_sequence(V, A, E, frames=0)
    with pytest.raises(InputError, match="shape"):
        gg_alignment_sequence(V, A[:2], E)
    with pytest.raises(InputError, match="weight"):
        gg_alignment_sequence(V, A, E, weights={"bending": 1.0})
    with pytest.raises(InputError, match="zero-length"):
        gg_alignment_sequence(np.array([[0.0, 0, 0], [0, 0, 0], [1, 2, 0]]), A, E)
