"""``gridshell fabricate`` through main([...]): GG and NCP bundles on disk, bad parameters."""
from __future__ import annotations

import csv
import json

import pytest
from tests.helpers.fab_cases import make_bundle, plan_labels, read_dxf_sheet

from gridshell.design.bundle import write_bundle
from gridshell.cli.main import main

ISSUE_ARGS = ["--width", "20", "--thickness", "1", "--hole", "3", "--sheet", "600x400",
              "--scale", "1:10"]


@pytest.fixture(scope="module")
def bundles(tmp_path_factory):
    root = tmp_path_factory.mktemp("bundles")
    write_bundle(root / "gg", make_bundle("GG"))
    write_bundle(root / "ncp", make_bundle("NCP", nr=4, nc=4))
    return root


@pytest.mark.parametrize("name", ["gg", "ncp"])
def test_fabricate_from_the_cli(bundles, name, capsys):
    d = bundles / name
    code = main(["fabricate", "--force", str(d), *ISSUE_ARGS, "-q", "--json"])
    assert code == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["ok"] and "utilisation [%]" in summary
    out = d / "fabrication"
    rep = json.loads((out / "fabrication.json").read_text())
    assert rep["kind"] == name.upper()
    assert rep["n_strips"] == (9 if name == "gg" else 8)
    for k in range(rep["n_sheets"]):
        doc, parts = read_dxf_sheet(out / f"sheet_{k + 1:02d}.dxf")
        assert doc.header["$INSUNITS"] == 4
    with open(out / "cutlist.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == rep["n_pieces"]
    assert {"lamella", "family", "flat_length_mm", "joint_positions_mm", "sheet",
            "piece"} <= set(rows[0])
    assert (out / "plan.png").stat().st_size > 0 and (out / "plan.svg").is_file()
    # every lamella id on the plan, one sheet preview per sheet, all listed in the report
    ids = sorted(int(lam["id"]) for lam in json.loads((d / "design.json").read_text())["lamellae"])
    assert sorted(plan_labels(out / "plan.svg")) == ids
    previews = [f"sheet_{k + 1:02d}.png" for k in range(rep["n_sheets"])]
    assert rep["previews"] == previews and set(previews) <= set(rep["files"])
    assert all((out / f).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for f in previews)


def test_summary_in_text(bundles, tmp_path, capsys):
    assert main(["fabricate", "--force", str(bundles / "gg"), "-o", str(tmp_path / "o"), "--joints", "marks",
                 "--no-labels", "--dxf-version", "R12", "--segments", "--kerf", "0.1",
                 "--no-plan"]) == 0
    cap = capsys.readouterr()
    out = cap.out
    assert "writing" in cap.err and "plan" not in cap.err
    assert not (tmp_path / "o" / "plan.png").exists()
    assert "sheets" in out and "utilisation" in out and "pieces split" in out


@pytest.mark.parametrize("args,message", [
    (["--hole", "25"], "hole diameter"),                       # hole wider than the strip
    (["--sheet", "600x15"], "does not fit the sheet"),        # strip wider than the sheet
    (["--width", "-20"], "--width"),                           # negative sizes
    (["--gap", "-5"], "--gap"),
    (["--scale", "1:0"], "scale"),
    (["--sheet", "big"], "sheet size"),
    (["--joints", "slots"], "orthogonal"),                     # slots on a GG design
    (["--axis", "edge"], "--axis edge"),                       # no edge stands on a GG surface
])
def test_nonsensical_parameters_fail_before_writing(bundles, tmp_path, capsys, args, message):
    out = tmp_path / "out"
    code = main(["fabricate", "--force", str(bundles / "gg"), "-o", str(out), "-q", *args])
    assert code == 2
    assert message in capsys.readouterr().err
    assert not out.exists()
    assert list(tmp_path.iterdir()) == []


def test_bad_bundle_and_unsafe_output(bundles, tmp_path, capsys):
    assert main(["fabricate", "--force", str(tmp_path / "nothing"), "-q"]) == 2
    # refuse to replace the bundle or a foreign directory
    assert main(["fabricate", "--force", str(bundles / "gg"), "-o", str(bundles / "gg"), "-q"]) == 5
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "notes.txt").write_text("keep")
    assert main(["fabricate", "--force", str(bundles / "gg"), "-o", str(tmp_path / "mine"), "-q"]) == 5
    assert (tmp_path / "mine" / "notes.txt").read_text() == "keep"


def test_joints_too_close_for_holes_warn_by_default_and_refuse_when_asked(bundles, tmp_path,
                                                                           capsys):
    """A small model: by default the joints are engraved as marks with a warning in the
    summary and fabrication.json; an explicit --joints hole is refused (exit 2)."""
    b = bundles / "gg"
    out = tmp_path / "fab"
    assert main(["fabricate", str(b), "-o", str(out), "--scale", "1:100", "--no-plan", "--force",
                 "--json", "-q"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert "engraved as marks" in summary["warning"]
    rep = json.loads((out / "fabrication.json").read_text())
    assert rep["params"]["joints"] == "marks" and rep["joints_fallback"]
    assert main(["fabricate", str(b), "-o", str(tmp_path / "fab2"), "--scale", "1:100",
                 "--joints", "hole", "--force", "-q"]) == 2
    assert "too close for hole" in capsys.readouterr().err
    assert not (tmp_path / "fab2").exists()
