"""gridshell.geometry.meshfile._parse_plain: OBJ files laid out as the tool writes them are read with
numpy on the bytes, giving bit for bit the arrays the line-by-line parser (and the regex
parsers) give; every other file goes to those parsers, which read it or name its problem as
before."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from gridshell.core.errors import MeshError
from gridshell.geometry.meshfile import (_decode, _parse_obj, _parse_obj_fast, _parse_obj_regex,
                                _parse_plain, _parse_polylines_fast, _parse_polylines_regex,
                                read_configuration, read_mesh, read_polylines, write_mesh,
                                write_polylines)
from gridshell.geometry.quadmesh import _as_padded

ROOT = Path(__file__).resolve().parents[2]


def _slow_mesh(path: Path):
    V, faces, _ = _parse_obj(path, _decode(path))
    P, sizes = _as_padded(faces)
    return V, P, sizes


def _same_arrays(a, b) -> None:
    assert len(a) == len(b)
    for x, y in zip(a, b):
        x, y = np.asarray(x), np.asarray(y)
        assert x.dtype == y.dtype and x.shape == y.shape
        np.testing.assert_array_equal(x, y)


def _bits(x: np.ndarray) -> bytes:
    return np.ascontiguousarray(x, np.float64).tobytes()


@pytest.mark.parametrize("path", sorted(ROOT.glob("samples/*.obj")) +
                         sorted(ROOT.glob("gridshell/data/*.obj")), ids=lambda p: p.name)
def test_shipped_obj_files_read_as_the_line_parser_reads_them(path):
    data = path.read_bytes()
    fast = _parse_obj_fast(data)
    assert fast is not None
    slow = _slow_mesh(path)
    _same_arrays(fast, slow)
    assert _bits(fast[0]) == _bits(slow[0])       # -0.0 and all: the same bits


def test_written_meshes_take_the_plain_path_bit_for_bit(tmp_path):
    """write_mesh's quads and triangles (full-precision coordinates over many magnitudes, a
    signed zero) and write_polylines' axes: the plain path, the same bits as the parsers."""
    rng = np.random.default_rng(3)
    V = rng.normal(size=(500, 3)) * 10.0 ** rng.integers(-9, 5, size=(500, 1))
    V[0, 0] = -0.0
    quads = rng.integers(0, 500, size=(300, 4))
    tris = rng.integers(0, 500, size=(300, 3))
    for name, F in (("q.obj", quads), ("t.obj", tris)):
        (tmp_path / name).write_text(f"# {len(V)} vertices\n" +
                                     "".join(f"v {x!r} {y!r} {z!r}\n" for x, y, z in V.tolist()) +
                                     "".join("f " + " ".join(str(i + 1) for i in f) + "\n"
                                             for f in F.tolist()))
        data = (tmp_path / name).read_bytes()
        assert _parse_plain(data, b"f") is not None
        fast, slow = _parse_obj_fast(data), _slow_mesh(tmp_path / name)
        _same_arrays(fast, slow)
        assert _bits(fast[0]) == _bits(V) == _bits(slow[0])
    grid = np.stack(np.meshgrid(np.arange(6.0), np.arange(5.0), indexing="ij"), -1).reshape(-1, 2)
    Vg = np.column_stack([grid, 0.1 * np.sin(grid[:, 0])])
    Fg = np.array([[i * 5 + j, (i + 1) * 5 + j, (i + 1) * 5 + j + 1, i * 5 + j + 1]
                   for i in range(5) for j in range(4)])
    write_mesh(tmp_path / "s.obj", Vg, Fg)
    m = read_mesh(tmp_path / "s.obj")
    assert _bits(m.V) == _bits(Vg) and np.array_equal(m.F, Fg)
    polys = [rng.normal(size=(int(k), 3)) for k in rng.integers(2, 50, 12)]
    write_polylines(tmp_path / "a.obj", polys)
    data = (tmp_path / "a.obj").read_bytes()
    assert _parse_plain(data, b"l") is not None
    back = read_polylines(tmp_path / "a.obj")
    V2, _, lines = _parse_obj(tmp_path / "a.obj", _decode(tmp_path / "a.obj"))
    _same_arrays(back, [V2[np.asarray(i, np.int64)] for i in lines])
    _same_arrays(back, polys)


def test_mixed_face_sizes_and_crlf_tabs(tmp_path):
    text = ("# mixed\r\n\r\nv\t0 0 0\r\nv 1 0 0\r\nv 1 1 0\r\nv 0 1 0\r\nv 2 0.5 1e-3\r\n"
            "# faces\r\nf 1 2 3 4\r\nf 2\t5 3\r\n")
    (tmp_path / "m.obj").write_bytes(text.encode())
    assert _parse_plain(text.encode(), b"f") is not None
    fast = _parse_obj_fast(text.encode())
    _same_arrays(fast, _slow_mesh(tmp_path / "m.obj"))
    assert fast[1].tolist() == [[0, 1, 2, 3], [1, 4, 2, -1]] and fast[2].tolist() == [4, 3]


@pytest.mark.parametrize("text", [
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nf -3 -2 -1\n",                     # relative indices
    "v 0 0 0 1 0 0\nv 1 0 0 1 0 0\nv 1 1 0 1 0 0\nf 1 2 3\n",      # 'v' with colours
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1/1 2/2 3/3\n",                  # i/t indices
    "  v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n",                      # indented
    "v 0 0 0\nv 1 0 0\n# c\nv 1 1 0\nf 1 2 3\n",                   # records split
    "v 0 0 0\nv 1 0 0\nf 1 2 3\nv 1 1 0\n",                        # interleaved
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nvn 0 0 1\nf 1 2 3\n",              # other records
    "v 0 0 0\nv 1 0 0\nv 1 1 0\no a\nf 1 2 3\n",                   # an object name
    "v 0 0 0\nv 0x1p3 0 0\nv 1 1 0\nf 1 2 3\n",                    # hex
    "v 0 0 0\nv 1_0 0 0\nv 1 1 0\nf 1 2 3\n",                      # float() reads 1_0
    "v 0 0 0\nv 1-2 0 0\nv 1 1 0\nf 1 2 3\n",                      # not a number
    "v 0 0 0\nv inf 0 0\nv 1 1 0\nf 1 2 3\n",                      # infinite
    "v 0 0 0\nv nan 0 0\nv 1 1 0\nf 1 2 3\n",
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 0\n",                        # index 0
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 99999999999999999999\n",     # beyond int64
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 +3\n",                       # a signed index
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nf\nf 1 2 3\n",                     # an empty face
    "v 0 0 0\rv 1 0 0\rv 1 1 0\rf 1 2 3\r",                         # CR line ends
    "v 0 0 0\nv 1 0\r0\nv 1 1 0\nf 1 2 3\n",                       # a lone CR in a record
    "# a\x0cv 5 5 5\nv 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n",         # form feed in a comment
    "# caf\u00e9\nv 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n",            # non-ASCII comment
    "v 0 0 0 # x\nv 1 0 0\nv 1 1 0\nf 1 2 3\n",                    # comment after a record
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3 # x\n",
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\nl 1 2\n",                 # a polyline in a mesh
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv\nf 1 2 3\n",                     # an empty vertex
    "\x00v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n",                    # binary
])
def test_other_files_read_as_before(tmp_path, text):
    """Not plain: the general parsers read the file as before (the regex parser, else the
    line parser): read_configuration gives their arrays or refuses the file as before."""
    data = text.encode("utf-8")
    assert _parse_plain(data, b"f") is None
    (tmp_path / "x.obj").write_bytes(data)
    try:
        want = _parse_obj_regex(data) or _slow_mesh(tmp_path / "x.obj")
        V, P, sizes = want
        if len(P) and (P.max() >= len(V) or not np.all(np.isfinite(V))):
            raise MeshError("out of range or not finite")
    except (MeshError, OverflowError):   # an index beyond int64: the line parser's
        with pytest.raises((MeshError, OverflowError)):   # OverflowError or, as before, the
            # regex parser's MeshError naming the index
            read_configuration(tmp_path / "x.obj")
        return
    _same_arrays(read_configuration(tmp_path / "x.obj"), want)


@pytest.mark.parametrize("text", [
    "v 0 0 0\nv 1 0 0\nl -2 -1\n",
    "v 0 0 0\nv 1 0 0\ng a\nl 1 2\n",
    "v 0 0 0\nv 1 0 0\nl 1 2\nf 1 2 1\n",
])
def test_other_polyline_files_are_not_plain(text):
    assert _parse_plain(text.encode(), b"l") is None


def test_records_of_other_sizes_are_not_plain_even_when_the_counts_add_up():
    """Four numbers, three, two: nine numbers for three vertices, but the line parser refuses
    the third record; the plain path counts each record's tokens."""
    assert _parse_plain(b"v 0 0 0 1\nv 1 0 0\nv 1 1\nf 1 2 3\n", b"f") is None


def test_plain_polylines_match_the_line_parser(tmp_path):
    text = "# axes\r\nv 0 0 0\r\nv 1 2 3\r\nv 4 5 6\r\n\r\nl 1 2 3\r\nl\t3 1\r\nl 2\r\n"
    (tmp_path / "d.obj").write_bytes(text.encode())
    assert _parse_plain(text.encode(), b"l") is not None
    V, lines = _parse_polylines_fast(text.encode())
    V2, _, lines2 = _parse_obj(tmp_path / "d.obj", _decode(tmp_path / "d.obj"))
    _same_arrays([V], [V2])
    _same_arrays(lines, [np.asarray(i, np.int64) for i in lines2])
    regex = _parse_polylines_regex(text.encode())
    _same_arrays([regex[0]], [V])
    _same_arrays(regex[1], lines)


@pytest.mark.parametrize("text, match", [
    ("v 0 0 0\nv 1 0 0\nv 2 0 0\nl 1 2\nl 2 4\n", "polyline 1 refers to missing vertices"),
    ("v 0 0 0\nv 1 0 0\nv 2e9 0 0\nl 1 2\nl 2 3\n", "polyline 1 point 1"),
    ("v 0 0 0\nv 1 0 0\nv 2e9 0 0\nl 3 2\nl 2 4\n", "polyline 0 point 0"),
])
def test_plain_polylines_checked_at_once_name_the_first_problem(tmp_path, text, match):
    """read_polylines accepts the polylines of a plain file in one check; a file that fails
    it is checked polyline by polyline, which names the first problem as before."""
    (tmp_path / "p.obj").write_text(text)
    assert _parse_plain(text.encode(), b"l") is not None
    with pytest.raises(MeshError, match=match):
        read_polylines(tmp_path / "p.obj")


def test_polylines_are_their_own_arrays(tmp_path):
    write_polylines(tmp_path / "a.obj", [np.eye(3), np.ones((2, 3))])
    a, b = read_polylines(tmp_path / "a.obj")
    assert a.flags.owndata and b.flags.owndata and a.flags.writeable
    a[0, 0] = 7.0
    assert b[0, 0] == 1.0


def test_bbox_diagonal_column_by_column_is_the_rows_reduction():
    from gridshell.geometry.quadmesh import bbox_diagonal

    rng = np.random.default_rng(0)
    for V in (rng.normal(size=(1000, 3)) * 1e3, rng.normal(size=(5, 2)), np.zeros((1, 3)),
              np.array([[np.nan, 0.0, 0.0], [1.0, 2.0, 3.0]])):
        want = float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))
        got = bbox_diagonal(V)
        assert got == want or (np.isnan(got) and np.isnan(want))


@pytest.mark.parametrize("kind", ["f", "l"])
def test_records_whose_counts_add_up_are_refused_by_every_path(tmp_path, kind):
    """``v 0 0 0 1`` then ``v 1 1``: six numbers for two vertices. Read as one stream of
    numbers (the vectorized parser once did) the 1 of the first record became the second
    vertex's x, silently; every path now refuses it and the line parser names the record."""
    from gridshell.geometry.meshfile import read_mesh, read_polylines

    text = f"v 0 0 0 1\nv 1 1\nv 0 1 0\nv 1 1 0\n{kind} 1 2 3\n"
    (tmp_path / "odd.obj").write_text(text)
    assert _parse_plain(text.encode(), kind.encode()) is None
    regex = _parse_obj_regex if kind == "f" else _parse_polylines_regex
    assert regex(text.encode()) is None
    with pytest.raises(MeshError, match="line 2 .*'v 1 1'"):
        (read_mesh if kind == "f" else read_polylines)(tmp_path / "odd.obj")


def test_a_polyline_index_past_int64_is_a_missing_vertex(tmp_path):
    """The line parser's indices are Python ints: one past int64 was a bare OverflowError."""
    from gridshell.geometry.meshfile import read_polylines

    (tmp_path / "big.obj").write_text("v 0 0 0\nv 1 0 0\nvn 0 0 1\nl 1 99999999999999999999999\n")
    with pytest.raises(MeshError, match="polyline 0 refers to missing vertices"):
        read_polylines(tmp_path / "big.obj")
