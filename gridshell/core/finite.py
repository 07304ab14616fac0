"""Finite or nothing: the last check of every output file before it appears.

The readers validate what goes in (finite, counts consistent, with a message naming the file
and the field); this module is the safety net on the way out. :func:`problem` finds a
non-finite number in a written file by its format:

- ``.json``: parsed strictly (``NaN``, ``Infinity`` are not JSON);
- ``.npy``: loaded without pickles, every float finite;
- text geometry and tables (``.obj .ply .off .csv .svg .dxf``): no ``nan`` / ``inf`` token
  (``repr`` and ``%g`` of a non-finite float), case-insensitive, as a whole word.

The atomic writers (:mod:`gridshell.core.atomic`) call :func:`check` before a file or directory is
renamed into place, so a non-finite number never reaches an output: the write fails with
:class:`~gridshell.core.errors.GridshellError` (a bug of the caller) and nothing is written.
"""
from __future__ import annotations

import io
import json
import os
import re
from pathlib import Path

import numpy as np

__all__ = ["TEXT_FORMATS", "check", "check_tree", "problem"]

#: text formats scanned for ``nan`` / ``inf`` tokens
TEXT_FORMATS = (".obj", ".ply", ".off", ".csv", ".svg", ".dxf")
_TOKEN = re.compile(rb"(?<![A-Za-z0-9_])[-+]?(nan|inf|infinity)(?![A-Za-z0-9_])", re.I)


def _bad_constant(name: str) -> float:
    raise ValueError(name)


def problem(path: str | os.PathLike, data: bytes | None = None) -> str | None:
    """Where the file ``path`` (or its content ``data``) holds a non-finite number, or None."""
    path = Path(path)
    ext = path.suffix.lower()
    if ext not in TEXT_FORMATS + (".json", ".npy"):
        return None
    if data is None:
        data = path.read_bytes()
    if ext == ".json":
        try:
            json.loads(data.decode("utf-8"), parse_constant=_bad_constant)
        except ValueError as exc:
            return f"a non-finite number ({exc})" if str(exc) in (
                "NaN", "Infinity", "-Infinity") else None
        return None
    if ext == ".npy":
        try:
            a = np.load(io.BytesIO(data), allow_pickle=False)
        except (ValueError, OSError, EOFError):
            return None  # not ours to judge: the reader reports a malformed array
        if a.dtype.kind in "fc" and not np.all(np.isfinite(a)):
            return f"{int((~np.isfinite(a)).sum())} non-finite values"
        return None
    low = data.lower()           # every match holds "nan" or "inf": skip the slow scan
    if b"nan" not in low and b"inf" not in low:
        return None
    m = _TOKEN.search(data)
    if m is None:
        return None
    line = data.count(b"\n", 0, m.start()) + 1
    return f"'{m.group(0).decode(errors='replace')}' at line {line}"


def check(path: str | os.PathLike, name: str | None = None) -> None:
    """:class:`GridshellError` if the file ``path`` holds a non-finite number (:func:`problem`);
    ``name``: how to call it in the message (default its file name)."""
    why = problem(path)
    if why:
        from gridshell.core.errors import GridshellError

        raise GridshellError(f"refusing to write {name or Path(path).name}: it would hold {why}; "
                             "this is a bug, please report it")


def check_tree(directory: str | os.PathLike) -> None:
    """:func:`check` every file under ``directory`` (named relative to it)."""
    directory = Path(directory)
    for root, _, names in os.walk(directory):
        for n in names:
            p = Path(root) / n
            if not p.is_symlink():
                check(p, p.relative_to(directory).as_posix())
