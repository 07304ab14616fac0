"""``gridshell phlw`` from the command line (tiny sizes: the API tests check the numbers)."""
import json

import numpy as np

from gridshell.cli.main import main
from gridshell.geometry.grid import grid_quads
from gridshell.geometry.meshfile import write_mesh


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
#: SMALL stops the optimizer before it converges: such a surface is written only when allowed
ALLOW = ["--allow-unconverged"]


def test_cli_writes_every_output_and_a_json_summary(tmp_path, capsys):
    ref = _torus_obj(tmp_path / "torus.obj")
    out = tmp_path / "design"
    code = main(["phlw", str(ref), "-o", str(out), "--mode", "cnc", "--json", *SMALL, *ALLOW])
    assert code == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["ok"] and summary["mode"] == "cnc"
    # the figures of the step, in the summary and in report.json
    assert isinstance(summary["quality"]["ok"], bool) and len(summary["quality"]["gates"]) == 4
    assert json.loads((out / "report.json").read_text())["quality"] == summary["quality"]
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
        assert main(["phlw", str(ref), "-o", str(tmp_path / mode), "--mode", mode, *SMALL,
                     *ALLOW]) == 0
        cap = capsys.readouterr()
        assert "round 1/1" in cap.err and "PHLW surface design" in cap.out
        # the summary ends with one pass / FAIL line per figure of the PHLW step
        last = cap.out.strip().splitlines()[-4:]
        assert all(ln.strip().startswith(("pass  ", "FAIL  ")) for ln in last), last
        # the converged gate agrees with the step's own record
        rep = json.loads((tmp_path / mode / "report.json").read_text())
        conv = next(g for g in rep["quality"]["gates"] if "converged" in g["label"])
        word = "pass  optimizer converged: yes" if conv["ok"] else "FAIL  optimizer converged: no"
        assert word in cap.out, cap.out


def test_cli_bad_reference_exits_with_input_error(tmp_path, capsys):
    assert main(["phlw", str(tmp_path / "missing.obj"), "-o", str(tmp_path / "o")]) == 2
    assert "no such file" in capsys.readouterr().err


def test_cli_unconverged_surface_exits_4_unless_allowed(tmp_path, capsys):
    """A PHLW step stopped after 4 iterations has not converged: exit 4, nothing written,
    the failing figure named; --strict is still accepted (deprecated, same behaviour)."""
    ref = tmp_path / "torus.obj"        # a torus zone bent off revolution: the step has work
    th, ph = np.meshgrid(np.linspace(-0.8, 0.8, 12), np.linspace(0, 1.2, 12), indexing="ij")
    rho = 2.0 + np.cos(th) + 0.15 * np.sin(3 * ph) * np.cos(2 * th)
    write_mesh(ref, np.stack([rho * np.cos(ph), rho * np.sin(ph), np.sin(th)], -1)
               .reshape(-1, 3), grid_quads(12, 12))
    for extra in ([], ["--strict"]):
        out = tmp_path / "design"
        assert main(["phlw", str(ref), "-o", str(out), "--mode", "phlw", *SMALL, *extra]) == 4
        err = capsys.readouterr().err
        assert "optimizer converged: no" in err and "--allow-unconverged" in err
        assert not out.exists()


def test_cli_converged_surface_passes_every_gate(tmp_path, capsys):
    """With its default iteration limits the step converges on a torus zone (a CNC surface
    already): exit 0, every figure passes and report.json says so."""
    ref = _torus_obj(tmp_path / "torus.obj")
    out = tmp_path / "design"
    assert main(["phlw", str(ref), "-o", str(out), "--mode", "cnc", "--json", "--ctrl", "6",
                 "6", "--samples", "8", "8", "--check-samples", "15", "15"]) == 0
    q = json.loads(capsys.readouterr().out)["quality"]
    assert q["ok"] and [g["name"] for g in q["gates"]] == ["converged", "energy", "relation",
                                                            "angle"]
    assert json.loads((out / "report.json").read_text())["quality"]["ok"] is True
