"""The strips of an NCP / CNC / AA alignment state (gridshell.structure.heldpath, issue 28): the
sequence's joints and axes held, the strips between them at their elastic equilibrium from the
cut shape. Closed forms on one lamella of a straight-cut (AA) strip, 20:1:

- a strip on a circle of radius rho in a plane, axes along the plane's normal, moved rigidly:
  the strip bends about its weak axis with curvature 1 / rho, no strong-axis bending, no
  twist;
- joints on a line, axes turning about it at a constant rate tau: a twisted straight strip
  (a helicoid) with twist tau, no bending;
- a CNC strip (cut as an arc of radius R) held on that circle with its axes in the plane
  (pointing at the centre): the strip lies as cut, all curvature changes ~ 0.
Each within 2 %; the strips pass through the held joints and keep their arc lengths."""
from __future__ import annotations

import numpy as np
import pytest

from gridshell.design.bundle import CollapseCurve, DesignBundle
from gridshell.geometry.net import Lamella, Net
from gridshell.structure.frames import darboux_curvatures
from gridshell.structure.heldpath import held_state

RHO, K = 2.0, 9


def _bundle(J: np.ndarray, kind: str = "AA", radius: float | None = None,
            A: np.ndarray | None = None) -> DesignBundle:
    """One lamella through the joints ``J``, its dense axis ``A`` (default the polyline
    refined 8 times)."""
    if A is None:
        s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(J, axis=0), axis=1))])
        u = np.linspace(0, s[-1], 8 * (len(J) - 1) + 1)
        A = np.stack([np.interp(u, s, J[:, c]) for c in range(3)], 1)
    sA = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(A, axis=0), axis=1))])
    js = np.array([sA[np.argmin(np.linalg.norm(A - j, axis=1))] for j in J])
    lam = Lamella(0, 1, np.arange(len(J)), js, A)
    net = Net(J, np.zeros((0, 4), np.int64), [lam])
    col = None
    if kind == "CNC":
        th = np.linspace(0, 2 * np.pi, 200)
        col = CollapseCurve(np.stack([radius * np.cos(th), radius * np.sin(th)], 1),
                            np.stack([np.cos(th), np.sin(th)], 1), "circle", radius)
    return DesignBundle(kind=kind, net=net, aligned=J.copy(), surface_V=np.zeros((0, 3)),
                        surface_F=np.zeros((0, 3), np.int64), collapse=col)


def _arc(n: int = K, span: float = 1.2):
    """``n`` joints on a circle of radius RHO (z = 0) over the angle ``span`` and the dense
    circle through them (64 samples per joint-to-joint piece)."""
    th = np.linspace(-span / 2, span / 2, n)
    dense = np.linspace(-span / 2, span / 2, 64 * (n - 1) + 1)
    on = lambda a: np.stack([RHO * np.sin(a), RHO * np.cos(a) - RHO, 0 * a], 1)  # noqa: E731
    return on(th), on(dense)


def _measure(st):
    """The Darboux curvatures of the state's strip and its inner nodes (the end bays left
    out: a free end carries no moment)."""
    dc = darboux_curvatures(st["X"][0], st["N"][0])
    return dc, slice(4, -4)


def test_a_strip_bent_on_a_circle_about_its_weak_axis_stays_there_when_moved():
    """The design: a straight-cut strip on a circle of radius rho, axes along the plane's
    normal (weak-axis curvature 1 / rho); the state: the design turned and moved rigidly. The
    held strips bend about the weak axis with 1 / rho (the end bays, whose free ends carry no
    moment, left out), no strong-axis bending, no twist."""
    J, A = _arc()
    n = np.tile([0.0, 0.0, 1.0], (K, 1))
    b = _bundle(J, A=A)
    c, s_ = np.cos(0.7), np.sin(0.7)
    Q = np.array([[1.0, 0, 0], [0, c, -s_], [0, s_, c]])
    V, R = J @ Q.T + [0.3, -1.0, 2.0], n @ Q.T
    st = held_state(b, V, R, n)
    assert st["converged"]
    X, N = st["X"][0], st["N"][0]
    dc = darboux_curvatures(X, N)
    i = slice(6, -6)                                # two bays from each free end
    assert np.abs(dc.kg[i]) == pytest.approx(np.full(len(dc.kg[i]), 1 / RHO), rel=0.02)
    assert np.abs(dc.kn[i]).max() < 0.02 / RHO and np.abs(dc.tau_g[i]).max() < 0.02 / RHO
    assert np.linalg.norm(X[st["joint"][0] >= 0] - V, axis=1).max() < 1e-12
    L = np.linalg.norm(np.diff(X, axis=0), axis=1).sum()
    assert L == pytest.approx(RHO * 1.2, rel=2e-3)                  # the arc length kept
    assert st["bound"] < 1e-6


def test_axes_turning_about_a_line_twist_a_straight_strip():
    L, tau = 1.6, 0.8
    x = np.linspace(0, L, K)
    J = np.stack([x, np.zeros(K), np.zeros(K)], 1)
    a0 = np.tile([0.0, 0.0, 1.0], (K, 1))
    R = np.stack([np.zeros(K), -np.sin(tau * x), np.cos(tau * x)], 1)
    st = held_state(_bundle(J), J, R, a0)
    assert st["converged"]
    dc, i = _measure(st)
    assert np.abs(dc.tau_g[i]) == pytest.approx(np.full(len(dc.tau_g[i]), tau), rel=0.02)
    assert np.abs(dc.kn[i]).max() < 0.02 * tau and np.abs(dc.kg[i]).max() < 0.02 * tau


def test_a_cnc_strip_held_on_its_own_circle_lies_as_cut():
    J, A = _arc()
    centre = np.array([0.0, -RHO, 0.0])
    R = (centre - J) / RHO                              # in the plane, at the centre
    b = _bundle(J, "CNC", radius=RHO, A=A)
    st = held_state(b, J, R, R)
    assert st["converged"]
    assert st["kcut"][0] == pytest.approx(np.full(len(st["kcut"][0]), 1 / RHO))
    dc, i = _measure(st)
    assert np.abs(dc.kn[i]) == pytest.approx(np.full(len(dc.kn[i]), 1 / RHO), rel=0.02)
    assert np.abs(dc.kg[i]).max() < 0.02 / RHO and np.abs(dc.tau_g[i]).max() < 0.02 / RHO
    d = np.linalg.norm(st["X"][0] - centre, axis=1)
    assert d == pytest.approx(np.full(len(d), RHO), rel=1e-3)
