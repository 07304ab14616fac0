"""Atomic file and directory writes: never leave a half-written output behind."""
from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from pathlib import Path
from typing import Iterator

from .errors import OutputError


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _publish_mode(path: Path, directory: bool = False) -> None:
    """Give a temporary file (0600) or directory (0700) the mode a plain open() would."""
    os.chmod(path, (0o777 if directory else 0o666) & ~_umask())


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; rename it onto ``path`` only if the block succeeds."""
    path = Path(path)
    parent = path.parent if str(path.parent) else Path(".")
    try:
        parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp" + path.suffix, dir=parent)
        os.close(fd)
        _publish_mode(Path(tmp))
    except OSError as exc:
        raise OutputError(f"cannot write to {parent}: {exc.strerror or exc}. "
                          "Choose a writable output location.") from exc
    tmp_path = Path(tmp)
    try:
        yield tmp_path
        os.replace(tmp_path, path)
    finally:
        if tmp_path.exists():
            tmp_path.unlink()


def write_text(path: str | os.PathLike, text: str) -> None:
    """Write ``text`` to ``path`` atomically (UTF-8)."""
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")


def write_bytes(path: str | os.PathLike, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically."""
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)


@contextlib.contextmanager
def atomic_dir(path: str | os.PathLike, overwrite: bool = True) -> Iterator[Path]:
    """Yield a fresh temporary directory beside ``path``; it replaces ``path`` only on success.

    If the block raises, the temporary directory is removed and ``path`` is untouched.
    """
    path = Path(path)
    parent = path.parent if str(path.parent) else Path(".")
    try:
        parent.mkdir(parents=True, exist_ok=True)
        tmp = Path(tempfile.mkdtemp(prefix=f".{path.name}.", suffix=".tmp", dir=parent))
        _publish_mode(tmp, directory=True)
    except OSError as exc:
        raise OutputError(f"cannot create output directory {path}: {exc.strerror or exc}. "
                          "Choose a writable output location.") from exc
    try:
        yield tmp
        if path.exists():
            if not overwrite:
                raise OutputError(f"{path} exists; pass overwrite=True or choose another directory.")
            old = Path(tempfile.mkdtemp(prefix=f".{path.name}.", suffix=".old", dir=parent))
            os.replace(path, old / "d")
            os.replace(tmp, path)
            shutil.rmtree(old, ignore_errors=True)
        else:
            os.replace(tmp, path)
    finally:
        if tmp.exists():
            shutil.rmtree(tmp, ignore_errors=True)


def check_output(path: str | os.PathLike, *, directory: bool = True,
                 marker: str | None = None) -> Path:
    """Raise :class:`OutputError` now, before any work, if ``path`` cannot be written.

    Outputs are written through a temporary beside ``path`` (:func:`atomic_path`,
    :func:`atomic_dir`), so the nearest existing ancestor of ``path`` must be a writable
    directory. With ``marker``, an existing non-empty directory at ``path`` is only replaced if
    it holds ``marker`` (the output of an earlier run): a misspelt ``-o`` must never wipe
    unrelated files. (Permissions are checked with :func:`os.access`; the atomic writers still
    report what the operating system refuses.)

    Returns
    -------
    Path
        ``path``.
    """
    path = Path(path)
    if path.exists():
        if directory and not path.is_dir():
            raise OutputError(f"{path} exists and is not a directory; choose another output "
                              "directory")
        if not directory and path.is_dir():
            raise OutputError(f"{path} is a directory; give the path of a file")
        if marker is not None and any(path.iterdir()) and not (path / marker).exists():
            raise OutputError(f"{path} exists and is not the output of an earlier run (no "
                              f"{marker}); choose another output directory or remove it")
    anc = path.parent if str(path.parent) else Path(".")
    while not anc.exists() and anc != anc.parent:
        anc = anc.parent
    if not anc.is_dir():
        raise OutputError(f"cannot write {path}: {anc} is a file, not a directory. Choose a "
                          "writable output location.")
    if not os.access(anc, os.W_OK | os.X_OK):
        raise OutputError(f"cannot write {path}: {anc} is not writable (permission denied). "
                          "Choose a writable output location.")
    return path
