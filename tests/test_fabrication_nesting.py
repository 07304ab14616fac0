"""Nesting (issue item 4): rows first-fit decreasing, stacks of congruent curved strips,
sheets as needed, splices for lamellae longer than a sheet."""
from __future__ import annotations

import csv

import numpy as np
import pytest
import shapely
from fab_cases import make_bundle, read_dxf_sheet

from fabrication import FabParams, fabricate
from fabrication.nesting import check_layout, nest
from fabrication.part import build_part
from fabrication.splice import extent, split_strip
from fabrication.strips import strips_from_bundle


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


def test_rows_first_fit_decreasing_fill_several_sheets():
    parts, layout, params = _layout("GG", sheet="250x100", gap=4, nr=5, nc=6)
    assert layout.n_sheets > 1
    _assert_valid(layout, 4)
    # straight strips stay axis-parallel, in rows of the strip width
    for p in layout.parts:
        x0, y0, x1, y1 = p.polygon().bounds
        assert y1 - y0 == pytest.approx(20.0)
    # first-fit decreasing: no later sheet holds a strip that fits the gap left in a row
    # of an earlier sheet
    ys = {}
    for p, s in zip(layout.parts, layout.sheet_of):
        x0, y0, x1, y1 = p.polygon().bounds
        ys.setdefault((s, round(y0, 6)), []).append(x1)
    free = {key: 250 - 4 - max(v) for key, v in ys.items()}
    for p, s in zip(layout.parts, layout.sheet_of):
        L = p.polygon().bounds[2] - p.polygon().bounds[0]
        assert not any(f >= L + 4 + 1e-6 for (sh, _), f in free.items() if sh < s)


def test_portrait_sheet():
    parts, layout, params = _layout("GG", sheet="100x300", gap=3)
    _assert_valid(layout, 3)
    for p in layout.parts:
        x0, y0, x1, y1 = p.polygon().bounds
        assert y1 - y0 > x1 - x0        # strips run along the long side


def test_congruent_arcs_nest_in_stacks():
    """Arcs of one circle (lamellae of different lengths) stack along their symmetry axis,
    longest first, each dropped onto those below until it is ``gap`` from them: consecutive
    parts of a stack are at least width + gap apart (their middles are normal to the drop)
    and far less than a part's height - they nest."""
    parts, layout, params = _layout("CNC", sheet="600x400", gap=5)
    _assert_valid(layout, 5)
    assert layout.n_sheets == 1
    stacks = {}
    for p in layout.on_sheet(0):
        x0, _, x1, _ = p.polygon().bounds
        stacks.setdefault(round(0.5 * (x0 + x1), 3), []).append(p)   # centred in a stack
    steps = 0
    for ps in stacks.values():
        ps.sort(key=lambda p: p.polygon().bounds[1])
        for i in range(1, len(ps)):
            p, q = ps[i - 1], ps[i]
            assert q.strip.length <= p.strip.length + 1e-6       # longest first
            dy = q.polygon().bounds[1] - p.polygon().bounds[1]
            h = q.polygon().bounds[3] - q.polygon().bounds[1]
            assert 25 - 1e-6 <= dy < h
            # dropped as far as the gap allows: it touches the stack below at ~gap
            below = shapely.unary_union([r.polygon(0.001) for r in ps[:i]])
            assert 5 - 0.02 <= q.polygon(0.001).distance(below) <= 5 + 0.5
            steps += 1
    assert steps >= 6


def test_ncp_pieces_stack_on_several_sheets():
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


def test_a_sheet_smaller_than_a_joint_spacing_is_an_input_error():
    from gridshell.errors import InputError

    b = make_bundle("GG")
    params = FabParams(scale="1:1", sheet="100x60")
    with pytest.raises(InputError, match="larger --sheet"):
        split_strip(strips_from_bundle(b, params)[0], params)


@pytest.mark.parametrize("kind, nr, nc, sheet, most", [("CNC", 4, 4, "300x150", 2),
                                                      ("CNC", 5, 6, "400x200", 5),
                                                      ("NCP", 5, 6, "300x120", 7)])
def test_curved_parts_go_to_the_first_stack_with_room(kind, nr, nc, sheet, most):
    """First fit for stacks: a part goes into the first stack (on any sheet) with room for it,
    else into a new stack right of the others on the first sheet with room. Before, only the
    last stack was tried and these layouts took 3, 6 and 9 sheets. No part on a later sheet
    fits in the width left right of an earlier sheet's stacks."""
    parts, layout, params = _layout(kind, sheet=sheet, gap=5, nr=nr, nc=nc)
    _assert_valid(layout, 5)
    assert layout.n_sheets <= most
    W, H = layout.sheet
    L = max(W, H)
    along = 0 if W >= H else 1          # the nesting frame's long side
    end = {}
    for p, s in zip(layout.parts, layout.sheet_of):
        end[s] = max(end.get(s, 0.0), p.polygon().bounds[2 + along])
    for p, s in zip(layout.parts, layout.sheet_of):
        b = p.polygon().bounds
        for s0 in range(s):
            assert L - 5 - (end[s0] + 5) < b[2 + along] - b[along] - 1e-6, (s, s0)
