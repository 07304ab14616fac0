"""``verify_bundle`` and ``gridshell verify`` / ``fabricate`` as quality gates (issue 13 item 3,
issue 14 item 3): the verdict comes from figures recomputed from the files, a missing file or
figure is not a pass, every stored count and figure is compared with the files."""
from __future__ import annotations

import io
import json

import numpy as np
import pytest
from tests.helpers.fab_cases import make_bundle

from gridshell.design.bundle import write_bundle
from gridshell.cli.main import main
from gridshell.core.errors import GridshellError, InputError
from gridshell.geometry.meshfile import orientation_problem, read_configuration, write_mesh
from gridshell.design.verification import verify_bundle

FLAT = {"c": 0.0, "twist": 0.0, "stretch": 0.0}  # a plane rectangular grid: Delta_a = 0


def _npy(a) -> bytes:
    buf = io.BytesIO()
    np.save(buf, np.asarray(a, float))
    return buf.getvalue()


def _write(path, kind="GG", axes=True, **net_kw):
    b = make_bundle(kind, **net_kw)
    n = len(b.net.joints)
    r = np.tile([0.0, 0.0, 1.0], (n, 1))
    extra = {"axes_r.npy": _npy(r), "aligned_r.npy": _npy(r)} if axes else None
    return write_bundle(path, b, extra=extra)


def _design(path):
    return json.loads((path / "design.json").read_text())


def _set_design(path, d):
    (path / "design.json").write_text(json.dumps(d))


def _verify(capsys, path, code):
    assert main(["verify", str(path)]) == code
    cap = capsys.readouterr()
    assert "Traceback" not in cap.err
    return json.loads(cap.out), cap.err


def test_good_gg_bundle_is_ok_with_a_pass_line_per_figure(tmp_path, capsys):
    b = _write(tmp_path / "gg", **FLAT)
    res, err = _verify(capsys, b, 0)
    assert res["ok"] and res["problems"] == [] and res["mismatch"] == []
    assert [g["name"] for g in res["gates"]] == ["delta_a_mean", "delta_a_max",
                                                 "delta_a_arc_mean", "delta_a_arc_max"]
    assert err.count("pass  Delta_a") == 4 and "FAIL" not in err


def test_failing_gg_figures_make_verify_not_ok_and_exit_4(tmp_path, capsys):
    b = _write(tmp_path / "gg")  # the twisted saddle grid is not alignable (Delta_a ~ 10 %)
    res, err = _verify(capsys, b, 4)
    assert res["ok"] is False and res["problems"] == []
    assert res["alignability"]["max"] > 3
    assert "FAIL  Delta_a max" in err and "NOT ok" in err


def test_fabricate_refuses_a_failing_design_unless_forced(tmp_path, capsys):
    b = _write(tmp_path / "gg")
    out = tmp_path / "fab"
    assert main(["fabricate", str(b), "-o", str(out), "--no-plan", "-q"]) == 2
    err = capsys.readouterr().err
    assert "Delta_a max" in err and ">= 3 %" in err and "--force" in err
    assert err.count("\n") == 1 and "Traceback" not in err and not out.exists()
    assert main(["fabricate", str(b), "-o", str(out), "--no-plan", "-q", "--force"]) == 0
    assert (out / "cutlist.csv").is_file()


def test_fabricate_decides_from_recomputed_figures_not_stored_flags(tmp_path, capsys):
    b = _write(tmp_path / "gg")
    d = _design(b)
    good = {"mean": 0.1, "max": 0.2}
    d["metrics"] = {"alignability": good, "alignability_arc": good, "converged": True}
    d["params"] = {"converged": True}
    _set_design(b, d)
    res, _ = _verify(capsys, b, 2)  # the stored figures disagree with the files
    assert "alignability" in res["mismatch"] and not res["ok"]
    out = tmp_path / "fab"
    assert main(["fabricate", str(b), "-o", str(out), "--no-plan", "-q"]) == 2
    assert "Delta_a max" in capsys.readouterr().err and not out.exists()


def test_fabricate_cuts_a_passing_design_without_force(tmp_path, capsys):
    b = _write(tmp_path / "gg", **FLAT)
    assert main(["fabricate", str(b), "-o", str(tmp_path / "fab"), "--no-plan", "-q"]) == 0


@pytest.mark.parametrize("kind", ["AA", "CNC", "NCP"])
def test_ncp_bundle_without_aligned_obj_is_not_ok(tmp_path, capsys, kind):
    b = _write(tmp_path / kind, kind=kind, **FLAT)
    (b / "aligned.obj").unlink()
    res, err = _verify(capsys, b, 2)
    assert res["ok"] is False
    assert any("aligned.obj is missing" in p for p in res["problems"])
    assert "FAIL  Delta_l max: not measured" in err
    if kind != "NCP":
        assert "FAIL  collapse error: not measured" in err


def test_ncp_bundle_without_rotation_axes_is_not_ok(tmp_path, capsys):
    b = _write(tmp_path / "ncp", kind="NCP", axes=False, **FLAT)
    res, _ = _verify(capsys, b, 2)
    assert any("axes_r.npy is missing" in p for p in res["problems"])
    assert res["delta_l"] is None


@pytest.mark.parametrize("field, value", [("n_joints", 5), ("n_loops", 1), ("n_joints", "98"),
                                          ("n_joints", None)])
def test_gg_stored_counts_are_compared_with_the_files(tmp_path, capsys, field, value):
    b = _write(tmp_path / "gg", **FLAT)
    d = _design(b)
    d[field] = value
    _set_design(b, d)
    res, err = _verify(capsys, b, 2)
    assert field in res["mismatch"] and not res["ok"] and "changed after" in err


def test_gg_stored_figures_are_compared_with_the_files(tmp_path, capsys):
    b = _write(tmp_path / "gg", **FLAT)
    v = verify_bundle(b)
    d = _design(b)
    d["metrics"] = {"alignability": v["alignability"], "alignability_arc": v["alignability_arc"],
                    "geodesic_turning": v["geodesic_turning"],
                    "n_lamellae": {"C1": 4, "C3": 5}, "n_joints": v["n_joints"]}
    _set_design(b, d)
    assert verify_bundle(b)["ok"]
    d["metrics"]["geodesic_turning"] += 0.5
    d["metrics"]["n_lamellae"] = {"C1": 3, "C3": 5}
    _set_design(b, d)
    assert verify_bundle(b)["mismatch"] == ["metrics.n_lamellae", "geodesic_turning"]


@pytest.mark.parametrize("content", [
    b"\x93NUMPY garbage" + bytes(range(256)),
    bytes(np.random.default_rng(0).integers(0, 256, 300, dtype=np.uint8)),
    b"",
    "pickle",
    "shape",
    "nan",
])
def test_rotation_axes_files_are_loaded_safely(tmp_path, capsys, content):
    b = _write(tmp_path / "ncp", kind="NCP", **FLAT)
    n = len(read_configuration(b / "net.obj")[0])
    if content == "pickle":
        buf = io.BytesIO()
        np.save(buf, np.array([{"a": 1}] * n, dtype=object), allow_pickle=True)
        content = buf.getvalue()
    elif content == "shape":
        content = _npy(np.zeros((n + 1, 3)))
    elif content == "nan":
        content = _npy(np.full((n, 3), np.nan))
    (b / "axes_r.npy").write_bytes(content)
    with pytest.raises(InputError, match="axes_r.npy"):
        verify_bundle(b)
    assert main(["verify", str(b)]) == 2
    err = capsys.readouterr().err
    assert "axes_r.npy" in err and "Traceback" not in err and err.count("\n") == 1


def test_verify_json_is_strict(tmp_path, capsys):
    # a flat NCP net: Delta_n is 0/0 (no normal curvature) -> NaN, printed as null
    b = _write(tmp_path / "ncp", kind="NCP", **FLAT)
    assert main(["verify", str(b)]) == 4
    out = capsys.readouterr().out
    assert "NaN" not in out and json.loads(out)["gates"][-1]["value"] is None


# ------------------------------------------------------------------------ OBJ orientation

def test_write_mesh_refuses_inconsistent_orientation(tmp_path):
    V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, -1, 0], [1, -1, 0.0]])
    with pytest.raises(GridshellError, match="inconsistently oriented"):
        write_mesh(tmp_path / "bad.obj", V, [[0, 1, 2, 3], [0, 1, 5, 4]])
    assert not (tmp_path / "bad.obj").exists() and list(tmp_path.iterdir()) == []
    write_mesh(tmp_path / "good.obj", V, [[0, 1, 2, 3], [1, 0, 4, 5]])


def test_collapsed_net_with_degenerate_loops_is_still_writable(tmp_path):
    # aligned.obj: every joint on a line, loops of zero area, orientation is combinatorial
    from gridshell.geometry.grid import grid_quads

    F = grid_quads(4, 5)
    V = np.zeros((20, 3))
    V[:, 0] = np.linspace(0, 1, 20)
    assert orientation_problem(F, 20) is None
    write_mesh(tmp_path / "aligned.obj", V, F)
    assert np.array_equal(read_configuration(tmp_path / "aligned.obj")[0], V)
    assert orientation_problem(F[:, ::-1][[0]].tolist() + F[1:].tolist(), 20) is not None


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_write_mesh_refuses_non_finite_vertices(tmp_path, bad):
    V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, bad]])
    with pytest.raises(GridshellError, match="not finite"):
        write_mesh(tmp_path / "m.obj", V, [[0, 1, 2, 3]])
    assert list(tmp_path.iterdir()) == []


def test_bundle_writer_checks_every_obj_it_holds(tmp_path):
    """An OBJ handed to write_bundle as bytes (``extra``) is checked too; mixed face sizes."""
    b = make_bundle("GG", **FLAT)
    bad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 -1 0\nf 1 2 3 4\nf 1 2 5\n"
    with pytest.raises(GridshellError, match="frame_000.obj.*inconsistently oriented"):
        write_bundle(tmp_path / "b", b, extra={"sequence/frame_000.obj": bad.encode()})
    assert list(tmp_path.iterdir()) == []
    good = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 -1 0\nf 1 2 3 4\nf 2 1 5\n"
    write_bundle(tmp_path / "b", b, extra={"sequence/frame_000.obj": good.encode()})
    assert orientation_problem([[0, 1, 2, 3], [0, 1, 4, -1]], 5) is not None
    assert orientation_problem([[0, 1, 2, 3], [1, 0, 4, -1]], 5) is None


def test_fabricate_summary_says_what_was_checked(tmp_path, capsys):
    good = _write(tmp_path / "good", **FLAT)
    assert main(["fabricate", str(good), "-o", str(tmp_path / "f1"), "--no-plan", "-q",
                 "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["design checks"] == \
        "all 4 figures within the paper's thresholds"
    bad = _write(tmp_path / "bad")
    assert main(["fabricate", str(bad), "-o", str(tmp_path / "f2"), "--no-plan", "-q", "--json",
                 "--force"]) == 0
    line = json.loads(capsys.readouterr().out)["design checks"]
    assert line.startswith("cut with --force: 4 of 4 figures fail") and "Delta_a max" in line
