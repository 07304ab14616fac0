"""``gridshell analyze``: the files it writes (analysis.json, analysis.png, the manifest), the
summary and its JSON, the recommended command, exit codes (0; 2 for a bad option before any
work; 5 for an output refused) and that it never replaces a directory it did not write."""
from __future__ import annotations

import json

import numpy as np
import pytest
from tests.analysis.test_analysis import paraboloid, saddle

from gridshell import api
from gridshell.cli.main import main
from gridshell.geometry.meshfile import write_mesh


@pytest.fixture
def dome_obj(tmp_path):
    V, F = paraboloid()
    path = tmp_path / "dome.obj"
    write_mesh(path, V, F)
    return path


def test_analyze_writes_json_png_and_manifest(tmp_path, dome_obj, capsys):
    out = tmp_path / "dome-analysis"
    assert main(["analyze", str(dome_obj), "-o", str(out), "--no-trial"]) == 0
    text = capsys.readouterr().out
    assert "recommended" in text and "near umbilic" in text
    data = json.loads((out / "analysis.json").read_text())
    assert set(data) >= {"target", "classes_percent", "regions", "ncp", "gg", "recommendation"}
    assert data["ncp"]["aa"]["coverage_percent"] == 0.0
    assert 0 < data["ncp"]["phlw"]["coverage_percent"] < 100
    assert (out / "analysis.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert (out / "manifest.json").exists()
    # a second run replaces its own earlier analysis
    assert main(["analyze", str(dome_obj), "-o", str(out), "--no-trial", "-q"]) == 0


def test_analyze_json_summary_and_the_command_for_this_target(tmp_path, capsys):
    V, F = saddle()
    path = tmp_path / "hypar in mm.obj"
    write_mesh(path, V * 1000.0, F)
    assert main(["analyze", str(path), "--units", "mm", "--no-files", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["ok"] is True
    cmd = d["recommended"]
    assert "'" + str(path) + "'" in cmd and cmd.endswith("--units mm")
    assert not (tmp_path / "hypar in mm-analysis").exists()


@pytest.mark.parametrize("bad", [["--samples", "4"], ["--samples", "1000"],
                                 ["--min-coverage", "120"]])
def test_bad_options_refused_before_any_work(tmp_path, dome_obj, capsys, bad):
    out = tmp_path / "a"
    # refused by the parser, before any work, in one line
    assert main(["analyze", str(dome_obj), "-o", str(out), *bad]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"argument {bad[0]}" in err[0]
    assert not out.exists()


def test_never_replaces_a_foreign_directory(tmp_path, dome_obj, capsys):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("the user's own file")
    assert main(["analyze", str(dome_obj), "-o", str(out), "--no-trial"]) == 5   # output refused
    assert "nothing was changed" in capsys.readouterr().err
    assert (out / "notes.txt").read_text() == "the user's own file"
    assert not (out / "analysis.json").exists()


def test_missing_target_is_a_clear_error(tmp_path, capsys):
    assert main(["analyze", str(tmp_path / "nope.obj"), "--no-files"]) == 2
    assert "nope.obj" in capsys.readouterr().err


def test_api_analyze_with_trial_recommends_gg_on_a_dome(tmp_path):
    V, F = paraboloid()
    a = api.analyze((V, F), units="m", samples=24, output=tmp_path / "an")
    assert a.gg is not None and a.gg.error is None
    assert a.gg.deviation_mean is not None and a.gg.deviation_mean < 2.0
    assert 50 < a.gg.coverage <= 100
    assert a.recommendation.pipeline == "gg"
    assert np.isfinite(a.seconds)
    assert (tmp_path / "an" / "analysis.json").exists()
