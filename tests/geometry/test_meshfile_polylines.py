"""gridshell.geometry.meshfile.read_polylines: the vectorized reading of plain polyline OBJ files gives
the arrays the line-by-line parser gives, and hands everything else to that parser."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from gridshell.core.errors import MeshError
from gridshell.geometry.meshfile import (_decode, _parse_obj, _parse_polylines_fast, read_polylines,
                                write_polylines)


def _slow(path: Path) -> list[np.ndarray]:
    V, _, lines = _parse_obj(path, _decode(path))
    return [V[np.asarray(i, np.int64)] for i in lines]


def _same(a: list[np.ndarray], b: list[np.ndarray]) -> None:
    assert len(a) == len(b)
    for x, y in zip(a, b):
        assert x.dtype == y.dtype and x.shape == y.shape
        np.testing.assert_array_equal(x, y)


def test_written_polylines_read_back_as_the_line_parser_reads_them(tmp_path):
    """write_polylines' files (40 polylines of random lengths and full-precision coordinates,
    one of a single segment) take the fast path and read back bit for bit."""
    rng = np.random.default_rng(7)
    polys = [rng.normal(size=(int(k), 3)) * 10.0 ** rng.integers(-6, 4)
             for k in rng.integers(2, 400, 40)]
    polys[3] = polys[3][:2]
    write_polylines(tmp_path / "a.obj", polys)
    assert _parse_polylines_fast((tmp_path / "a.obj").read_bytes()) is not None
    back = read_polylines(tmp_path / "a.obj")
    _same(back, _slow(tmp_path / "a.obj"))
    _same(back, polys)


@pytest.mark.parametrize("text", [
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nl 1 2 3\nl -1 -2\n",            # relative indices
    "v 0 0 0\nv 1 0 0\nvt 0 0\nl 1/1 2/1\n",                      # other records, i/t
    "v 0 0 0 1\nv 1 0 0 1\nl 1 2\n",                              # weighted vertices
    "v 0 0 0\nv 1 0 0\nl\nl 1 2\n",                               # an empty l record
    "v 0 0 0\nv 0x1p3 0 0\nl 1 2\n",                              # a hex number
    "v 0 0 0\nv 1 0 0\nf 1 2 2\nl 1 2\n",                         # a face
])
def test_other_files_take_the_line_parser(tmp_path, text):
    (tmp_path / "b.obj").write_text(text)
    assert _parse_polylines_fast(text.encode()) is None
    try:
        want = _slow(tmp_path / "b.obj")
    except MeshError as e:
        with pytest.raises(MeshError, match=str(e)[:20]):
            read_polylines(tmp_path / "b.obj")
        return
    _same(read_polylines(tmp_path / "b.obj"), want)


@pytest.mark.parametrize("text, match", [
    ("v 0 0 0\nv 1 0 0\nl 1 3\n", "missing vertices"),
    ("v 0 0 0\nv 1 0 0\nl 1 0\n", "missing vertices"),
    ("v 0 0 0\nv 1 0 nan\nl 1 2\n", "NaN or infinite"),
    ("v 0 0 0\nv 1 0 abc\nl 1 2\n", "non-number"),
    ("v 0 0 0\nv 1 0 0\nq 1 2\nl 1 2\n", "not a valid OBJ record"),
])
def test_bad_files_are_refused_as_before(tmp_path, text, match):
    (tmp_path / "c.obj").write_text(text)
    with pytest.raises(MeshError, match=match):
        read_polylines(tmp_path / "c.obj")


def test_comments_groups_and_crlf(tmp_path):
    text = "# axes\r\no axes\r\nv 0 0 0\r\nv 1 2 3\r\n  v 4 5 6\r\ng a\r\nl 1 2 3\r\nl 3 1\r\n"
    (tmp_path / "d.obj").write_bytes(text.encode())
    assert _parse_polylines_fast(text.encode()) is not None
    _same(read_polylines(tmp_path / "d.obj"), _slow(tmp_path / "d.obj"))
    _same(read_polylines(tmp_path / "d.obj"),
          [np.array([[0.0, 0, 0], [1, 2, 3], [4, 5, 6]]), np.array([[4.0, 5, 6], [0, 0, 0]])])
