"""Rhino ``.3dm`` input: a mesh, a NURBS surface or a single-face Brep, picked by name, id or
layer when the file holds several, in the file's unit system; one Rhino object as input
(:func:`object_input`, also the Grasshopper server's). Rhino objects become arrays in
:mod:`gridshell.geometry.rhino_adapter` (double-precision vertices, polygons as Rhino keeps
them).

A NURBS surface becomes the :class:`~gridshell.geometry.bspline.BSplineSurface` it is (still in file
units; the caller converts): Rhino stores ``count + order - 2`` knots per direction (no end knots), so one
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
from gridshell.geometry import rhino_adapter as rh
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
    name: str = ""  # the file's name (or what names the object) in messages


def file_units(model: Any, name: str) -> Units | None:
    """The :class:`Units` of a File3dm's model unit system, None when it has none."""
    key = rh.unit_system_name(model)
    if key in ("None", "Unset"):
        return None
    if key not in RHINO_UNITS:
        raise InputError(f"{name}: the model's unit system is {key}, which gridshell does not "
                         "convert; set the model's units to metres or millimetres in Rhino "
                         "(or pass --units with a file in no units)")
    return parse_units(RHINO_UNITS[key])


def _objects(model: Any) -> list[RhinoObject]:
    out = []
    for g, name, id_, layer in rh.model_objects(model):
        kind, usable = rh.geometry_kind(g)
        out.append(RhinoObject(kind=kind, name=name, id=id_, layer=layer, geometry=g,
                               usable=usable))
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
    """``V (n,3)`` (double precision), padded faces and sizes of a Rhino mesh
    (:func:`gridshell.geometry.rhino_adapter.mesh_arrays`)."""
    V, P, sizes = rh.mesh_arrays(mesh)
    if len(V) == 0 or len(P) == 0:
        raise MeshError(f"{name}: the mesh is empty; export it again")
    return V, P, sizes


def nurbs_to_bspline(ns: Any, name: str) -> tuple[Any, float | None]:
    """The :class:`BSplineSurface` of a rhino3dm NurbsSurface (file units, knots on [0, 1]):
    the surface itself when it is non-rational (:func:`gridshell.geometry.rhino_adapter.
    nurbs_to_bspline`), else its non-rational fit (:func:`_fit_rational`); and for a rational
    surface the largest distance of the fit (file units; None for a non-rational surface)."""
    parts = rh.nurbs_parts(ns, name)
    if not parts.rational:
        return rh.nurbs_to_bspline(parts, name), None
    return _fit_rational(parts)


def rational_points(parts: rh.NurbsParts, s: np.ndarray, t: np.ndarray) -> np.ndarray:
    """``S (len(s), len(t), 3)``: the rational surface ``parts`` on the grid ``s x t`` of its
    parameters mapped onto ``[0, 1]``: ``sum N_i N_j w_ij C_ij / sum N_i N_j w_ij``."""
    from gridshell.geometry.bspline import basis_matrix

    ku, kv = parts.unit_knots()
    Bu = basis_matrix(ku, parts.degree_u, np.asarray(s, float)).toarray()
    Bv = basis_matrix(kv, parts.degree_v, np.asarray(t, float)).toarray()
    W = parts.weights
    num = np.einsum("ai,ijk,bj->abk", Bu, W[..., None] * parts.ctrl, Bv)
    return num / (Bu @ W @ Bv.T)[..., None]


def _fit_rational(parts: rh.NurbsParts) -> tuple[Any, float]:
    """A non-rational surface fitted (least squares, same degrees, uniform knots) to a dense
    sampling of the rational ``parts``, with 2, 4 or 8 times as many spans: the first whose
    largest distance on a denser sampling is below :data:`RATIONAL_TOLERANCE` of the
    diagonal of the control net. Returns it and that distance (file units)."""
    import scipy.sparse.linalg as spla

    from gridshell.geometry.bspline import BSplineSurface, open_uniform_knots

    du, dv = parts.degree_u, parts.degree_v
    spans_u = max(len(np.unique(parts.knots_u[du:len(parts.knots_u) - du])) - 1, 1)
    spans_v = max(len(np.unique(parts.knots_v[dv:len(parts.knots_v) - dv])) - 1, 1)

    def sample(nu: int, nv: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        s, t = np.linspace(0, 1, nu), np.linspace(0, 1, nv)
        return s, t, rational_points(parts, s, t)

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


def object_input(g: Any, name: str, obj: RhinoObject | None = None) -> RhinoInput:
    """The :class:`RhinoInput` (no units) of one Rhino object ``g``: a mesh's arrays, or the
    B-spline of a NURBS surface or single-face Brep (a reversed face flips ``u``; a trimmed
    face gives its whole underlying surface, said in the notes). :class:`InputError` for any
    other object (``name`` names it in messages; ``obj`` is its record, made when None)."""
    if obj is None:
        kind, usable = rh.geometry_kind(g)
        if not usable:
            raise InputError(f"{name}: a {kind} is not a target surface; connect a mesh, a "
                             "NURBS surface or a single-face Brep")
        obj = RhinoObject(kind=kind, name="", id="", layer="", geometry=g)
    out = RhinoInput(units=None, object=obj, name=name)
    if obj.kind == "mesh":
        out.V, out.P, out.sizes = _mesh_arrays(g, name)
        return out
    ns, reversed_, trimmed = rh.surface_nurbs(g)
    if trimmed:
        out.notes.append("the Brep face is trimmed: its whole underlying surface is used")
    if ns is None:
        raise InputError(f"{name}: {obj.label()} has no NURBS form; convert it to a NURBS "
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
    model = rh.read_file(path)
    if model is None:
        raise InputError(f"{name}: not a readable Rhino .3dm file (corrupt or truncated); save "
                         "it again from Rhino (File > Save As, version 7 or 8)")
    units = file_units(model, name)
    pick = _pick(_objects(model), obj, name)
    out = object_input(pick.geometry, name, pick)
    out.units = units
    return out
