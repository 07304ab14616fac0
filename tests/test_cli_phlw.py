"""``gridshell phlw`` from the command line (tiny sizes: the API tests check the numbers)."""
import json

import numpy as np

from gridshell.cli.main import main
from gridshell.grid import grid_quads
from gridshell.quadmesh import write_mesh


def _torus_obj(path, a=12, b=12, inner=False):
    """A torus zone: the outer side (K > 0), or the inner side (K < 0, where mode aa has
    asymptotic directions)."""
    th0 = np.pi if inner else 0.0
    th, ph = np.meshgrid(np.linspace(th0 - 0.8, th0 + 0.8, a), np.linspace(0, 1.2, b),
                         indexing="ij")
    rho = 2.0 + np.cos(th)
    P = np.stack([rho * np.cos(ph), rho * np.sin(ph), np.sin(th)], -1)
    write_mesh(path, P.reshape(-1, 3), grid_quads(a, b))
    return path


SMALL = ["--ctrl", "5", "5", "--degree", "3", "3", "--samples", "7", "7", "--outer", "1",
         "--max-iter", "4", "--check-samples", "15", "15"]


def test_cli_writes_every_output_and_a_json_summary(tmp_path, capsys):
    ref = _torus_obj(tmp_path / "torus.obj")
    out = tmp_path / "design"
    code = main(["phlw", str(ref), "-o", str(out), "--mode", "cnc", "--json", *SMALL])
    assert code == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["ok"] and summary["mode"] == "cnc"
    for name in ("surface.json", "surface.obj", "rows.csv", "report.json",
                 "curvature_diagram.png"):
        assert (out / name).stat().st_size > 0, name
    report = json.loads((out / "report.json").read_text())
    assert len(report["rows"]) == 7 and len({r["n"] for r in report["rows"]}) == 1
    assert "E_PHLW" in report["before"] and "E_PHLW" in report["after"]
    # surface.obj: 15 x 15 samples, rows = u
    V = [ln for ln in (out / "surface.obj").read_text().splitlines() if ln.startswith("v ")]
    assert len(V) == 225


def test_cli_progress_on_stderr_and_modes(tmp_path, capsys):
    for mode in ("phlw", "aa"):
        ref = _torus_obj(tmp_path / f"torus_{mode}.obj", inner=mode == "aa")
        assert main(["phlw", str(ref), "-o", str(tmp_path / mode), "--mode", mode, *SMALL]) == 0
        cap = capsys.readouterr()
        assert "round 1/1" in cap.err and "PHLW surface design" in cap.out


def test_cli_bad_reference_exits_with_input_error(tmp_path, capsys):
    assert main(["phlw", str(tmp_path / "missing.obj"), "-o", str(tmp_path / "o")]) == 2
    assert "no such file" in capsys.readouterr().err
