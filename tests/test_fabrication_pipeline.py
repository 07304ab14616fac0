"""Acceptance of issue #6 on synthetic GG, CNC and NCP bundles: files re-read, joint spacing,
counts, no overlaps, NCP congruence, CNC radius."""
from __future__ import annotations

import json

import numpy as np
import pytest
import shapely
import shapely.affinity
from fab_cases import fit_circle, make_bundle, parabola_at, read_dxf_sheet

from fabrication import FabParams, fabricate

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


def _design_spacings(b):
    return [np.diff(lam.joint_s) * MM for lam in b.net.lamellae]


def _match_all(measured, design, tol=0.05):
    """Every measured spacing vector matches a distinct design lamella within ``tol`` mm."""
    left = list(range(len(design)))
    worst = 0.0
    for m in measured:
        errs = [(np.max(np.abs(m - design[i])) if len(design[i]) == len(m) else np.inf, i)
                for i in left]
        e, i = min(errs)
        assert e <= tol, f"spacing {m} matches no design lamella (best error {e} mm)"
        worst = max(worst, e)
        left.remove(i)
    assert not left
    return worst


def _part_spacing(kind, part):
    H = part["holes"]
    if kind == "GG":
        return np.linalg.norm(np.diff(H, axis=0), axis=1)
    if kind == "CNC":
        c, _ = fit_circle(H)
        ang = np.unwrap(np.arctan2(H[:, 1] - c[1], H[:, 0] - c[0]))
        return np.abs(np.diff(ang)) * R_DESIGN * MM
    raise AssertionError


def test_counts_of_strips_and_joint_marks(made):
    kind, b, out, rep, sheets = made
    parts = [p for _, ps in sheets for p in ps]
    assert len(parts) == len(b.net.lamellae) == rep["n_strips"] == rep["n_pieces"]
    assert sum(len(p["holes"]) for p in parts) == sum(len(l.joints) for l in b.net.lamellae)
    assert rep["n_joint_marks"] == rep["n_design_joints"]


def test_joint_spacing_equals_design_arc_length(made):
    kind, b, out, rep, sheets = made
    parts = [p for _, ps in sheets for p in ps]
    design = _design_spacings(b)
    if kind in ("GG", "CNC"):
        worst = _match_all([_part_spacing(kind, p) for p in parts], design)
    else:
        # NCP: align each part's holes to the analytic parabola (mm) at the design's
        # collapse positions, then read their arc lengths along the parabola
        x = np.linspace(-1.5, 1.5, 200001)
        C = np.stack([x, 0.6 * x ** 2], 1) * MM
        s_curve = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(C, axis=0), axis=1))])
        lam = b.net.lamellae[0]
        expect = parabola_at(b.collapse_s[lam.id]) * MM
        measured = []
        for p in parts:
            H = p["holes"]
            R, t = _kabsch(H, expect)
            A = H @ R.T + t
            assert np.max(np.linalg.norm(A - expect, axis=1)) < 0.05
            idx = [np.argmin(np.linalg.norm(C - a, axis=1)) for a in A]
            measured.append(np.diff(s_curve[idx]))
        worst = _match_all(measured, design, tol=0.05)
    assert worst < 0.05


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
                ("CUT", "SCORE", "ENGRAVE")} == {"CUT": 1, "SCORE": 5, "ENGRAVE": 7}
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
    kind, b, out, rep, sheets = _made("NCP", tmp_path_factory)
    parts = [p for _, ps in sheets for p in ps]
    ref = parts[0]
    for p in parts[1:]:
        R, t = _kabsch(p["holes"], ref["holes"])
        ang = np.degrees(np.arctan2(R[1, 0], R[0, 0]))
        moved = shapely.affinity.rotate(p["poly"], ang, origin=(0, 0))
        moved = shapely.affinity.translate(moved, *t)
        assert moved.symmetric_difference(ref["poly"]).area < 0.02 * ref["poly"].length


def test_outputs_and_report(made):
    kind, b, out, rep, sheets = made
    names = {p.name for p in out.iterdir()}
    assert set(rep["files"]) == names
    assert {"cutlist.csv", "fabrication.json"} <= names
    assert ({"plan.png", "plan.svg"} <= names) == (kind == "GG")
    stored = json.loads((out / "fabrication.json").read_text())
    assert stored["n_sheets"] == rep["n_sheets"] and 0 < stored["utilisation"] < 1
    assert not any(p.name.startswith(".") for p in out.parent.iterdir())


def test_fabrication_never_imports_an_optimizer():
    import ast
    import pathlib

    import fabrication

    root = pathlib.Path(fabrication.__file__).parent
    for f in root.glob("*.py"):
        for node in ast.walk(ast.parse(f.read_text())):
            names = ([a.name for a in node.names] if isinstance(node, ast.Import) else
                     [node.module or ""] if isinstance(node, ast.ImportFrom) else [])
            for n in names:
                assert not n.startswith(("gridshell.gg", "gridshell.ncp", "gridshell.solver")), f
                if n.startswith("gridshell"):
                    assert n in ("gridshell.bundle", "gridshell.errors", "gridshell.atomic",
                                 "gridshell.net"), (f, n)
