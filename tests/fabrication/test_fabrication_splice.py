"""Splices between joints (issue 13): a lamella whose joint spacing exceeds the sheet is cut
between two joints into lap-spliced pieces that each fit the sheet."""
from __future__ import annotations

import csv
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from ezdxf import recover
from tests.helpers.fab_cases import make_bundle, read_dxf_sheet

from gridshell.fabrication import FabParams, fabricate
from gridshell.fabrication.axis import ArcAxis, LineAxis
from gridshell.fabrication.dxf import write_sheet_dxf
from gridshell.fabrication.nesting import check_layout, nest
from gridshell.fabrication.part import build_part
from gridshell.fabrication.splice import extent, split_strip
from gridshell.fabrication.strip import Strip
from gridshell.fabrication.strips import strips_from_bundle
from gridshell.fabrication.svg import write_sheet_svg
from gridshell.core.errors import InputError

DEFAULTS = FabParams()          # 1:10 polypropylene: 20 x 1 mm strips, 600 x 400 mm sheets


def _strip(axis, joint_s, margin=15.0, width=20.0):
    js = np.asarray(joint_s, float)
    return Strip(lamella=7, family=1, orientation="tangent", axis=axis,
                 s0=js[0] - margin, s1=js[-1] + margin, t_lo=-width / 2, t_hi=width / 2,
                 joint_s=js, joint_index=np.arange(len(js)) + 100,
                 neighbours=[[20 + i] for i in range(len(js))])


def _span_notes(pieces):
    """The span splices, each once: ``(earlier piece, note)``."""
    return [(p, n) for p in pieces for n in p.splices
            if n["with"] > p.piece and n["kind"] == "span"]


def _check_pieces(strip, pieces, params):
    L_long = max(params.sheet) - 2 * params.gap
    L_short = min(params.sheet) - 2 * params.gap
    for p in pieces:
        a, b = extent(p, params.kerf)
        assert a <= L_long + 1e-6 and b <= L_short + 1e-6, (p.name, a, b)
    # consecutive pieces overlap by the stated overlap; lengths less overlaps = the strip
    overlaps = [p.s1 - q.s0 for p, q in zip(pieces[:-1], pieces[1:])]
    for p, q, ov in zip(pieces[:-1], pieces[1:], overlaps):
        note = next(n for n in p.splices if n["with"] == q.piece)
        assert ov == pytest.approx(note["overlap"])
        assert ov > 0
    assert sum(p.length for p in pieces) - sum(overlaps) == pytest.approx(strip.length, abs=1e-6)
    # every joint is on some piece, exactly where it was
    assert np.unique(np.concatenate([p.joint_s for p in pieces])) == pytest.approx(strip.joint_s)
    # span splices: strictly between two consecutive joints, a margin (> hole clearance) clear
    js = strip.joint_s
    for p, n in _span_notes(pieces):
        a, b = n["from"], n["to"]
        i = np.searchsorted(js, a)
        assert 0 < i < len(js) and js[i - 1] < a < b < js[i]
        assert min(a - js[i - 1], js[i] - b) >= params.margin - 1e-9 > params.hole / 2
        # the splice fasteners are on both pieces, at the same lamella position
        q = pieces[n["with"] - 1]
        for s in n["fasteners"]:
            assert a < s < b
            assert np.any(np.isclose(p.splice_s, s)) and np.any(np.isclose(q.splice_s, s))


def _write_and_read(parts, params, tmp_path):
    layout = nest(parts, params)
    check_layout(layout, params.gap)
    n_holes = 0
    for k in range(layout.n_sheets):
        sp = layout.on_sheet(k)
        dxf, svg = tmp_path / f"s{k}.dxf", tmp_path / f"s{k}.svg"
        write_sheet_dxf(dxf, sp, params.sheet, params)
        write_sheet_svg(svg, sp, params.sheet, params)
        doc, auditor = recover.readfile(str(dxf))
        assert not auditor.has_errors and not doc.audit().has_errors
        _, read = read_dxf_sheet(dxf)
        assert len(read) == len(sp)
        n_holes += sum(len(r["holes"]) for r in read)
        root = ET.parse(svg).getroot()
        nums = []
        for e in root.iter():
            for key in ("cx", "cy", "r", "x1", "y1"):
                if key in e.attrib:
                    nums.append(float(e.attrib[key]))
        assert nums and np.all(np.isfinite(nums))
    for p in layout.parts:
        assert np.all(np.isfinite(p.outline.V)) and np.all(np.isfinite(p.holes))
        assert all(np.all(np.isfinite(L)) for L in p.engrave)
    return layout, n_holes


@pytest.mark.parametrize("spacing, n_joints", [(1500.0, 3), (931.3, 2), (2400.0, 2)])
def test_long_straight_strip_is_spliced_between_joints(spacing, n_joints, tmp_path):
    params = DEFAULTS
    strip = _strip(LineAxis(), spacing * np.arange(n_joints))
    pieces = split_strip(strip, params)
    assert len(pieces) >= 2
    _check_pieces(strip, pieces, params)
    notes = _span_notes(pieces)
    assert notes and all(n["lamella"] == 7 and n["label"].startswith("L7-S") for _, n in notes)
    # pieces as long as the sheet allows: none but the last is shorter than half the sheet
    L = max(params.sheet) - 2 * params.gap
    assert all(p.length > L / 2 for p in pieces[:-1])
    parts = [build_part(p, params) for p in pieces]
    layout, n_holes = _write_and_read(parts, params, tmp_path)
    # joint holes plus two fastener holes on each of the two pieces of every span splice
    assert n_holes == len(strip.joint_s) + 4 * len(notes)
    # the splice is engraved on both pieces, between its fasteners (x = s on a straight strip)
    for p, n in notes:
        for k in (p.piece, n["with"]):
            part = parts[k - 1]
            lo, hi = n["fasteners"][0], n["fasteners"][-1]
            inside = [L for L in part.engrave if lo < L[:, 0].min() and L[:, 0].max() < hi]
            assert inside, (part.strip.name, n)


def test_long_circular_arc_strip_is_spliced_between_joints(tmp_path):
    """A circular strip (CNC, or NCP collapsing into a circle) of radius 2000 mm with joints
    1200 mm apart along the arc; every piece is an arc of the circle, whose chord extent is
    the closed form."""
    params = DEFAULTS
    R = 2000.0
    strip = _strip(ArcAxis(1.0 / R), [0.0, 1200.0, 2400.0, 3600.0])
    strip.orientation = "orthogonal"
    pieces = split_strip(strip, params)
    _check_pieces(strip, pieces, params)
    assert _span_notes(pieces)
    # each piece is an arc of the one circle: its chord extent is the closed form
    for p in pieces:
        phi = p.length / R
        assert extent(p)[0] == pytest.approx(2 * (R + 10) * np.sin(phi / 2), rel=1e-3)
    parts = [build_part(p, params) for p in pieces]
    _write_and_read(parts, params, tmp_path)


def test_stated_overlap_is_used_for_span_splices():
    params = FabParams(overlap=50.0)
    strip = _strip(LineAxis(), [0.0, 2000.0])
    pieces = split_strip(strip, params)
    _check_pieces(strip, pieces, params)
    for _, n in _span_notes(pieces):
        assert n["overlap"] == pytest.approx(50.0)
        assert n["fasteners"] == pytest.approx([n["from"] + 15, n["to"] - 15])


def test_strips_that_fit_are_unchanged():
    params = DEFAULTS
    strip = _strip(LineAxis(), [0.0, 200.0, 400.0])
    (p,) = split_strip(strip, params)
    assert p is strip and len(p.splice_s) == 0


def test_a_large_design_fabricates_with_the_defaults(tmp_path):
    """The 1:1 saddle bundle has joints ~250 mm apart; on a 300 x 200 mm sheet no two joint
    spacings fit, which used to stop with 'does not fit ... even between two joints'."""
    b = make_bundle("GG", nr=3, nc=5)
    params = FabParams(scale="1:1", sheet="300x200")
    rep = fabricate(b, tmp_path / "fab", params, plan=False)
    assert rep["n_pieces"] > rep["n_strips"]
    span = [s for d in rep["pieces_split"] for s in d["span_splices_mm"]]
    assert span
    with open(tmp_path / "fab" / "cutlist.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    texts = " ".join(r["splice"] for r in rows)
    for d in rep["pieces_split"]:
        for s in d["span_splices_mm"]:
            assert f"lamella {d['lamella']}" in texts and f"{s:.1f} mm along" in texts
    sheets = [read_dxf_sheet(tmp_path / "fab" / f"sheet_{k + 1:02d}.dxf")[1]
              for k in range(rep["n_sheets"])]
    assert sum(len(s) for s in sheets) == rep["n_pieces"]


def test_what_cannot_be_cut_is_a_one_line_input_error():
    # a circular strip so tight that even its shortest piece is wider than the sheet
    params = FabParams(sheet="600x32", gap=5)
    strip = _strip(ArcAxis(1.0 / 150.0), [0.0, 300.0, 600.0])
    with pytest.raises(InputError) as e:
        split_strip(strip, params)
    msg = str(e.value)
    assert "\n" not in msg and "lamella 7" in msg and "--sheet" in msg


def test_lamellae_joint_splices_cannot_cut_are_spliced_between_joints(tmp_path):
    """AA strips with slots, 1:2, on a 400 x 200 mm sheet: two joint spacings do not fit
    lamellae 4-8, and lamella 3's farthest joint splices leave a last stretch no piece can
    cover (both used to stop the fabrication); they are spliced between joints instead.
    With slots, the span-splice fasteners are score marks on both pieces."""
    b = make_bundle("AA", nr=4, nc=5)
    params = FabParams(joints="slots", scale="1:2", sheet="400x200")
    rep = fabricate(b, tmp_path / "fab", params, plan=False)
    n_span = sum(len(d["span_splices_mm"]) for d in rep["pieces_split"])
    assert n_span
    scores = 0
    for k in range(rep["n_sheets"]):
        for part in read_dxf_sheet(tmp_path / "fab" / f"sheet_{k + 1:02d}.dxf")[1]:
            scores += len(part["scores"])
            x0, y0, x1, y1 = part["poly"].bounds
            W, H = params.sheet[0] - 2 * params.gap, params.sheet[1] - 2 * params.gap
            assert max(x1 - x0, y1 - y0) <= W + 1e-6 and min(x1 - x0, y1 - y0) <= H + 1e-6
    assert scores == 2 * 2 * n_span         # two marks per splice, on both of its pieces


def test_short_sheet_where_the_greedy_split_strands_the_rest():
    """AA 1:1 on a 194 x 119 mm sheet: piece after piece as long as the sheet allows puts an
    overlap just short of joint 2, from where no piece reaches past the joint's clearance
    (this used to stop with 'does not fit'); the exact span-splice plan places the overlaps
    so that every joint is crossed."""
    b = make_bundle("AA", nr=4, nc=5)
    params = FabParams(scale="1:1", sheet="194x119", joints="marks")
    for strip in strips_from_bundle(b, params):
        pieces = split_strip(strip, params)
        _check_pieces(strip, pieces, params)
        assert _span_notes(pieces)


def test_span_and_joint_splices_combine():
    """A 1500 mm span, then joints 80 mm apart for 960 mm: no span overlap fits between the
    close joints (80 < overlap + 2 margins), so span splices alone cannot cut it and joint
    splices alone cannot cross the span; both together do."""
    params = DEFAULTS
    js = np.concatenate([[0.0], 1500.0 + 80.0 * np.arange(13)])
    strip = _strip(LineAxis(), js)
    pieces = split_strip(strip, params)
    _check_pieces(strip, pieces, params)
    kinds = {n["kind"] for p in pieces for n in p.splices}
    assert kinds == {"span", "joint"}
    for p, q in zip(pieces[:-1], pieces[1:]):
        n = next(n for n in p.splices if n["with"] == q.piece)
        if n["kind"] == "joint":          # the two pieces share two joints
            k = n["splice_joint"]
            assert n["shared_joints"] == [k, k + 1]
            assert set(js[[k, k + 1]]) <= set(p.joint_s) & set(q.joint_s)
