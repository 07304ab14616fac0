"""Joint features (issue item 2) and analytic kerf compensation (item 5)."""
from __future__ import annotations

import numpy as np
import pytest
import shapely
from tests.helpers.fab_cases import make_bundle

from gridshell.fabrication.params import FabParams
from gridshell.fabrication.part import build_part
from gridshell.fabrication.strips import strips_from_bundle
from gridshell.core.errors import InputError


def _part(kind, **kw):
    b = make_bundle(kind, nr=4, nc=4 if kind == "NCP" else 5)
    params = FabParams(**kw)
    strips = strips_from_bundle(b, params)
    return b, params, [build_part(s, params) for s in strips]


def test_holes_on_the_axis_at_the_joints():
    b, p, parts = _part("GG", hole=3)
    for part in parts:
        s = part.strip
        assert part.holes == pytest.approx(np.column_stack([s.joint_s, np.zeros(len(s.joint_s))]))
        assert part.radii == pytest.approx(1.5)
        assert len(part.scores) == 0


def test_slots_are_cross_halving_notches_from_opposite_edges():
    b, p, parts = _part("AA", joints="slots", thickness=1, clearance=0.2, width=20)
    for part in parts:
        s = part.strip
        poly = shapely.Polygon(part.outline.flatten())
        assert poly.is_valid and len(part.holes) == 0
        n = len(s.joint_s)
        assert poly.area == pytest.approx(s.length * 20 - n * 1.2 * 10)
        # each notch: 1.2 mm wide, 10 mm deep, centred on the joint, from the family's edge
        edge = 10.0 if s.family == 1 else -10.0
        for x in s.joint_s:
            inside = shapely.Point(x, edge * 0.5).buffer(0.01)        # in the notch
            assert not poly.intersects(inside)
            assert poly.contains(shapely.Point(x, -edge * 0.5))       # other half whole
            assert poly.contains(shapely.Point(x + 0.65, edge * 0.5))  # beside the notch
            assert not poly.contains(shapely.Point(x + 0.55, edge * 0.99))
        V = part.outline.V
        bottoms = V[np.isclose(V[:, 1], 0.0)]
        assert len(bottoms) == 2 * n
        assert (bottoms[1::2, 0] - bottoms[::2, 0]) == pytest.approx(np.full(n, 1.2)) or \
            np.abs(bottoms[::2, 0] - bottoms[1::2, 0]) == pytest.approx(np.full(n, 1.2))


def test_slots_on_curved_strips_keep_the_joint_positions():
    b, p, parts = _part("CNC", joints="slots")
    for part in parts:
        s = part.strip
        poly = shapely.Polygon(part.outline.flatten())
        assert poly.is_valid
        n = len(s.joint_s)
        # notch bottom midpoints lie on the axis at the joints
        t_edge = 5.0 if s.family == 1 else -5.0
        for x in s.joint_s:
            assert not poly.contains(shapely.Point(*s.axis.point(x, t_edge)))
            assert poly.contains(shapely.Point(*s.axis.point(x, -t_edge)))
        assert poly.area == pytest.approx(_strip_area(s) - n * 1.2 * 10, rel=1e-3)


def _strip_area(s):
    r1, r2 = s.axis.radius - s.t_lo, s.axis.radius - s.t_hi
    return 0.5 * abs(r1 ** 2 - r2 ** 2) * s.length / s.axis.radius


def test_marks_are_score_lines_across_the_strip():
    b, p, parts = _part("NCP", joints="marks")
    for part in parts:
        s = part.strip
        assert len(part.scores) == len(s.joint_s) and len(part.holes) == 0
        L = np.linalg.norm(part.scores[:, 1] - part.scores[:, 0], axis=1)
        assert L == pytest.approx(np.full(len(L), 20.0), rel=1e-3)
        mid = part.scores.mean(axis=1)
        assert mid == pytest.approx(s.axis.point(s.joint_s, 0.0), abs=1e-6)


def test_joints_too_close_for_the_feature():
    b = make_bundle("GG")
    params = FabParams(scale="1:1000", hole=3, margin=15)
    with pytest.raises(InputError, match="too close"):
        build_part(strips_from_bundle(b, params)[0], params)


@pytest.mark.parametrize("kind,joints", [("GG", "hole"), ("CNC", "hole"), ("AA", "slots"),
                                         ("CNC", "slots"), ("NCP", "hole")])
def test_kerf_moves_outlines_out_and_holes_in(kind, joints):
    kerf = 0.3
    _, _, plain = _part(kind, joints=joints, tolerance=0.001)
    _, _, comp = _part(kind, joints=joints, kerf=kerf, tolerance=0.001)
    for a, b in zip(plain, comp):
        nominal = shapely.Polygon(a.outline.flatten(0.001))
        cut = shapely.Polygon(b.outline.flatten(0.001))
        grown = nominal.buffer(kerf / 2, join_style="mitre", mitre_limit=10)
        # the kerf outline is the exact offset (mitred corners): nothing but tessellation off
        assert cut.symmetric_difference(grown).area < 1e-3 * nominal.length
        assert b.radii == pytest.approx(a.radii - kerf / 2)
        assert b.holes == pytest.approx(a.holes)
    if kind == "CNC" and joints == "hole":
        R = comp[0].strip.axis.radius
        V, B = comp[0].outline.V, comp[0].outline.B
        r = [np.linalg.norm(V[i] - [0, R]) for i in np.flatnonzero(B)]
        assert sorted(r) == pytest.approx([R - 10 - kerf / 2, R + 10 + kerf / 2])


def test_joints_too_close_for_holes_are_engraved_as_marks_by_default(tmp_path):
    """A small model at 1:10: holes would merge, so the default engraves marks and says so;
    an explicit --joints hole (fallback_marks=False) refuses as before."""
    from gridshell.fabrication.pipeline import plan_parts

    b = make_bundle("GG")
    strict = FabParams(scale="1:100", hole=3, margin=15, fallback_marks=False)
    with pytest.raises(InputError, match="too close"):
        plan_parts(b, strict)
    parts, layout, info = plan_parts(b, FabParams(scale="1:100", hole=3, margin=15))
    assert info["params"].joints == "marks" and "engraved as marks" in info["joints_fallback"]
    assert all(len(p.holes) == 0 for p in parts)
    assert sum(len(p.scores) for p in parts) == sum(len(p.strip.joint_s) for p in parts)
    # a scale at which the holes fit keeps them and reports no fallback
    parts, _, info = plan_parts(b, FabParams(hole=3, margin=15))
    assert info["joints_fallback"] is None and info["params"].joints == "hole"
    assert sum(len(p.holes) for p in parts) > 0
