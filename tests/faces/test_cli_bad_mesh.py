"""``gridshell gg BAD.obj``: a mesh file the readers refuse (vertices without faces, a face index
past the vertices) is exit 2 with one line on stderr naming the file (and the line), no
traceback, nothing written; in this process and as the installed command's own process."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tests.faces.test_hostile_inputs import GG, MESH_CASES, _UNCLEANED, _write_hostile, run_hostile

from gridshell.cli.main import main
from gridshell.geometry import meshfile

N = 25  # a 25 x 25 grid: 625 vertices, as the report that found the bug had


def _vertices() -> list[str]:
    u, v = np.meshgrid(np.linspace(0, 2, N), np.linspace(0, 2, N), indexing="ij")
    V = np.stack([u, v, 0.1 * (u - 1) * (v - 1)], axis=-1).reshape(-1, 3)
    return [f"v {x!r} {y!r} {z!r}" for x, y, z in V.tolist()]


def _faces() -> list[str]:
    return [f"f {a} {a + N} {a + N + 1} {a + 1}" for a in
            (j * N + i + 1 for j in range(N - 1) for i in range(N - 1))]


def _bad_obj(tmp_path: Path, case: str) -> Path:
    faces = _faces()
    if case == "no faces":
        faces = []
    else:
        faces[5] = f"f 1 2 {case} 3"            # line 631
    path = tmp_path / "BAD.obj"
    path.write_text("\n".join(_vertices() + faces) + "\n")
    return path


CASES = ["no faces", "-99999", "99999", "626", "0"]


@pytest.mark.parametrize("line_parser", [False, True], ids=["fast", "plain"])
@pytest.mark.parametrize("case", CASES)
def test_gg_of_a_bad_obj_is_exit_2_with_one_line(tmp_path, capsys, monkeypatch, case,
                                                 line_parser):
    if line_parser:
        monkeypatch.setattr(meshfile, "_parse_obj_fast", lambda data: None)
    path = _bad_obj(tmp_path, case)
    out = tmp_path / "out"
    got = main(["gg", str(path), "-o", str(out), "--grid", "6", "6", "--no-preview"])
    cap = capsys.readouterr()
    lines = [ln for ln in cap.err.splitlines() if ln.strip()]
    assert got == 2, cap.err
    assert len(lines) == 1 and "Traceback" not in cap.err, cap.err
    assert lines[0].startswith("gridshell gg: error: BAD.obj: "), lines[0]
    if case != "no faces":
        assert "line 631" in lines[0], lines[0]
    assert not out.exists()


def test_the_process_exits_2(tmp_path):
    """The command as a user runs it: ``python -m gridshell gg BAD.obj``, its exit status."""
    path = _bad_obj(tmp_path, "-99999")
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[2])}
    run = subprocess.run([sys.executable, "-m", "gridshell", "gg", str(path), "-o",
                          str(tmp_path / "out"), "-q"], capture_output=True, text=True,
                         env=env, timeout=120)
    lines = [ln for ln in run.stderr.splitlines() if ln.strip()]
    assert run.returncode == 2 and len(lines) == 1, run.stderr
    assert "BAD.obj" in lines[0] and "line 631" in lines[0], lines[0]


@pytest.mark.parametrize("kind", MESH_CASES)
def test_the_hostile_meshes_through_the_line_parser(tmp_path, capsys, monkeypatch, kind):
    """The hostile-input suite's malformed OBJ files with the vectorized OBJ readers off:
    the line parser gives the same categories and words."""
    monkeypatch.setattr(meshfile, "_parse_obj_fast", lambda data: None)
    src = tmp_path / "target.obj"
    words = _write_hostile(src, kind)
    run_hostile(capsys, tmp_path, ["gg", str(src), "-o", str(tmp_path / "out"), *GG,
                                   *_UNCLEANED.get(kind, [])], 2, words + [src.name])
