"""gridshell build: one command from a model to a build pack (issue 30). The pack is checked
against the tools it chains, run on their own: the figures recomputed from its files, the
section against the check at that thickness and at thicker stock ones, the reuse of
unchanged stages, and a user's file in the pack never lost."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from gridshell.cli.main import main
from gridshell.core.errors import OutputError
from gridshell.data import __file__ as _data
from gridshell.design.bundle import read_bundle
from gridshell.design.verification import verify_bundle
from gridshell.structure.materials import get_material
from gridshell.workflow.build import BUILD_JSON, STAGES, build
from gridshell.workflow.structure import check_structure

DOME = str(Path(_data).parent / "dome.obj")


@pytest.fixture(scope="module")
def pack(tmp_path_factory):
    out = tmp_path_factory.mktemp("pack") / "dome"
    return out, build(DOME, out, lamellae=8, frames=4)


def test_the_pack_holds_every_stage_and_its_figures_hold(pack):
    out, res = pack
    assert list(res.stages) == list(STAGES) and not res.reused
    for f in ("design.json", "structure.json", "equilibrium/equilibrium.json",
              "fabrication/manifest.json", "model.3dm", "report.html", "report.pdf",
              "render.png",
              "analysis/analysis.json", BUILD_JSON):
        assert (out / f).is_file(), f
    assert list((out / "fabrication").glob("*.dxf")) and list((out / "fabrication").glob("*.svg"))
    assert verify_bundle(out)["ok"]                       # recomputed from the pack's files
    b = read_bundle(out)                                   # the count asked is the count made
    assert sorted(len(b.net.family(f)) for f in (1, 3)) == [8, 8]
    rec = json.loads((out / BUILD_JSON).read_text())
    assert res.kind == rec["kind"] == "gg" and res.stages["design"]["kind"] == "GG"
    man = json.loads((out / "manifest.json").read_text())
    assert man["command"] == "build" and BUILD_JSON in man["files"]
    assert {"fabrication", "equilibrium", "analysis"} <= set(man["outputs"])


def test_the_section_is_the_thinnest_stock_thickness_that_holds(pack):
    out, res = pack
    sec = res.section
    mat = get_material(sec["material"])
    chosen = check_structure(out, material=mat.name, thickness=sec["thickness_mm"],
                             write=False, picture=False)
    assert chosen.ok and chosen.result["max_utilisation"] == pytest.approx(
        sec["utilisation"], rel=1e-6)
    assert sec["thickness_mm"] == min(mat.sheet_thicknesses_mm)
    thicker = sorted(t for t in mat.sheet_thicknesses_mm if t > sec["thickness_mm"])[:3]
    u = [check_structure(out, material=mat.name, thickness=t, write=False,
                         picture=False).result["max_utilisation"] for t in thicker]
    assert all(b >= a for a, b in zip([sec["utilisation"], *u], u))   # never falls
    s = json.loads((out / "structure.json").read_text())["section"]
    assert s["thickness_mm"] == sec["thickness_mm"]


def test_a_rerun_reuses_every_stage_and_a_new_material_reuses_the_design(pack):
    out, first = pack
    files = json.loads((out / "manifest.json").read_text())["files"]
    again = build(DOME, out, lamellae=8, frames=4)
    assert again.reused == list(STAGES) and again.seconds < 5.0
    assert json.loads((out / "manifest.json").read_text())["files"]["design.json"] == \
        files["design.json"]
    other = build(DOME, out, lamellae=8, frames=4, material="petg")
    assert other.reused == ["analyze", "design", "verify"]
    assert json.loads((out / "structure.json").read_text())["material"]["name"] == "petg"
    assert verify_bundle(out)["ok"]


def test_a_material_that_holds_at_no_stock_thickness_is_refused_naming_the_scale(tmp_path):
    from gridshell.structure.verdict import Overstressed

    with pytest.raises(Overstressed, match=r"no stock thickness of spruce holds .*(build at "
                                           r"1:\d|not even at full size)"):
        build(DOME, tmp_path / "p", lamellae=8, frames=0, material="spruce")


def test_a_users_file_in_the_pack_is_never_lost(tmp_path, pack):
    out, _ = pack
    import shutil

    mine = tmp_path / "mine"
    shutil.copytree(out, mine)
    (mine / "notes.txt").write_text("my notes")
    with pytest.raises(OutputError):
        build(DOME, mine, lamellae=9, frames=4)           # a new design would replace the pack
    assert (mine / "notes.txt").read_text() == "my notes"


@pytest.mark.parametrize("argv,what", [
    (["--lamellae", "1"], "--lamellae"), (["--scale", "1:0"], "--scale"),
    (["--kind", "xx"], "--kind"), (["--material", "steel"], "--material"),
    (["--width", "-2"], "--width"), (["--sheet", "600"], "--sheet"),
    (["--frames", "-1"], "--frames"), (["--units", "km"], "--units"),
])
def test_bad_options_are_refused_before_any_work(tmp_path, capsys, argv, what):
    out = tmp_path / "p"
    try:
        code = main(["build", DOME, "-o", str(out), *argv])
    except SystemExit as e:
        code = e.code
    assert code == 2 and what in capsys.readouterr().err
    assert not out.exists()


def test_the_report_states_every_verdict_and_the_bill_of_materials(pack, tmp_path):
    import shutil

    from gridshell.render.report import report_html
    from gridshell.render.verdicts import bill_of_materials, verdicts

    out, res = pack
    page = (out / "report.html").read_text()
    assert 'id="equilibrium"' in page and "Bill of materials" in page
    v = {t: (st, text) for t, st, text in verdicts(out, True, "")}
    assert set(v) == {"figures", "structure", "equilibrium", "sheets"}
    assert all(st == "pass" for st, _ in v.values())
    fab = json.loads((out / "fabrication" / "fabrication.json").read_text())
    rows = dict(bill_of_materials(out))
    length = sum(q["flat_length_mm"] for q in fab["pieces"]) / 1000
    assert rows["total strip length"] == f"{length:.2f} m"
    p = fab["params"]
    kg = length * p["width"] * 1e-3 * p["thickness"] * 1e-3 * get_material(
        json.loads((out / "structure.json").read_text())["material"]["name"]).density
    assert rows["mass of the strips"].startswith(f"{kg:.3g} kg")
    # the net's fidelity to the user's target, as design.json stores it
    f = json.loads((out / "design.json").read_text())["metrics"]["fidelity"]
    assert f"covers {f['coverage']:.0f} % of it" in page and "fidelity to the target" in page
    assert f"mean {f['deviation_mean']:.3g} %" in page
    # an overstressed check is said first, as a failure, above the figures that pass
    bad = tmp_path / "bad"
    shutil.copytree(out, bad)
    s = json.loads((bad / "structure.json").read_text())
    s.update(verdict="overstressed", max_utilisation=11.47, governing_state="frame_005")
    (bad / "structure.json").write_text(json.dumps(s))
    html = report_html(bad)
    i_fail, i_pass = html.find("verdict fail"), html.find("verdict pass")
    assert 0 < i_fail < i_pass and "overstressed, max utilisation 11.47 (frame_005)" in html


def test_a_new_design_with_the_analysis_reused_keeps_the_analysis_in_the_pack(tmp_path):
    out = tmp_path / "p"
    build(DOME, out, lamellae=6, frames=0)
    again = build(DOME, out, lamellae=8, frames=0)         # the design changes, not the model
    assert "analyze" in again.reused and "design" not in again.reused
    assert (out / "analysis" / "analysis.json").is_file()
    assert verify_bundle(out)["ok"]


def test_the_report_and_its_pdf_carry_the_assembly(pack):
    """The build's report.html has the assembly section (every joint closed once, each step
    naming the strips the design's joint joins) and report.pdf is the same on A4 pages: the
    overview, the assembly, the tables, one page per cut sheet, structure and equilibrium."""
    import re

    from gridshell.design.assembly import assembly_plan
    from gridshell.render.pdf import LINES
    from gridshell.render.verdicts import bill_of_materials

    out, _ = pack
    design = json.loads((out / "design.json").read_text())
    fab = json.loads((out / "fabrication" / "fabrication.json").read_text())
    plan = assembly_plan(design, fab)
    joins = {}
    for r in design["lamellae"]:
        for j in r["joints"]:
            joins.setdefault(j, set()).add(r["id"])
    crossings = sorted(j for j, on in joins.items() if len(on) == 2)
    assert sorted(t["joint"] for t in plan["steps"]) == crossings
    assert sorted(plan["single"]) == sorted(j for j, on in joins.items() if len(on) == 1)
    assert all({t["strip"], t["across"]} == joins[t["joint"]] for t in plan["steps"])
    page = (out / "report.html").read_text()
    assert 'id="assembly"' in page and f"in the order they are closed ({len(crossings)})" in page
    assert dict(bill_of_materials(out))["joints"].startswith(f"{len(crossings)}: one bolt")
    assert page.index('id="fabrication"') < page.index('id="assembly"') < \
        page.index('id="structure"')
    pdf = (out / "report.pdf").read_bytes()
    assert pdf.startswith(b"%PDF") and pdf.rstrip().endswith(b"%%EOF")
    pages = len(re.findall(rb"/Type /Page\b", pdf))
    n_tables = -(-len(plan["strips"]) // LINES) + -(-len(plan["steps"]) // LINES)
    expected = 1 + 1 + n_tables + fab["n_sheets"] + 1 + 1
    assert pages == expected, (pages, expected)
