"""Writers (issue item 5): DXF R2010/R12 re-read and audited; SVG measured in mm."""
from __future__ import annotations

import numpy as np
import pytest
import shapely
from tests.helpers.fab_cases import make_bundle, read_dxf_sheet

from gridshell.fabrication.layers import LAYERS
from gridshell.fabrication import FabParams, fabricate


@pytest.fixture(scope="module")
def cnc_bundle():
    return make_bundle("CNC", nr=3, nc=4)


@pytest.mark.parametrize("version,segments,joints", [("R2010", False, "hole"),
                                                     ("R12", False, "marks"),
                                                     ("R2010", True, "slots"),
                                                     ("R12", True, "hole")])
def test_dxf_round_trip(cnc_bundle, tmp_path, version, segments, joints):
    rep = fabricate(cnc_bundle, tmp_path / "f", FabParams(dxf_version=version, segments=segments,
                                                          joints=joints, kerf=0.1),
                    plan=False)
    doc, parts = read_dxf_sheet(tmp_path / "f" / "sheet_01.dxf")
    assert doc.dxfversion == ("AC1009" if version == "R12" else "AC1024")
    assert doc.header["$INSUNITS"] == 4
    layers = {l.dxf.name: l.dxf.color for l in doc.layers}
    assert (layers["CUT"], layers["SCORE"], layers["ENGRAVE"]) == (1, 5, 3)   # never ACI 7
    check_extents(doc)
    if version == "R2010":     # true colours as well as ACI, on the layers and the entities
        rgb = {l.dxf.name: l.rgb for l in doc.layers if l.dxf.name in LAYERS}
        assert rgb == {k: v[1] for k, v in LAYERS.items()}
        assert all(e.rgb == LAYERS[e.dxf.layer][1] and e.dxf.color == LAYERS[e.dxf.layer][0]
                   for e in doc.modelspace())
    assert len(parts) == rep["n_pieces"]
    outline_type = "POLYLINE" if version == "R12" else "LWPOLYLINE"
    outlines = [e for e in doc.modelspace() if e.dxf.layer == "CUT" and e.dxftype() == outline_type]
    if version == "R12":
        bulges = [v.dxf.bulge for e in outlines for v in e.vertices]
    else:
        bulges = [b for e in outlines for *_, b in e.get_points("xyb")]
    assert any(bulges) != segments          # bulges unless --segments
    if joints == "marks":
        assert sum(len(p["scores"]) for p in parts) == rep["n_joint_marks"]
    if joints == "hole":
        assert all(r == pytest.approx(1.5 - 0.05) for p in parts for r in p["radii"])


def test_svg_parses_and_measures_in_mm(cnc_bundle, tmp_path):
    from svgelements import SVG, Circle, Path, Polyline

    rep = fabricate(cnc_bundle, tmp_path / "f", FabParams(sheet="600x400"), plan=False)
    f = tmp_path / "f" / "sheet_01.svg"
    text = f.read_text()
    assert 'width="600mm"' in text and 'height="400mm"' in text and 'viewBox="0 0 600 400"' in text
    svg = SVG.parse(str(f), ppi=25.4)       # 1 px = 1 mm
    assert svg.width == pytest.approx(600) and svg.height == pytest.approx(400)
    els = list(svg.elements())
    circles = [e for e in els if isinstance(e, Circle)]
    paths = [e for e in els if isinstance(e, Path) and not isinstance(e, Polyline)]
    strokes = [e for e in els if isinstance(e, Polyline)]
    assert {e.stroke.hexrgb.upper() for e in circles + paths} == {"#FF0000"}
    assert {e.stroke.hexrgb.upper() for e in strokes} == {"#00FF00"}
    assert all(e.fill is None or e.fill.value is None for e in circles + paths + strokes)
    # the same holes as the DXF, y flipped
    doc, parts = read_dxf_sheet(tmp_path / "f" / "sheet_01.dxf")
    H = np.concatenate([p["holes"] for p in parts])
    C = np.array([[c.cx, 400 - c.cy] for c in circles])
    assert len(C) == len(H) == rep["n_joint_marks"]
    assert np.sort(C, axis=0) == pytest.approx(np.sort(H, axis=0), abs=1e-3)
    assert all(c.rx == pytest.approx(1.5) for c in circles)
    # arcs come back with the radii of the DXF bulges, passing through the same points
    from svgelements import Arc
    radii = sorted({round(seg.rx, 2) for p in paths for seg in p if isinstance(seg, Arc)})
    assert radii == pytest.approx([90.0, 110.0], abs=0.01)
    for p in paths:
        pts = [shapely.Point(pt.x, 400 - pt.y)
               for pt in (p.point(t) for t in np.linspace(0, 1, 60))]
        assert min(max(pp["poly"].exterior.distance(q) for q in pts) for pp in parts) < 0.03


@pytest.fixture(scope="module")
def gg_bundle():
    return make_bundle("GG")


@pytest.mark.parametrize("joints", ["marks", "hole"])
def test_gg_svg_round_trip_layers_colours_and_units(gg_bundle, tmp_path, joints):
    """A GG (straight strips) sheet read back with svgelements: width/height in mm equal the
    viewBox (1 unit = 1 mm), SCORE lines pure #0000FF, CUT #FF0000, ENGRAVE #00FF00, hairline
    strokes, no fill; and the same outlines, holes, score lines and strokes as the DXF."""
    import xml.etree.ElementTree as ET

    from svgelements import SVG, Circle, Line, Move, Path, Polyline, Shape, SimpleLine

    W, H = 500, 300
    rep = fabricate(gg_bundle, tmp_path / "f", FabParams(joints=joints, sheet=f"{W}x{H}"),
                    plan=False)
    ns = "{http://www.w3.org/2000/svg}"
    expect = {"CUT": "#FF0000", "SCORE": "#0000FF", "ENGRAVE": "#00FF00"}
    tags = {"CUT": {"path", "circle"}, "SCORE": {"line"}, "ENGRAVE": {"polyline"}}
    for k in range(rep["n_sheets"]):
        f = tmp_path / "f" / f"sheet_{k + 1:02d}.svg"
        root = ET.parse(f).getroot()
        assert (root.get("width"), root.get("height")) == (f"{W}mm", f"{H}mm")
        assert [float(v) for v in root.get("viewBox").split()] == [0, 0, W, H]
        # each layer group holds only its own elements, each in the layer's pure colour
        groups = {g.get("id"): g for g in root.iter(f"{ns}g")}
        assert set(groups) == set(expect)
        for name, g in groups.items():
            for e in g:
                assert e.tag[len(ns):] in tags[name]
                assert e.get("stroke") == expect[name] and e.get("fill") == "none"
                assert float(e.get("stroke-width")) <= 0.05            # a hairline, mm
        svg = SVG.parse(str(f), ppi=25.4)                                # 1 px = 1 mm
        assert svg.width == pytest.approx(W, rel=1e-5) and svg.height == pytest.approx(H, rel=1e-5)
        assert (svg.viewbox.width, svg.viewbox.height) == (W, H)
        shapes = [e for e in svg.elements() if isinstance(e, Shape)]
        assert all(e.fill is None or e.fill.value is None for e in shapes)
        assert all(e.stroke_width == pytest.approx(0.025, rel=1e-3) for e in shapes)
        lines = [e for e in shapes if isinstance(e, SimpleLine)]
        strokes = [e for e in shapes if isinstance(e, Polyline)]
        circles = [e for e in shapes if isinstance(e, Circle)]
        outlines = [e for e in shapes if isinstance(e, Path) and not isinstance(e, Polyline)]
        assert {e.stroke.hexrgb.upper() for e in lines} == ({"#0000FF"} if joints == "marks"
                                                            else set())
        assert {e.stroke.hexrgb.upper() for e in circles + outlines} == {"#FF0000"}
        assert {e.stroke.hexrgb.upper() for e in strokes} == {"#00FF00"}
        # the same geometry as the DXF, y flipped
        doc, parts = read_dxf_sheet(tmp_path / "f" / f"sheet_{k + 1:02d}.dxf")
        assert len(outlines) == len(parts)
        for e in outlines:
            V = np.array([(s.end.x, H - s.end.y) for s in e if isinstance(s, (Move, Line))])
            P = shapely.Polygon(V)
            best = min(parts, key=lambda q: q["poly"].symmetric_difference(P).area)
            assert best["poly"].symmetric_difference(P).area < 1e-3 * P.length
            assert best["poly"].bounds == pytest.approx(P.bounds, abs=1e-3)
        S = np.array([[[l.x1, H - l.y1], [l.x2, H - l.y2]] for l in lines]).reshape(-1, 2, 2)
        D = np.array([L for q in parts for L in q["scores"]]).reshape(-1, 2, 2)
        C = np.array([[c.cx, H - c.cy] for c in circles]).reshape(-1, 2)
        Hd = np.concatenate([q["holes"] for q in parts])
        assert len(strokes) == sum(len(q["engrave"]) for q in parts) > 0
        if joints == "marks":
            assert len(S) == len(D) == sum(len(lam.joints) for lam in gg_bundle.net.lamellae)
            assert len(C) == 0
            key = lambda A: A[np.lexsort((A[:, 1], A[:, 0]))]       # noqa: E731
            assert key(S.mean(axis=1)) == pytest.approx(key(D.mean(axis=1)), abs=1e-3)
            assert np.linalg.norm(S[:, 1] - S[:, 0], axis=1) == pytest.approx(
                np.full(len(S), 20.0), abs=1e-3)
        else:
            assert len(S) == 0 and len(C) == len(Hd) > 0
            assert np.sort(C, axis=0) == pytest.approx(np.sort(Hd, axis=0), abs=1e-3)
            assert all(c.rx == pytest.approx(1.5) for c in circles)


def check_extents(doc):
    """$EXTMIN / $EXTMAX are the drawing's real extents (mm): the bounding box of every
    entity, recomputed with ezdxf.bbox, within 0.01 mm; never the 1e20 defaults."""
    from ezdxf import bbox

    box = bbox.extents(doc.modelspace(), fast=False)
    lo, hi = doc.header["$EXTMIN"], doc.header["$EXTMAX"]
    assert np.allclose(np.asarray(lo)[:2], [box.extmin.x, box.extmin.y], atol=0.01)
    assert np.allclose(np.asarray(hi)[:2], [box.extmax.x, box.extmax.y], atol=0.01)
    assert 0 <= lo[0] < hi[0] < 1e6 and 0 <= lo[1] < hi[1] < 1e6
