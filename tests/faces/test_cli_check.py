"""``gridshell check`` on small synthetic bundles of every kind: structure.json's contract, the
manifest, the picture, exit codes (0 elastic, 4 overstressed, 2 bad input), user values, the
report section and fabricate's warning."""
from __future__ import annotations

import json

import numpy as np
import pytest
from tests.helpers.render_cases import make_bundle, sequence_extra, write_case

from gridshell.core import manifest
from gridshell.design.bundle import CollapseCurve, write_bundle
from gridshell.cli.main import main

LAMELLA_KEYS = {"id", "family", "utilisation", "max_utilisation", "worst_s_m", "worst_joint",
                "min_radius_m", "max_elastic_thickness_mm"}


def _ncp_case(path, shape="curve"):
    b = make_bundle("NCP" if shape != "circle" else "CNC",
                    metrics={"n": 0.3} if shape == "circle" else None)
    t = np.linspace(-0.8, 0.8, 200)
    R = 4.0
    P = np.stack([R * np.sin(t), R - R * np.cos(t)], axis=1)
    N = np.stack([-np.sin(t), np.cos(t)], axis=1)
    b.collapse = CollapseCurve(points=P, normals=N, shape=shape,
                               radius=R if shape == "circle" else None)
    b.collapse_s = {lam.id: lam.joint_s + 0.5 for lam in b.net.lamellae}
    return write_bundle(path, b, extra=sequence_extra(b))


def _read(d):
    return json.loads((d / "structure.json").read_text())


def test_check_gg_writes_the_contract(tmp_path, capsys):
    d = write_case(tmp_path / "gg", "GG", sequence=True)
    code = main(["check", str(d), "--material", "pp", "--width", "20", "--thickness", "1",
                 "--scale", "1:10", "-q"])
    out = capsys.readouterr().out
    r = _read(d)
    assert code == (0 if r["verdict"] == "ok" else 4)
    assert "max utilisation" in out and "lamella" in out
    assert r["section"]["width_mm"] == 20 and r["section"]["thickness_mm"] == 1
    assert r["section"]["scale"] == pytest.approx(0.1)
    assert r["material"]["name"] == "pp" and r["verdict"] in ("ok", "overstressed")
    assert isinstance(r["max_utilisation"], float) and r["states"]["frames"]
    from gridshell.design.bundle import read_bundle
    b = read_bundle(d)
    for lam, rec in zip(b.net.lamellae, r["lamellae"]):
        assert LAMELLA_KEYS <= set(rec)
        assert rec["id"] == lam.id and len(rec["utilisation"]) == len(lam.axis)
        assert rec["max_utilisation"] == pytest.approx(max(rec["utilisation"]))
        assert rec["worst_joint"] in lam.joints.tolist()
        assert 0 <= rec["worst_s_m"] <= lam.length + 1e-9
    files = manifest.read(d)["files"]
    assert "structure.json" in files and "structure.png" in files
    # the collapsed GG net lies on one line: no stress in transport
    assert r["states"]["collapsed"]["max_utilisation"] == pytest.approx(0.0, abs=1e-9)


def test_check_json_and_overstressed_exit(tmp_path, capsys):
    d = write_case(tmp_path / "gg", "GG")
    assert main(["check", str(d), "--json", "-q", "--no-picture"]) in (0, 4)
    ok = json.loads(capsys.readouterr().out)
    assert ok["file"].endswith("structure.json") and ok["picture"] is None
    # the same design at 1:200: twenty times the curvature
    code = main(["check", str(d), "--scale", "1:200", "--json", "-q", "--no-picture"])
    res = json.loads(capsys.readouterr().out)
    assert code == 4 and res["ok"] is False and res["verdict"] == "overstressed"
    assert res["max_utilisation"] == pytest.approx(20 * ok["max_utilisation"], rel=0.2)
    assert _read(d)["verdict"] == "overstressed"   # written all the same


def test_weak_axis_utilisation_grows_with_thickness(tmp_path, capsys):
    """The synthetic rows are not geodesics: at 20 mm their strong-axis bending alone exceeds
    the allowable stress of pp (no thickness helps); at 5 mm some thickness stays elastic."""
    d = write_case(tmp_path / "gg", "GG")
    main(["check", str(d), "-q", "--no-picture", "--no-states"])
    assert _read(d)["max_elastic_thickness_mm"] == 0.0
    u = []
    for t in ("0.5", "1", "2"):
        main(["check", str(d), "--width", "5", "--thickness", t, "-q", "--no-picture",
              "--no-states"])
        u.append(_read(d)["max_utilisation"])
        capsys.readouterr()
    assert u[0] < u[1] < u[2]
    t_max = _read(d)["max_elastic_thickness_mm"]
    assert t_max > 0


@pytest.mark.parametrize("shape", ["curve", "circle", "line"])
def test_check_orthogonal_kinds(tmp_path, capsys, shape):
    d = _ncp_case(tmp_path / shape, shape)
    assert main(["check", str(d), "-q", "--no-picture"]) in (0, 4)
    r = _read(d)
    assert r["orientation"] == "orthogonal"
    assert r["cut_shape"] == {"curve": "curve", "circle": "arc", "line": "line"}[shape]
    assert all(np.isfinite(x["max_utilisation"]) for x in r["lamellae"])


def test_check_aa(tmp_path, capsys):
    d = write_case(tmp_path / "aa", "AA", sequence=True)
    assert main(["check", str(d), "-q"]) in (0, 4)
    assert _read(d)["cut_shape"] == "line"


def test_user_values(tmp_path, capsys):
    d = write_case(tmp_path / "gg", "GG")
    assert main(["check", str(d), "--E", "3", "--allowable", "45", "-q", "--no-picture",
                 "--no-states"]) in (0, 4)
    m = _read(d)["material"]
    assert m["name"] == "user" and m["E"] == 3e9 and m["allowable"] == 45e6
    assert main(["check", str(d), "--material", "spruce", "--allowable", "10", "-q",
                 "--no-picture", "--no-states"]) in (0, 4)
    m = _read(d)["material"]
    assert m["allowable"] == 10e6 and m["E"] == 11e9


@pytest.mark.parametrize("argv, what", [
    (["--material", "unobtainium"], "unknown material"),
    (["--thickness", "0"], "--thickness"),
    (["--scale", "ten"], "scale"),
    (["--E", "3"], "--allowable"),
    (["--allowable", "-5"], "--allowable"),
])
def test_bad_input_exit_2(tmp_path, capsys, argv, what):
    d = write_case(tmp_path / "gg", "GG")
    assert main(["check", str(d), *argv]) == 2
    assert what in capsys.readouterr().err
    assert not (d / "structure.json").exists()


def test_not_a_bundle(tmp_path, capsys):
    assert main(["check", str(tmp_path)]) == 2


def test_report_and_fabricate_use_the_check(tmp_path, capsys):
    d = write_case(tmp_path / "gg", "GG")
    main(["check", str(d), "--scale", "1:200", "-q"])
    main(["render", str(d), "--report", "-q", "--no-sequence"])
    page = (d / "report.html").read_text()
    assert 'id="structure"' in page and "overstressed" in page
    capsys.readouterr()
    fab = ["fabricate", str(d), "--scale", "1:200", "--width", "5", "--hole", "1", "--margin",
           "5", "--joints", "marks"]
    code = main(fab + ["--force"])    # the synthetic bundle fails verify too
    out = capsys.readouterr().out
    assert code == 0
    assert "cut with --force: OVERSTRESSED" in out and "lamella" in out
    rep = json.loads((d / "fabrication" / "fabrication.json").read_text())
    assert rep["structure"]["verdict"] == "overstressed" and rep["structure"]["forced"]


def test_strip_defaults_from_the_cut_files(tmp_path, capsys):
    """Without --width/--thickness/--scale the check takes those fabricate cut with."""
    d = write_case(tmp_path / "gg", "GG")
    (d / "fabrication").mkdir()
    (d / "fabrication" / "fabrication.json").write_text(json.dumps(
        {"params": {"width": 12.0, "thickness": 0.8, "scale": 0.05}}))
    main(["check", str(d), "-q", "--no-picture", "--no-states"])
    sec = _read(d)["section"]
    assert (sec["width_mm"], sec["thickness_mm"], sec["scale"]) == (12.0, 0.8, 0.05)
    main(["check", str(d), "--thickness", "2", "-q", "--no-picture", "--no-states"])
    assert _read(d)["section"]["thickness_mm"] == 2.0


def test_folded_sequence_states_are_listed_not_judged(tmp_path, capsys):
    from gridshell.geometry.meshfile import write_mesh

    b = make_bundle("GG")
    extra = sequence_extra(b, frames=3)
    V = 0.5 * (b.net.joints + b.aligned)
    V[::2, 2] += 0.5                       # every other joint lifted: lamellae zig-zag
    extra["sequence/frame_001.obj"] = lambda p, V=V: write_mesh(p, V, b.net.loops)
    d = write_bundle(tmp_path / "gg", b, extra=extra)
    main(["check", str(d), "--width", "5", "-q", "--no-picture"])
    out = capsys.readouterr().out
    st = _read(d)["states"]
    assert "frame_001" in st["unresolved"] and "fold" in out
    f1 = st["frames"][1]
    assert not f1["resolved"] and f1["max_turn_deg"] > 30
    assert _read(d)["governing_state"] != "frame_001"


@pytest.mark.parametrize("kind, shape, cut", [("GG", None, "line"), ("AA", None, "line"),
                                              ("NCP", "curve", "curve"), ("NCP", "line", "line"),
                                              ("CNC", "circle", "arc")])
def test_cut_shape_is_the_one_fabricate_cuts(kind, shape, cut):
    """The check judges the strip fabricate cuts: straight GG / AA strips, CNC arcs of the
    collapse circle, NCP pieces of the collapse curve (one rule, gridshell.design.bundle)."""
    from gridshell.fabrication.strips import axis_shape, collapse_radius

    from gridshell.structure import cutshape

    b = make_bundle(kind, metrics={"n": 0.3} if kind == "CNC" else None)
    if shape is not None:
        t = np.linspace(-0.5, 0.5, 50)
        b.collapse = CollapseCurve(points=np.stack([t, t ** 2], 1),
                                   normals=np.stack([0 * t, 1 + 0 * t], 1), shape=shape,
                                   radius=2.0 if shape == "circle" else None)
    assert cutshape.cut_shape(b) == axis_shape(b) == cut
    if axis_shape(b) == "arc":
        assert cutshape.collapse_radius(b) == collapse_radius(b) == 2.0
