"""--max-deviation on the design commands: a net farther from the target than asked is refused
(exit 4) and nothing is written; within it the summary gives the same figures as design.json."""
from __future__ import annotations

import json

from gridshell.cli.main import main
from gridshell.data import path as data_path


def test_gg_refuses_a_net_farther_than_asked_and_writes_nothing(tmp_path, capsys):
    out = tmp_path / "g"
    code = main(["gg", str(data_path("dome.obj")), "-o", str(out), "--frames", "0",
                 "--no-preview", "--lamellae", "8", "--max-deviation", "0.001"])
    assert code == 4 and "--max-deviation 0.001 %" in capsys.readouterr().err
    assert not out.exists()
    assert main(["gg", str(data_path("dome.obj")), "-o", str(out), "--frames", "0",
                 "--no-preview", "--lamellae", "8", "--max-deviation", "5", "--json"]) == 0
    f = json.loads((out / "design.json").read_text())["metrics"]["fidelity"]
    summary = json.loads(capsys.readouterr().out)
    assert f"mean {f['deviation_mean']:.3g} %" in summary["fidelity to the target"]
    assert 0 < f["deviation_mean"] <= f["deviation_p95"] <= f["deviation_max"] < 5
    assert 50 < f["coverage"] <= 100


def test_ncp_gives_its_fidelity_to_the_reference_mesh(tmp_path, capsys):
    out = tmp_path / "n"
    ref = str(data_path("torus_patch.obj"))
    assert main(["ncp", ref, "-o", str(out), "--mode", "cnc", "--curves", "6", "--frames", "2",
                 "--no-render", "--max-deviation", "0.0001"]) == 4
    assert not out.exists()
    assert main(["ncp", ref, "-o", str(out), "--mode", "cnc", "--curves", "6", "--frames", "2",
                 "--no-render"]) == 0
    f = json.loads((out / "design.json").read_text())["metrics"]["fidelity"]
    assert f["target"] == "the reference mesh" and f["deviation_max"] < 1.0
