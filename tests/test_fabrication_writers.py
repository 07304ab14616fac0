"""Writers (issue item 5): DXF R2010/R12 re-read and audited; SVG measured in mm."""
from __future__ import annotations

import numpy as np
import pytest
import shapely
from fab_cases import make_bundle, read_dxf_sheet

from fabrication import FabParams, fabricate


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
    assert (layers["CUT"], layers["SCORE"], layers["ENGRAVE"]) == (1, 5, 7)
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
    assert {e.stroke.hexrgb.upper() for e in strokes} == {"#000000"}
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
