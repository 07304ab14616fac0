"""measure.fairness against closed forms (a circle in a plane, a helix geodesic on a cylinder)
and on lamellae built with a known defect (a corner, a hairpin, a loop, a fold)."""
from __future__ import annotations

import numpy as np
import pytest

from gridshell.measure.fairness import (FAIR_RADIUS_WIDTHS, fairness_metrics, folded_loops,
                                        lamella_fairness)
from gridshell.measure.quality import design_gates, fairness_gates

W = 0.2          # strip width at the built scale, metres


def _plane_circle(R, turn=np.pi, k=400):
    t = np.linspace(0, turn, k)
    P = np.column_stack([R * np.cos(t), R * np.sin(t), np.zeros(k)])
    return P, np.tile([0.0, 0.0, 1.0], (k, 1))


def test_circle_in_a_plane_closed_form():
    R = 3.0
    P, N = _plane_circle(R)
    f = lamella_fairness(1, P, N, tangent=True, width=W, diagonal=10.0)
    assert f.radius_in_plane == pytest.approx(R, rel=1e-3)       # kg = 1/R: bent in its plane
    assert f.radius == pytest.approx(R, rel=1e-3)
    assert f.corner_deg == pytest.approx(np.degrees(np.pi / 399), rel=1e-3)
    # within 3 widths of arc the tangent turns 3 W / R
    assert f.hairpin_deg == pytest.approx(np.degrees(3 * W / R), rel=0.02)
    assert f.loop_s is None
    # the same arc as an orthogonal strip keeps kn = 0: it is its cut shape, not bent
    g = lamella_fairness(1, P, N, tangent=False, width=W, diagonal=10.0)
    assert g.radius_in_plane > 1e6


def test_helix_geodesic_on_a_cylinder_closed_form():
    R, alpha = 1.5, np.radians(50)          # a geodesic at alpha to the rulings
    t = np.linspace(0, 3.0, 600)
    phi = t * np.sin(alpha) / R
    P = np.column_stack([R * np.cos(phi), R * np.sin(phi), t * np.cos(alpha)])
    N = np.column_stack([np.cos(phi), np.sin(phi), np.zeros_like(phi)])
    f = lamella_fairness(1, P, N, tangent=True, width=W, diagonal=10.0)
    assert f.radius_in_plane > 1e3                                  # kg = 0
    assert f.radius == pytest.approx(R / np.sin(alpha) ** 2, rel=1e-3)   # kappa = sin^2 / R
    o = lamella_fairness(1, P, N, tangent=False, width=W, diagonal=10.0)
    assert o.radius_in_plane > 1e3            # kn constant: the cut shape of an orthogonal strip


def test_corner_is_found_where_it_is():
    a = np.linspace(0, 1, 50)
    P = np.concatenate([np.column_stack([a, 0 * a, 0 * a]),
                        np.column_stack([1 + a[1:] * np.cos(0.8), a[1:] * np.sin(0.8),
                                         0 * a[1:]])])
    N = np.tile([0.0, 0.0, 1.0], (len(P), 1))
    f = lamella_fairness(4, P, N, tangent=True, width=W, diagonal=3.0)
    assert f.corner_deg == pytest.approx(np.degrees(0.8), rel=1e-6)
    assert f.s_corner == pytest.approx(1.0, abs=1e-9)
    gates = {g.name: g for g in fairness_gates(fairness_metrics(
        [(4, P)], *_plane(), tangent=True, width=W))}
    assert not gates["fair_corner"].ok and "lamella 4 at s = 1 m" in gates["fair_corner"].detail


def _plane(h=10.0):
    V = np.array([[-h, -h, 0], [h, -h, 0], [h, h, 0], [-h, h, 0]], float)
    return V, np.array([[0, 1, 2], [0, 2, 3]])


def test_hairpin_and_loop():
    # a hairpin: out along x, a half turn of radius W / 2, back
    a = np.linspace(0, 2, 200)
    t = np.linspace(0, np.pi, 30)[1:-1]
    P = np.concatenate([np.column_stack([a, 0 * a, 0 * a]),
                        np.column_stack([2 + 0.2 * W * np.sin(t), 0.2 * W * (1 - np.cos(t)),
                                         0 * t]),
                        np.column_stack([a[::-1], 0 * a + 0.4 * W, 0 * a])])
    f = lamella_fairness(7, P, np.tile([0, 0, 1.0], (len(P), 1)), tangent=True, width=W,
                         diagonal=5.0)
    assert f.hairpin_deg > 170                            # within a window of the bend
    assert abs(f.s_hairpin - (2 + 0.2 * W * np.pi / 2)) < 3 * W
    assert f.radius < W                                   # bent tighter than its width
    assert f.loop_s is not None                           # both legs within W / 2 of each other
    # a loop: a full circle of radius 2 W and on along x, crossing itself
    t = np.linspace(0, 2 * np.pi, 200)
    L = np.concatenate([np.column_stack([np.linspace(-2, 0, 100)[:-1], np.zeros(99),
                                         np.zeros(99)]),
                        np.column_stack([2 * W * np.sin(t), 2 * W * (1 - np.cos(t)), 0 * t]),
                        np.column_stack([np.linspace(0, 2, 100)[1:], np.zeros(99),
                                         np.zeros(99)])])
    m = fairness_metrics([(19, L)], *_plane(), tangent=False, width=W)
    gates = {g.name: g for g in fairness_gates(m)}
    assert not gates["fair_loop"].ok and "lamella 19" in gates["fair_loop"].detail
    assert gates["fair_radius"].ok          # kn = 0: an orthogonal strip bent about its weak axis
    # as a tangent strip the same loop is bent in its plane to 2 W < 10 W
    g = {g.name: g for g in fairness_gates(fairness_metrics([(19, L)], *_plane(), tangent=True,
                                                            width=W))}["fair_radius"]
    assert not g.ok and g.detail.endswith(f"{FAIR_RADIUS_WIDTHS:g} strip widths")
    assert "lamella 19" in g.detail


def test_off_the_surface():
    P, _ = _plane_circle(1.0, turn=np.pi / 2, k=100)
    P[50, 2] = 0.3                                        # one sample 0.3 m above the plane
    m = fairness_metrics([(2, P)], *_plane(1.0), tangent=True, width=W)
    d = m["lamellae"][0]
    diag = np.linalg.norm([2.0, 2.0, 0.0])
    assert d["off_surface_percent"] == pytest.approx(100 * 0.3 / diag, rel=1e-6)
    gates = {g.name: g for g in fairness_gates(m)}
    assert not gates["fair_surface"].ok


def test_folds_of_an_alignment_sequence():
    # two quads side by side; in state 2 the second one is folded back over the first
    V0 = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0], [1, 1, 0], [2, 1, 0]], float)
    Q = np.array([[0, 1, 4, 3], [1, 2, 5, 4]])
    V1 = V0.copy()
    V1[[2, 5], 2] = 0.5                                   # bent up 27 degrees: no fold
    V2 = V0.copy()
    V2[[2, 5], 0] = 0.2                                   # folded back over the first quad
    V2[[2, 5], 2] = 0.1
    R = V0 @ np.array([[0, 0, 1], [0, 1, 0], [-1, 0, 0]], float).T   # both turned 90 degrees
    assert folded_loops([V0, V1, R, V0], Q) == []         # a rigid turn of the net is no fold
    assert folded_loops([V0, V1, V2, V0], Q) == [(2, 1)]
    assert folded_loops([V0, V1, V2], Q) == []            # the last state (collapsed) not judged
    # a loop that shrinks to nothing is not a fold
    V3 = V2.copy()
    V3[:, 1] *= 0.01
    assert folded_loops([V0, V3, V0], Q) == []
    m = fairness_metrics([], *_plane(), tangent=True, width=W, states=[V0, V1, V2, V0], loops=Q)
    g = {g.name: g for g in fairness_gates(m)}["fair_fold"]
    assert not g.ok and "state 2, loop 1" in g.detail


def test_no_fairness_record_no_gates():
    assert fairness_gates(None) == []


def test_design_gates_include_fairness_when_measured():
    P, _ = _plane_circle(0.5)                            # bent in its plane to 0.5 m < 2 m
    m = {"alignability": {"mean": 0.1, "max": 0.2}, "alignability_arc": {"mean": 0.1, "max": 0.2},
         "fairness": fairness_metrics([(3, P)], *_plane(), tangent=True, width=W)}
    gates = design_gates("GG", m)
    assert [g.name for g in gates][:4] == ["delta_a_mean", "delta_a_max", "delta_a_arc_mean",
                                          "delta_a_arc_max"]
    bad = [g for g in gates if not g.ok]
    assert [g.name for g in bad] == ["fair_radius"] and "lamella 3" in bad[0].line()
    assert len(design_gates("GG", {k: v for k, v in m.items() if k != "fairness"})) == 4


def test_an_isolated_fold_is_reported_not_refused():
    fair = {"width_m": W, "limits": {"radius_in_plane_m": 2.0, "corner_deg": 30,
                                     "hairpin_deg": 150, "hairpin_window_m": 0.6,
                                     "off_surface_percent": 2.0},
            "lamellae": [], "folds": [{"state": 3, "loop": 19}], "n_states": 8,
            "n_loops": 60, "fold_share": 0.05}
    g = {g.name: g for g in fairness_gates(fair)}["fair_fold"]
    assert g.ok and "isolated" in g.detail and "loop 19" in g.detail
    fair["folds"] = [{"state": 3, "loop": k} for k in range(4)]       # 4 of 60 > 5 %
    assert not {g.name: g for g in fairness_gates(fair)}["fair_fold"].ok


def test_folds_of_an_approximate_path_are_reported_not_gated():
    fair = {"width_m": W, "limits": {"radius_in_plane_m": 2.0, "corner_deg": 30,
                                     "hairpin_deg": 150, "hairpin_window_m": 0.6,
                                     "off_surface_percent": 2.0},
            "lamellae": [], "folds": [{"state": 3, "loop": k} for k in range(10)],
            "n_states": 8, "n_loops": 60, "fold_share": 0.05, "gate_folds": False}
    g = {g.name: g for g in fairness_gates(fair)}["fair_fold"]
    assert g.ok and "not gated" in g.detail and "more than 5 %" in g.detail
