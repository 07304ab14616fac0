"""The one module that imports rhino3dm (8.x): Rhino geometry <-> numpy arrays, and .3dm files.

Everything that reads or builds a Rhino object goes through here - the .3dm reader
(:mod:`gridshell.io.rhino`), the Grasshopper server (:mod:`gridshell.server.rhino`) and the
.3dm export (:mod:`gridshell.export`) - so that one Rhino object gives one set of arrays
whichever door it comes in by:

- a mesh is ``V (n,3) float64`` (the double-precision vertices a .3dm or a Hops message
  stores, never their float32 copies) and its faces as Rhino keeps them, triangles and quads in
  one padded array ``P (m,4)`` (``-1`` in the fourth column of a triangle) with their sizes;
- a NURBS surface is our :class:`~gridshell.geometry.bspline.BSplineSurface` (eq. 4.1) exactly:
  the same degrees and control points, Rhino's ``count + order - 2`` knots per direction with
  one end knot added at each end (end knots take no part in the surface on its domain), the
  knots mapped affinely onto ``[0, 1]`` (the same surface); a rational surface (weights not
  all equal) has no B-spline form and is refused by :func:`nurbs_to_bspline` (its parts,
  weights included, are :func:`nurbs_parts`);
- coordinates are taken as given (the callers convert units).

rhino3dm is imported on first use (:func:`rhino`), so importing this module is cheap.
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Any

import numpy as np

from gridshell.core.errors import InputError

__all__ = ["Model3dm", "NurbsParts", "bspline_to_nurbs", "circle", "circle_curve", "cylinder",
           "decode", "geometry_kind", "is_mesh", "mesh", "mesh_arrays", "model_objects",
           "nurbs_parts", "nurbs_to_bspline", "point", "point_list", "polycurve",
           "polyline_curve", "read_file", "rhino", "surface_nurbs", "unit_system_name",
           "write_file"]


def rhino() -> Any:
    """The rhino3dm module (imported here, once); :class:`InputError` if it is missing."""
    try:
        import rhino3dm
    except ImportError:  # pragma: no cover - a dependency of the package
        raise InputError("rhino3dm is not installed; install it with 'pip install rhino3dm' "
                         "to read or write .3dm files") from None
    return rhino3dm


# ----------------------------------------------------------------------------- files


def read_file(path: str | os.PathLike) -> Any:
    """The ``File3dm`` of the file at ``path``, None when rhino3dm cannot read it."""
    return rhino().File3dm.Read(str(path))


def write_file(model: Any, path: str | os.PathLike, version: int = 8) -> bool:
    """Write ``model`` (a ``File3dm``) to ``path`` as a .3dm of ``version``; False on failure."""
    return bool(model.Write(str(path), int(version)))


def unit_system_name(model: Any) -> str:
    """The name of a File3dm's model unit system (``"Meters"``, ``"Millimeters"``, ``"None"``)."""
    us = model.Settings.ModelUnitSystem
    return getattr(us, "name", str(us)).split(".")[-1]


def model_objects(model: Any) -> list[tuple[Any, str, str, str]]:
    """``(geometry, name, id, layer)`` of every object of a File3dm, in file order (the layer's
    full path, ``"?"`` for a file without a layer table)."""
    out = []
    for obj in model.Objects:
        g, a = obj.Geometry, obj.Attributes
        try:
            layer = model.Layers[a.LayerIndex].FullPath or model.Layers[a.LayerIndex].Name
        except Exception:  # noqa: BLE001 - a file without layer table
            layer = "?"
        out.append((g, a.Name or "", str(a.Id), layer))
    return out


def decode(data: dict) -> Any:
    """The Rhino object of its JSON form (``CommonObject.Encode``: what Hops sends), None when
    it is not one."""
    try:
        return rhino().CommonObject.Decode(data)
    except (TypeError, ValueError):
        return None


#: rhino3dm class name -> what a user calls it
_CURVES = {"LineCurve": "curve", "NurbsCurve": "curve", "PolylineCurve": "curve",
           "ArcCurve": "curve", "PolyCurve": "curve", "Point": "point",
           "PointCloud": "point cloud"}


def geometry_kind(g: Any) -> tuple[str, bool]:
    """``(kind, usable)`` of a Rhino object as a target surface: ``"mesh"``, ``"NURBS
    surface"`` and ``"Brep (1 face)"`` are usable; a Brep of several faces, an extrusion, a
    curve, a point ... are not (``kind`` names them)."""
    r = rhino()
    if isinstance(g, r.Mesh):
        return "mesh", True
    if isinstance(g, r.Brep):
        n = len(g.Faces)
        return ("Brep (1 face)", True) if n == 1 else (f"Brep of {n} faces", False)
    if isinstance(g, r.Extrusion):
        return "extrusion", False
    if isinstance(g, r.Surface):
        return "NURBS surface", True
    name = type(g).__name__
    return _CURVES.get(name, name), False


def is_mesh(g: Any) -> bool:
    """Whether ``g`` is a Rhino mesh."""
    return isinstance(g, rhino().Mesh)


# ----------------------------------------------------------------------------- meshes


def mesh_arrays(m: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(V (n,3) float64, P (m,4) int64, sizes (m,))`` of a Rhino mesh: the double-precision
    vertices (``ToPoint3dArray``; a mesh without them gives its float32 ones exactly), the
    faces in Rhino's order, a triangle ``(a, b, c, c)`` as ``(a, b, c, -1)`` of size 3."""
    pts = m.Vertices.ToPoint3dArray()
    V = np.array([(p.X, p.Y, p.Z) for p in pts], dtype=np.float64).reshape(-1, 3)
    faces = m.Faces
    P = np.array([tuple(faces[i]) for i in range(len(faces))], dtype=np.int64).reshape(-1, 4)
    tri = P[:, 2] == P[:, 3]
    P[tri, 3] = -1
    return V, P, np.where(tri, 3, 4).astype(np.int64)


def mesh(V: np.ndarray, F: np.ndarray, what: str = "surface", compact: bool = True) -> Any:
    """A Rhino mesh of vertices ``V (n,3)`` (stored in double precision, as the bundle's) and
    triangle / quad faces ``F (m,3|4)`` (negative indices pad a triangle in a quad array);
    :class:`InputError` naming a face of another number of corners (``what`` names the mesh).
    ``compact``: drop the vertices no face uses (False keeps every vertex, in order: a net's
    joints that lie on no loop)."""
    V = np.asarray(V, float).reshape(-1, 3)
    F = np.asarray(F, np.int64)
    F = F.reshape(len(F), -1) if F.size else F.reshape(0, 3)
    m = rhino().Mesh()
    verts, faces = m.Vertices, m.Faces   # one wrapper each (every attribute access makes one)
    verts.UseDoublePrecisionVertices = True
    # one Python-level call per vertex / face through map(), the arrays' columns as arguments
    # (rhino3dm 8 has no bulk constructor); same vertices and faces, same order, as adding
    # them one by one
    if len(V):
        list(map(verts.AddPoint3d, *V.T.tolist()))
    n_corners = (F >= 0).sum(axis=1)
    bad = np.flatnonzero((n_corners < 3) | (n_corners > 4))
    if len(bad):
        f = [i for i in F[bad[0]].tolist() if i >= 0]
        raise InputError(f"{what} face {f} has {len(f)} corners; only triangles and quads "
                         "can go into a Rhino mesh")
    if F.shape[1] == 3 or (F.shape[1] == 4 and np.all(n_corners == 4)):
        if len(F):
            list(map(faces.AddFace, *F.T.tolist()))
    else:       # mixed triangles (padded with negative indices) and quads: keep the order
        add = faces.AddFace
        for f in F.tolist():
            add(*[i for i in f if i >= 0])
    m.Normals.ComputeNormals()
    if compact:
        m.Compact()
    return m


# ----------------------------------------------------------------------------- NURBS surfaces


@dataclass(frozen=True)
class NurbsParts:
    """A Rhino NURBS surface as arrays: degrees, full knot vectors (``n + degree + 1`` each, on
    Rhino's own domain), control points ``ctrl (nu, nv, 3)`` (Euclidean, not weighted) and
    ``weights (nu, nv)``; ``rational`` when the weights are not all equal."""

    degree_u: int
    degree_v: int
    knots_u: np.ndarray
    knots_v: np.ndarray
    ctrl: np.ndarray
    weights: np.ndarray
    rational: bool

    def unit_knots(self) -> tuple[np.ndarray, np.ndarray]:
        """The knot vectors mapped affinely onto the domain ``[0, 1]`` (the same surface)."""
        return (_unit(self.knots_u, self.degree_u, len(self.ctrl)),
                _unit(self.knots_v, self.degree_v, self.ctrl.shape[1]))


def _unit(knots: np.ndarray, d: int, n: int) -> np.ndarray:
    a, b = float(knots[d]), float(knots[n])
    if not b > a:
        raise InputError("the NURBS surface has an empty parameter domain; the file is corrupt, "
                         "export it again")
    return (knots - a) / (b - a)


def surface_nurbs(g: Any) -> tuple[Any, bool, bool]:
    """``(ns, reversed, trimmed)`` of a surface or a single-face Brep: its NURBS form (None
    when it has none), whether the Brep face's normal is the surface's reversed, and whether
    the face is trimmed (its whole underlying surface is ``ns``)."""
    r = rhino()
    if isinstance(g, r.Brep):
        face = g.Faces[0]
        srf = face.UnderlyingSurface()
        ns = srf if isinstance(srf, r.NurbsSurface) else srf.ToNurbsSurface()
        return ns, bool(face.OrientationIsReversed), not bool(g.IsSurface)
    return (g if isinstance(g, r.NurbsSurface) else g.ToNurbsSurface()), False, False


def nurbs_parts(ns: Any, name: str = "the NURBS surface") -> NurbsParts:
    """The :class:`NurbsParts` of a rhino3dm NurbsSurface: Rhino's ``count + order - 2`` knots
    per direction with the first and the last repeated once (the superfluous end knots of
    openNURBS, which no basis function on the domain depends on)."""
    du, dv = ns.OrderU - 1, ns.OrderV - 1
    nu, nv = ns.Points.CountU, ns.Points.CountV
    ku = np.array([ns.KnotsU[i] for i in range(len(ns.KnotsU))], dtype=np.float64)
    kv = np.array([ns.KnotsV[i] for i in range(len(ns.KnotsV))], dtype=np.float64)
    if len(ku) != nu + du - 1 or len(kv) != nv + dv - 1:  # Rhino: count + order - 2
        raise InputError(f"{name}: the NURBS surface has {len(ku)} x {len(kv)} knots for "
                         f"{nu} x {nv} control points of order {du + 1} x {dv + 1}; the file is "
                         "corrupt, export it again")
    pts = ns.Points
    H = np.array([[(p := pts[i, j]).X, p.Y, p.Z, p.W] for i in range(nu) for j in range(nv)],
                 dtype=np.float64).reshape(nu, nv, 4)
    W = H[..., 3].copy()
    if not (np.all(np.isfinite(H)) and np.all(W > 0)):
        raise InputError(f"{name}: the NURBS surface has non-finite control points or weights "
                         "that are not positive; rebuild it in Rhino")
    rational = bool(ns.IsRational)
    C = H[..., :3] / W[..., None] if rational else H[..., :3]  # homogeneous when rational
    rational = rational and not np.allclose(W, W.flat[0], rtol=1e-12, atol=0)
    return NurbsParts(du, dv, np.concatenate([ku[:1], ku, ku[-1:]]),
                      np.concatenate([kv[:1], kv, kv[-1:]]), C, W, rational)


def nurbs_to_bspline(ns: Any, name: str = "the NURBS surface") -> Any:
    """The :class:`~gridshell.geometry.bspline.BSplineSurface` a non-rational NURBS surface is
    (control points as given, knots on ``[0, 1]``); :class:`InputError` for a rational one,
    which no B-spline represents exactly."""
    from gridshell.geometry.bspline import BSplineSurface

    parts = ns if isinstance(ns, NurbsParts) else nurbs_parts(ns, name)
    if parts.rational:
        raise InputError(f"{name}: the NURBS surface is rational (weights "
                         f"{parts.weights.min():.6g} to {parts.weights.max():.6g}), which a "
                         "B-spline cannot represent exactly; rebuild it non-rational in Rhino "
                         "(Rebuild) or read it through the .3dm reader, which fits one")
    ku, kv = parts.unit_knots()
    return BSplineSurface(parts.degree_u, parts.degree_v, ku, kv, parts.ctrl.copy())


def bspline_to_nurbs(degree_u: int, degree_v: int, knots_u: np.ndarray, knots_v: np.ndarray,
                     ctrl: np.ndarray) -> Any:
    """A non-rational Rhino NurbsSurface from full knot vectors (``n + degree + 1`` values
    each, as :class:`~gridshell.geometry.bspline.BSplineSurface` holds them) and control points
    ``ctrl (nu, nv, 3)``. Rhino drops the first and the last knot of each vector."""
    r = rhino()
    ctrl = np.asarray(ctrl, float)
    nu, nv, _ = ctrl.shape
    ns = r.NurbsSurface.Create(3, False, degree_u + 1, degree_v + 1, nu, nv)
    for k, t in enumerate(np.asarray(knots_u, float)[1:-1].tolist()):
        ns.KnotsU[k] = t
    for k, t in enumerate(np.asarray(knots_v, float)[1:-1].tolist()):
        ns.KnotsV[k] = t
    pts, P4 = ns.Points, r.Point4d
    for i in range(nu):
        for j in range(nv):
            x, y, z = ctrl[i, j].tolist()
            pts[i, j] = P4(x, y, z, 1.0)
    return ns


# ----------------------------------------------------------------------------- curves, points


def point(p: Any, z: float | None = None) -> Any:
    """A ``Point3d`` of ``p (3,)``, or of ``p (2,)`` at height ``z``."""
    p = [float(c) for c in p]
    return rhino().Point3d(p[0], p[1], float(z) if z is not None else p[2])


def point_list(P: np.ndarray) -> Any:
    """A ``Point3dList`` of ``P (k,3)`` (or ``(k,2)``, z = 0)."""
    P = np.asarray(P, float)
    if P.ndim == 2 and P.shape[1] == 2:
        P = np.column_stack([P, np.zeros(len(P))])
    pts = rhino().Point3dList()
    # one Add per point through map(), the columns as arguments: the points of a loop
    # adding them one by one, in order, at ~2/3 of its time
    list(map(pts.Add, *P.reshape(-1, 3).T.tolist()))
    return pts


def polyline_curve(P: np.ndarray) -> Any:
    """A ``PolylineCurve`` through ``P (k,3)`` (or ``(k,2)``, z = 0)."""
    return rhino().PolylineCurve(point_list(P))


def polycurve(spans: list[tuple[np.ndarray, ...]]) -> Any:
    """A ``PolyCurve`` of straight segments ``(a, b)`` and circular arcs ``(a, mid, b)``
    (through three points ``(3,)`` each), joined in order."""
    r = rhino()
    pc = r.PolyCurve()
    for s in spans:
        if len(s) == 2:
            pc.Append(r.Line(point(s[0]), point(s[1])))
        else:
            pc.Append(r.Arc(point(s[0]), point(s[1]), point(s[2])))
    return pc


def circle(centre: Any, radius: float, z: float = 0.0) -> Any:
    """A ``Circle`` in the plane ``z``, centre ``(x, y)`` (``Objects.AddCircle`` takes it)."""
    return rhino().Circle(point(centre[:2], z), float(radius))


def circle_curve(centre: Any, radius: float, z: float = 0.0) -> Any:
    """The circle of :func:`circle` as a ``NurbsCurve`` (a curve output)."""
    return circle(centre, radius, z).ToNurbsCurve()


def cylinder(centre: np.ndarray, axis: np.ndarray, radius: float, height: float) -> Any:
    """A closed cylinder (capped ``Extrusion``: Rhino's own light representation of a
    cylinder, as its Cylinder command makes) of ``radius`` and ``height`` centred at
    ``centre (3,)`` along the unit ``axis (3,)``. The same solid as a capped Brep cylinder
    (``Cylinder.ToBrep``), at ~1/7 of its size in the file and ~1/5 of its write time."""
    r = rhino()
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    base = np.asarray(centre, float) - 0.5 * height * axis
    c = r.Circle(float(radius))      # its plane replaced: centre and axis from here
    c.Plane = r.Plane(r.Point3d(*base.tolist()), r.Vector3d(*axis.tolist()))
    return r.Extrusion.CreateCylinderExtrusion(r.Cylinder(c, float(height)), True, True)


# ----------------------------------------------------------------------------- a model to write


class Model3dm:
    """A new File3dm (``model``) in the unit system ``unit_system`` (a rhino3dm
    ``UnitSystem`` member name, e.g. ``"Millimeters"``) with absolute tolerance ``tolerance``
    (model units), named layers and object attributes with user strings; ``counts`` holds the
    objects given attributes per layer."""

    def __init__(self, unit_system: str, tolerance: float, application: str = "gridshell"):
        r = rhino()
        self.r = r
        self.model = r.File3dm()
        self.model.Settings.ModelUnitSystem = getattr(r.UnitSystem, unit_system)
        self.model.Settings.ModelAbsoluteTolerance = float(tolerance)
        self.model.ApplicationName = application
        self.layers: dict[str, int] = {}
        self.counts: dict[str, int] = {}

    def layer(self, name: str, colour: tuple[int, int, int, int]) -> None:
        """Add the layer ``name`` of RGBA ``colour`` (0-255)."""
        layer = self.r.Layer()
        layer.Name = name
        layer.Color = colour
        self.layers[name] = self.model.Layers.Add(layer)
        self.counts[name] = 0

    def attrs(self, layer: str, name: str = "", **strings: object) -> Any:
        """New ``ObjectAttributes`` on ``layer``, named ``name``, with the user strings
        ``strings`` (values as ``str``)."""
        a = self.r.ObjectAttributes()
        a.LayerIndex = self.layers[layer]
        if name:
            a.Name = name
        for k, v in strings.items():
            a.SetUserString(k, str(v))
        self.counts[layer] += 1
        return a

    def shared(self, n: int, layer: str, name: str, **strings: object) -> Any:
        """:meth:`attrs` for ``n`` objects at once (counted ``n`` times; 0: each counted as
        :meth:`again` hands the set out): rhino3dm copies the attributes into each object it
        adds, so objects with equal attributes (a part's holes, its label strokes) can share
        one set."""
        a = self.attrs(layer, name, **strings)
        self.counts[layer] += n - 1
        return a

    def again(self, a: Any, layer: str, name: str, **strings: object) -> Any:
        """The attributes ``a`` (:meth:`attrs`) for one more object on ``layer`` named
        ``name``, with the user strings ``strings`` set to new values (keys ``a`` has keep
        their place, as a new :meth:`attrs` with the same keys in the same order would
        give) and the others kept: rhino3dm copies the attributes into each object it adds,
        so one set serves a run of objects whose attributes differ in a few values."""
        a.LayerIndex = self.layers[layer]
        a.Name = name
        for k, v in strings.items():
            a.SetUserString(k, str(v))
        self.counts[layer] += 1
        return a

    def strings(self, values: dict[str, str]) -> None:
        """Set the model's own user strings (``model.Strings``)."""
        for k, v in values.items():
            self.model.Strings[k] = v
