"""Flat strips (issue item 1): straight, circular and collapse-curve shapes, axis placement."""
from __future__ import annotations

import numpy as np
import pytest
from tests.helpers.fab_cases import make_bundle, parabola_at

from gridshell.fabrication import fabricate
from gridshell.fabrication.axis import ArcAxis, CurveAxis, DenseCurve, LineAxis
from gridshell.fabrication.params import FabParams
from gridshell.fabrication.strips import strips_from_bundle
from gridshell.core.errors import InputError


def test_gg_and_aa_unroll_to_straight_strips_of_the_axis_length():
    for kind in ("GG", "AA"):
        b = make_bundle(kind)
        strips = strips_from_bundle(b, FabParams(margin=15, scale="1:10"))
        assert len(strips) == len(b.net.lamellae)
        for s, lam in zip(strips, b.net.lamellae):
            assert isinstance(s.axis, LineAxis)
            assert s.length == pytest.approx(lam.length * 100 + 30)
            assert s.joint_s == pytest.approx(lam.joint_s * 100)
            assert s.orientation == ("tangent" if kind == "GG" else "orthogonal")


def test_scale_one_to_one_and_axis_edge():
    b = make_bundle("AA")
    s = strips_from_bundle(b, FabParams(scale="1:1", axis="edge", sheet="3000x2000"))[0]
    assert s.length == pytest.approx(b.net.lamellae[0].length * 1000 + 30)
    assert (s.t_lo, s.t_hi) == (0.0, 20.0)
    s = strips_from_bundle(b, FabParams(scale="0.1"))[0]
    assert (s.t_lo, s.t_hi) == (-10.0, 10.0)


def test_cnc_strip_is_an_arc_of_radius_one_over_n():
    b = make_bundle("CNC", R=1.3)
    s = strips_from_bundle(b, FabParams())[0]
    assert isinstance(s.axis, ArcAxis) and s.axis.radius == pytest.approx(130.0)
    # points of the axis are at distance R from the centre and s apart along the arc
    P = s.axis.point(s.joint_s, 0.0)
    c = np.array([0.0, 130.0])
    assert np.linalg.norm(P - c, axis=1) == pytest.approx(np.full(len(P), 130.0))
    ang = np.unwrap(np.arctan2(P[:, 1] - c[1], P[:, 0] - c[0]))
    assert np.diff(ang) * 130 == pytest.approx(np.diff(s.joint_s))
    # without a collapse record the radius comes from metrics.n
    b.collapse = None
    b.metrics["n"] = 1 / 1.3
    assert strips_from_bundle(b, FabParams())[0].axis.radius == pytest.approx(130.0)
    b.metrics = {}
    with pytest.raises(InputError, match="metrics.n"):
        strips_from_bundle(b, FabParams())


def test_cnc_edge_axis_on_the_side_of_the_normals():
    b = make_bundle("CNC", R=1.0)   # normals point to the centre: the strip lies inside
    s = strips_from_bundle(b, FabParams(axis="edge"))[0]
    assert (s.t_lo, s.t_hi) == (0.0, 20.0)
    b.collapse.normals = -b.collapse.normals
    s = strips_from_bundle(b, FabParams(axis="edge"))[0]
    assert (s.t_lo, s.t_hi) == (-20.0, 0.0)


def test_ncp_strips_lie_on_the_collapse_curve_at_collapse_s():
    b = make_bundle("NCP", nr=4, nc=4)
    strips = strips_from_bundle(b, FabParams())
    for s in strips:
        assert isinstance(s.axis, CurveAxis)
        P = s.axis.point(s.joint_s, 0.0)
        Q = parabola_at(b.collapse_s[s.lamella]) * 100
        # same points up to a rigid motion: equal pairwise distances
        dP = np.linalg.norm(P[:, None] - P[None], axis=2)
        dQ = np.linalg.norm(Q[:, None] - Q[None], axis=2)
        assert np.abs(dP - dQ).max() < 0.01
        # the strip's own arc length between joints is the design's
        S = s.axis.S
        assert np.interp(s.joint_s, S, S) == pytest.approx(s.joint_s)
        assert s.s0 == pytest.approx(-15) and s.s1 == pytest.approx(s.joint_s[-1] + 15)


def test_ncp_without_collapse_s_starts_at_curve_arclength_zero():
    b = make_bundle("NCP", nr=3, nc=3)
    b.collapse_s = None
    s = strips_from_bundle(b, FabParams())[0]
    P = s.axis.point(s.joint_s[0], 0.0)
    assert P == pytest.approx(np.array([-1.5, 0.6 * 2.25]) * 100, abs=1e-6)


def test_ncp_curve_too_tight_for_the_width_is_an_input_error():
    b = make_bundle("NCP", nr=3, nc=3, collapse_offset=1.6)   # across the vertex, R = 83 mm
    strips_from_bundle(b, FabParams(width=150, hole=3, sheet="1000x1000", scale="1:10"))
    with pytest.raises(InputError, match="reduce --width"):
        strips_from_bundle(b, FabParams(width=190, hole=3, sheet="1000x1000", scale="1:10"))


def test_slots_need_orthogonal_lamellae():
    with pytest.raises(InputError, match="orthogonal"):
        strips_from_bundle(make_bundle("GG"), FabParams(joints="slots"))


def test_edge_axis_needs_orthogonal_lamellae(tmp_path):
    """--axis edge means the edge an orthogonal lamella stands on; GG strips refuse it (before
    any file is written) and keep the axis on the centre line."""
    b = make_bundle("GG")
    with pytest.raises(InputError, match="tangent to the surface.*--axis centre"):
        strips_from_bundle(b, FabParams(axis="edge"))
    with pytest.raises(InputError, match="--axis edge"):
        fabricate(b, tmp_path / "out", FabParams(axis="edge"), plan=False)
    assert list(tmp_path.iterdir()) == []
    s = strips_from_bundle(b, FabParams(axis="centre"))[0]
    assert (s.t_lo, s.t_hi) == (-10.0, 10.0)
    for kind in ("AA", "CNC", "NCP"):
        s = strips_from_bundle(make_bundle(kind, nr=3, nc=3), FabParams(axis="edge"))[0]
        assert 0.0 in (s.t_lo, s.t_hi) and s.t_hi - s.t_lo == 20.0


def test_dense_curve_arclength_and_extension():
    t = np.linspace(0, np.pi, 50)
    D = DenseCurve(np.stack([np.cos(t), np.sin(t)], 1) * 100)
    assert D.length == pytest.approx(100 * np.pi, rel=1e-5)
    P = D.piece(-10, 0)                       # beyond the start: along the end tangent
    assert np.linalg.norm(P[0] - D.D[0]) == pytest.approx(10)
    T = (D.D[1] - D.D[0]) / np.linalg.norm(D.D[1] - D.D[0])
    assert (D.D[0] - P[0]) / 10 == pytest.approx(T)
