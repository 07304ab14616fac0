"""The output manifest: what a gridshell command wrote into its output directory.

Every output directory (design bundle, PHLW result, fabrication output, demo) holds
``manifest.json``::

    {"format": "gridshell.manifest", "version": 1, "tool": "gridshell", "tool_version": "0.1.0",
     "command": "gg", "argv": [...], "kind": "GG", "created": "2026-12-01T23:00:00Z",
     "files": {"design.json": {"size": 1234, "sha256": "..."}, "sequence/frame_000.obj": ...},
     "dirs": ["sequence"], "outputs": ["fabrication"]}

``files`` lists every file the tool wrote (paths relative to the directory, ``/``-separated),
``dirs`` the subdirectories it made, ``outputs`` the nested output directories with a manifest of their own (``DIR/fabrication``
of ``gridshell fabricate``, the bundles of ``gridshell demo``). Files the tool adds later to an
existing output (``gridshell render`` writes ``render.png`` into a bundle) are added to its
manifest as they are written (:func:`register`).

An existing directory may be replaced (:func:`refusal`) only if it is empty, or its manifest
says it is the output of the same command and every file in it is listed there unchanged
(size and SHA-256), every nested output likewise. Anything else - files the tool did not write,
a file changed since, another command's output, a symbolic link - is refused: nothing the tool
did not write is ever deleted.
"""
from __future__ import annotations

import datetime
import hashlib
import json
import os
import tempfile
from pathlib import Path
from typing import Any, Sequence

__all__ = ["FORMAT", "MANIFEST", "build", "owner_of", "read", "refusal", "register",
           "set_command", "sha256_of", "unchanged", "write"]

MANIFEST = "manifest.json"
FORMAT = "gridshell.manifest"
VERSION = 1
#: the owner of outputs written outside the CLI (the Python API) without an explicit owner
API_OWNER = "python"
#: how many ancestors :func:`register` looks through for the manifest of a written file
_REGISTER_DEPTH = 3

_context: dict[str, Any] = {"command": None, "argv": None}


def set_command(command: str | None, argv: Sequence[str] | None = None) -> None:
    """Record the CLI command being run (``gridshell.cli.main`` does; None resets)."""
    _context["command"] = command
    _context["argv"] = list(argv) if argv is not None else None


def owner_of(owner: str | None = None) -> str:
    """The command an output belongs to: ``owner`` if given, else the CLI command being run,
    else :data:`API_OWNER`."""
    return owner or _context["command"] or API_OWNER


def is_temporary(path: Path) -> bool:
    """True for the temporary directories of :mod:`gridshell.core.atomic` (``.NAME.xxx.tmp``)."""
    return path.name.startswith(".") and path.name.endswith((".tmp", ".old"))


def sha256_of(path: str | os.PathLike) -> str:
    """SHA-256 of a file's bytes (hex)."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


_sha256 = sha256_of


def unchanged(directory: str | os.PathLike, rel: str) -> bool:
    """Whether ``directory/rel`` is listed in the directory's manifest with the size and
    SHA-256 it has now: a file the tool wrote and nobody changed since (replaceable)."""
    m = read(directory)
    path = Path(directory) / rel
    rec = (m or {}).get("files", {}).get(rel)
    if not isinstance(rec, dict) or path.is_symlink() or not path.is_file():
        return False
    return rec.get("size") == path.stat().st_size and rec.get("sha256") == sha256_of(path)


def _record(path: Path) -> dict[str, Any]:
    return {"size": path.stat().st_size, "sha256": _sha256(path)}


def read(directory: str | os.PathLike) -> dict | None:
    """The manifest of ``directory``, or None if it has none (or a file of that name that is
    not a gridshell manifest)."""
    f = Path(directory) / MANIFEST
    if f.is_symlink() or not f.is_file():
        return None
    try:
        m = json.loads(f.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError):
        return None
    if not (isinstance(m, dict) and m.get("format") == FORMAT and isinstance(m.get("files"), dict)
            and isinstance(m.get("command"), str)):
        return None
    m.setdefault("outputs", [])
    m.setdefault("dirs", [])
    return m


def _walk(directory: Path) -> tuple[list[str], list[str], list[str], list[str]]:
    """(files, nested outputs, symbolic links, subdirectories) under ``directory``, relative
    ``/`` paths; the manifest itself and the files of nested outputs are not listed."""
    files, outputs, links, subdirs = [], [], [], []
    for root, dirs, names in os.walk(directory, followlinks=False):
        r = Path(root)
        rel = r.relative_to(directory)
        keep = []
        for d in sorted(dirs):
            p = r / d
            if p.is_symlink():
                links.append((rel / d).as_posix())
            elif read(p) is not None:
                outputs.append((rel / d).as_posix())
            else:
                keep.append(d)
                subdirs.append((rel / d).as_posix())
        dirs[:] = keep
        for n in sorted(names):
            p = r / n
            if r == directory and n == MANIFEST:
                continue
            (links if p.is_symlink() else files).append((rel / n).as_posix())
    return files, outputs, links, subdirs


def build(directory: str | os.PathLike, owner: str | None = None,
          kind: str | None = None) -> dict[str, Any]:
    """The manifest of the files now in ``directory`` (written by ``owner``, see
    :func:`owner_of`; ``kind``: what the output is, e.g. a design kind)."""
    from gridshell.core.version import __version__

    directory = Path(directory)
    files, outputs, _, subdirs = _walk(directory)
    return {"format": FORMAT, "version": VERSION, "tool": "gridshell",
            "tool_version": __version__, "command": owner_of(owner), "argv": _context["argv"],
            "kind": kind,
            "created": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
            "files": {f: _record(directory / f) for f in files}, "dirs": subdirs,
            "outputs": outputs}


def write(directory: str | os.PathLike, manifest: dict[str, Any]) -> None:
    """Write ``manifest`` to ``directory/manifest.json`` atomically."""
    directory = Path(directory)
    fd, tmp = tempfile.mkstemp(prefix=f".{MANIFEST}.", suffix=".tmp", dir=directory)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            json.dump(manifest, f, indent=1)
            f.write("\n")
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, directory / MANIFEST)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _names(items: list[str], k: int = 3) -> str:
    more = f" and {len(items) - k} more" if len(items) > k else ""
    return ", ".join(items[:k]) + more


def refusal(path: str | os.PathLike, owner: str | None = None) -> str | None:
    """Why the directory ``path`` may not be replaced by an output of ``owner``
    (:func:`owner_of`), or None if it may (absent, empty, or this command's output with every
    file listed and unchanged). The reason is one line, naming the path and what to do."""
    path = Path(path)
    owner = owner_of(owner)
    fix = "choose another output directory (nothing was changed)"
    if path.is_symlink():
        return f"{path} is a symbolic link; gridshell never replaces one - {fix}"
    if not path.exists():
        return None
    if not path.is_dir():
        return f"{path} exists and is not a directory; {fix}"
    try:
        empty = not any(path.iterdir())
    except OSError as exc:
        return f"cannot read {path} ({exc.strerror or exc}); {fix}"
    if empty:
        return None
    m = read(path)
    if m is None:
        held = _names(sorted(p.name + ("/" if p.is_dir() else "") for p in path.iterdir()))
        return (f"{path} is not the output of an earlier run of 'gridshell {owner}' (it holds "
                f"{held} and no gridshell {MANIFEST}); {fix}")
    if m["command"] != owner:
        return (f"{path} is not the output of an earlier run of 'gridshell {owner}' but of "
                f"'gridshell {m['command']}'; {fix}")
    return _foreign(path, m, fix)


def _foreign(path: Path, m: dict, fix: str) -> str | None:
    """Why ``path`` holds something its manifest ``m`` does not account for, or None."""
    try:
        files, outputs, links, subdirs = _walk(path)
    except OSError as exc:
        return f"cannot read {path} ({exc.strerror or exc}); {fix}"
    listed = m["files"]
    foreign = [f for f in files if f not in listed] + links
    foreign += [o for o in outputs if o not in m["outputs"]]
    foreign += [d + "/" for d in subdirs if d not in m.get("dirs", ())]
    if foreign:
        return (f"{path} holds files gridshell did not write ({_names(foreign)}); {fix} or "
                "move them out")
    changed = []
    for f in files:
        rec = listed[f]
        try:
            if not isinstance(rec, dict) or (path / f).stat().st_size != rec.get("size") \
                    or _sha256(path / f) != rec.get("sha256"):
                changed.append(f)
        except OSError:
            changed.append(f)
    if changed:
        return f"{path}: {_names(changed)} changed after gridshell wrote it; {fix} or move it out"
    for o in outputs:
        sub = read(path / o)
        why = _foreign(path / o, sub, fix) if sub is not None else f"{path / o} is unreadable"
        if why:
            return why
    return None


def _holder(path: Path) -> tuple[Path, dict] | None:
    """The nearest ancestor of ``path`` (within :data:`_REGISTER_DEPTH`) with a manifest, and
    the manifest; None if there is none or a temporary directory comes first."""
    d = path.parent
    for _ in range(_REGISTER_DEPTH):
        if is_temporary(d):
            return None
        m = read(d)
        if m is not None:
            return d, m
        if d.parent == d:
            return None
        d = d.parent
    return None


def register(path: str | os.PathLike, output: bool = False) -> None:
    """Add the file ``path`` just written (or, with ``output``, the output directory) to the
    manifest of the output directory it lies in, if any; a file already listed gets its new
    size and hash. Best effort: a manifest that cannot be rewritten is left as it was (the
    directory then cannot be replaced, which is the safe side)."""
    path = Path(path)
    if path.name == MANIFEST:
        return
    found = _holder(path)
    if found is None:
        return
    d, m = found
    try:
        rel = path.relative_to(d).as_posix()
        if output:
            if rel not in m["outputs"]:
                m["outputs"].append(rel)
        else:
            m["files"][rel] = _record(path)
        dirs = m.setdefault("dirs", [])
        for p in Path(rel).parents:
            if str(p) != "." and p.as_posix() not in dirs:
                dirs.append(p.as_posix())
        write(d, m)
    except (OSError, ValueError):
        pass
