"""Atomic writes: complete file or nothing, with the permissions of a plain write."""
from __future__ import annotations

import os

import pytest

from gridshell.core.atomic import atomic_dir, atomic_path, write_text
from gridshell.core.errors import OutputError


def test_written_files_and_directories_get_the_umask_mode(tmp_path):
    old = os.umask(0o022)
    try:
        write_text(tmp_path / "a.txt", "x")
        with atomic_dir(tmp_path / "d") as d:
            (d / "f").write_text("y")
    finally:
        os.umask(old)
    assert (tmp_path / "a.txt").stat().st_mode & 0o777 == 0o644
    assert (tmp_path / "d").stat().st_mode & 0o777 == 0o755


def test_failure_leaves_nothing_and_keeps_the_old_file(tmp_path):
    write_text(tmp_path / "a.txt", "old")
    with pytest.raises(RuntimeError):
        with atomic_path(tmp_path / "a.txt") as tmp:
            tmp.write_text("half")
            raise RuntimeError("boom")
    assert (tmp_path / "a.txt").read_text() == "old"
    with pytest.raises(RuntimeError):
        with atomic_dir(tmp_path / "d") as d:
            (d / "f").write_text("half")
            raise RuntimeError("boom")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.txt"]


def test_failure_removes_the_directories_it_made_and_only_those(tmp_path):
    (tmp_path / "have").mkdir()
    with pytest.raises(RuntimeError):
        with atomic_path(tmp_path / "have" / "new" / "deeper" / "a.txt") as tmp:
            assert tmp.parent == tmp_path / "have" / "new" / "deeper"
            raise RuntimeError("boom")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["have"]
    assert list((tmp_path / "have").iterdir()) == []
    with pytest.raises(RuntimeError):             # another file came into a made directory
        with atomic_path(tmp_path / "new" / "deeper" / "a.txt") as tmp:
            (tmp_path / "new" / "theirs.txt").write_text("not ours")
            raise RuntimeError("boom")
    assert sorted(p.relative_to(tmp_path).as_posix() for p in tmp_path.rglob("*")) == \
        ["have", "new", "new/theirs.txt"]
    with atomic_path(tmp_path / "made" / "a.txt") as tmp:           # success keeps them
        tmp.write_text("ok")
    assert (tmp_path / "made" / "a.txt").read_text() == "ok"


def test_unwritable_location_is_an_output_error(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("")
    with pytest.raises(OutputError, match="writable"):
        write_text(blocker / "sub" / "a.txt", "x")
