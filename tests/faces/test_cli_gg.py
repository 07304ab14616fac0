"""Tests of the ``gridshell gg`` and ``gridshell verify`` commands, called through main([...])."""
from __future__ import annotations

import io
import json

import numpy as np
import pytest
from tests.helpers.gg_cases import helicoid_grid

from gridshell.design.bundle import DesignBundle, read_bundle, write_bundle
from gridshell.cli.main import main
from gridshell.geometry.grid import grid_quads
from gridshell.geometry.net import Lamella, Net
from gridshell.geometry.meshfile import write_mesh


def _helicoid_target(tmp_path, n=12):
    P = helicoid_grid(n, n, c=0.5)
    path = tmp_path / "helicoid.obj"
    write_mesh(path, P.reshape(-1, 3), grid_quads(n, n))
    return path


def test_gg_then_verify(tmp_path, capsys):
    target = _helicoid_target(tmp_path)
    out = tmp_path / "design"
    code = main(["gg", str(target), "-o", str(out), "--grid", "12", "12", "--lamellae", "5",
                 "-q", "--json"])
    assert code == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["ok"] and summary["verdict"].startswith("PASS")
    # the paper's figures as gates, one per figure (quality.design_gates)
    paper = [g for g in summary["gates"] if not g["name"].startswith("fair_")]
    assert [g["name"] for g in paper] == ["delta_a_mean", "delta_a_max",
                                          "delta_a_arc_mean", "delta_a_arc_max"]
    assert all(g["ok"] and g["value"] < g["limit"] for g in paper)
    # and the lamella fairness (measure.fairness), every check held
    fair = [g for g in summary["gates"] if g["name"].startswith("fair_")]
    assert {"fair_radius", "fair_corner", "fair_loop"} <= {g["name"] for g in fair}
    assert all(g["ok"] for g in fair)
    b = read_bundle(out)
    assert b.kind == "GG" and len(b.net.loops) > 0 and (out / "preview.png").is_file()
    assert b.revolution_V is not None
    assert main(["verify", str(out), "--per-loop"]) == 0
    res = json.loads(capsys.readouterr().out)
    stored = b.metrics
    assert res["alignability"]["mean"] == pytest.approx(stored["alignability"]["mean"], rel=1e-6)
    assert res["alignability_arc"]["max"] == pytest.approx(stored["alignability_arc"]["max"],
                                                           rel=1e-6, abs=1e-9)
    assert len(res["per_loop"]["alignability"]) == len(b.net.loops)
    assert res["geodesic_turning"] == pytest.approx(stored["geodesic_turning"], rel=1e-6)
    assert res["deviation"]["max"] == pytest.approx(stored["deviation"]["max"], rel=1e-6)
    assert res["delta_l"] is None


def test_gg_bad_targets_leave_no_output(tmp_path):
    out = tmp_path / "design"
    assert main(["gg", str(tmp_path / "missing.obj"), "-o", str(out), "-q"]) != 0
    assert not out.exists()
    # a closed tube is not a disk
    n = 8
    ang = np.linspace(0, 2 * np.pi, n + 1)[:-1]
    z = np.linspace(0, 1, 4)
    V = np.array([[np.cos(a), np.sin(a), h] for h in z for a in ang])
    F = [[i * n + j, i * n + (j + 1) % n, (i + 1) * n + (j + 1) % n, (i + 1) * n + j]
         for i in range(3) for j in range(n)]
    tube = tmp_path / "tube.obj"
    write_mesh(tube, V, np.array(F))
    assert main(["gg", str(tube), "-o", str(out), "-q"]) != 0
    assert not out.exists()


def test_verify_ncp_bundle_with_and_without_rotation_axes(tmp_path, capsys):
    # a flat 3 x 3 joint grid with its two lamella families; aligned = a 10 % stretch
    i, j = np.meshgrid(np.arange(3.0), np.arange(3.0), indexing="ij")
    V = np.stack([j.ravel(), i.ravel(), np.zeros(9)], 1)
    G = np.arange(9).reshape(3, 3)
    lams = [Lamella(k, 1, G[k], [0, 1, 2], V[G[k]]) for k in range(3)]
    lams += [Lamella(3 + k, 3, G[:, k], [0, 1, 2], V[G[:, k]]) for k in range(3)]
    net = Net(V, grid_quads(3, 3), lams)
    r = np.tile([0, 0, 1.0], (9, 1))
    b = DesignBundle(kind="NCP", net=net, aligned=1.1 * V, surface_V=V, surface_F=grid_quads(3, 3))
    buf = io.BytesIO()
    np.save(buf, r)
    write_bundle(tmp_path / "ncp", b, extra={"axes_r.npy": buf.getvalue(),
                                              "aligned_r.npy": buf.getvalue()})
    assert main(["verify", str(tmp_path / "ncp")]) == 4  # Delta_l 10 % misses the 1 %
    res = json.loads(capsys.readouterr().out)
    assert res["alignability"]["max"] == pytest.approx(0.0, abs=1e-12)
    assert res["delta_l"]["max"] == pytest.approx(10.0)
    assert "geodesic_turning" not in res and not res["ok"] and not res["problems"]
    write_bundle(tmp_path / "ncp2", b)
    assert main(["verify", str(tmp_path / "ncp2")]) == 2  # no rotation axes: incomplete
    res = json.loads(capsys.readouterr().out)
    assert res["delta_n"] is None and not res["ok"] and "axes_r.npy is missing" in \
        res["problems"][0]
    assert main(["verify", str(tmp_path / "nothing")]) == 2


def test_unconverged_design_is_an_error_unless_allowed(tmp_path, capsys):
    # a dome: far from any GG surface, one round and no projection miss the paper's figures
    x, y = np.meshgrid(np.linspace(-1, 1, 9), np.linspace(-0.8, 0.8, 7), indexing="ij")
    V = np.stack([x.ravel(), y.ravel(), -(x.ravel() ** 2 / 2.0 + y.ravel() ** 2 / 1.2)], 1)
    target = tmp_path / "dome.obj"
    write_mesh(target, V, grid_quads(9, 7))
    out = tmp_path / "design"
    args = ["gg", str(target), "-o", str(out), "--rounds", "1", "--polish", "0", "-q"]
    assert main(args) == 4
    err = capsys.readouterr().err
    assert "misses the paper's figures" in err and "Traceback" not in err
    assert "Delta_a max" in err and ">= 3 %" in err  # names the failing figures
    assert not out.exists() and not list(tmp_path.glob(".design*"))
    assert main([*args, "--allow-unconverged", "--no-preview"]) == 0
    text = capsys.readouterr().out
    assert "FAIL  Delta_a max" in text and "verdict: FAIL" in text
    assert (out / "design.json").is_file()
    params = read_bundle(out).params
    assert params["quality"]["ok"] is False and params["converged"] is False
    assert any(not g["ok"] for g in params["quality"]["gates"])


def test_gg_prints_progress_on_stderr_and_a_one_screen_summary(tmp_path, capsys):
    target = _helicoid_target(tmp_path)
    out = tmp_path / "design"
    assert main(["gg", str(target), "-o", str(out), "--lamellae", "5", "--frames", "3"]) == 0
    cap = capsys.readouterr()
    err = cap.err.strip().splitlines()
    # progress: one timed line per step, from the target to the written bundle
    assert all(ln.startswith("[") and "s] " in ln for ln in err), err
    text = "\n".join(err)
    for step in ("target:", "designing the GG surface", "tracing geodesics", "alignment sequence",
                 "rendering", f"writing {out}"):
        assert step in text, step
    # the summary: a title and one line per figure, fitting on a screen
    lines = cap.out.strip().splitlines()
    assert lines[0] == "GG design" and len(lines) <= 24
    body = {ln.split("  ")[1].strip(): ln for ln in lines[1:]}
    for key in ("Delta_a straight [%]", "geodesic turning [%]", "deviation [% diag]",
                "deviation target->surface [% diag]", "coverage [% of target area]",
                "alignment sequence"):
        assert any(k.startswith(key) for k in body), key
    assert "mean=" in next(ln for k, ln in body.items() if k.startswith("Delta_a straight"))
    # the summary ends with one pass/fail line per figure and the verdict
    assert lines[-1].strip().startswith("verdict: PASS")
    gate_lines = [ln.strip() for ln in lines if ln.strip().startswith(("pass  ", "FAIL  "))]
    assert len(gate_lines) == 5 and gate_lines[0].startswith("pass  lamella fairness")
    assert all(ln.startswith("pass  Delta_a") for ln in gate_lines[1:])
    cov = float(next(ln for k, ln in body.items() if k.startswith("coverage")).split()[-1])
    assert cov == pytest.approx(100.0, abs=1.0)       # the helicoid grid is its own design
    assert (out / "alignment.gif").is_file() and len(list(out.glob("sequence/frame_*.obj"))) == 4


def test_gg_non_uniform_offsets(tmp_path, capsys):
    # helicoid (u cos v, u sin v, c v) with the rulings as meridians: the reference parallel
    # (the middle one, u = 0) is the axis x = y = 0, and arc length along it from the first
    # meridian (v = 0) is z = c v - so each lamella must cross the axis at z = its offset
    target = _helicoid_target(tmp_path)
    out = tmp_path / "design"
    assert main(["gg", str(target), "-o", str(out), "--offsets", "0.15", "0.4", "0.85",
                 "--offsets3", "0.3", "0.6", "--frames", "0", "--no-preview", "-q",
                 "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["ok"]
    b = read_bundle(out)
    assert b.params["offsets"] == [[0.15, 0.4, 0.85], [0.3, 0.6]]
    assert b.params["n_lamellae"] is None and b.params["spacing"] is None
    for fam, offsets in ((1, [0.15, 0.4, 0.85]), (3, [0.3, 0.6])):
        crossings = []
        for lam in b.net.family(fam):
            k = np.argmin(np.hypot(lam.axis[:, 0], lam.axis[:, 1]))
            assert np.hypot(*lam.axis[k, :2]) < 1e-6
            crossings.append(lam.axis[k, 2])
        np.testing.assert_allclose(np.sort(crossings), offsets, rtol=3e-3)


@pytest.mark.parametrize("extra, message", [
    (["--offsets", "0.3"], "at least 2"),
    (["--offsets", "0.3", "0.3", "0.5"], "given twice"),
    (["--offsets", "nan", "0.2"], "finite"),
    (["--offsets1", "0.1", "0.4"], "--offsets3 is missing"),
    (["--spacing", "0.2", "--offsets3", "0.1", "0.4"], "replace --lamellae and --spacing"),
])
def test_gg_bad_offsets_are_named_and_write_nothing(tmp_path, capsys, extra, message):
    target = _helicoid_target(tmp_path)
    out = tmp_path / "design"
    assert main(["gg", str(target), "-o", str(out), "-q", *extra]) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err
    assert not out.exists()


def test_gg_offsets_and_lamellae_are_exclusive(tmp_path, capsys):
    target = _helicoid_target(tmp_path)
    assert main(["gg", str(target), "-o", str(tmp_path / "d"), "--lamellae", "5", "--offsets",
                 "0.1", "0.5"]) == 2
    assert "not allowed with argument" in capsys.readouterr().err
