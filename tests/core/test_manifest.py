"""The output manifest (issue 14 item 1): ``-o`` replaces a directory only if it is empty or the
same command's output with nothing but the files its manifest lists; checked again at the
rename; nothing the tool did not write is ever deleted."""
from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest
from tests.helpers.fab_cases import make_bundle
from tests.helpers.gg_cases import helicoid_grid

from gridshell.core import manifest
from gridshell.core.atomic import atomic_dir, check_output, write_bytes
from gridshell.design.bundle import write_bundle
from gridshell.cli.main import main
from gridshell.core.errors import OutputError
from gridshell.geometry.grid import grid_quads
from gridshell.geometry.meshfile import write_mesh

GG = ["--grid", "6", "6", "--lamellae", "3", "--no-preview", "--frames", "0", "-q"]


def snapshot(d: Path) -> dict[str, bytes]:
    """Every file under ``d`` (relative path -> bytes), symbolic links as their target."""
    out = {}
    for root, _, names in os.walk(d):
        for n in names:
            p = Path(root) / n
            out[p.relative_to(d).as_posix()] = (b"->" + os.readlink(p).encode()
                                                if p.is_symlink() else p.read_bytes())
    return out


def _helicoid(tmp_path):
    path = tmp_path / "helicoid.obj"
    write_mesh(path, helicoid_grid(8, 8).reshape(-1, 3), grid_quads(8, 8))
    return path


def _refused(capsys, argv, words=()):
    assert main(argv) == 5
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and "Traceback" not in err, err
    for w in words:
        assert w in lines[0], (w, lines[0])
    return lines[0]


# ------------------------------------------------------------------ the failures of issue 14

def test_gg_refuses_a_directory_with_an_unrelated_design_json(tmp_path, capsys):
    d = tmp_path / "out"
    (d / "notes").mkdir(parents=True)
    (d / "design.json").write_text('{"theme": "dark"}')
    (d / "thesis.docx").write_bytes(b"PK\x03\x04 precious")
    (d / "notes" / "todo.txt").write_text("write chapter 3\n")
    before = snapshot(d)
    _refused(capsys, ["gg", str(_helicoid(tmp_path)), "-o", str(d), *GG],
             ["not the output of an earlier run", "manifest.json"])
    assert snapshot(d) == before


def test_phlw_refuses_a_directory_with_an_unrelated_report_json(tmp_path, capsys):
    d = tmp_path / "out"
    d.mkdir()
    (d / "report.json").write_text('{"quarter": 3}')
    before = snapshot(d)
    _refused(capsys, ["phlw", str(_helicoid(tmp_path)), "-o", str(d)], ["not the output"])
    assert snapshot(d) == before


def test_ncp_refuses_a_gg_bundle(tmp_path, capsys):
    b = write_bundle(tmp_path / "gg", make_bundle("GG"))
    before = snapshot(b)
    _refused(capsys, ["ncp", str(_helicoid(tmp_path)), "-o", str(b)], ["'gridshell gg'"])
    assert snapshot(b) == before


def test_rerunning_gg_keeps_the_users_notes_and_replaces_its_own_output(tmp_path, capsys):
    target, b = _helicoid(tmp_path), tmp_path / "design"
    assert main(["gg", str(target), "-o", str(b), *GG]) == 0
    m = manifest.read(b)
    assert m["command"] == "gg" and "design.json" in m["files"] and "net.obj" in m["files"]
    assert m["argv"][:2] == ["gridshell", "gg"]
    (b / "my_notes.txt").write_text("joint 12 is loose\n")
    before = snapshot(b)
    _refused(capsys, ["gg", str(target), "-o", str(b), *GG], ["my_notes.txt"])
    assert snapshot(b) == before
    (b / "my_notes.txt").unlink()
    assert main(["gg", str(target), "-o", str(b), *GG]) == 0  # its own output: replaced


def test_a_directory_appearing_during_the_run_is_not_swapped_away(tmp_path, capsys,
                                                                   monkeypatch):
    import gridshell.gg.pipeline as pipeline

    target, out = _helicoid(tmp_path), tmp_path / "design"
    real = pipeline.design_gg

    def racing(*args, **kwargs):
        res = real(*args, **kwargs)
        out.mkdir()
        (out / "arrived.txt").write_text("meanwhile\n")
        return res

    monkeypatch.setattr(pipeline, "design_gg", racing)
    _refused(capsys, ["gg", str(target), "-o", str(out), *GG], ["arrived.txt"])
    assert snapshot(out) == {"arrived.txt": b"meanwhile\n"}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["design", "helicoid.obj"]


@pytest.mark.parametrize("link", ["dangling", "to a directory", "to a file"])
def test_output_symlinks_are_refused_cleanly(tmp_path, capsys, link):
    real = tmp_path / "real"
    if link == "to a directory":
        real.mkdir()
        (real / "keep.txt").write_text("x")
    elif link == "to a file":
        real.write_text("x")
    out = tmp_path / "out"
    out.symlink_to(real)
    before = snapshot(tmp_path)
    _refused(capsys, ["gg", str(_helicoid(tmp_path)), "-o", str(out), *GG], ["symbolic link"])
    after = snapshot(tmp_path)
    after.pop("helicoid.obj")
    before.pop("helicoid.obj", None)
    assert after == before and os.readlink(out) == str(real)


def test_fabricate_into_a_foreign_directory_is_an_output_error(tmp_path, capsys):
    b = write_bundle(tmp_path / "gg", make_bundle("GG"))
    d = tmp_path / "mine"
    d.mkdir()
    (d / "cut.dxf").write_text("mine")
    _refused(capsys, ["fabricate", str(b), "-o", str(d), "--force"], ["cut.dxf"])
    assert (d / "cut.dxf").read_text() == "mine"


# ------------------------------------------------------------------ the rules, through the API

def test_empty_directory_and_own_output_are_replaced(tmp_path):
    d = tmp_path / "d"
    d.mkdir()
    with atomic_dir(d, owner="x") as t:
        (t / "a.txt").write_text("1")
    assert manifest.read(d)["files"]["a.txt"]["size"] == 1
    with atomic_dir(d, owner="x") as t:
        (t / "b.txt").write_text("2")
    assert sorted(p.name for p in d.iterdir()) == ["b.txt", manifest.MANIFEST]


@pytest.mark.parametrize("tamper", ["foreign file", "changed file", "other owner",
                                    "fake manifest", "foreign subdirectory", "symlink inside"])
def test_anything_unlisted_is_refused_at_start_and_at_the_rename(tmp_path, tamper):
    d = tmp_path / "d"
    with atomic_dir(d, owner="x") as t:
        (t / "a.txt").write_text("1")
        (t / "sub").mkdir()
        (t / "sub" / "b.txt").write_text("2")

    def spoil():
        if tamper == "foreign file":
            (d / "sub" / "mine.txt").write_text("mine")
        elif tamper == "changed file":
            (d / "a.txt").write_text("9")  # same size, other content
        elif tamper == "other owner":
            m = manifest.read(d)
            manifest.write(d, {**m, "command": "y"})
        elif tamper == "fake manifest":
            (d / manifest.MANIFEST).write_text(json.dumps({"format": "other", "files": {}}))
        elif tamper == "foreign subdirectory":
            (d / "photos").mkdir()
        else:
            (d / "link").symlink_to(tmp_path)

    spoil()
    before = snapshot(d)
    with pytest.raises(OutputError):
        check_output(d, owner="x")
    with pytest.raises(OutputError):
        with atomic_dir(d, owner="x") as t:
            (t / "new.txt").write_text("new")
    assert snapshot(d) == before
    # the same, when it happens while the block runs (checked again at the rename)
    d2 = tmp_path / "d2"
    with atomic_dir(d2, owner="x") as t:
        (t / "a.txt").write_text("1")
        (t / "sub").mkdir()
        (t / "sub" / "b.txt").write_text("2")
    d, d2 = d2, d
    with pytest.raises(OutputError):
        with atomic_dir(d, owner="x") as t:
            (t / "new.txt").write_text("new")
            spoil()
            before = snapshot(d)
    assert snapshot(d) == before
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporaries


def test_files_added_later_and_nested_outputs_are_registered(tmp_path):
    """render.png written into a bundle, DIR/fabrication: the bundle stays replaceable."""
    from gridshell.fabrication import fabricate

    b = write_bundle(tmp_path / "gg", make_bundle("GG"))
    write_bytes(b / "render.png", b"\x89PNG fake")
    write_bytes(b / "sequence" / "frame_000.png", b"\x89PNG fake")
    fabricate(b, b / "fabrication", plan=False)
    m = manifest.read(b)
    assert "render.png" in m["files"] and "sequence/frame_000.png" in m["files"]
    assert m["outputs"] == ["fabrication"] and manifest.read(b / "fabrication")["command"] \
        == "fabricate"
    assert manifest.refusal(b, "gg") is None
    (b / "fabrication" / "mine.txt").write_text("mine")  # a foreign file in the nested output
    assert "mine.txt" in manifest.refusal(b, "gg")
    (b / "fabrication" / "mine.txt").unlink()
    write_bundle(b, make_bundle("GG"))
    assert not (b / "fabrication").exists() and not (b / "render.png").exists()


def test_manifest_lists_sizes_and_hashes_of_every_file(tmp_path):
    import hashlib

    b = write_bundle(tmp_path / "b", make_bundle("CNC"))
    m = manifest.read(b)
    assert m["tool"] == "gridshell" and m["command"] == "ncp" and m["kind"].endswith("CNC")
    files = {p.relative_to(b).as_posix() for p in b.rglob("*") if p.is_file()}
    assert set(m["files"]) == files - {manifest.MANIFEST}
    for f, rec in m["files"].items():
        data = (b / f).read_bytes()
        assert rec == {"size": len(data), "sha256": hashlib.sha256(data).hexdigest()}
    assert np.isfinite([r["size"] for r in m["files"].values()]).all()
