"""Rhino ``.3dm`` input through rhino3dm: a mesh, a NURBS surface or a single-face Brep, picked
by name, id or layer when the file holds several, in the file's unit system.

A NURBS surface becomes a :class:`~gridshell.geometry.bspline.BSplineSurface` (still in file units; the
caller converts): Rhino stores ``count + order - 2`` knots per direction (no end knots), so one
knot is added at each end, and the knot vectors are mapped onto ``[0, 1]`` (an affine change of
parameter: the surface is the same). A rational surface (weights not all equal) has no exact
non-rational form: it is fitted by a non-rational one of the same degrees with as
many spans as needed (2, 4 or 8 times) for a largest distance below 0.01 % of its diagonal,
and that distance is reported.
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from gridshell.core.errors import InputError, MeshError
from gridshell.core.units import Units, parse_units

#: Rhino unit system name -> our unit name
RHINO_UNITS = {"Millimeters": "mm", "Centimeters": "cm", "Meters": "m", "Inches": "in",
               "Feet": "ft", "Decimeters": "dm", "Kilometers": "km", "Microns": "um",
               "Yards": "yd", "Miles": "mi", "Dekameters": "dam", "Hectometers": "hm"}
#: samples per control point (x 1/4) used to fit a rational surface; twice as dense to check
_RATIONAL_SAMPLES = 12
#: a rational surface is approximated until its largest distance is below this fraction of its
#: diagonal (or with 8 times its spans)
RATIONAL_TOLERANCE = 1e-4


@dataclass
class RhinoObject:
    """One object of a .3dm file as a candidate input."""

    kind: str  # "mesh", "NURBS surface", "Brep (1 face)", or what it is when unusable
    name: str
    id: str
    layer: str
    geometry: Any = None
    usable: bool = True

    def label(self) -> str:
        who = f"'{self.name}'" if self.name else "unnamed"
        return f"{who} {self.kind} on layer '{self.layer}' (id {self.id})"


@dataclass
class RhinoInput:
    """What :func:`read_3dm` found: a polygon mesh (``V``, ``P``, ``sizes``) or a ``surface``,
    in file units, the file's units (None if it has none) and notes for the summary."""

    units: Units | None
    object: RhinoObject
    V: np.ndarray | None = None
    P: np.ndarray | None = None
    sizes: np.ndarray | None = None
    surface: Any = None
    rational_error: float | None = None
    notes: list[str] = field(default_factory=list)


def _rhino():
    import rhino3dm

    return rhino3dm


def file_units(model: Any, name: str) -> Units | None:
    """The :class:`Units` of a File3dm's model unit system, None when it has none."""
    us = model.Settings.ModelUnitSystem
    key = getattr(us, "name", str(us)).split(".")[-1]
    if key in ("None", "Unset"):
        return None
    if key not in RHINO_UNITS:
        raise InputError(f"{name}: the model's unit system is {key}, which gridshell does not "
                         "convert; set the model's units to metres or millimetres in Rhino "
                         "(or pass --units with a file in no units)")
    return parse_units(RHINO_UNITS[key])


def _objects(model: Any) -> list[RhinoObject]:
    r = _rhino()
    out = []
    for obj in model.Objects:
        g, a = obj.Geometry, obj.Attributes
        try:
            layer = model.Layers[a.LayerIndex].FullPath or model.Layers[a.LayerIndex].Name
        except Exception:  # noqa: BLE001 - a file without layer table
            layer = "?"
        rec = RhinoObject(kind=type(g).__name__, name=a.Name or "", id=str(a.Id), layer=layer,
                          geometry=g, usable=False)
        if isinstance(g, r.Mesh):
            rec.kind, rec.usable = "mesh", True
        elif isinstance(g, r.Brep):
            n = len(g.Faces)
            rec.kind, rec.usable = (("Brep (1 face)", True) if n == 1 else
                                    (f"Brep of {n} faces", False))
        elif isinstance(g, r.Extrusion):
            rec.kind, rec.usable = "extrusion", False
        elif isinstance(g, r.Surface):
            rec.kind, rec.usable = "NURBS surface", True
        else:
            rec.kind = {"LineCurve": "curve", "NurbsCurve": "curve", "PolylineCurve": "curve",
                        "ArcCurve": "curve", "PolyCurve": "curve", "Point": "point",
                        "PointCloud": "point cloud"}.get(rec.kind, rec.kind)
        out.append(rec)
    return out


def _pick(objs: list[RhinoObject], wanted: str | None, name: str) -> RhinoObject:
    usable = [o for o in objs if o.usable]
    if wanted is None:
        if len(usable) == 1:
            return usable[0]
        if not usable:
            kinds = _count_kinds(objs)
            raise InputError(f"{name}: no mesh, NURBS surface or single-face Brep in the file "
                             f"(it holds {kinds}); export the surface or a mesh of it to the "
                             ".3dm")
        listing = "; ".join(o.label() for o in usable)
        raise InputError(f"{name}: {len(usable)} objects could be the surface: {listing}; pick "
                         "one with --object NAME|ID|LAYER")
    w = str(wanted).strip()
    for test in (lambda o: o.name == w, lambda o: o.name.lower() == w.lower(),
                 lambda o: o.id.lower() == w.lower(),
                 lambda o: o.layer == w or o.layer.split("::")[-1] == w,
                 lambda o: o.layer.lower() == w.lower()
                 or o.layer.split("::")[-1].lower() == w.lower()):
        hit = [o for o in objs if test(o)]
        if hit:
            good = [o for o in hit if o.usable]
            if len(good) == 1:
                return good[0]
            if not good:
                raise InputError(f"{name}: --object {w!r} is {hit[0].label()}, not a mesh, NURBS "
                                 "surface or single-face Brep; pick one of: "
                                 + ("; ".join(o.label() for o in usable) or "none in the file"))
            raise InputError(f"{name}: --object {w!r} matches {len(good)} objects: "
                             + "; ".join(o.label() for o in good) + "; give a name or an id")
    raise InputError(f"{name}: no object named {w!r} (nor with that id or layer); the file "
                     "holds: " + ("; ".join(o.label() for o in usable) or "no usable object"))


def _count_kinds(objs: list[RhinoObject]) -> str:
    if not objs:
        return "no objects"
    kinds: dict[str, int] = {}
    for o in objs:
        kinds[o.kind] = kinds.get(o.kind, 0) + 1
    return ", ".join(f"{n} {k}{'s' if n > 1 and not k.endswith('s') else ''}"
                     for k, n in kinds.items())


def _mesh_arrays(mesh: Any, name: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``V (n,3)`` (double precision), padded faces and sizes of a rhino3dm Mesh."""
    pts = mesh.Vertices.ToPoint3dArray()
    V = np.array([[p.X, p.Y, p.Z] for p in pts], dtype=np.float64).reshape(-1, 3)
    F = np.array([tuple(mesh.Faces[i]) for i in range(len(mesh.Faces))],
                 dtype=np.int64).reshape(-1, 4)
    if len(V) == 0 or len(F) == 0:
        raise MeshError(f"{name}: the mesh is empty; export it again")
    tri = F[:, 2] == F[:, 3]
    P = F.copy()
    P[tri, 3] = -1
    sizes = np.where(tri, 3, 4)
    return V, P, sizes


def nurbs_to_bspline(ns: Any, name: str) -> tuple[Any, float | None]:
    """The :class:`BSplineSurface` of a rhino3dm NurbsSurface (file units, knots on [0, 1]),
    and for a rational surface the largest distance of the non-rational fit (file units;
    None for a non-rational surface)."""
    from gridshell.geometry.bspline import BSplineSurface

    du, dv = ns.OrderU - 1, ns.OrderV - 1
    nu, nv = ns.Points.CountU, ns.Points.CountV
    ku = np.array([ns.KnotsU[i] for i in range(len(ns.KnotsU))], dtype=np.float64)
    kv = np.array([ns.KnotsV[i] for i in range(len(ns.KnotsV))], dtype=np.float64)
    if len(ku) != nu + du - 1 or len(kv) != nv + dv - 1:  # Rhino: count + order - 2
        raise InputError(f"{name}: the NURBS surface has {len(ku)} x {len(kv)} knots for "
                         f"{nu} x {nv} control points of order {du + 1} x {dv + 1}; the file is "
                         "corrupt, export it again")
    full_u = np.concatenate([[ku[0]], ku, [ku[-1]]])
    full_v = np.concatenate([[kv[0]], kv, [kv[-1]]])
    W = np.array([[ns.Points[i, j].W for j in range(nv)] for i in range(nu)], dtype=np.float64)
    rational = bool(ns.IsRational) and not np.allclose(W, W.flat[0], rtol=1e-12, atol=0)
    (u0, u1), (v0, v1) = _domain(full_u, du), _domain(full_v, dv)
    if not rational:
        C = np.array([[[ns.Points[i, j].X, ns.Points[i, j].Y, ns.Points[i, j].Z]
                       for j in range(nv)] for i in range(nu)], dtype=np.float64)
        if bool(ns.IsRational):
            C = C / W[..., None]  # equal weights: homogeneous coordinates, one scale
        surf = BSplineSurface(du, dv, (full_u - u0) / (u1 - u0), (full_v - v0) / (v1 - v0), C)
        return surf, None
    return _fit_rational(ns, du, dv, full_u, full_v, name)


def _domain(knots: np.ndarray, d: int) -> tuple[float, float]:
    a, b = float(knots[d]), float(knots[len(knots) - d - 1])
    if not b > a:
        raise InputError("the NURBS surface has an empty parameter domain; the file is corrupt")
    return a, b


def _fit_rational(ns: Any, du: int, dv: int, full_u: np.ndarray, full_v: np.ndarray,
                  name: str) -> tuple[Any, float]:
    """A non-rational surface fitted (least squares, same degrees, uniform knots) to a dense
    sampling of the rational ``ns``, with 2, 4 or 8 times as many spans: the first whose
    largest distance on a denser sampling is below :data:`RATIONAL_TOLERANCE` of the
    diagonal of the control net. Returns it and that distance (file units)."""
    import scipy.sparse.linalg as spla

    from gridshell.geometry.bspline import BSplineSurface, open_uniform_knots

    (u0, u1), (v0, v1) = _domain(full_u, du), _domain(full_v, dv)
    spans_u = max(len(np.unique(full_u[du:len(full_u) - du])) - 1, 1)
    spans_v = max(len(np.unique(full_v[dv:len(full_v) - dv])) - 1, 1)

    def sample(nu: int, nv: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        s, t = np.linspace(0, 1, nu), np.linspace(0, 1, nv)
        P = np.array([[_xyz(ns.PointAt(u0 + a * (u1 - u0), v0 + b * (v1 - v0))) for b in t]
                      for a in s], dtype=np.float64)
        return s, t, P

    best = None
    for k in (2, 4, 8):
        cu, cv = min(k * spans_u + du, 60), min(k * spans_v + dv, 60)
        surf = BSplineSurface(du, dv, open_uniform_knots(cu, du), open_uniform_knots(cv, dv),
                              np.zeros((cu, cv, 3)))
        s, t, P = sample(_RATIONAL_SAMPLES * cu // 4 + 2, _RATIONAL_SAMPLES * cv // 4 + 2)
        A = surf.operator_grid(s, t)
        solve = spla.factorized((A.T @ A).tocsc())
        C = np.stack([solve(A.T @ P[..., i].ravel()) for i in range(3)], axis=1)
        fit = BSplineSurface(du, dv, surf.knots_u, surf.knots_v, C.reshape(cu, cv, 3))
        s2, t2, P2 = sample(2 * len(s) + 1, 2 * len(t) + 1)
        err = float(np.linalg.norm(fit.evaluate_grid(s2, t2) - P2, axis=-1).max())
        best = (fit, err)
        diag = float(np.linalg.norm(np.ptp(P2.reshape(-1, 3), axis=0)))
        if err <= RATIONAL_TOLERANCE * diag:
            break
    return best


def _xyz(p: Any) -> tuple[float, float, float]:
    return (p.X, p.Y, p.Z)


def read_3dm(path: str | os.PathLike, obj: str | None = None) -> RhinoInput:
    """Read the input surface of a .3dm file (see the module docstring).

    Raises :class:`InputError` for a missing, corrupt or empty file, a file without a mesh /
    surface / single-face Brep, several candidates without ``obj`` (all listed), and an
    ``obj`` that matches none or several (by name, then id, then layer)."""
    path = Path(path)
    name = path.name
    if not path.is_file():
        raise InputError(f"{path}: no such file; check the path")
    if not os.access(path, os.R_OK):
        raise InputError(f"{path}: cannot read the file (permission denied); fix its permissions")
    if path.stat().st_size == 0:
        raise InputError(f"{name}: the file is empty; save the model again")
    model = _rhino().File3dm.Read(str(path))
    if model is None:
        raise InputError(f"{name}: not a readable Rhino .3dm file (corrupt or truncated); save "
                         "it again from Rhino (File > Save As, version 7 or 8)")
    units = file_units(model, name)
    objs = _objects(model)
    pick = _pick(objs, obj, name)
    out = RhinoInput(units=units, object=pick)
    g = pick.geometry
    if pick.kind == "mesh":
        out.V, out.P, out.sizes = _mesh_arrays(g, name)
        return out
    if pick.kind.startswith("Brep"):
        face = g.Faces[0]
        if not bool(g.IsSurface):
            out.notes.append("the Brep face is trimmed: its whole underlying surface is used")
        srf = face.UnderlyingSurface()
        ns = srf.ToNurbsSurface() if not isinstance(srf, _rhino().NurbsSurface) else srf
        reversed_ = bool(face.OrientationIsReversed)
    else:
        ns = g if isinstance(g, _rhino().NurbsSurface) else g.ToNurbsSurface()
        reversed_ = False
    if ns is None:
        raise InputError(f"{name}: {pick.label()} has no NURBS form; convert it to a NURBS "
                         "surface in Rhino (ToNurbs)")
    surf, err = nurbs_to_bspline(ns, name)
    if reversed_:  # the face's normal is the surface's reversed: flip u
        from gridshell.geometry.bspline import BSplineSurface

        surf = BSplineSurface(surf.degree_u, surf.degree_v, 1.0 - surf.knots_u[::-1],
                              surf.knots_v, surf.ctrl[::-1].copy())
    out.surface = surf
    if err is not None:
        out.notes.append(f"rational surface approximated by a non-rational B-spline "
                         f"({surf.ctrl.shape[0]} x {surf.ctrl.shape[1]} control points), largest "
                         f"distance {err:.3g} file units")
        out.rational_error = err
    return out
