"""Acceptance of issue #6 on synthetic GG, CNC and NCP bundles: files re-read, joint spacing,
counts, no overlaps, NCP congruence, CNC radius, assembly plan and sheet previews.

Parts read back from the DXF are matched to lamellae by id: the report's ``pieces`` give each
piece's lamella, sheet and placement, and the cut list its joint positions, so a part that
carried another lamella's joints (or collapse position) fails."""
from __future__ import annotations

import json

import numpy as np
import pytest
import shapely
import shapely.affinity
from tests.helpers.fab_cases import (fit_circle, make_bundle, match_pieces, parabola_at, parabola_band,
                       plan_labels, read_cutlist, read_dxf_sheet, similarity_fit)

from gridshell.fabrication import FabParams, fabricate
from gridshell.geometry.net import polyline_arclength

MM = 100.0      # mm per design metre at 1:10
R_DESIGN = 1.0  # CNC collapse radius, m


_MADE: dict = {}


def _made(kind, tmp_path_factory):
    """Bundle of ``kind`` fabricated once per test session."""
    if kind not in _MADE:
        _MADE[kind] = _fabricate(kind, tmp_path_factory)
    return _MADE[kind]


@pytest.fixture(scope="module", params=["GG", "CNC", "NCP"])
def made(request, tmp_path_factory):
    return _made(request.param, tmp_path_factory)


def _fabricate(kind, tmp_path_factory):
    shape = dict(nr=4, nc=4) if kind == "NCP" else dict(nr=4, nc=5)
    b = make_bundle(kind, R=R_DESIGN, **shape)
    out = tmp_path_factory.mktemp(kind) / "fab"
    rep = fabricate(b, out, FabParams(width=20, thickness=1, hole=3, sheet="600x400",
                                      scale="1:10"), plan=kind == "GG")
    sheets = [read_dxf_sheet(out / f"sheet_{k + 1:02d}.dxf") for k in range(rep["n_sheets"])]
    return kind, b, out, rep, sheets


def test_the_synthetic_lamellae_differ():
    """The cases distinguish lamellae: no two share their joint spacings (rows and columns
    of the twisted saddle), and NCP lamellae start at different collapse positions."""
    for kind, shape in (("GG", dict(nr=4, nc=5)), ("NCP", dict(nr=4, nc=4))):
        b = make_bundle(kind, **shape)
        d = [np.diff(lam.joint_s) * MM for lam in b.net.lamellae]
        for i in range(len(d)):
            for j in range(i + 1, len(d)):
                assert len(d[i]) != len(d[j]) or np.max(np.abs(d[i] - d[j])) > 1.0
    starts = [cs[0] for cs in b.collapse_s.values()]
    assert np.min(np.diff(np.sort(starts))) * MM > 5.0


def test_counts_of_strips_and_joint_marks(made):
    kind, b, out, rep, sheets = made
    parts = [p for _, ps in sheets for p in ps]
    assert len(parts) == len(b.net.lamellae) == rep["n_strips"] == rep["n_pieces"]
    assert sum(len(p["holes"]) for p in parts) == sum(len(l.joints) for l in b.net.lamellae)
    assert rep["n_joint_marks"] == rep["n_design_joints"]
    # one piece per lamella id, each found on its sheet with its own joint count
    found = match_pieces(b, rep, sheets)
    assert sorted(found) == sorted((int(lam.id), 1) for lam in b.net.lamellae)
    for lam in b.net.lamellae:
        assert len(found[(int(lam.id), 1)][0]["holes"]) == len(lam.joints)


def _measured_spacing(kind, b, lam, holes):
    """Distances (mm) between consecutive holes along the strip axis, measured on the DXF."""
    if kind == "GG":
        return np.linalg.norm(np.diff(holes, axis=0), axis=1)
    if kind == "CNC":
        c, r = fit_circle(holes)
        ang = np.unwrap(np.arctan2(holes[:, 1] - c[1], holes[:, 0] - c[0]))
        return np.abs(np.diff(ang)) * r
    # NCP: align the holes (rigidly) to the analytic parabola in mm at this lamella's
    # collapse positions, then read their arc lengths along the parabola
    x = np.linspace(-1.5, 1.5, 200001)
    C = np.stack([x, 0.6 * x ** 2], 1) * MM
    s_curve = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(C, axis=0), axis=1))])
    expect = parabola_at(b.collapse_s[lam.id]) * MM
    R, t = _kabsch(holes, expect)
    A = holes @ R.T + t
    assert np.max(np.linalg.norm(A - expect, axis=1)) < 0.05
    idx = [np.argmin(np.linalg.norm(C - a, axis=1)) for a in A]
    return np.diff(s_curve[idx])


def test_joint_spacing_equals_design_arc_length(made):
    """Each lamella's part (found by id) has its own design spacings within 0.05 mm, and the
    cut list row of that id says the same."""
    kind, b, out, rep, sheets = made
    found = match_pieces(b, rep, sheets)
    rows = read_cutlist(out / "cutlist.csv")
    worst = 0.0
    for lam in b.net.lamellae:
        part, _ = found[(int(lam.id), 1)]
        design = np.diff(lam.joint_s) * MM
        measured = _measured_spacing(kind, b, lam, part["holes"])
        worst = max(worst, float(np.max(np.abs(measured - design))))
        row = rows[(int(lam.id), 1)]
        assert int(row["family"]) == lam.family and int(row["n_joints"]) == len(lam.joints)
        assert np.diff(row["joint_positions_mm"]) == pytest.approx(design, abs=2e-3)
        assert float(row["axis_length_mm"]) == pytest.approx(lam.length * MM, abs=2e-3)
    assert worst < 0.05


def test_cutlist_sheet_and_piece_of_every_lamella(made):
    kind, b, out, rep, sheets = made
    rows = read_cutlist(out / "cutlist.csv")
    assert sorted(rows) == sorted((int(lam.id), 1) for lam in b.net.lamellae)
    for pc in rep["pieces"]:
        row = rows[(pc["lamella"], pc["piece"])]
        assert int(row["sheet"]) == pc["sheet"]
        assert float(row["flat_length_mm"]) == pytest.approx(pc["flat_length_mm"], abs=2e-3)


def _kabsch(P, Q):
    """Rotation R and translation t minimising |P R^T + t - Q|."""
    pc, qc = P.mean(0), Q.mean(0)
    U, _, Vt = np.linalg.svd((P - pc).T @ (Q - qc))
    D = np.diag([1, np.sign(np.linalg.det(Vt.T @ U.T))])
    R = Vt.T @ D @ U.T
    return R, qc - pc @ R.T


def test_parts_never_overlap_and_stay_inside_sheets(made):
    kind, b, out, rep, sheets = made
    W, H = rep["params"]["sheet"]
    box = shapely.box(0, 0, W, H)
    for _, parts in sheets:
        polys = [p["poly"] for p in parts]
        assert all(P.is_valid and box.contains(P) for P in polys)
        for i in range(len(polys)):
            for j in range(i + 1, len(polys)):
                assert not polys[i].intersects(polys[j])
                assert polys[i].distance(polys[j]) >= rep["params"]["gap"] - 1e-3


def test_dxf_header_layers_and_order(made):
    kind, b, out, rep, sheets = made
    for doc, _ in sheets:
        assert doc.header["$INSUNITS"] == 4
        assert {l.dxf.name: l.dxf.color for l in doc.layers if l.dxf.name in
                ("CUT", "SCORE", "ENGRAVE")} == {"CUT": 1, "SCORE": 5, "ENGRAVE": 3}
        types = [e.dxftype() for e in doc.modelspace() if e.dxf.layer == "CUT"]
        # holes (CIRCLE) come before every outline
        assert types.index("LWPOLYLINE") > max(i for i, t in enumerate(types) if t == "CIRCLE")
        assert not any(e.dxftype() in ("TEXT", "MTEXT") for e in doc.modelspace())


def test_cnc_arcs_have_radius_one_over_n(tmp_path_factory):
    kind, b, out, rep, sheets = _made("CNC", tmp_path_factory)
    R = R_DESIGN * MM
    for _, parts in sheets:
        for p in parts:
            pts = np.array(p["entity"].get_points("xyb"))
            radii = []
            for i in np.flatnonzero(pts[:, 2]):
                a, c, bulge = pts[i, :2], pts[(i + 1) % len(pts), :2], pts[i, 2]
                th = 4 * np.arctan(bulge)
                radii.append(np.linalg.norm(c - a) / (2 * abs(np.sin(th / 2))))
            radii = np.sort(radii)
            assert len(radii) == 2
            assert radii == pytest.approx([R - 10, R + 10], rel=1e-3)
            assert 0.5 * radii.sum() == pytest.approx(R, rel=1e-3)
            _, r_holes = fit_circle(p["holes"])
            assert r_holes == pytest.approx(R, rel=1e-3)


def test_ncp_strips_are_congruent(tmp_path_factory):
    """Every NCP strip is the piece of one band around the collapse curve that its lamella's
    collapse_s selects: the part found by id, moved rigidly onto its joints on the analytic
    parabola, covers the analytic band between its ends (margins included)."""
    kind, b, out, rep, sheets = _made("NCP", tmp_path_factory)
    found = match_pieces(b, rep, sheets)
    margin = rep["params"]["margin"] / MM
    for lam in b.net.lamellae:
        part, _ = found[(int(lam.id), 1)]
        cs, js = b.collapse_s[lam.id], lam.joint_s
        expect = parabola_at(cs) * MM
        R, t = _kabsch(part["holes"], expect)
        ang = np.degrees(np.arctan2(R[1, 0], R[0, 0]))
        assert np.linalg.det(R) > 0      # a rigid motion, no mirror image
        moved = shapely.affinity.rotate(part["poly"], ang, origin=(0, 0))
        moved = shapely.affinity.translate(moved, *t)
        u0 = cs[0] + min(0.0, js[0]) - js[0] - margin
        u1 = cs[0] + max(lam.length, js[-1]) - js[0] + margin
        ref = parabola_band(u0, u1, 10.0, MM)
        assert moved.symmetric_difference(ref).area < 0.01 * ref.length


def test_plan_shows_every_lamella_id_at_its_place(tmp_path_factory):
    """plan.svg holds every lamella id once, on its own lamella: most at the projected
    midpoint of the axis (those fix the similarity - scale, rotation, reflection, shift -
    from the net's best-fitting plane to the SVG), every one within a fraction of a point of
    its own projected axis, and no id on another lamella's place."""
    kind, b, out, rep, sheets = _made("GG", tmp_path_factory)
    labels = plan_labels(out / "plan.svg")
    lams = b.net.lamellae
    assert sorted(labels) == sorted(int(lam.id) for lam in lams)
    X = np.concatenate([b.net.joints] + [lam.axis for lam in lams])
    c = X.mean(axis=0)
    E = np.linalg.svd(X - c)[2][:2]
    mids = []
    for lam in lams:
        s = polyline_arclength(lam.axis)
        mids.append([np.interp(s[-1] / 2, s, lam.axis[:, j]) for j in range(3)])
    P = (np.array(mids) - c) @ E.T
    Q = np.array([labels[int(lam.id)] for lam in lams])
    _, res = similarity_fit(P, Q)
    keep = res <= np.sort(res)[len(res) // 2]
    for _ in range(3):                       # the ids left at the midpoints fix the map
        A, B = P[keep], Q[keep]
        pc, qc = A.mean(0), B.mean(0)
        U, S, Vt = np.linalg.svd((B - qc).T @ (A - pc))
        R = U @ Vt
        k = S.sum() / ((A - pc) ** 2).sum()
        res = np.linalg.norm(k * (P - pc) @ R.T + qc - Q, axis=1)
        keep = res < 0.05
    assert keep.mean() > 0.6 and np.ptp(Q, axis=0).max() > 100
    for lam, q in zip(lams, Q):
        line = shapely.LineString(k * ((lam.axis - c) @ E.T - pc) @ R.T + qc)
        assert line.distance(shapely.Point(q)) < 0.05, lam.id


@pytest.mark.parametrize("kind, nr, nc", [("NCP", 8, 8), ("CNC", 7, 9), ("GG", 9, 7)])
def test_plan_labels_do_not_overlap(kind, nr, nc):
    """The boxes of the ids (white frame included) overlap nowhere, checked with shapely; on
    these nets the middle lamellae of both families meet at the middle, where the ids at the
    midpoints used to hide each other (L5, L6 under L17, L18 in the NCP demo)."""
    import itertools

    from gridshell.fabrication.plan import label_boxes, plan_figure

    b = make_bundle(kind, nr=nr, nc=nc, a=0.2, stretch=0.0, twist=0.0)
    fig = plan_figure(b.net)
    boxes = {k: shapely.box(*v) for k, v in label_boxes(fig).items()}
    assert sorted(boxes) == sorted(int(lam.id) for lam in b.net.lamellae)
    for (i, A), (j, B) in itertools.combinations(boxes.items(), 2):
        assert A.intersection(B).area == 0.0, (i, j)


def test_sheet_previews(made):
    """sheet_NN.png: listed in the report, the drawn sheet has the sheet's aspect ratio, the
    CUT red lines cover where the DXF parts are, labels engraved in green, the title names the
    sheet size and part count."""
    from PIL import Image

    from gridshell.fabrication.preview import SHEET_FILL

    kind, b, out, rep, sheets = made
    W, H = rep["params"]["sheet"]
    assert rep["previews"] == [f"sheet_{k + 1:02d}.png" for k in range(rep["n_sheets"])]
    fill = np.array([int(SHEET_FILL[i:i + 2], 16) for i in (1, 3, 5)])
    for name, (doc, parts) in zip(rep["previews"], sheets):
        with Image.open(out / name) as im:
            title = im.text["Title"]
            img = np.asarray(im.convert("RGB")).astype(int)
        assert f"{W:g} x {H:g} mm" in title and f"{len(parts)} parts" in title
        rows, cols = np.nonzero(np.all(img == fill, axis=2))
        r0, r1, c0, c1 = rows.min(), rows.max() + 1, cols.min(), cols.max() + 1
        assert (c1 - c0) / (r1 - r0) == pytest.approx(W / H, rel=0.01)
        assert c1 - c0 >= 800                                   # a readable size
        red = (img[..., 0] > 200) & (img[..., 1] < 90) & (img[..., 2] < 90)
        green = (img[..., 1] > 150) & (img[..., 0] < 120) & (img[..., 2] < 120)
        assert red.sum() > 1000 and green[r0:r1, c0:c1].sum() > 100
        # the red lines span the DXF parts' extent, mapped into the drawn sheet
        x0, y0, x1, y1 = shapely.unary_union([p["poly"] for p in parts]).bounds
        kx, ky = (c1 - c0) / W, (r1 - r0) / H
        rr, cc = np.nonzero(red)
        assert cc.min() == pytest.approx(c0 + x0 * kx, abs=3)
        assert cc.max() == pytest.approx(c0 + x1 * kx, abs=3)
        assert rr.min() == pytest.approx(r1 - y1 * ky, abs=3)
        assert rr.max() == pytest.approx(r1 - y0 * ky, abs=3)


def test_outputs_and_report(made):
    kind, b, out, rep, sheets = made
    names = {p.name for p in out.iterdir()}
    assert set(rep["files"]) == names
    assert {"cutlist.csv", "fabrication.json"} <= names
    assert ({"plan.png", "plan.svg"} <= names) == (kind == "GG")
    assert {f"sheet_{k + 1:02d}{e}" for k in range(rep["n_sheets"])
            for e in (".dxf", ".svg", ".png")} <= names
    stored = json.loads((out / "fabrication.json").read_text())
    assert stored["n_sheets"] == rep["n_sheets"] and 0 < stored["utilisation"] < 1
    assert not any(p.name.startswith(".") for p in out.parent.iterdir())


def test_fabrication_never_imports_an_optimizer():
    import ast
    import pathlib

    from gridshell import fabrication
    root = pathlib.Path(fabrication.__file__).parent
    for f in root.glob("*.py"):
        for node in ast.walk(ast.parse(f.read_text())):
            names = ([a.name for a in node.names] if isinstance(node, ast.Import) else
                     [node.module or ""] if isinstance(node, ast.ImportFrom) else [])
            for n in names:
                assert not n.startswith(("gridshell.gg", "gridshell.ncp", "gridshell.solver")), f
                if n.startswith("gridshell") and not n.startswith("gridshell.fabrication"):
                    assert n in ("gridshell.design.bundle", "gridshell.design.section",
                                 "gridshell.core.errors", "gridshell.core.atomic",
                                 "gridshell.core.manifest",
                                 "gridshell.geometry.net"), (f, n)
