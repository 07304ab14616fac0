"""gridshell.workflow.outputs.write_outputs (``gridshell render --report --3dm``): the .3dm built in a
second process while the pictures and the report are made gives the files of the calls one
after the other, byte for byte and object by object; a failure on either side leaves no .3dm,
no temporary file and no process behind, and the other side's error is the one raised."""
from __future__ import annotations

import json
import os
import shutil
import sys
import threading

import pytest
from tests.helpers.render_cases import make_bundle, write_case
from tests.helpers.io_cases import rhino_objects

from gridshell.workflow import outputs
from gridshell.core.aside import can_fork
from gridshell.design.bundle import write_bundle
from gridshell.core.errors import InputError
from gridshell.export.rhino import export_3dm as write_3dm
from gridshell.render.report import write_report
from gridshell.render.ribbons import render_bundle
from gridshell.render.sequence import render_bundle_sequence


def _case(path, kind: str):
    if kind == "CNC":                   # as tests/export/test_export_rhino.py makes one
        b = make_bundle("CNC")
        b.params["n"] = b.metrics["n"] = 0.5
        return write_bundle(path, b)
    return write_case(path, kind, sequence=kind == "GG")


def _no_children() -> bool:
    try:
        os.waitpid(-1, os.WNOHANG)
    except ChildProcessError:
        return True
    return False


def _manifest(d) -> list:
    """The manifest's files in order with their digests, the .3dm's size and digest left out
    (its objects carry fresh ids)."""
    files = json.loads((d / "manifest.json").read_text())["files"]
    return [(k, None if k.endswith(".3dm") else v) for k, v in files.items()]


def _hidden(d) -> list[str]:
    return sorted(p.name for p in d.iterdir() if p.name.startswith("."))


@pytest.mark.parametrize("serial", [False, True])
@pytest.mark.parametrize("kind, options", [
    ("GG", {"force": True}),
    ("AA", {"force": True, "scale": 0.005}),
    ("CNC", {"force": True, "sheet": "300x200"}),
    ("GG", {}),                                     # fails its figures: no cut sheets
])
def test_outputs_equal_the_calls_one_after_the_other(tmp_path, monkeypatch, kind, options,
                                                     serial):
    if serial:
        monkeypatch.setenv("GRIDSHELL_SERIAL", "1")
    elif not can_fork():
        pytest.skip("no fork here")
    a = _case(tmp_path / "a" / "case", kind)
    b = shutil.copytree(a, tmp_path / "b" / "case")
    got = outputs.write_outputs(a, sequence=kind == "GG", report=True, rhino=a / "m.3dm",
                                rhino_options=options)
    png = render_bundle(b)
    seq = render_bundle_sequence(b) if kind == "GG" else None
    html = write_report(b)
    info = write_3dm(b, b / "m.3dm", **options)
    assert got["render"] == a / "render.png" and png == b / "render.png"
    assert (a / "render.png").read_bytes() == png.read_bytes()
    assert got["report"] == a / "report.html"
    assert (a / "report.html").read_bytes() == html.read_bytes()
    if seq is not None:
        assert len(got["sequence"]["frames"]) == len(seq["frames"]) == 3
        assert (a / "alignment.gif").read_bytes() == (b / "alignment.gif").read_bytes()
    else:
        assert got["sequence"] is None and not (a / "alignment.gif").exists()
    assert got["rhino"]["path"] == str(a / "m.3dm")
    assert {k: v for k, v in got["rhino"].items() if k != "path"} == \
        {k: v for k, v in info.items() if k != "path"}
    assert rhino_objects(a / "m.3dm") == rhino_objects(b / "m.3dm")
    assert sorted(p.name for p in a.iterdir()) == sorted(p.name for p in b.iterdir())
    assert _manifest(a) == _manifest(b)
    assert _hidden(a) == [] and _no_children()


def test_a_failing_render_leaves_no_model_and_no_process(tmp_path, monkeypatch):
    d = _case(tmp_path / "case", "AA")
    (d / "m.3dm").write_bytes(b"the user's own model")

    def broken(*args, **kwargs):
        raise InputError("the picture failed")

    monkeypatch.setattr("gridshell.render.ribbons.render_bundle", broken)
    with pytest.raises(InputError, match="^the picture failed$"):
        outputs.write_outputs(d, report=True, rhino=d / "m.3dm")
    assert (d / "m.3dm").read_bytes() == b"the user's own model"     # untouched
    assert not (d / "report.html").exists()
    assert _hidden(d) == [] and _no_children()


def test_a_failing_model_raises_its_error_after_the_pictures(tmp_path):
    d = _case(tmp_path / "case", "AA")
    with pytest.raises(InputError) as direct:
        write_3dm(d, tmp_path / "direct.3dm", sheet="no size")
    with pytest.raises(InputError) as e:
        outputs.write_outputs(d, report=True, rhino=d / "m.3dm",
                              rhino_options={"sheet": "no size"})
    assert str(e.value) == str(direct.value)
    assert (d / "render.png").is_file() and (d / "report.html").is_file()
    assert not (d / "m.3dm").exists() and not (tmp_path / "direct.3dm").exists()
    assert _hidden(d) == [] and _no_children()


def test_a_failing_model_leaves_no_directory_it_made(tmp_path):
    d = _case(tmp_path / "case", "AA")
    with pytest.raises(InputError):
        outputs.write_outputs(d, png=False, rhino=tmp_path / "new" / "sub" / "m.3dm",
                              rhino_options={"sheet": "no size"})
    with pytest.raises(InputError):
        write_3dm(d, tmp_path / "other" / "m.3dm", sheet="no size")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["case"]
    assert _no_children()


def test_bad_requests_fail_before_anything_is_written(tmp_path):
    d = _case(tmp_path / "case", "AA")
    before = sorted(p.name for p in d.iterdir())
    with pytest.raises(InputError, match="needs the extension .3dm"):
        outputs.write_outputs(d, report=True, rhino=d / "m.obj")
    with pytest.raises(TypeError, match="no progress"):
        outputs.write_outputs(d, rhino=d / "m.3dm", rhino_options={"progress": print})
    assert sorted(p.name for p in d.iterdir()) == before


def test_the_model_is_built_in_another_process_where_it_can_fork(tmp_path, monkeypatch):
    """The parent never builds the model where it can fork; with GRIDSHELL_SERIAL=1 it does."""
    if not can_fork():
        pytest.skip(f"no fork here ({sys.platform}, {threading.active_count()} threads)")
    import gridshell.export.rhino as rhino

    d = _case(tmp_path / "case", "AA")
    pids: list[int] = []
    real = rhino.write_model

    def spy(*args, **kwargs):
        pids.append(os.getpid())        # in the child: lost with it
        return real(*args, **kwargs)

    monkeypatch.setattr(rhino, "write_model", spy)
    outputs.write_outputs(d, png=False, rhino=d / "m.3dm")
    assert pids == [] and (d / "m.3dm").is_file()
    monkeypatch.setenv("GRIDSHELL_SERIAL", "1")
    outputs.write_outputs(d, png=False, rhino=d / "n.3dm")
    assert pids == [os.getpid()]
    assert rhino_objects(d / "m.3dm") == rhino_objects(d / "n.3dm")
