"""The corpus: named, reproducible references built from the families of
:mod:`gridshell.corpus.surfaces`, each placed, sized, turned, moved and meshed.

A reference's name is ``<family>-<k>``; its coefficients come from a generator seeded with
the CRC-32 of its name (the same name gives the same surface, whatever else the corpus
holds). The variants (mesh size, quad or triangle mesh, size, orientation, offset) cycle
over the reference's position in the corpus so that every family meets every kind.
"""
from __future__ import annotations

import math
import zlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Iterable

import numpy as np

from gridshell.corpus.geometry import curvatures, fundamental_forms, grid_faces, sample_grid
from gridshell.corpus.surfaces import FAMILIES, Shape

__all__ = ["COUNTS", "FAST", "MODES", "REFERENCES", "Reference", "build_reference", "get",
           "names", "select"]

#: references per family (110 in all); the last five families (the domes and hills architects
#: draw) are written in the users' units and formats (:data:`_FILES`)
COUNTS: dict[str, int] = {"revolution": 10, "associate": 8, "hill": 8, "dome": 7, "ridge": 5,
                          "saddle": 8, "monkey": 5, "sphere-cap": 4, "near-sphere": 5,
                          "pseudosphere": 4, "near-pseudosphere": 5, "dini": 3,
                          "bump": 7, "round-dome": 7, "asym-hill": 7, "pavilion": 7,
                          "round-plan": 10}
#: families whose target files come in a user's units and formats, not metres in OBJ
_USER_FILES = ("bump", "round-dome", "asym-hill", "pavilion", "round-plan")
#: (format, units) of those files, cycled: Rhino models in millimetres first
_FILES = [("3dm", "mm"), ("obj", "mm"), ("ply", "m"), ("3dm", "cm"), ("off", "mm"),
          ("obj", "m"), ("3dm", "m"), ("ply", "mm"), ("3dm", "mm")]

#: the runs of the corpus: pipeline / mode -> CLI words after ``gridshell``
MODES: dict[str, list[str]] = {"gg": ["gg"], "ncp-phlw": ["ncp", "--mode", "phlw"],
                               "ncp-cnc": ["ncp", "--mode", "cnc"],
                               "ncp-aa": ["ncp", "--mode", "aa"]}

#: mesh size along the patch's longer side, cycled over the corpus
_RES = [16, 10, 24, 30, 20, 40, 12, 60, 24, 30, 80, 20, 200, 16, 24, 30, 40, 20, 120, 12, 30,
        50, 20]
#: size bins (largest horizontal span, metres), cycled
_SIZES = [(0.5, 0.5), (0.7, 2.0), (2.0, 5.0), (5.0, 12.0), (12.0, 30.0), (30.0, 59.0),
          (60.0, 60.0)]
_ORIENT = ["upright", "yaw", "tilted", "yaw", "upright", "yaw", "tilted", "yaw", "y-up", "any"]
_OFFSET = ["none", "near", "far", "near"]

#: K D^2 (D: the patch's bounding-box diagonal) below which K counts as zero
_K_ZERO = 1e-3
#: |k1 - k2| D below which a point counts as (near) umbilic for the NCP modes
_UMBILIC = 0.1


@dataclass(frozen=True)
class Reference:
    """One reference surface of the corpus; lengths in metres.

    name, family, index : stable name ``<family>-<k>``, family, position in the corpus
    params : the family's coefficients (canonical units)
    rows, cols : vertex grid (columns ``P[:, j]`` are the meridians where the surface has
        them; ``gridshell gg --meridians cols``, the default)
    mesh : "quad" (the grid's quads) or "tri" (two triangles per quad, ``diagonal``)
    size : largest horizontal span before the rotation
    orientation : "upright", "yaw" (about z), "tilted" (up to 30 degrees, and yaw), "y-up"
        (z turned to y, as exported by y-up tools) or "any" (uniformly random rotation)
    rotation : (3, 3) applied after scaling, about the centre of the patch's base
    offset : (3,) translation applied last
    revolution : isometric to a surface of revolution exactly
    curvature : "K>0", "K<0" (everywhere on the patch) or "mixed"
    K_range : (min, max) Gaussian curvature, 1/m^2
    umbilic_gap : min over the patch of |k1 - k2| * bbox diagonal (0 for a sphere)
    modes : the runs that apply (keys of :data:`MODES`): gg always; ncp-phlw and ncp-cnc on
        saddle-like and dome-like references (K of one sign, no umbilic point); ncp-aa where
        K < 0
    no_net : runs that must answer "no net exists" (exit 3): ncp-aa where K > 0
    tried : runs a user would try on the shapes architects draw although the surface does not
        admit them by construction (an umbilic, K of both signs): the contract is exit 0 with
        every figure, or a refusal (exit 3 / 4) with its reason, never a failing design
    file_format, units : how the target file is written for a run (:meth:`write_target`):
        "obj", "ply", "off" or "3dm" (a Rhino mesh); "m", "cm" or "mm"
    """

    name: str
    family: str
    index: int
    params: dict[str, Any] = field(repr=False)
    rows: int
    cols: int
    mesh: str
    diagonal: str
    size: float
    orientation: str
    rotation: tuple = field(repr=False)
    offset: tuple = field(repr=False)
    revolution: bool
    curvature: str
    K_range: tuple[float, float]
    umbilic_gap: float
    modes: tuple[str, ...]
    no_net: tuple[str, ...]
    _f: Callable = field(repr=False, compare=False)
    _scale: float = field(repr=False, compare=False)
    _shape: Shape = field(repr=False, compare=False)
    file_format: str = "obj"
    units: str = "m"
    tried: tuple[str, ...] = ()

    @property
    def scale(self) -> float:
        """Metres per canonical unit of the family (:mod:`gridshell.corpus.surfaces`)."""
        return self._scale

    @property
    def shape(self) -> Shape:
        """The canonical patch (family coefficients, closed forms)."""
        return self._shape

    # ------------------------------------------------------------------ geometry (metres)
    def surface(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Points ``(..., 3)`` of the reference at parameters ``(a, b)`` of the unit square."""
        R, t = np.asarray(self.rotation), np.asarray(self.offset)
        return self._scale * self._f(a, b) @ R.T + t

    def grid(self) -> np.ndarray:
        """``P (rows, cols, 3)``: the vertex grid."""
        return sample_grid(self.surface, self.rows, self.cols)

    def mesh_arrays(self) -> tuple[np.ndarray, np.ndarray]:
        """``(V (rows*cols, 3), F)``: the quad or triangle mesh, faces consistently oriented."""
        return (self.grid().reshape(-1, 3),
                grid_faces(self.rows, self.cols, self.mesh, self.diagonal))

    def write_target(self, folder: str | Path) -> Path:
        """Write the mesh as a user would bring it, in :attr:`file_format` and :attr:`units`,
        into ``folder`` (``target.<ext>``; a .3dm says its unit, the others do not: pass
        ``--units`` :attr:`units`); returns the path."""
        from gridshell.corpus.files import write_target

        return write_target(self, Path(folder))

    def write_obj(self, path: str | Path) -> Path:
        """Write the mesh as an OBJ file (exact coordinates; atomic); returns the path."""
        from gridshell.geometry.meshfile import write_mesh

        path = Path(path)
        V, F = self.mesh_arrays()
        write_mesh(path, V, F)
        return path

    # ------------------------------------------------------------------ curvature
    def gaussian_curvature(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """K at ``(a, b)`` by central differences of :meth:`surface`, 1/m^2."""
        return curvatures(self.surface, a, b)[0]

    def principal_curvatures(self, a: np.ndarray, b: np.ndarray
                             ) -> tuple[np.ndarray, np.ndarray]:
        """``(k1, k2)``, ``k1 <= k2``, 1/m, by central differences (normal ``S_a x S_b``)."""
        return curvatures(self.surface, a, b)[1:]

    def first_form(self, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, ...]:
        """``(E, F, G)`` in the ``(a, b)`` parameters by central differences, m^2."""
        return fundamental_forms(self.surface, a, b)[:3]

    def closed_K(self, a: np.ndarray, b: np.ndarray) -> np.ndarray | None:
        """K from the family's closed form, 1/m^2 (None when the family has none)."""
        K = self._shape.closed.get("K")
        return None if K is None else K(a, b) / self._scale**2

    def closed_metric(self, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, ...] | None:
        """``(E, F, G)`` from the family's closed form, m^2 (None when it has none)."""
        g = self._shape.closed.get("metric")
        return None if g is None else tuple(x * self._scale**2 for x in g(a, b))

    def as_dict(self) -> dict[str, Any]:
        """The reference's description, JSON-able."""
        return {"name": self.name, "family": self.family, "params": _jsonable(self.params),
                "rows": self.rows, "cols": self.cols, "mesh": self.mesh,
                "diagonal": self.diagonal, "size": self.size, "orientation": self.orientation,
                "rotation": [list(r) for r in self.rotation], "offset": list(self.offset),
                "revolution": self.revolution, "curvature": self.curvature,
                "K_range": list(self.K_range), "umbilic_gap": self.umbilic_gap,
                "modes": list(self.modes), "no_net": list(self.no_net),
                "file_format": self.file_format, "units": self.units, "tried": list(self.tried)}


def _jsonable(x: Any) -> Any:
    if isinstance(x, dict):
        return {k: _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, (np.floating, np.integer)):
        return x.item()
    return x


def _rotation(rng: np.random.Generator, kind: str) -> np.ndarray:
    def rz(t):
        c, s = math.cos(t), math.sin(t)
        return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])

    def rx(t):
        c, s = math.cos(t), math.sin(t)
        return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    yaw = rng.uniform(0, 2 * math.pi)
    if kind == "upright":
        return np.eye(3)
    if kind == "yaw":
        return rz(yaw)
    if kind == "tilted":
        return rz(yaw) @ rx(math.radians(rng.uniform(5.0, 30.0))) @ rz(rng.uniform(0, 6.3))
    if kind == "y-up":  # z -> y, y -> -z (a y-up export), turned about the new up axis
        return np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]]) @ rz(yaw)
    q = rng.normal(size=4)  # uniform on SO(3): a normalized Gaussian quaternion
    w, x, y, z = q / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def _placed(shape: Shape) -> Callable:
    """``shape.f`` with its normal up (faces of :func:`grid_faces` facing +z; ``b`` reversed
    if needed), its base's bounding box centred on the origin and its lowest point at z = 0."""
    f = shape.f
    a, b = np.meshgrid(np.linspace(0, 1, 41), np.linspace(0, 1, 41), indexing="ij")
    P = f(a, b)
    fa, fb = np.gradient(P, axis=0), np.gradient(P, axis=1)
    if np.cross(fb, fa)[..., 2].mean() < 0:
        f0 = f

        def f(a, b, f0=f0):
            return f0(a, 1 - np.asarray(b, float))
        P = f(a, b)
    lo, hi = P.reshape(-1, 3).min(0), P.reshape(-1, 3).max(0)
    c = np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, lo[2]])
    return lambda a, b: f(a, b) - c


def _side_lengths(f: Callable) -> tuple[float, float]:
    """Lengths of the mid column (along ``a``) and the mid row (along ``b``)."""
    t = np.linspace(0, 1, 201)
    col = f(t, 0.5 + 0 * t)
    row = f(0.5 + 0 * t, t)
    return (float(np.linalg.norm(np.diff(col, axis=0), axis=1).sum()),
            float(np.linalg.norm(np.diff(row, axis=0), axis=1).sum()))


def build_reference(family: str, k: int, index: int) -> Reference:
    """The ``k``-th reference of ``family``, at position ``index`` of the corpus."""
    name = f"{family}-{k:02d}"
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    shape = FAMILIES[family](rng)
    f = _placed(shape)
    # resolution: n along the longer side, cells about square
    n = _RES[index % len(_RES)]
    la, lb = _side_lengths(f)
    if la >= lb:
        rows, cols = n, max(10, int(round(n * lb / la)))
    else:
        rows, cols = max(10, int(round(n * la / lb))), n
    mesh = "tri" if index % 3 == 1 else "quad"
    diagonal = "alternate" if (index // 3) % 2 == 0 else "same"
    # size: the largest horizontal span
    lo_s, hi_s = _SIZES[(3 * index) % len(_SIZES)]
    size = float(lo_s if lo_s == hi_s else math.exp(rng.uniform(math.log(lo_s), math.log(hi_s))))
    a, b = np.meshgrid(np.linspace(0, 1, 41), np.linspace(0, 1, 41), indexing="ij")
    P = f(a, b).reshape(-1, 3)
    span = float(max(np.ptp(P[:, 0]), np.ptp(P[:, 1])))
    scale = size / span
    orientation = _ORIENT[index % len(_ORIENT)]
    R = _rotation(rng, orientation)
    kind = _OFFSET[(index // 2) % len(_OFFSET)]
    if kind == "none":
        t = np.zeros(3)
    else:
        d = rng.normal(size=3)
        d /= np.linalg.norm(d)
        r = rng.uniform(0.2, 1.0) * size if kind == "near" else min(1000.0, rng.uniform(20, 100)
                                                                      * size)
        t = d * r
    # curvature class over the patch (scale-free: K D^2, |k1 - k2| D)
    K, k1, k2 = curvatures(f, a, b)
    D = float(np.linalg.norm(np.ptp(P, axis=0)))
    Kn = K * D * D
    if Kn.min() > _K_ZERO:
        curv = "K>0"
    elif Kn.max() < -_K_ZERO:
        curv = "K<0"
    else:
        curv = "mixed"
    gap = float(np.min(np.abs(k2 - k1)) * D)
    modes = ["gg"]
    if curv != "mixed" and gap > _UMBILIC:
        modes += ["ncp-phlw", "ncp-cnc"]
    if curv == "K<0":
        modes.append("ncp-aa")
    no_net = ("ncp-aa",) if curv == "K>0" else ()
    return Reference(
        name=name, family=family, index=index, params=_jsonable(shape.params), rows=rows,
        cols=cols, mesh=mesh, diagonal=diagonal, size=size, orientation=orientation,
        rotation=tuple(tuple(float(x) for x in r) for r in R),
        offset=tuple(float(x) for x in t), revolution=shape.revolution, curvature=curv,
        K_range=(float(K.min()) / scale**2, float(K.max()) / scale**2), umbilic_gap=gap,
        modes=tuple(modes), no_net=no_net, _f=f, _scale=scale, _shape=shape,
        tried=tuple(m for m in ("ncp-phlw", "ncp-cnc", "ncp-aa") if family in _USER_FILES
                    and m not in modes and m not in no_net),
        **_file_of(family, k))


def _file_of(family: str, k: int) -> dict[str, str]:
    """The target file's format and units: metres in OBJ, or for the families users draw the
    ``k``-th entry of :data:`_FILES` (offset per family, so that every family meets each)."""
    if family not in _USER_FILES:
        return {}
    fmt, units = _FILES[(k + 2 * _USER_FILES.index(family)) % len(_FILES)]
    return {"file_format": fmt, "units": units}


def _build() -> tuple[Reference, ...]:
    out, index = [], 0
    for family, count in COUNTS.items():
        for k in range(count):
            out.append(build_reference(family, k, index))
            index += 1
    return tuple(out)


#: every reference, in corpus order
REFERENCES: tuple[Reference, ...] = _build()
_BY_NAME = {r.name: r for r in REFERENCES}

#: a small subset spanning families, sizes (0.5 m to 60 m), quads and triangles: the
#: references of tests/corpus/test_corpus_pipelines.py
FAST: tuple[str, ...] = ("hill-06", "saddle-04", "revolution-02", "associate-03",
                         "pseudosphere-03", "dome-05")


def names() -> list[str]:
    """Names of every reference, in corpus order."""
    return [r.name for r in REFERENCES]


def get(name: str) -> Reference:
    """The reference called ``name`` (KeyError naming the choices if there is none)."""
    try:
        return _BY_NAME[name]
    except KeyError:
        raise KeyError(f"no reference {name!r}; the corpus has {', '.join(names())}, "
                       f"families {', '.join(COUNTS)}, subset 'fast'") from None


def select(spec: str | Iterable[str] | None = None) -> list[Reference]:
    """References by name, family or ``"fast"`` (comma-separated or an iterable; None: all)."""
    if spec is None:
        return list(REFERENCES)
    words = spec.split(",") if isinstance(spec, str) else list(spec)
    out: list[Reference] = []
    for w in (w.strip() for w in words):
        if not w:
            continue
        if w == "fast":
            picked = [get(n) for n in FAST]
        elif w in COUNTS:
            picked = [r for r in REFERENCES if r.family == w]
        else:
            picked = [get(w)]
        seen = {r.name for r in out}
        out += [r for r in picked if r.name not in seen]
    return out
