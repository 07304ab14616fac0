"""``gridshell ncp`` from the command line (small sizes: the API tests check the numbers)."""
import json

import numpy as np
import pytest

from gridshell.cli.main import main
from gridshell.geometry.grid import grid_quads
from gridshell.geometry.meshfile import write_mesh

from tests.helpers.ncp_cases import PHLW_SADDLE, pseudosphere, torus_grid

SMALL = ["--curves", "6", "--samples", "24", "24", "--collapse-samples", "200", "200",
         "--frames", "2", "--rounds", "1"]


def test_cli_from_a_bspline_json_then_verify(tmp_path, capsys):
    src = tmp_path / "surface.json"
    pseudosphere().save(src)
    out = tmp_path / "aa"
    assert main(["ncp", str(src), "-o", str(out), "--mode", "aa", "--json", *SMALL]) == 0
    captured = capsys.readouterr()
    summary = json.loads(captured.out)
    assert summary["ok"] and summary["kind"] == "AA"
    assert "collapse curve" in captured.err and "post-optimization" in captured.err
    for name in ("design.json", "aligned.obj", "alignment.gif", "axes_r.npy",
                 "sequence/frame_002.obj"):
        assert (out / name).is_file(), name
    assert main(["verify", str(out)]) == 0
    v = json.loads(capsys.readouterr().out)
    assert v["ok"] and v["kind"] == "AA" and v["delta_l"]["max"] < 1
    # recomputed from aligned.obj, and equal to what the design stored
    assert v["aligned_line_error"] < 0.5 and v["mismatch"] == []
    assert v["aligned_line_error"] == pytest.approx(v["stored"]["aligned_line_error"], rel=1e-6)
    # measured on axes.obj with the normals of surface.obj: the crossing lamellae agree
    assert v["crossing_kn"]["joints"] > 10 and v["crossing_kn"]["max"] < 5


def test_cli_from_a_mesh_runs_the_phlw_step(tmp_path, capsys):
    P = torus_grid(12, 12)
    ref = tmp_path / "torus.obj"
    write_mesh(ref, P.reshape(-1, 3), grid_quads(12, 12))
    out = tmp_path / "cnc"
    code = main(["ncp", str(ref), "-o", str(out), "--mode", "cnc", "--no-render", "-q",
                 "--phlw-ctrl", "6", "6", "--phlw-samples", "7", "7", "--phlw-outer", "1",
                 "--phlw-max-iter", "3", *SMALL])
    assert code == 0
    d = json.loads((out / "design.json").read_text())
    assert d["kind"] == "CNC" and d["collapse"]["shape"] == "circle"
    assert not (out / "alignment.gif").exists()
    text = capsys.readouterr().out
    assert "CNC design" in text
    # the summary ends with one pass / FAIL line per figure: Delta_a mean, max, Delta_l,
    # Delta_n, collapse error; design.json says the same
    last = [ln.strip() for ln in text.strip().splitlines()[-5:]]
    assert [ln.split("  ")[1].split(" ")[0:2] for ln in last] == [
        ["Delta_a", "mean"], ["Delta_a", "max"], ["Delta_l", "max"], ["Delta_n", "max"],
        ["collapse", "error"]]
    assert all(ln.startswith("pass  ") for ln in last)
    assert d["metrics"]["quality"]["ok"] is True
    assert main(["verify", str(out)]) == 0
    v = json.loads(capsys.readouterr().out)
    assert v["kind"] == "CNC" and v["mismatch"] == []
    # the aligned joints on the design's circle of radius 1/n
    assert v["aligned_radius_error"] < 1 and v["aligned_radius_error_n"] < 1
    assert v["aligned_circle_deviation"]["max"] < 1
    # the net's fidelity to the user's torus.obj, recomputed from it: what design.json says
    f, stored = v["fidelity"], d["metrics"]["fidelity"]
    assert f["target"] == str(ref) and f["coverage"] == pytest.approx(stored["coverage"], abs=0.5)
    assert f["deviation_mean"] == pytest.approx(stored["deviation_mean"], rel=1e-3)
    assert any(ln.startswith("fidelity (not a gate): joints from") for ln in v["checks"])
    # without the target file the fidelity is skipped, the design's figures still checked
    ref.rename(tmp_path / "gone.obj")
    assert main(["verify", str(out)]) == 0
    v = json.loads(capsys.readouterr().out)
    assert "skipped" in v["fidelity"] and v["mismatch"] == []


def test_cli_phlw_mode_then_verify(tmp_path, capsys):
    """A general PHLW net (kind NCP, n per row) from the PHLW issue's surface, end to end."""
    out = tmp_path / "ncp"
    assert main(["ncp", str(PHLW_SADDLE), "-o", str(out), "--mode", "phlw", "--no-render",
                 "--json", *SMALL]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["ok"] and summary["kind"] == "NCP" and summary["converged"]
    d = json.loads((out / "design.json").read_text())
    assert d["collapse"]["shape"] == "curve" and d["collapse"]["radius"] is None
    assert main(["verify", str(out)]) == 0
    v = json.loads(capsys.readouterr().out)
    assert v["ok"] and v["kind"] == "NCP" and v["mismatch"] == []
    for key, skey in (("alignability", "Delta_a after [%]"), ("delta_l", "Delta_l [%]"),
                      ("delta_n", "Delta_n [%]"), ("deviation", "deviation [% diag]")):
        assert v[key]["max"] == pytest.approx(summary[skey]["max"], rel=1e-6), key
    # the acceptance figures, recomputed from the files
    assert v["alignability"]["mean"] < 1 and v["delta_l"]["max"] < 1 and v["delta_n"]["max"] < 1
    assert v["deviation"]["max"] < 1 and v["crossing_kn"]["max"] < 5
    assert v["aligned_plane_distance"]["max"] < 1e-9       # % of the span: one plane
    assert "aligned_radius" not in v and "aligned_line_error" not in v


def test_cli_reports_bad_input(tmp_path, capsys):
    bad = tmp_path / "bad.json"
    bad.write_text("{}")
    assert main(["ncp", str(bad), "-o", str(tmp_path / "x")]) == 2
    assert "error" in capsys.readouterr().err
    assert not np.any([p.name == "x" for p in tmp_path.iterdir()])
