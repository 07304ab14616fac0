"""Mesh files (OBJ, PLY, OFF): :func:`read_mesh`, :func:`write_mesh`, polylines.

Mesh files (OBJ, PLY, OFF) are parsed and written here with numpy rather than through
``openmesh.read_polymesh`` / ``openmesh.write_mesh``, because OpenMesh 1.2.1 (python bindings)
is unusable as a file layer for this project:

* its readers and writers go through single precision: a round trip loses ~3e-8 relative
  (OBJ is written with ``%f``, OFF with 6 significant digits, binary PLY as float32, and even a
  file holding doubles is read into float32);
* on bad input it repairs silently instead of failing: a face on a non-manifold edge gets
  fresh copies of its vertices (vertex count and indices change), a repeated index in a face
  is dropped (a quad becomes a triangle), an out-of-range face is skipped, a truncated vertex
  record is skipped; failures only go to stderr, and a missing/garbage file yields an empty mesh;
* a PLY file truncated inside its header makes ``read_polymesh`` loop forever.

Our writers emit ASCII with 17 significant digits (exact for float64); OpenMesh reads them.
"""
from __future__ import annotations

import os
import re
import warnings
from pathlib import Path
from typing import Callable, Sequence

import numpy as np

from gridshell.core.atomic import atomic_path
from gridshell.core.errors import MeshError
from gridshell.geometry.objplain import parse_plain as _parse_plain
from gridshell.geometry.quadmesh import (EXTENT_RANGE, MESH_FORMATS, QuadMesh, TriMesh, _as_padded, _face_edges,
                       _triangulate_padded, bbox_diagonal, validate_mesh)


def _check_readable(path: Path) -> str:
    """Extension (lower case) of a readable, non-empty mesh file, else :class:`MeshError`."""
    if not path.exists():
        raise MeshError(f"{path}: no such file; check the path")
    if not path.is_file():
        raise MeshError(f"{path}: not a file; give the path of an OBJ, PLY or OFF mesh")
    if not os.access(path, os.R_OK):
        raise MeshError(f"{path}: cannot read the file (permission denied); fix its permissions")
    ext = path.suffix.lower()
    if ext not in MESH_FORMATS:
        raise MeshError(f"{path.name}: unknown mesh format '{path.suffix}'; "
                        "give an .obj, .ply or .off file")
    if path.stat().st_size == 0:
        raise MeshError(f"{path.name}: the file is empty; export the mesh again")
    return ext


def _corrupt(path: Path, what: str) -> MeshError:
    return MeshError(f"{path.name}: {what}; the file is truncated or corrupt, export it again")


def _decode(path: Path) -> list[str]:
    data = path.read_bytes()
    if b"\x00" in data:
        raise _corrupt(path, f"not a text {path.suffix.upper()[1:]} file (binary bytes found)")
    try:
        return data.decode("utf-8").splitlines()
    except UnicodeDecodeError:
        return data.decode("latin-1").splitlines()


def _parse_obj(path: Path, lines: list[str]) -> tuple[np.ndarray, list[list[int]], list[list[int]]]:
    """Vertices, faces (0-based) and polylines (0-based) of OBJ ``lines``."""
    verts: list[list[str]] = []
    faces: list[list[int]] = []
    polylines: list[list[int]] = []
    where: list[str] = []  # each face's line, for messages
    known = {"vt", "vn", "vp", "o", "g", "s", "usemtl", "mtllib", "p", "#"}
    for lineno, raw in enumerate(lines, 1):
        t = raw.split()
        if not t or t[0].startswith("#"):
            continue
        tag = t[0]
        try:
            if tag == "v":
                if len(t) < 4:
                    raise ValueError
                verts.append(t[1:4])
            elif tag in ("f", "l"):
                idx = [int(s.split("/")[0]) for s in t[1:]]
                nv = len(verts)
                if tag == "f" and not idx:
                    raise ValueError
                idx = [i - 1 if i > 0 else nv + i for i in idx]  # negative = relative
                (faces if tag == "f" else polylines).append(idx)
                if tag == "f":
                    where.append(f"line {lineno} ({raw.strip()[:40]!r})")
            elif tag not in known:
                raise ValueError
        except ValueError:
            raise _corrupt(path, f"line {lineno} is not a valid OBJ record ({raw[:40]!r})") from None
    try:
        V = np.array(verts, dtype=float).reshape(-1, 3)
    except ValueError:
        raise _corrupt(path, "a vertex record holds a non-number") from None
    check_face_indices(path, faces, len(V), where.__getitem__)
    return V, faces, polylines


def check_face_indices(path: Path, faces: list[list[int]] | np.ndarray, n_vertices: int,
                       where: Callable[[int], str]) -> None:
    """:class:`MeshError` naming the first of ``faces`` (0-based vertex indices, lists or an
    ``(m,k)`` array) that refers to a vertex outside ``0 .. n_vertices - 1``: ``where(i)``
    is the place of face ``i`` in the file (``"line 12 ('f 1 2 9')"``, ``"face record 3"``)."""
    if isinstance(faces, np.ndarray):
        bad = np.flatnonzero(((faces < 0) | (faces >= n_vertices)).any(axis=1)) \
            if faces.size else np.zeros(0, np.int64)
        first = int(bad[0]) if len(bad) else None
    else:
        first = next((i for i, f in enumerate(faces)
                      if min(f) < 0 or max(f) >= n_vertices), None)
    if first is not None:
        raise _corrupt(path, f"{where(first)}: a face refers to a vertex outside 0 .. "
                       f"{n_vertices - 1} (the file holds {n_vertices} vertices, counted from 0)")


_OBJ_OTHER = re.compile(rb"^(?![ \t]*(?:v[ \t]|f[ \t]|vt[ \t]|vn[ \t]|#|o[ \t]|g[ \t]|s[ \t]|"
                        rb"usemtl[ \t]|mtllib[ \t]|\r?$))", re.M)


def _parse_obj_fast(data: bytes) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """Vertices, padded faces (0-based) and face sizes of an OBJ of ``v`` and ``f`` records,
    vectorized: :func:`_parse_plain` for the files the tool writes, else
    :func:`_parse_obj_regex`; None when neither reads it."""
    plain = _parse_plain(data, b"f")
    if plain is None:
        return _parse_obj_regex(data)
    V, flat, sizes = plain
    return V, _padded(flat, sizes), sizes


def _padded(flat: np.ndarray, sizes: np.ndarray) -> np.ndarray:
    """Faces ``(m, k) int64``, 0-based, of the 1-based indices ``flat`` of ``m`` faces of
    ``sizes`` corners one after the other; a face of fewer than ``k = max(sizes)`` corners
    padded with -1."""
    k = int(sizes.max())
    if np.all(sizes == k):
        return flat.reshape(-1, k) - 1
    P = np.full((len(sizes), k), -1, np.int64)
    P[np.repeat(np.arange(len(sizes)), sizes),
      np.arange(len(flat)) - np.repeat(np.cumsum(sizes) - sizes, sizes)] = flat - 1
    return P


def _xyz_records(vrec: list[bytes]) -> np.ndarray | None:
    """``(n,3)`` float of the ``v`` records' texts ``vrec``, each exactly three finite numbers;
    None otherwise (a record of 2 or 4 numbers: the numbers of all records read as one stream
    would shift into the next vertex). A NaN between records marks where each ends."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            R = np.fromstring(b" nan ".join(vrec) + b" nan", dtype=np.float64, sep=" ")
        except ValueError:
            return None
    if len(R) != 4 * len(vrec):
        return None
    R = R.reshape(-1, 4)
    if not (np.all(np.isnan(R[:, 3])) and np.all(np.isfinite(R[:, :3]))):
        return None
    return np.ascontiguousarray(R[:, :3])


def _parse_obj_regex(data: bytes) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """Vertices, padded faces (0-based) and face sizes of a plain OBJ (``v x y z`` and ``f``
    records with positive indices, optionally ``i/t/n``), vectorized: a 200k-triangle file in
    a fraction of a second. None for anything else (``l`` or ``p`` records, negative indices,
    other vertex records, malformed numbers): :func:`_parse_obj` then reads it, and names the
    problem."""
    if b"\x00" in data or _OBJ_OTHER.search(data):
        return None
    vrec = re.findall(rb"^[ \t]*v[ \t]+([^\n]*)", data, re.M)
    frec = re.findall(rb"^[ \t]*f[ \t]+([^\n]*)", data, re.M)
    if not vrec or not frec:
        return None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ftext = re.sub(rb"/[^ \t\r]*", b"", b" 0 ".join(frec))  # 0 separates faces
        if b"-" in ftext:
            return None
        try:  # malformed text: the line-by-line parser names it
            flat = np.fromstring(ftext, dtype=np.int64, sep=" ")
        except ValueError:
            return None
    V = _xyz_records(vrec)
    if V is None:
        return None
    cuts = np.flatnonzero(flat == 0)
    if len(cuts) != len(frec) - 1:
        return None
    starts = np.concatenate([[0], cuts + 1])
    ends = np.concatenate([cuts, [len(flat)]])
    sizes = ends - starts
    if len(sizes) == 0 or sizes.min() < 1:
        return None
    return V, _padded(flat[flat != 0], sizes), sizes


_POLY_OTHER = re.compile(rb"^(?![ \t]*(?:v[ \t]|l[ \t]|#|o[ \t]|g[ \t]|\r?$))", re.M)


def _parse_polylines_fast(data: bytes) -> tuple[np.ndarray, list[np.ndarray]] | None:
    """Vertices ``(n,3)`` and polylines (0-based ``int64`` index arrays, file order) of a
    polyline OBJ, vectorized: :func:`_parse_plain` for the files the tool writes, else
    :func:`_parse_polylines_regex`; None when neither reads it."""
    plain = _parse_plain(data, b"l")
    if plain is None:
        return _parse_polylines_regex(data)
    V, flat, sizes = plain
    return V, np.split(flat - 1, np.cumsum(sizes)[:-1])


def _parse_polylines_regex(data: bytes) -> tuple[np.ndarray, list[np.ndarray]] | None:
    """Vertices ``(n,3)`` and polylines (0-based ``int64`` index arrays, file order) of a
    plain polyline OBJ (``v x y z`` and ``l`` records with positive indices, comments,
    ``o`` / ``g``), vectorized: the same arrays as :func:`_parse_obj` gives, without its
    ~10 Python objects per line (the 4x axes, 7.9k lines: ~0.15 s in a process whose heap is
    large, most of it garbage collection). None for anything else (other records, negative or
    ``i/t`` indices, an empty ``l``, hex or malformed numbers): :func:`_parse_obj` then reads
    it and names the problem."""
    if b"\x00" in data or _POLY_OTHER.search(data):
        return None
    vrec = re.findall(rb"^[ \t]*v[ \t]+([^\n]*)", data, re.M)
    lrec = re.findall(rb"^[ \t]*l[ \t]+([^\n]*)", data, re.M)
    if not lrec:
        return None
    vtext, ltext = b" ".join(vrec), b" 0 ".join(lrec)      # 0 separates the polylines
    if b"-" in ltext or b"/" in ltext or b"x" in vtext or b"X" in vtext:
        return None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:  # malformed text: the line-by-line parser names it
            flat = np.fromstring(ltext, dtype=np.int64, sep=" ")
        except ValueError:
            return None
    V = _xyz_records(vrec) if vrec else np.zeros((0, 3))
    if V is None:
        return None
    cuts = np.flatnonzero(flat == 0)
    if len(cuts) != len(lrec) - 1 or np.any(np.diff(np.r_[-1, cuts, len(flat)]) < 2):
        return None
    parts = np.split(flat - 1, cuts)            # each after the first opens with the 0
    return V, [parts[0]] + [p[1:] for p in parts[1:]]


def _parse_off(path: Path, lines: list[str]) -> tuple[np.ndarray, list[list[int]]]:
    numbered = [(n, ln.split("#")[0].split()) for n, ln in enumerate(lines, 1)]
    numbered = [(n, t) for n, t in numbered if t]
    body = [t for _, t in numbered]
    if not body or not body[0][0].upper().endswith("OFF"):
        raise _corrupt(path, "no OFF header")
    head = body[0][1:] if len(body[0]) > 1 else (body[1] if len(body) > 1 else [])
    rest = body[1:] if len(body[0]) > 1 else body[2:]
    try:
        nv, nf = int(head[0]), int(head[1])
    except (IndexError, ValueError):
        raise _corrupt(path, "the OFF header has no vertex and face counts") from None
    if nv < 0 or nf < 0:
        raise _corrupt(path, f"the OFF header announces {nv} vertices and {nf} faces")
    if len(rest) < nv + nf:
        raise _corrupt(path, f"the header announces {nv} vertices and {nf} faces but the file "
                       f"holds {len(rest)} records")
    try:
        V = np.array([r[:3] for r in rest[:nv]], dtype=float).reshape(-1, 3)
        faces = []
        for r in rest[nv:nv + nf]:
            k = int(r[0])
            if k < 1 or len(r) < k + 1:
                raise ValueError
            faces.append([int(s) for s in r[1:k + 1]])
    except ValueError:
        raise _corrupt(path, "a vertex or face record is incomplete or not numeric") from None
    first = len(numbered) - len(rest) + nv  # the first face record's place in ``numbered``
    check_face_indices(path, faces, len(V), lambda i: f"line {numbered[first + i][0]}")
    return V, faces


_PLY_TYPES = {"char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2",
              "int16": "i2", "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4",
              "uint": "u4", "uint32": "u4", "float": "f4", "float32": "f4", "double": "f8",
              "float64": "f8"}


def _parse_ply(path: Path) -> tuple[np.ndarray, list[list[int]] | np.ndarray]:
    """Vertices and faces (0-based, checked against the vertices) of an ASCII or binary PLY."""
    fmt, elements, body, line0 = _ply_header(path, path.read_bytes())
    if fmt == "ascii":
        V, faces, where = _ply_ascii(path, body, elements, line0)
    else:
        V, faces = _ply_binary(path, body, elements, "<" if fmt == "binary_little_endian" else ">")
        where = lambda i: f"face record {i + 1}"  # noqa: E731
    if V is not None:
        check_face_indices(path, faces, len(V), where)
    return V, faces


def _ply_header(path: Path, data: bytes) -> tuple[str, list, bytes, int]:
    """Format, elements ``[name, count, [(prop, type, list_type | None)]]``, the body's bytes
    and the line number of its first line, of a PLY file's ``data``."""
    end = data.find(b"end_header")
    if not data.startswith(b"ply") or end < 0:
        raise _corrupt(path, "no complete PLY header")
    nl = data.find(b"\n", end)
    header = data[:end].decode("ascii", errors="replace").splitlines()
    body = data[nl + 1:] if nl >= 0 else b""
    fmt, elements = None, []
    try:
        for ln in header[1:]:
            t = ln.split()
            if not t or t[0] in ("comment", "obj_info"):
                continue
            if t[0] == "format":
                fmt = t[1]
            elif t[0] == "element":
                elements.append([t[1], int(t[2]), []])
                if elements[-1][1] < 0:
                    raise ValueError
            elif t[0] == "property":
                if t[1] == "list":
                    elements[-1][2].append((t[4], _PLY_TYPES[t[3]], _PLY_TYPES[t[2]]))
                else:
                    elements[-1][2].append((t[2], _PLY_TYPES[t[1]], None))
    except (IndexError, KeyError, ValueError):
        raise _corrupt(path, "the PLY header is malformed") from None
    if fmt not in ("ascii", "binary_little_endian", "binary_big_endian"):
        raise _corrupt(path, f"unknown PLY format {fmt!r}")
    names = [e[0] for e in elements]
    if "vertex" not in names or "face" not in names:
        raise _corrupt(path, "the PLY file has no vertex or no face element")
    return fmt, elements, body, len(header) + 2


def _ply_ascii(path: Path, body: bytes, elements: list, line0: int
               ) -> tuple[np.ndarray | None, list[list[int]], Callable[[int], str]]:
    """Vertices, faces and the place of each face (``where(i)``, its line) of an ASCII PLY
    body whose first line is line ``line0`` of the file."""
    rows = [(n, ln.split()) for n, ln in
            enumerate(body.decode("ascii", errors="replace").splitlines(), line0)]
    rows = [(n, r) for n, r in rows if r]
    V, faces, face_pos, pos = None, [], 0, 0
    for name, count, props in elements:
        chunk = [r for _, r in rows[pos:pos + count]]
        if len(chunk) < count:
            raise _corrupt(path, f"the {name} element announces {count} records, "
                           f"found {len(chunk)}")
        try:
            if name == "vertex":
                col = {p[0]: i for i, p in enumerate(props)}
                V = np.array([[r[col["x"]], r[col["y"]], r[col["z"]]] for r in chunk],
                             dtype=float).reshape(-1, 3)
            elif name == "face":
                faces, face_pos = [[int(s) for s in r[1:1 + int(r[0])]] for r in chunk], pos
                if any(int(r[0]) < 1 or len(f) != int(r[0]) for f, r in zip(faces, chunk)):
                    raise ValueError
        except (KeyError, ValueError, IndexError):
            raise _corrupt(path, f"a {name} record is incomplete or not numeric") from None
        pos += count
    return V, faces, lambda i: f"line {rows[face_pos + i][0]}"


def _ply_binary(path: Path, body: bytes, elements: list, bo: str
                ) -> tuple[np.ndarray | None, list[list[int]] | np.ndarray]:
    """Vertices and faces of a binary PLY body of byte order ``bo`` (``"<"`` or ``">"``)."""
    V, faces, off = None, [], 0
    for name, count, props in elements:
        if any(p[2] is not None for p in props):
            if name != "face" or len(props) != 1:
                raise MeshError(f"{path.name}: PLY element '{name}' with list properties is not "
                                "supported; export vertices and faces only")
            _, itype, ctype = props[0]
            faces, off = _ply_binary_lists(path, body, off, count, bo + ctype, bo + itype)
            continue
        try:
            dt = np.dtype([(p[0], bo + p[1]) for p in props])
        except ValueError:  # two properties of one name
            raise _corrupt(path, f"the PLY {name} element's properties are malformed") from None
        need = dt.itemsize * count
        if len(body) - off < need:
            raise _corrupt(path, f"the {name} element is cut short")
        arr = np.frombuffer(body, dtype=dt, count=count, offset=off)
        off += need
        if name == "vertex":
            try:
                V = np.stack([arr["x"], arr["y"], arr["z"]], axis=1).astype(float)
            except (KeyError, ValueError):
                raise _corrupt(path, "the PLY vertices have no x, y, z") from None
    return V, faces


def _ply_binary_lists(path: Path, body: bytes, off: int, count: int, ctype: str,
                      itype: str) -> tuple[np.ndarray | list[list[int]], int]:
    """Binary PLY face lists: vectorized when all faces have the same size."""
    cdt, idt = np.dtype(ctype), np.dtype(itype)
    if count == 0:
        return np.zeros((0, 3), np.int64), off
    if len(body) - off < cdt.itemsize:
        raise _corrupt(path, "the face element is cut short")
    k = int(np.frombuffer(body, dtype=cdt, count=1, offset=off)[0])
    dt = np.dtype([("n", cdt), ("i", idt, (k,))])
    if len(body) - off >= dt.itemsize * count:
        arr = np.frombuffer(body, dtype=dt, count=count, offset=off)
        if np.all(arr["n"] == k):
            return arr["i"].astype(np.int64), off + dt.itemsize * count
    faces = []
    for _ in range(count):  # mixed sizes: sequential
        if len(body) - off < cdt.itemsize:
            raise _corrupt(path, "the face element is cut short")
        k = int(np.frombuffer(body, dtype=cdt, count=1, offset=off)[0])
        off += cdt.itemsize
        if len(body) - off < k * idt.itemsize:
            raise _corrupt(path, "the face element is cut short")
        faces.append(np.frombuffer(body, dtype=idt, count=k, offset=off).tolist())
        off += k * idt.itemsize
    return faces, off


def _read_raw(path: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``V (n,3)``, padded faces ``(m,k)`` and face sizes ``(m,)`` of a mesh file."""
    ext = _check_readable(path)
    try:
        fast = _parse_obj_fast(path.read_bytes()) if ext == ".obj" else None
        if fast is not None and fast[1].max() < len(fast[0]):
            return fast  # else the line parser names the face's line
        if ext == ".obj":
            V, faces, _ = _parse_obj(path, _decode(path))
        elif ext == ".off":
            V, faces = _parse_off(path, _decode(path))
        else:
            V, faces = _parse_ply(path)
    except OSError as exc:
        raise MeshError(f"{path}: cannot read the file ({exc.strerror or exc})") from exc
    if V is None or len(V) == 0:
        raise _corrupt(path, "no vertices found")
    P, sizes = _as_padded(faces if not isinstance(faces, np.ndarray) else faces)
    return V, P, sizes


def read_configuration(path: str | os.PathLike) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Vertices ``V (n,3)``, padded faces ``(m,k)`` (``-1`` padded) and face sizes ``(m,)`` of a
    mesh file, without the geometry checks of :func:`read_mesh`.

    For configurations that are degenerate by design: a collapsed (aligned) net puts every
    joint of a loop on one line, which :func:`validate_mesh` rejects as zero-area faces. The
    file must still parse and hold at least one vertex (:class:`MeshError` otherwise);
    coordinates must be finite.
    """
    V, P, sizes = _polygons(Path(path))
    check_coordinates(V, Path(path).name)
    return V, P, sizes


def _require_faces(path: Path, V: np.ndarray, P: np.ndarray) -> None:
    """:class:`MeshError` for a mesh file of vertices only (a point cloud, or faces lost)."""
    if len(P) == 0:
        raise MeshError(f"{path.name}: the mesh is empty, {len(V)} vertices but no faces (no face "
                        "record on any line); export the mesh with its faces, not as points")


def read_polygons(path: str | os.PathLike) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Vertices ``V (n,3)`` (finite, in the file's units), padded faces ``(m,k)`` (``-1``
    padded, indices checked) and face sizes ``(m,)`` of a mesh file: the file as it is, before
    unit conversion, cleaning and the geometry checks (:mod:`gridshell.io` reads user meshes
    through it). A file of vertices only is a :class:`MeshError`."""
    V, P, sizes = _polygons(Path(path))
    _require_faces(Path(path), V, P)
    return V, P, sizes


def _polygons(path: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`read_polygons` without the faces required (a bundle's configurations)."""
    V, P, sizes = _read_raw(path)
    V = np.asarray(V, dtype=np.float64).reshape(-1, 3)
    if not np.all(np.isfinite(V)):
        raise MeshError(f"{path.name}: {int((~np.isfinite(V)).any(axis=1).sum())} vertices have "
                        "NaN or infinite coordinates; re-export the mesh")
    if len(P) and (P.max() >= len(V)):
        raise MeshError(f"{path.name}: a face refers to vertex {int(P.max())} but the file has "
                        f"{len(V)} vertices (outside 0 .. {len(V) - 1}); the file is truncated "
                        "or corrupt")
    return V, P, sizes


def check_coordinates(V: np.ndarray, name: str, what: str = "vertex") -> None:
    """:class:`MeshError` naming the first finite coordinate of ``V (n,3)`` (metres) beyond
    ``EXTENT_RANGE[1]`` from the origin: out-of-range coordinates (other units, or a corrupt
    file), reported as such rather than as the degenerate faces they cause."""
    V = np.asarray(V, dtype=np.float64).reshape(-1, 3)
    fin = np.isfinite(V).all(axis=1)
    big = fin & (np.abs(np.where(np.isfinite(V), V, 0.0)).max(axis=1, initial=0.0)
                 > EXTENT_RANGE[1])
    if big.any():
        i = int(np.flatnonzero(big)[0])
        x, y, z = V[i]
        raise MeshError(f"{name}: {int(big.sum())} points have coordinates out of range ({what} "
                        f"{i} at ({x:.3g}, {y:.3g}, {z:.3g}) m, beyond +-{EXTENT_RANGE[1]:g} m: "
                        "the mesh spans more than a gridshell can); coordinates are read as "
                        "metres - rescale the mesh or repair the file")


def read_mesh(path: str | os.PathLike, kind: str = "any",
              manifold_vertices: bool = True) -> QuadMesh | TriMesh:
    """Read an OBJ, PLY (ASCII or binary) or OFF mesh, keeping vertex and face order.

    Parameters
    ----------
    path : path-like
        The mesh file; the format is taken from the extension.
    kind : {"any", "quad", "tri"}
        ``"quad"``: every face must be a quad, gives a :class:`QuadMesh`. ``"tri"``: gives a
        :class:`TriMesh`, quads split along their shorter diagonal (other polygons fanned).
        ``"any"``: a :class:`QuadMesh` if all faces are quads, a :class:`TriMesh` otherwise
        (mixed faces triangulated).
    manifold_vertices : bool
        ``False`` accepts vertices whose faces form several fans (see :func:`validate_mesh`).

    Returns
    -------
    QuadMesh or TriMesh
        Coordinates in the file's units (metres by convention), full float64 precision.

    Raises
    ------
    MeshError
        Missing, unreadable, empty, truncated or garbage file, unknown extension, a mesh
        that fails :func:`validate_mesh`, or one whose size is outside :data:`EXTENT_RANGE`.
    """
    if kind not in ("any", "quad", "tri"):
        raise ValueError(f"kind must be 'any', 'quad' or 'tri', got {kind!r}")
    path = Path(path)
    V, P, sizes = _read_raw(path)
    _require_faces(path, V, P)
    check_coordinates(V, path.name)
    validate_mesh(V, P, require_quads=kind == "quad", name=path.name,
                  manifold_vertices=manifold_vertices)
    _check_extent(V, path.name)
    if kind != "tri" and np.all(sizes == 4):
        return QuadMesh(V, P[:, :4], check=False)
    if np.all(sizes == 3):
        return TriMesh(V, P[:, :3], check=False)
    return TriMesh(V, _triangulate_padded(V, P, sizes), check=False)


def _check_extent(V: np.ndarray, name: str) -> None:
    """:class:`MeshError` unless the bounding-box diagonal of ``V`` lies in :data:`EXTENT_RANGE`."""
    d = bbox_diagonal(V)
    lo, hi = EXTENT_RANGE
    if not lo <= d <= hi:
        raise MeshError(f"{name}: the mesh spans {d:.3g} m (bounding-box diagonal), outside the "
                        f"{lo:g} .. {hi:g} m a gridshell can have; coordinates are read as "
                        "metres - rescale the mesh (or export it in metres)")


def _obj_vertex_text(V: np.ndarray) -> str:
    V = np.asarray(V, dtype=np.float64).reshape(-1, 3)
    return "".join(f"v {x!r} {y!r} {z!r}\n" for x, y, z in V.tolist())


def _index_text(prefix: str, F: np.ndarray, offset: int) -> str:
    if len(F) == 0:
        return ""
    S = (np.asarray(F, dtype=np.int64) + offset).astype(str)
    return "".join(prefix + " ".join(row) + "\n" for row in S.tolist())


def orientation_problem(F: np.ndarray, n_vertices: int) -> str | None:
    """Why the faces ``F (m,k)`` (rows padded with -1 for smaller faces) are not consistently
    oriented, or None.

    Purely combinatorial (each directed edge ``(F[i, j], F[i, j+1])`` at most once, so the two
    faces of an interior edge run it in opposite directions), so it holds for a collapsed net
    whose loops are geometrically degenerate (aligned.obj).
    """
    F = np.asarray(F, dtype=np.int64)
    if F.size == 0:
        return None
    src, dst, _ = _face_edges(F)  # rows padded with -1 (faces of mixed sizes) allowed
    directed = src * np.int64(max(n_vertices, 1)) + dst
    u, c = np.unique(directed, return_counts=True)
    if np.any(c > 1):
        d = u[c > 1]
        n = max(n_vertices, 1)
        return (f"{len(d)} edges are run in the same direction by two faces (the first joins "
                f"vertices {d[0] // n} and {d[0] % n}): the faces are inconsistently oriented")
    return None


def _check_writable_mesh(name: str, V: np.ndarray, F: np.ndarray) -> None:
    """:class:`GridshellError` (a bug of the caller: the tool never writes such a file) unless
    ``V`` is finite, ``F`` refers to existing vertices and is consistently oriented."""
    from gridshell.core.errors import GridshellError

    bad = ~np.isfinite(V).all(axis=1)
    if bad.any():
        raise GridshellError(f"refusing to write {name}: {int(bad.sum())} vertices are not "
                             f"finite (NaN or Inf; the first is vertex {int(np.flatnonzero(bad)[0])})"
                             "; this is a bug, please report it")
    if F.size and (F.min() < 0 or F.max() >= len(V)):
        raise GridshellError(f"refusing to write {name}: faces refer to vertices outside 0 .. "
                             f"{len(V) - 1}; this is a bug, please report it")
    problem = orientation_problem(F, len(V))
    if problem is not None:
        raise GridshellError(f"refusing to write {name}: {problem}; this is a bug, please "
                             "report it")


def write_mesh(path: str | os.PathLike, V: np.ndarray, F: np.ndarray) -> None:
    """Write ``V (n,3)``, ``F (m,k)`` to an OBJ, PLY or OFF file (ASCII), atomically.

    Vertex and face order are kept and coordinates are written with 17 significant digits,
    so :func:`read_mesh` returns exactly ``V`` and ``F``. (OpenMesh's writers are not used:
    they round coordinates to single precision.)

    Parameters
    ----------
    path : path-like
        Output file; ``.obj``, ``.ply`` or ``.off``.
    V : (n,3) float
        Vertex positions, metres.
    F : (m,k) int
        Faces (0-based vertex indices), all of one size ``k``, consistently oriented
        (:func:`orientation_problem`).

    Raises :class:`~gridshell.core.errors.GridshellError` for non-finite vertices, faces outside
    the vertices or inconsistent orientation: the tool never writes such a mesh.
    """
    path = Path(path)
    ext = path.suffix.lower()
    if ext not in MESH_FORMATS:
        raise MeshError(f"{path.name}: unknown mesh format '{path.suffix}'; "
                        "write an .obj, .ply or .off file")
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
    if V.ndim != 2 or V.shape[1] != 3 or F.ndim != 2:
        raise MeshError(f"{path.name}: expected V (n,3) and F (m,k), got {V.shape} and {F.shape}")
    _check_writable_mesh(path.name, V, F)
    vtext = "".join(" ".join(map(repr, r)) + "\n" for r in V.tolist())
    if ext == ".obj":
        text = (f"# {len(V)} vertices, {len(F)} faces\n" + "".join("v " + s for s in
                vtext.splitlines(keepends=True)) + _index_text("f ", F, 1))
    elif ext == ".off":
        text = (f"OFF\n{len(V)} {len(F)} 0\n" + vtext
                + _index_text(f"{F.shape[1]} ", F, 0))
    else:
        text = ("ply\nformat ascii 1.0\n"
                f"element vertex {len(V)}\nproperty double x\nproperty double y\n"
                f"property double z\nelement face {len(F)}\n"
                "property list uchar int vertex_indices\nend_header\n"
                + vtext + _index_text(f"{F.shape[1]} ", F, 0))
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="ascii")


def write_polylines(path: str | os.PathLike, polylines: Sequence[np.ndarray]) -> None:
    """Write polylines to an OBJ file (``v`` records, then one ``l`` record each), atomically.

    Parameters
    ----------
    path : path-like
        Output ``.obj`` file.
    polylines : list of (k_i,3) float
        Polylines in order, metres; each needs at least 2 points.
    """
    parts, lines, start = [], [], 1
    for i, P in enumerate(polylines):
        P = np.asarray(P, dtype=np.float64)
        if P.ndim != 2 or P.shape[1] != 3 or len(P) < 2:
            raise MeshError(f"polyline {i}: expected (k,3) points with k >= 2, got {P.shape}")
        if not np.all(np.isfinite(P)):
            from gridshell.core.errors import GridshellError
            raise GridshellError(f"refusing to write {Path(path).name}: polyline {i} has "
                                 "non-finite points (NaN or Inf); this is a bug, please report it")
        parts.append(_obj_vertex_text(P))
        lines.append("l " + " ".join(map(str, range(start, start + len(P)))) + "\n")
        start += len(P)
    with atomic_path(path) as tmp:
        tmp.write_text(f"# {len(lines)} polylines\n" + "".join(parts) + "".join(lines),
                       encoding="ascii")


def read_polylines(path: str | os.PathLike) -> list[np.ndarray]:
    """Polylines ``[(k_i,3) float]`` of the ``l`` records of an OBJ file, in file order."""
    path = Path(path)
    if _check_readable(path) != ".obj":
        raise MeshError(f"{path.name}: polylines are read from OBJ files only; give an .obj file")
    fast = _parse_polylines_fast(path.read_bytes())
    V, lines = fast if fast is not None else _parse_obj(path, _decode(path))[::2]
    if fast is not None and lines:
        # every polyline at once: in range, finite and within EXTENT_RANGE, the polylines are
        # what the loop below takes (which names the first problem otherwise)
        flat = np.concatenate(lines)
        if len(flat) and flat.min() >= 0 and flat.max() < len(V):
            A = V[flat]
            if np.all(np.isfinite(A)) and np.abs(A).max() <= EXTENT_RANGE[1]:
                return [V[idx] for idx in lines]
    out = []
    for i, idx in enumerate(lines):
        # compared as Python ints: an index past int64 is a missing vertex, not an overflow
        if not all(0 <= int(j) < len(V) for j in idx):
            raise _corrupt(path, f"polyline {i} refers to missing vertices")
        idx = np.asarray(idx, dtype=np.int64)
        P = np.asarray(V[idx], dtype=np.float64)
        if not np.all(np.isfinite(P)):
            raise MeshError(f"{path.name}: polyline {i} has "
                            f"{int((~np.isfinite(P)).any(axis=1).sum())} points with NaN or "
                            "infinite coordinates; re-run the design command")
        check_coordinates(P, path.name, f"polyline {i} point")
        out.append(P)
    return out
