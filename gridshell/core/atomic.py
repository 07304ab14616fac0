"""Atomic file and directory writes: never leave a half-written output behind."""
from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from pathlib import Path
from typing import Iterator

from gridshell.core.errors import OutputError


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _publish_mode(path: Path, directory: bool = False) -> None:
    """Give a temporary file (0600) or directory (0700) the mode a plain open() would."""
    os.chmod(path, (0o777 if directory else 0o666) & ~_umask())


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; rename it onto ``path`` only if the block succeeds.

    A file written into an existing output directory (``render.png`` into a bundle) is added
    to its manifest (:func:`gridshell.core.manifest.register`). Directories made for ``path`` are
    removed again if the block fails (and nothing else came into them)."""
    path = Path(path)
    parent = path.parent if str(path.parent) else Path(".")
    made = [d for d in (parent, *parent.parents) if not os.path.lexists(d)]   # deepest first
    try:
        parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp" + path.suffix, dir=parent)
        os.close(fd)
        _publish_mode(Path(tmp))
    except OSError as exc:
        _remove_empty(made)
        raise OutputError(f"cannot write to {parent}: {exc.strerror or exc}. "
                          "Choose a writable output location.") from exc
    tmp_path = Path(tmp)
    published = False
    try:
        yield tmp_path
        from gridshell.core import finite

        finite.check(tmp_path, str(path))
        try:
            os.replace(tmp_path, path)
        except OSError as exc:
            raise OutputError(f"cannot write {path}: {exc.strerror or exc}. Choose a writable "
                              "output location.") from exc
        published = True
        from gridshell.core import manifest

        manifest.register(path)
    finally:
        if tmp_path.exists():
            tmp_path.unlink()
        if not published:
            _remove_empty(made)


def _remove_empty(made: list[Path]) -> None:
    """Remove the directories ``made`` (deepest first) while they are empty."""
    for d in made:
        try:
            os.rmdir(d)
        except OSError:         # not empty (something else came in) or gone: leave the rest
            return


def write_text(path: str | os.PathLike, text: str) -> None:
    """Write ``text`` to ``path`` atomically (UTF-8)."""
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")


def write_bytes(path: str | os.PathLike, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically."""
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)


@contextlib.contextmanager
def atomic_dir(path: str | os.PathLike, overwrite: bool = True, *, owner: str | None = None,
               kind: str | None = None) -> Iterator[Path]:
    """Yield a fresh temporary directory beside ``path``; it replaces ``path`` only on success.

    Before that every file is checked for non-finite numbers (:func:`gridshell.core.finite.check_tree`;
    a file of :func:`atomic_path` likewise). On success the directory gets its manifest (:mod:`gridshell.core.manifest`: the files written,
    ``owner``, default the CLI command being run, and ``kind``), and an existing ``path`` is
    replaced only if :func:`gridshell.core.manifest.refusal` allows it - checked again at the moment
    of the rename, and once more on the moved-away directory, so a directory that appeared or
    gained files while the command ran is never deleted (:class:`OutputError`, exit 5).
    If the block raises, the temporary directory is removed and ``path`` is untouched.
    """
    from gridshell.core import manifest

    path = Path(path)
    owner = manifest.owner_of(owner)
    parent = path.parent if str(path.parent) else Path(".")
    why = manifest.refusal(path, owner) if overwrite else None
    if why:
        raise OutputError(why)
    try:
        parent.mkdir(parents=True, exist_ok=True)
        tmp = Path(tempfile.mkdtemp(prefix=f".{path.name}.", suffix=".tmp", dir=parent))
        _publish_mode(tmp, directory=True)
    except OSError as exc:
        raise OutputError(f"cannot create output directory {path}: {exc.strerror or exc}. "
                          "Choose a writable output location.") from exc
    try:
        yield tmp
        from gridshell.core import finite

        finite.check_tree(tmp)
        try:
            manifest.write(tmp, manifest.build(tmp, owner, kind))
        except OSError as exc:
            raise OutputError(f"cannot write the manifest of {path}: {exc.strerror or exc}. "
                              "Choose a writable output location.") from exc
        _swap_in(tmp, path, parent, owner, overwrite)
        manifest.register(path, output=True)
    finally:
        if tmp.exists():
            shutil.rmtree(tmp, ignore_errors=True)


def _swap_in(tmp: Path, path: Path, parent: Path, owner: str, overwrite: bool) -> None:
    """Rename ``tmp`` onto ``path``; an existing ``path`` first moves aside, is checked there
    (:func:`gridshell.core.manifest.refusal`) and is deleted only if it is replaceable, else it is
    moved back. :class:`OutputError` for anything refused."""
    from gridshell.core import manifest

    if os.path.lexists(path):
        if not overwrite:
            raise OutputError(f"{path} exists; choose another output directory")
        why = manifest.refusal(path, owner)
        if why:
            raise OutputError(why)
        old = Path(tempfile.mkdtemp(prefix=f".{path.name}.", suffix=".old", dir=parent))
        moved = old / "d"
        try:
            os.replace(path, moved)
        except OSError as exc:
            os.rmdir(old)
            raise OutputError(f"cannot replace {path}: {exc.strerror or exc}. Choose a writable "
                              "output location.") from exc
        why = manifest.refusal(moved, owner)
        if why:  # changed between the check and the move: put it back untouched
            _restore(moved, path, old)
            raise OutputError(why.replace(str(moved), str(path)))
        try:
            os.replace(tmp, path)
        except OSError as exc:
            _restore(moved, path, old)
            raise OutputError(f"cannot replace {path}: {exc.strerror or exc} (something "
                              "appeared there meanwhile); nothing was changed") from exc
        shutil.rmtree(old, ignore_errors=True)
        return
    try:
        os.replace(tmp, path)  # refused by the OS if a non-empty directory appeared meanwhile
    except OSError as exc:
        raise OutputError(f"cannot create {path}: {exc.strerror or exc} (a directory appeared "
                          "there while the command ran?); nothing was changed; choose another "
                          "output directory") from exc


def _restore(moved: Path, path: Path, old: Path) -> None:
    """Move ``moved`` back to ``path`` (if nothing took its place) and drop ``old``."""
    try:
        os.replace(moved, path)
        os.rmdir(old)
    except OSError:  # leave it where it is (``old``): never delete what we did not write
        pass


def check_output(path: str | os.PathLike, *, directory: bool = True,
                 marker: str | None = None, owner: str | None = None) -> Path:
    """Raise :class:`OutputError` now, before any work, if ``path`` cannot be written.

    Outputs are written through a temporary beside ``path`` (:func:`atomic_path`,
    :func:`atomic_dir`), so the nearest existing ancestor of ``path`` must be a writable
    directory. An existing directory at ``path`` is replaced only if it is empty or the output
    of this command (``owner``, default the CLI command being run) with nothing but the files
    its manifest lists (:func:`gridshell.core.manifest.refusal`; a misspelt ``-o`` must never wipe
    unrelated files); :func:`atomic_dir` checks again at the rename. ``marker`` is accepted for
    compatibility and no longer needed: the manifest says whose output a directory is.
    (Permissions are checked with :func:`os.access`; the atomic writers still report what the
    operating system refuses.)

    Returns
    -------
    Path
        ``path``.
    """
    from gridshell.core import manifest

    path = Path(path)
    if path.is_symlink():
        raise OutputError(f"{path} is a symbolic link; gridshell never writes through or replaces "
                          "one - choose another output location (nothing was changed)")
    if path.exists():
        if directory:
            why = manifest.refusal(path, owner)
            if why:
                raise OutputError(why)
        elif path.is_dir():
            raise OutputError(f"{path} is a directory; give the path of a file")
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
