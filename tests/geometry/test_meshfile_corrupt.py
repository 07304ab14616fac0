"""Mesh files cut short or with bytes changed: the OBJ, PLY and OFF readers give a valid mesh or
the tool's own input error (:class:`~gridshell.core.errors.GridshellError`), never another
exception. Seeded random truncations and byte corruptions of small valid files, read by
:func:`~gridshell.geometry.meshfile.read_mesh` and :func:`~gridshell.io.read.read_input` (the
entry of every design command), through the vectorized OBJ readers and the line parser alone;
and the two cases that once crashed (vertices without faces, a face index past the vertices),
whose message names the file and the line.
"""
from __future__ import annotations

import struct

import numpy as np
import pytest

from gridshell.core.errors import GridshellError
from gridshell.geometry import meshfile
from gridshell.geometry.grid import grid_quads
from gridshell.geometry.meshfile import read_mesh, read_polygons
from gridshell.io.read import read_input

N = 5  # a 5 x 5 grid: 25 vertices, 16 quads


def _grid():
    """A gently curved 5 x 5 grid, 1 m across: ``V (25,3)`` metres, ``F (16,4)``."""
    u, v = np.meshgrid(np.linspace(0, 1, N), np.linspace(0, 1, N), indexing="ij")
    V = np.stack([u, v, 0.1 * (u - 0.5) * (v - 0.5)], axis=-1).reshape(-1, 3)
    return V, grid_quads(N, N)


def _valid_files() -> dict[str, bytes]:
    """The grid as each format the readers take: OBJ (plain, as the tool writes it, and with
    comments, ``i//n`` corners and relative indices), ASCII OFF, ASCII and binary PLY."""
    V, F = _grid()
    vt = "".join(f"v {x!r} {y!r} {z!r}\n" for x, y, z in V.tolist())
    obj = vt + "".join("f " + " ".join(str(i + 1) for i in f) + "\n" for f in F)
    rel = "# grid\no g\n" + vt + "".join(
        "f " + " ".join(f"{i - len(V)}//1" for i in f) + "\n" for f in F)
    off = f"OFF\n{len(V)} {len(F)} 0\n" + vt.replace("v ", "") + "".join(
        "4 " + " ".join(map(str, f)) + "\n" for f in F)
    head = (f"ply\nformat {{}} 1.0\nelement vertex {len(V)}\nproperty double x\n"
            f"property double y\nproperty double z\nelement face {len(F)}\n"
            "property list uchar int vertex_indices\nend_header\n")
    ply = head.format("ascii") + vt.replace("v ", "") + "".join(
        "4 " + " ".join(map(str, f)) + "\n" for f in F)
    binary = head.format("binary_little_endian").encode() + V.astype("<f8").tobytes() + b"".join(
        struct.pack("<B4i", 4, *map(int, f)) for f in F)
    return {"plain.obj": obj.encode(), "rel.obj": rel.encode(), "m.off": off.encode(),
            "a.ply": ply.encode(), "b.ply": binary}


def _mutants(data: bytes, rng: np.random.Generator, n: int) -> list[bytes]:
    """``n`` damaged copies of ``data``: cut at a random byte, a few bytes replaced by random
    bytes or by digits, signs and separators (which keep a text file parseable), a line
    dropped or repeated, a word replaced by a random integer (a face index past the
    vertices, negative, zero)."""
    out = []
    for k in range(n):
        b = bytearray(data)
        kind = k % 5
        if kind == 4:
            words = bytes(b).split(b" ")
            words[int(rng.integers(0, len(words)))] = b"%d" % rng.integers(-40, 40)
            out.append(b" ".join(words))
            continue
        if kind == 0:
            b = b[:int(rng.integers(1, len(b)))]
        elif kind in (1, 2):
            alphabet = (np.arange(256, dtype=np.uint8) if kind == 1
                        else np.frombuffer(b"0123456789-+. \nfve/#", np.uint8))
            for pos in rng.integers(0, len(b), size=int(rng.integers(1, 5))):
                b[int(pos)] = int(rng.choice(alphabet))
        else:
            lines = bytes(b).split(b"\n")
            i = int(rng.integers(0, len(lines)))
            lines[i:i + 1] = [] if rng.random() < 0.5 else [lines[i], lines[i]]
            b = bytearray(b"\n".join(lines))
        out.append(bytes(b))
    return out


def _read_all(path) -> None:
    """Read ``path`` as the commands do; any exception but the tool's own escapes."""
    for read in (lambda: read_mesh(path), lambda: read_input(path, units="m", require_disk=False)):
        try:
            mesh = read()
        except GridshellError as exc:
            msg = str(exc)
            assert msg and "\n" not in msg and path.name in msg, msg
            continue
        V = mesh.V
        F = mesh.F
        assert np.all(np.isfinite(V)) and len(F) and F.min() >= 0 and F.max() < len(V)


READERS = [(n, False) for n in sorted(_valid_files())] + \
    [(n, True) for n in sorted(_valid_files()) if n.endswith(".obj")]


@pytest.mark.parametrize("name,line_parser", READERS,
                         ids=[n + ("-plain" if p else "") for n, p in READERS])
def test_damaged_files_give_a_mesh_or_the_tools_error(tmp_path, monkeypatch, name, line_parser):
    """40 damaged copies of each PLY and OFF file, 20 of each OBJ through the vectorized
    readers and 20 through the line parser alone: 200 cases."""
    if line_parser:
        monkeypatch.setattr(meshfile, "_parse_obj_fast", lambda data: None)
    data = _valid_files()[name]
    rng = np.random.default_rng(sum(name.encode()))
    for k, bad in enumerate(_mutants(data, rng, 20 if name.endswith(".obj") else 40)):
        path = tmp_path / f"{k}_{name}"
        path.write_bytes(bad)
        _read_all(path)


@pytest.mark.parametrize("name", sorted(_valid_files()))
def test_the_valid_files_read_as_the_grid(tmp_path, name):
    """The undamaged files: the grid's vertices and faces exactly."""
    V, F = _grid()
    path = tmp_path / name
    path.write_bytes(_valid_files()[name])
    mesh = read_mesh(path)
    assert np.array_equal(mesh.V, V) and np.array_equal(mesh.F, F)


def _obj_with(face_line: str) -> bytes:
    data = _valid_files()["plain.obj"].decode().splitlines()
    data[N * N + 3] = face_line            # the fourth face, line 29
    return ("\n".join(data) + "\n").encode()


@pytest.mark.parametrize("line_parser", [False, True], ids=["fast", "plain"])
@pytest.mark.parametrize("face", ["f 1 2 -99999 3", "f 1 2 99999 3", "f 1 2 26 3", "f 1 0 2 3",
                                  "f 1 2 -26 3", "f 1 2 99999999999999999999999 3"])
def test_a_face_index_past_the_vertices_names_the_line(tmp_path, monkeypatch, line_parser, face):
    if line_parser:
        monkeypatch.setattr(meshfile, "_parse_obj_fast", lambda data: None)
    path = tmp_path / "bad.obj"
    path.write_bytes(_obj_with(face))
    for read in (read_polygons, read_mesh):
        with pytest.raises(GridshellError) as exc:
            read(path)
        msg = str(exc.value)
        assert "bad.obj" in msg and "line 29" in msg and "\n" not in msg, msg


@pytest.mark.parametrize("line_parser", [False, True], ids=["fast", "plain"])
def test_vertices_without_faces_are_refused(tmp_path, monkeypatch, line_parser):
    if line_parser:
        monkeypatch.setattr(meshfile, "_parse_obj_fast", lambda data: None)
    path = tmp_path / "points.obj"
    V, _ = _grid()
    path.write_text("".join(f"v {x!r} {y!r} {z!r}\n" for x, y, z in V.tolist()))
    for read in (read_polygons, read_mesh, read_input):
        with pytest.raises(GridshellError, match=r"points\.obj: the mesh is empty, 25 vertices but "
                                                 r"no faces"):
            read(path)


def test_off_and_ply_faces_past_the_vertices_name_their_place(tmp_path):
    files = _valid_files()
    (tmp_path / "m.off").write_bytes(files["m.off"].replace(b"\n4 0 1 6 5\n", b"\n4 0 1 6 99\n"))
    (tmp_path / "a.ply").write_bytes(files["a.ply"].replace(b"\n4 0 1 6 5\n", b"\n4 0 1 6 -7\n"))
    b = files["b.ply"]
    (tmp_path / "b.ply").write_bytes(b[:len(b) - 17] + struct.pack("<B4i", 4, 0, 1, 2, 25))
    for name, place in [("m.off", "line 28"), ("a.ply", "line 35"), ("b.ply", "face record 16")]:
        with pytest.raises(GridshellError) as exc:
            read_polygons(tmp_path / name)
        assert name in str(exc.value) and place in str(exc.value), str(exc.value)
