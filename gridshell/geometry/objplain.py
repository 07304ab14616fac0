"""The OBJ files the tool writes, read with numpy on the bytes (:func:`parse_plain`), for
:mod:`gridshell.geometry.meshfile`: comment or blank lines, one run of ``v x y z`` records and one run
of ``f`` or ``l`` records of positive indices, as :func:`gridshell.geometry.meshfile.write_mesh` and
:func:`~gridshell.geometry.meshfile.write_polylines` write them (coordinates in the file's units,
metres by convention). Any other file is left to :mod:`gridshell.geometry.meshfile`'s parsers.
"""
from __future__ import annotations

import warnings

import numpy as np

__all__ = ["parse_plain"]

#: what the numbers of plain ``v`` records hold (no hex, inf, nan, underscores)
_VCHARS = b"0123456789.eE+- \t\r\nv"
_ICHARS = b"0123456789 \t\r\n"


def _tokens_per_line(block: bytes, starts: np.ndarray) -> np.ndarray:
    """How many whitespace-separated tokens each line of ``block`` holds (``starts``, the
    offsets of its consecutive lines; whitespace = space, tab, CR, LF: every byte up to the
    space in a plain file, :func:`parse_plain`)."""
    ws = np.frombuffer(block, np.uint8) <= 32
    first = ~ws
    first[1:] &= ws[:-1]
    return np.add.reduceat(first, starts, dtype=np.int64)


def parse_plain(data: bytes, tag: bytes) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """Vertices ``(n,3)``, the indices of the ``tag`` records (``b"f"`` or ``b"l"``) one after
    the other, 1-based ``(sum of sizes,) int64``, and their sizes ``(m,) int64`` of an OBJ laid
    out as the tool writes it: comment or blank lines, one run of ``v x y z`` records, one run
    of ``tag`` records of positive plain indices, each record at the start of its line.

    The same numbers as :func:`gridshell.geometry.meshfile._parse_obj` (and its regex parsers) read
    from such a file, found with numpy on the bytes (no line-by-line Python, no regular
    expression over every line): a line is a record or comment by its first two bytes, each
    record's tokens are counted (3 numbers after ``v``, at least one index after ``tag``),
    and ``np.fromstring`` must read the records' text to its end, one number per token (a
    number ``float`` reads: only digits, ``.``, ``e``, signs). None for any other file (other
    records, records split or interleaved, indented, colours, ``i/t/n`` or negative indices,
    other bytes, CR not followed by LF): the general parsers read it."""
    if not data or (b"\r" in data and data.count(b"\r") != data.count(b"\r\n")):
        return None
    a = np.frombuffer(data, np.uint8)
    nl = np.flatnonzero(a == 10)
    # printable ASCII, tab, LF, CR only: no byte another line splitting (form feed, vertical
    # tab, file separators, NEL, non-ASCII) or decoding could read otherwise
    if a.max() >= 0x7F or np.count_nonzero(a < 0x20) != \
            len(nl) + data.count(b"\t") + data.count(b"\r"):
        return None
    starts = np.concatenate([[0], nl + 1])
    ends = np.concatenate([nl, [len(a)]])
    if starts[-1] == len(a):                 # nothing after the last LF
        starts, ends = starts[:-1], ends[:-1]
    first = a[np.minimum(starts, len(a) - 1)]
    second = a[np.minimum(starts + 1, len(a) - 1)]
    length = ends - starts
    blank = (length == 0) | ((length == 1) & (first == 13))
    spaced = (length >= 2) & ((second == 32) | (second == 9))
    is_v = spaced & (first == ord("v"))
    is_e = spaced & (first == tag[0])
    if not np.all(blank | (first == ord("#")) | is_v | is_e):
        return None
    vi, ei = np.flatnonzero(is_v), np.flatnonzero(is_e)
    if not len(vi) or not len(ei) or vi[-1] - vi[0] != len(vi) - 1 \
            or ei[-1] - ei[0] != len(ei) - 1:
        return None
    v0, e0 = int(starts[vi[0]]), int(starts[ei[0]])
    vblock, eblock = data[v0:int(ends[vi[-1]])], data[e0:int(ends[ei[-1]])]
    vtext, etext = vblock.translate(None, b"v"), eblock.translate(None, tag)
    if len(vtext) != len(vblock) - len(vi) or len(etext) != len(eblock) - len(ei) \
            or vtext.translate(None, _VCHARS) or etext.translate(None, _ICHARS):
        return None
    if np.any(_tokens_per_line(vblock, starts[vi] - v0) != 4):
        return None
    sizes = _tokens_per_line(eblock, starts[ei] - e0) - 1
    if sizes.min() < 1:
        return None
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        try:  # the whole text, or None
            V = np.fromstring(vtext, dtype=np.float64, sep=" ")
            flat = np.fromstring(etext, dtype=np.int64, sep=" ")
        except (ValueError, Warning):
            return None
    if len(V) != 3 * len(vi) or not np.all(np.isfinite(V)) or len(flat) != int(sizes.sum()) \
            or flat.min() < 1 or flat.max() >= 10 ** 17:   # saturated: too many digits
        return None
    return V.reshape(-1, 3), flat, sizes
