"""The design bundle: the directory every design command writes and other tools read.

Layout (all geometry in metres)::

    design.json     kind, units (the unit the input was drawn in: {"name", "metres_per_unit"};
                    absent = metres; the geometry itself is always metres), lamellae, metrics,
                    params, collapse curve
    net.obj         joints as vertices, net-loops as quad faces
    axes.obj        one dense polyline (``l`` record) per lamella axis, in design.json order
    aligned.obj     net.obj's vertices and faces in the collapsed configuration
    surface.obj     the designed surface (quad mesh)
    revolution.obj  GG only: the isometric surface of revolution
    *.png, ...      previews and extra files

``design.json`` lamella records: ``{id, family, joints, joint_s, length}`` and, for NCP kinds,
``collapse_s``: the arc length of each joint along the collapse curve.
"""
from __future__ import annotations

import copy
import hashlib
import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, NamedTuple, Sequence

import numpy as np

from gridshell.core.atomic import atomic_dir
from gridshell.core.errors import InputError
from gridshell.core.units import METRES, Units
from gridshell.geometry.net import Lamella, Net
from gridshell.core.recent import Recent

FORMAT = "gridshell.design"
VERSION = 1
KINDS = ("GG", "NCP", "CNC", "AA")


@dataclass
class CollapseCurve:
    """The planar curve an NCP gridshell collapses into (paper 4.2.3).

    Attributes
    ----------
    points : (k,2) float
        Collapse polyline in its plane, metres.
    normals : (k,2) float
        Flattened unit surface normals at the points.
    shape : str
        "circle" (CNC), "line" (AA) or "curve" (general PHLW).
    radius : float or None
        Radius for a circle, metres.
    """

    points: np.ndarray
    normals: np.ndarray
    shape: str = "curve"
    radius: float | None = None

    def to_json(self) -> dict:
        return {"shape": self.shape, "radius": self.radius,
                "points": np.asarray(self.points).tolist(),
                "normals": np.asarray(self.normals).tolist()}

    @classmethod
    def from_json(cls, d: dict) -> "CollapseCurve":
        return cls(points=np.asarray(d["points"], float).reshape(-1, 2),
                   normals=np.asarray(d["normals"], float).reshape(-1, 2),
                   shape=str(d.get("shape", "curve")), radius=d.get("radius"))


@dataclass
class DesignBundle:
    """Everything a design command produces; see the module docstring for the files."""

    kind: str
    net: Net
    aligned: np.ndarray
    surface_V: np.ndarray
    surface_F: np.ndarray
    metrics: dict[str, Any] = field(default_factory=dict)
    params: dict[str, Any] = field(default_factory=dict)
    collapse: CollapseCurve | None = None
    collapse_s: dict[int, np.ndarray] | None = None
    revolution_V: np.ndarray | None = None
    revolution_F: np.ndarray | None = None
    units: Units = METRES  # the unit the input was drawn in (geometry stays metres)

    def __post_init__(self) -> None:
        if not isinstance(self.units, Units):
            self.units = Units.from_json(self.units)
        if self.kind not in KINDS:
            raise InputError(f"design kind must be one of {', '.join(KINDS)}, got {self.kind!r}")
        self.aligned = np.asarray(self.aligned, float).reshape(-1, 3)
        if self.aligned.shape != self.net.joints.shape:
            raise InputError(f"aligned joints {self.aligned.shape} do not match net joints "
                             f"{self.net.joints.shape}")

    def design_json(self) -> dict:
        """The content of design.json."""
        lams = []
        for lam in self.net.lamellae:
            rec = {"id": int(lam.id), "family": int(lam.family),
                   "joints": lam.joints.tolist(), "joint_s": lam.joint_s.tolist(),
                   "length": lam.length}
            if self.collapse_s is not None and lam.id in self.collapse_s:
                rec["collapse_s"] = np.asarray(self.collapse_s[lam.id]).tolist()
            lams.append(rec)
        d = {"format": FORMAT, "version": VERSION, "kind": self.kind,
             "units": self.units.to_json(),
             "n_joints": int(len(self.net.joints)), "n_loops": int(len(self.net.loops)),
             "lamellae": lams, "metrics": _jsonable(self.metrics), "params": _jsonable(self.params)}
        if self.collapse is not None:
            d["collapse"] = self.collapse.to_json()
        return d


class Design(NamedTuple):
    """What a design function returns (:func:`gridshell.gg.pipeline.design_gg`,
    :func:`gridshell.ncp.pipeline.design_ncp`): the bundle and the report of the run (figures,
    timings, stage details; for writing also the arrays: ``"sequence"`` (GG), ``"state"``
    (NCP)). A tuple: ``bundle, report = design_gg(...)`` unpacks it. Written by
    :func:`gridshell.api.write`."""

    bundle: DesignBundle
    report: dict


#: report entries that hold arrays for the writers, not figures (left out of report.json)
REPORT_ARRAYS = ("state", "sequence")


def report_json(report: dict) -> str:
    """``report.json`` of a design run: the report without :data:`REPORT_ARRAYS`, strict JSON
    (a figure that could not be measured is null, never a NaN token)."""
    figures = {k: v for k, v in report.items() if k not in REPORT_ARRAYS}
    return json.dumps(finite_json(figures), indent=1, allow_nan=False, default=_json_default) \
        + "\n"


def _json_default(o: Any) -> Any:
    """JSON for what :func:`finite_json` leaves: numbers as float, anything else by name."""
    try:
        x = float(o)
    except (TypeError, ValueError):
        return str(o)
    return x if np.isfinite(x) else None


def finite_json(obj: Any) -> Any:
    """:func:`_jsonable` of ``obj`` with every non-finite float (NaN, Inf: a figure that could
    not be measured) replaced by None, so the JSON written is strict (no ``NaN`` token)."""
    obj = _jsonable(obj)
    if isinstance(obj, dict):
        return {k: finite_json(v) for k, v in obj.items()}
    if isinstance(obj, list):
        return [finite_json(v) for v in obj]
    if isinstance(obj, float) and not np.isfinite(obj):
        return None
    return obj


def _jsonable(obj: Any) -> Any:
    """Turn numpy scalars/arrays nested in dicts and lists into JSON types."""
    if isinstance(obj, dict):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, Path):
        return str(obj)
    return obj


def write_bundle(path: str | Path, bundle: DesignBundle,
                 extra: dict[str, bytes | Callable[[Path], None]] | None = None,
                 owner: str | None = None) -> Path:
    """Write ``bundle`` to directory ``path`` atomically; ``extra`` maps file names to bytes
    or to a callable that writes that file given its full path; ``owner``: the command the
    manifest names (default ``gg`` / ``ncp`` by kind). Returns ``path``."""
    from gridshell.geometry.meshfile import write_mesh, write_polylines

    path = Path(path)
    with atomic_dir(path, owner=owner or ("gg" if bundle.kind == "GG" else "ncp"),
                    kind=f"design bundle {bundle.kind}") as tmp:
        d = bundle.design_json()
        d["metrics"], d["params"] = finite_json(d["metrics"]), finite_json(d["params"])
        try:  # geometry (joint_s, collapse curve) must be finite: a bug if not
            text = json.dumps(d, indent=1, allow_nan=False)
        except ValueError:
            from gridshell.core.errors import GridshellError
            raise GridshellError("refusing to write design.json: a lamella's joint_s / "
                                 "collapse_s or the collapse curve holds NaN or Inf; this is a "
                                 "bug, please report it") from None
        (tmp / "design.json").write_text(text, encoding="utf-8")
        write_mesh(tmp / "net.obj", bundle.net.joints, bundle.net.loops)
        write_mesh(tmp / "aligned.obj", bundle.aligned, bundle.net.loops)
        write_polylines(tmp / "axes.obj", [lam.axis for lam in bundle.net.lamellae])
        write_mesh(tmp / "surface.obj", bundle.surface_V, bundle.surface_F)
        if bundle.revolution_V is not None:
            write_mesh(tmp / "revolution.obj", bundle.revolution_V, bundle.revolution_F)
        for name, content in (extra or {}).items():
            target = tmp / name
            target.parent.mkdir(parents=True, exist_ok=True)
            if callable(content):
                content(target)
            else:
                target.write_bytes(content)
        _check_obj_orientation(tmp)
    return path


def _check_obj_orientation(directory: Path) -> None:
    """:class:`GridshellError` (a bug) if an OBJ under ``directory`` (``extra`` files given as
    bytes included) has inconsistently oriented faces: every OBJ of a bundle passes its own
    readers (:func:`gridshell.geometry.meshfile.orientation_problem`, combinatorial, so collapsed
    loops pass)."""
    from gridshell.core.errors import GridshellError
    from gridshell.geometry.meshfile import orientation_problem, read_configuration

    for f in sorted(directory.rglob("*.obj")):
        V, P, sizes = read_configuration(f)
        if len(P) == 0 or f.name == "axes.obj":
            continue
        problem = orientation_problem(P, len(V))
        if problem is not None:
            raise GridshellError(f"refusing to write {f.relative_to(directory)}: {problem}; "
                                 "this is a bug, please report it")


def read_design_json(path: str | Path) -> dict:
    """Read and check ``design.json`` of bundle directory ``path``."""
    path = Path(path)
    f = path / "design.json"
    if not path.is_dir():
        raise InputError(f"{path} is not a directory; give the output directory of "
                         "'gridshell gg' or 'gridshell ncp'")
    if not f.is_file():
        raise InputError(f"{path} is not a design bundle (no design.json); give the output "
                         "directory of 'gridshell gg' or 'gridshell ncp'")
    try:
        d = json.loads(f.read_text(encoding="utf-8"))
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"{f} is not valid JSON ({exc}); re-run the design command") from exc
    except OSError as exc:
        raise InputError(f"{f}: cannot read the file ({exc.strerror or exc})") from exc
    if not isinstance(d, dict) or d.get("format") != FORMAT:
        fmt = d.get("format") if isinstance(d, dict) else type(d).__name__
        raise InputError(f"{f} is not a gridshell design file (format {fmt!r}); give the "
                         "output directory of 'gridshell gg' or 'gridshell ncp'")
    for key in ("kind", "lamellae"):
        if key not in d:
            raise InputError(f"{f} lacks '{key}'; re-run the design command")
    if d["kind"] not in KINDS:
        raise InputError(f"{f}: unknown design kind {d['kind']!r} (expected one of "
                         f"{', '.join(KINDS)}); re-run the design command")
    if not isinstance(d["lamellae"], list) or not all(isinstance(r, dict) for r in d["lamellae"]):
        raise InputError(f"{f}: 'lamellae' must be a list of lamella records; re-run the design "
                         "command")
    for key in ("metrics", "params", "collapse"):
        if key in d and d[key] is not None and not isinstance(d[key], dict):
            raise InputError(f"{f}: '{key}' must be a record (a JSON object), got "
                             f"{type(d[key]).__name__}; re-run the design command")
    return d


def read_net_mesh(path: str | Path):
    """The joints and loops of a bundle's ``net.obj`` as a QuadMesh.

    Loops may touch at a corner only (where a loop of the net is missing), so vertices whose
    loops form several fans are accepted; every other check of ``read_mesh`` applies.
    """
    from gridshell.geometry.meshfile import read_mesh

    return read_mesh(path, kind="quad", manifold_vertices=False)


def lamellae_from_design(d: dict, axes: list[np.ndarray], where: str | Path) -> list[Lamella]:
    """The lamellae of design.json ``d`` with their ``axes`` (from axes.obj, same order).

    Raises :class:`InputError` naming the first malformed record."""
    if len(axes) != len(d["lamellae"]):
        raise InputError(f"{where}: axes.obj has {len(axes)} polylines but design.json "
                         f"{len(d['lamellae'])} lamellae; re-run the design command")
    out = []
    for k, (r, ax) in enumerate(zip(d["lamellae"], axes)):
        try:
            for key in ("joint_s", "collapse_s", "length"):
                if key in r:
                    _finite_field(r[key], f"{where}: lamella record {k} of design.json, "
                                          f"field '{key}'")
            out.append(Lamella(id=int(r["id"]), family=int(r["family"]), joints=r["joints"],
                               joint_s=r["joint_s"], axis=ax))
        except (KeyError, TypeError, ValueError, OverflowError) as exc:
            if isinstance(exc, InputError):
                raise
            what = f"lacks {exc}" if isinstance(exc, KeyError) else f"is malformed ({exc})"
            raise InputError(f"{where}: lamella record {k} of design.json {what}; re-run the "
                             "design command") from None
        if "collapse_s" in r and np.size(r["collapse_s"]) != len(out[-1].joints):
            raise InputError(f"{where}: lamella record {k} of design.json has "
                             f"{np.size(r['collapse_s'])} collapse_s values for "
                             f"{len(out[-1].joints)} joints; re-run the design command")
    ids = [lam.id for lam in out]
    if len(set(ids)) != len(ids):
        raise InputError(f"{where}: design.json names lamella ids more than once; re-run the "
                         "design command")
    return out


def check_counts(d: dict, n_joints: int, n_loops: int, where: str | Path) -> None:
    """:class:`InputError` naming the field if the counts stored at the top of design.json
    ``d`` (``n_joints``, ``n_loops``) differ from net.obj's."""
    for key, real in (("n_joints", n_joints), ("n_loops", n_loops)):
        if key in d and not (type(d[key]) is int and d[key] == real):
            raise InputError(f"{where}: design.json, field '{key}' is {d[key]!r} but net.obj has "
                             f"{real}; the bundle was changed after the design - re-run the "
                             "design command")


def check_collapse(d: dict, where: str | Path) -> None:
    """:class:`InputError` naming the field unless the collapse curve of design.json ``d`` (if
    any) has finite ``points`` and ``normals`` and a finite positive ``radius`` (or none)."""
    c = d.get("collapse")
    if c is None:
        return
    if not isinstance(c, dict):
        raise InputError(f"{where}: design.json, field 'collapse' must be a record; re-run the "
                         "design command")
    for key in ("points", "normals", "radius"):
        if key in c and (c[key] is not None or key != "radius"):
            _finite_field(c[key], f"{where}: design.json, field 'collapse.{key}'")
    for key in ("points", "normals"):
        if key in c and not (np.ndim(c[key]) == 2 and np.shape(c[key])[1] == 2):
            raise InputError(f"{where}: design.json, field 'collapse.{key}' must be a list of "
                             "[x, y] pairs; re-run the design command")
    r = c.get("radius")
    if r is not None and not (isinstance(r, (int, float)) and r > 0):
        raise InputError(f"{where}: design.json, field 'collapse.radius' must be a positive "
                         f"number (metres), got {r!r}; re-run the design command")


def _finite_field(value: Any, what: str) -> None:
    """:class:`InputError` naming ``what`` unless ``value`` is a number or a list of finite
    numbers."""
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"{what} is not a list of numbers; re-run the design command") from None
    if not np.all(np.isfinite(a)):
        raise InputError(f"{what} holds {int((~np.isfinite(a)).sum())} non-finite values (NaN "
                         "or Inf); re-run the design command")


#: the files :func:`read_bundle` reads (revolution.obj when there is one)
BUNDLE_FILES = ("design.json", "net.obj", "aligned.obj", "axes.obj", "surface.obj",
                "revolution.obj")
#: bundles read in this process, by content (:func:`content_key`); a few, most recent last
_READ = Recent(4, copy=copy.deepcopy)


def content_key(path: str | Path, names: Sequence[str] = BUNDLE_FILES) -> tuple | None:
    """What identifies the content of the files ``names`` of directory ``path``: the resolved
    directory and each file's BLAKE2b digest (None for a file that is not there), or None when
    one of them cannot be read. Equal keys mean byte-identical files, whatever their times."""
    path = Path(path)
    digests = []
    for name in names:
        f = path / name
        try:
            data = f.read_bytes() if f.is_file() else None
        except OSError:
            return None
        digests.append(None if data is None else hashlib.blake2b(data, digest_size=20).digest())
    try:
        where = str(path.resolve())
    except OSError:
        return None
    return (where, tuple(names), tuple(digests))


def cached_bundle(path: str | Path) -> DesignBundle | None:
    """A copy of what :func:`read_bundle` read at ``path`` in this process if its files are
    byte for byte unchanged since (:func:`content_key`), else None (the files are hashed,
    not parsed)."""
    return _READ.get(content_key(path))


def read_bundle(path: str | Path) -> DesignBundle:
    """Read a design bundle directory written by :func:`write_bundle`.

    A bundle whose files (:data:`BUNDLE_FILES`) are byte for byte those of a bundle this
    process has read before is not parsed and checked again: a copy of that reading is
    returned (:func:`content_key`; a changed, added or removed file reads it anew). Each call
    returns its own copy, so the caller may change it."""
    path = Path(path)
    key = content_key(path)
    hit = _READ.get(key)
    if hit is not None:
        return hit
    bundle = _read_bundle(path)
    # stored only if the files did not change while they were read
    if key is not None and content_key(path) == key:
        _READ.put(key, bundle)
    return bundle


def _read_bundle(path: Path) -> DesignBundle:
    """:func:`read_bundle` without the cache: parse and check the files."""
    from gridshell.geometry.meshfile import read_configuration, read_mesh, read_polylines

    d = read_design_json(path)
    for name in ("net.obj", "aligned.obj", "axes.obj", "surface.obj"):
        if not (path / name).is_file():
            raise InputError(f"design bundle {path} lacks {name}; re-run the design command")
    net_mesh = read_net_mesh(path / "net.obj")
    # collapsed loops are degenerate by design: only the vertices, unchecked
    aligned = read_configuration(path / "aligned.obj")[0]
    if aligned.shape != net_mesh.V.shape:
        raise InputError(f"{path}: aligned.obj has {len(aligned)} vertices but net.obj "
                         f"{len(net_mesh.V)}; re-run the design command")
    check_counts(d, len(net_mesh.V), len(net_mesh.F), path)
    axes = read_polylines(path / "axes.obj")
    lamellae = lamellae_from_design(d, axes, path)
    net = Net(joints=net_mesh.V, loops=net_mesh.F, lamellae=lamellae)
    surf = read_mesh(path / "surface.obj", kind="any")
    rev_V = rev_F = None
    if (path / "revolution.obj").is_file():
        rev = read_mesh(path / "revolution.obj", kind="any")
        rev_V, rev_F = rev.V, rev.F
    try:
        collapse_s = {int(r["id"]): np.asarray(r["collapse_s"], float)
                      for r in d["lamellae"] if "collapse_s" in r} or None
        collapse = CollapseCurve.from_json(d["collapse"]) if "collapse" in d else None
    except (KeyError, TypeError, ValueError) as exc:
        raise InputError(f"{path}: the collapse curve in design.json is malformed ({exc!r}); "
                         "re-run the design command") from None
    check_collapse(d, path)
    return DesignBundle(kind=d["kind"], net=net, aligned=aligned, surface_V=surf.V,
                        surface_F=surf.F, metrics=d.get("metrics", {}),
                        params=d.get("params", {}), collapse=collapse, collapse_s=collapse_s,
                        revolution_V=rev_V, revolution_F=rev_F,
                        units=Units.from_json(d.get("units")))


def strip_cut_shape(bundle: "DesignBundle") -> str:
    """``"line"``, ``"arc"`` or ``"curve"``: the flat shape the bundle's strips are cut in (GG
    and AA straight, CNC arcs of the collapse circle, NCP pieces of its planar collapse curve);
    one rule for :mod:`gridshell.fabrication.strips` (what is cut) and :mod:`gridshell.structure` (what
    is checked)."""
    if bundle.kind in ("GG", "AA"):
        return "line"
    if bundle.kind == "CNC":
        return "arc"
    if bundle.collapse is None:
        raise InputError("NCP design bundle has no collapse curve in design.json; "
                         "re-run 'gridshell ncp' to write it")
    return {"circle": "arc", "line": "line"}.get(bundle.collapse.shape, "curve")


def collapse_radius(bundle: "DesignBundle") -> float:
    """Radius (m) of the circle a CNC (or circular NCP) design collapses into."""
    c = bundle.collapse
    if c is not None and c.shape == "circle" and c.radius:
        return abs(float(c.radius))
    n = bundle.metrics.get("n")
    if n is not None and np.isfinite(float(n)) and float(n) != 0:
        return 1.0 / abs(float(n))
    raise InputError("CNC design bundle gives neither collapse.radius nor metrics.n; "
                     "re-run the design command")
