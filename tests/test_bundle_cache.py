"""read_bundle reads a bundle once per process and content: a second read of byte-identical
files parses nothing and returns its own copy; any change of a file (even one that keeps its
size and modification time) is read anew."""
from __future__ import annotations

import os

import numpy as np
import pytest
from render_cases import write_case

import gridshell.meshfile as meshfile
from gridshell.bundle import content_key, read_bundle
from gridshell.errors import InputError


def _no_parsing(monkeypatch):
    def refuse(*args, **kwargs):
        raise AssertionError("the bundle was parsed again")
    for name in ("read_mesh", "read_configuration", "read_polylines"):
        monkeypatch.setattr(meshfile, name, refuse)


def test_a_second_read_parses_nothing_and_returns_its_own_copy(tmp_path, monkeypatch):
    d = write_case(tmp_path / "b")
    first = read_bundle(d)
    _no_parsing(monkeypatch)
    second = read_bundle(d)
    assert second is not first and second.net is not first.net
    assert np.array_equal(second.surface_V, first.surface_V)
    assert np.array_equal(second.net.joints, first.net.joints)
    assert all(np.array_equal(a.axis, b.axis) for a, b in zip(first.net.lamellae,
                                                                second.net.lamellae))
    assert second.metrics == first.metrics and second.params == first.params
    # what a caller does to its copy does not reach the next reader
    second.surface_V[:] = 0.0
    second.net.lamellae[0].axis[:] = 0.0
    second.params["nested"]["b"].append(99)
    third = read_bundle(d)
    assert np.array_equal(third.surface_V, first.surface_V)
    assert np.array_equal(third.net.lamellae[0].axis, first.net.lamellae[0].axis)
    assert third.params == first.params


def test_a_changed_file_is_read_anew_even_with_the_same_size_and_time(tmp_path):
    d = write_case(tmp_path / "b")
    before = read_bundle(d)
    f = d / "surface.obj"
    text = f.read_text()
    st = os.stat(f)
    # the first vertex's x coordinate, one digit changed: same size, same mtime
    i = text.index("v ") + 2
    digit = text[i + 1] if text[i] == "-" else text[i]
    j = i + 1 if text[i] == "-" else i
    new = "2" if digit != "2" else "3"
    f.write_text(text[:j] + new + text[j + 1:])
    os.utime(f, ns=(st.st_atime_ns, st.st_mtime_ns))
    assert os.stat(f).st_size == st.st_size and os.stat(f).st_mtime_ns == st.st_mtime_ns
    after = read_bundle(d)
    assert not np.array_equal(after.surface_V, before.surface_V)
    assert np.array_equal(after.surface_V[1:], before.surface_V[1:])


def test_a_broken_bundle_still_fails_after_a_good_read(tmp_path):
    d = write_case(tmp_path / "b")
    read_bundle(d)
    (d / "net.obj").write_text("garbage\n")
    with pytest.raises(InputError):
        read_bundle(d)
    (d / "net.obj").unlink()
    with pytest.raises(InputError, match="net.obj"):
        read_bundle(d)


def test_content_key_names_the_files_by_content():
    from pathlib import Path

    assert content_key(Path("/nonexistent-dir-xyz"))[2] == (None,) * 6


def test_an_added_revolution_file_is_read(tmp_path):
    d = write_case(tmp_path / "b")
    assert read_bundle(d).revolution_V is None
    b = read_bundle(d)
    meshfile.write_mesh(d / "revolution.obj", b.surface_V + 1.0, b.surface_F)
    assert np.array_equal(read_bundle(d).revolution_V, b.surface_V + 1.0)
