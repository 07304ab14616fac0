"""Nesting (issue item 4): rows first-fit decreasing, stacks of congruent curved strips,
sheets as needed, splices for lamellae longer than a sheet."""
from __future__ import annotations

import csv

import numpy as np
import pytest
import shapely
from tests.helpers.fab_cases import make_bundle, read_dxf_sheet

from gridshell.fabrication import FabParams, fabricate
from gridshell.fabrication.nesting import check_layout, nest
from gridshell.fabrication.part import build_part
from gridshell.fabrication.splice import extent, split_strip
from gridshell.fabrication.strips import strips_from_bundle


def _layout(kind, **kw):
    b = make_bundle(kind, nr=kw.pop("nr", 4), nc=kw.pop("nc", 5))
    params = FabParams(**kw)
    parts = [build_part(p, params) for s in strips_from_bundle(b, params)
             for p in split_strip(s, params)]
    return parts, nest(parts, params), params


def _assert_valid(layout, gap):
    check_layout(layout, gap)
    W, H = layout.sheet
    box = shapely.box(0, 0, W, H)
    for k in range(layout.n_sheets):
        polys = [p.polygon(0.001) for p in layout.on_sheet(k)]
        assert polys, "empty sheet"
        for i, P in enumerate(polys):
            assert box.contains(P)
            for Q in polys[i + 1:]:
                assert P.distance(Q) >= gap - 0.02


def _sheet_parts(layout):
    return [layout.on_sheet(k) for k in range(layout.n_sheets)]


@pytest.mark.slow
@pytest.mark.parametrize("kind, nr, nc, sheet, gap, kerf", [
    ("GG", 5, 6, "250x100", 4, 0.0), ("GG", 4, 5, "100x300", 3, 0.2),
    ("CNC", 4, 5, "600x400", 5, 0.0), ("CNC", 5, 6, "400x200", 5, 0.1),
    ("NCP", 5, 6, "300x120", 5, 0.0), ("NCP", 4, 4, "300x150", 2, 0.0)])
def test_parts_keep_the_gap_and_the_margin(kind, nr, nc, sheet, gap, kerf):
    """Checked with shapely on the cut outlines (kerf included): no two parts closer than the
    gap, every part inside the sheet less its gap-wide margin, no empty sheet."""
    parts, layout, params = _layout(kind, sheet=sheet, gap=gap, kerf=kerf, nr=nr, nc=nc)
    _assert_valid(layout, gap)
    W, H = layout.sheet
    inner = shapely.box(gap, gap, W - gap, H - gap).buffer(0.06)   # nesting.SLACK
    for ps in _sheet_parts(layout):
        assert ps
        assert all(inner.contains(p.polygon(0.001)) for p in ps)
    assert sorted(id(p.strip) for p in layout.parts) == sorted(id(p.strip) for p in parts)


def test_portrait_sheet():
    parts, layout, params = _layout("GG", sheet="100x300", gap=3)
    _assert_valid(layout, 3)
    for p in layout.parts:
        x0, y0, x1, y1 = p.polygon().bounds
        assert y1 - y0 > x1 - x0        # strips run along the long side


def test_straight_rows_are_filled_best_first():
    """Rows of straight strips: each row takes the longest strip left and the others that
    fill it best; with lengths that pair up exactly (a + b = one row) every row is full and
    the strips take the fewest rows, where first fit decreasing wastes one."""
    from gridshell.fabrication.nesting import _fullest

    L = np.array([60.0, 50, 45, 40, 35, 30])       # + gap each; capacity 100
    assert sorted(L[_fullest(L, 100.0)]) == [40.0, 60.0]
    M = np.array([70.0, 40, 30, 29])
    assert sum(M[_fullest(M, 100.0)]) == 100.0
    assert _fullest(np.array([120.0, 10]), 100.0) == []


def test_congruent_arcs_nest_into_each_other():
    """Arcs of one circle fall into each other: consecutive arcs of a pile are closer than
    the height of their bounding boxes (nested, not stacked box on box), and the sheet use
    beats the bounding boxes' by far."""
    parts, layout, params = _layout("CNC", sheet="600x400", gap=5)
    _assert_valid(layout, 5)
    assert layout.n_sheets == 1
    polys = [p.polygon(0.01) for p in layout.parts]
    boxes = shapely.unary_union([shapely.box(*P.bounds) for P in polys])
    overlapping_boxes = sum(P.area for P in [shapely.box(*Q.bounds) for Q in polys]) - boxes.area
    assert overlapping_boxes > 0.2 * boxes.area        # boxes overlap: the arcs interlock


@pytest.mark.parametrize("kind, nr, nc, sheet", [("CNC", 4, 5, "600x400"),
                                                ("NCP", 4, 4, "600x400"),
                                                ("GG", 4, 5, "600x400"),
                                                ("CNC", 4, 4, "500x400")])
def test_sheet_count_within_the_area_bound(kind, nr, nc, sheet):
    """At most ceil(1.15 x part area / sheet area) sheets (outline areas) where the parts
    fit at all; Layout.used agrees with the outline areas."""
    from gridshell.fabrication.nesting import sheet_bound

    parts, layout, params = _layout(kind, sheet=sheet, gap=5, nr=nr, nc=nc)
    _assert_valid(layout, 5)
    assert layout.n_sheets <= sheet_bound(parts, params.sheet)
    W, H = params.sheet
    area = sum(p.polygon(0.01).area for p in parts)
    assert layout.used() == pytest.approx(area / (layout.n_sheets * W * H))
    assert sum(layout.used(k) for k in range(layout.n_sheets)) == pytest.approx(
        layout.n_sheets * layout.used())


def test_ncp_pieces_on_several_sheets():
    parts, layout, params = _layout("NCP", sheet="300x120", gap=5, nr=4, nc=4)
    assert layout.n_sheets >= 2
    _assert_valid(layout, 5)


def test_long_lamellae_are_split_at_joints_with_the_stated_overlap(tmp_path):
    b = make_bundle("GG", nr=3, nc=8, a=0.2, stretch=0.05)
    params = FabParams(scale="1:2", sheet="600x300", margin=15)
    strips = strips_from_bundle(b, params)
    long = [s for s in strips if extent(s)[0] > 590]
    assert long
    for s in long:
        pieces = split_strip(s, params)
        assert len(pieces) >= 2
        for a, c in zip(pieces[:-1], pieces[1:]):
            k = a.splices[-1]["splice_joint"]
            assert c.s0 == pytest.approx(s.joint_s[k] - 15)   # margin before joint k
            ov = (s.joint_s[k + 1] - s.joint_s[k]) + 30              # default overlap
            assert a.s1 - c.s0 == pytest.approx(ov)
            assert a.splices[-1]["shared_joints"] == [k, k + 1]
        assert np.unique(np.concatenate([p.joint_s for p in pieces])) == pytest.approx(s.joint_s)
    # a stated overlap
    params2 = FabParams(scale="1:2", sheet="600x300", margin=15, overlap=40)
    pieces = split_strip(long[0], params2)
    assert pieces[0].s1 - pieces[1].s0 == pytest.approx(40)
    # through fabricate: no overlaps, the cut list says so
    rep = fabricate(b, tmp_path / "fab", params, plan=False)
    assert rep["pieces_split"] and rep["n_pieces"] > rep["n_strips"]
    parts = []
    for k in range(rep["n_sheets"]):
        parts += read_dxf_sheet(tmp_path / "fab" / f"sheet_{k + 1:02d}.dxf")[1]
    assert len(parts) == rep["n_pieces"]
    with open(tmp_path / "fab" / "cutlist.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    split_rows = [r for r in rows if r["piece"] != "1/1"]
    assert split_rows and all("overlaps piece" in r["splice"] for r in split_rows)
    assert {int(r["lamella"]) for r in split_rows} == {d["lamella"] for d in rep["pieces_split"]}
    # splice joints named as engraved on the strips: the ids of the crossing lamellae there
    # (the neighbours column of the same row), never positions along the lamella
    net = {int(lam.id): lam for lam in b.net.lamellae}
    cross = {}
    for lam in b.net.lamellae:
        for j in lam.joints:
            cross.setdefault(int(j), []).append(int(lam.id))
    for r in split_rows:
        nbs = r["neighbours"].split("|")
        for note in r["splice"].split("; "):
            named = note.split("(shared joints ")[1].rstrip(")").split(" and ")
            assert named and all(n in nbs for n in named), (named, nbs)
        lam = net[int(r["lamella"])]
        ids = {str(i) for j in lam.joints for i in cross[int(j)] if i != lam.id}
        assert all(n in ids for note in r["splice"].split("; ")
                   for n in note.split("(shared joints ")[1].rstrip(")").split(" and "))
    for r in rows:        # the material used, per sheet and for all, in every row
        assert int(r["n_sheets"]) == rep["n_sheets"]
        assert float(r["material_used_pct"]) == pytest.approx(100 * rep["material_used"], abs=0.06)
        assert float(r["sheet_used_pct"]) == pytest.approx(
            100 * rep["material_used_per_sheet"][int(r["sheet"]) - 1], abs=0.06)


def test_a_sheet_smaller_than_a_joint_spacing_is_an_input_error():
    from gridshell.core.errors import InputError

    b = make_bundle("GG")
    params = FabParams(scale="1:1", sheet="100x60")
    with pytest.raises(InputError, match="larger --sheet"):
        split_strip(strips_from_bundle(b, params)[0], params)
