"""rhino3dm geometry <-> arrays for the Hops components (model units at the edges: metres in,
metres out for designs, millimetres for cut curves).

A target comes in as a ``Rhino.Geometry.Mesh`` (quads and triangles), a NURBS surface or a
single-face Brep (sampled on a grid of ``samples x samples`` points into a quad mesh).
"""
from __future__ import annotations

import json
from typing import Any

import numpy as np

from gridshell.core.errors import InputError
from gridshell.export.rhino_geometry import mesh as _mesh

#: grid of points a surface is sampled on
SURFACE_SAMPLES = 24


def decode(item: dict) -> Any:
    """The rhino3dm object of one Hops input item ``{"type": ..., "data": "<json>"}``."""
    import rhino3dm

    data = item["data"]
    obj = rhino3dm.CommonObject.Decode(json.loads(data) if isinstance(data, str) else data)
    if obj is None:
        raise InputError(f"could not read the {item.get('type', 'geometry')} input; connect a "
                         "mesh or a surface")
    return obj


def mesh_arrays(m) -> tuple[np.ndarray, np.ndarray]:
    """``(V (n,3), F (m,4) or (m,3))`` of a rhino3dm Mesh; quads if it has any quads (triangles
    padded with -1 are not accepted downstream, so a mixed mesh is split into triangles)."""
    V = np.array([[m.Vertices[i].X, m.Vertices[i].Y, m.Vertices[i].Z]
                  for i in range(len(m.Vertices))], float).reshape(-1, 3)
    faces = [tuple(m.Faces[i]) for i in range(len(m.Faces))]
    if not len(V) or not faces:
        raise InputError("the mesh is empty; connect a mesh with faces")
    quads = [f for f in faces if f[2] != f[3]]
    if len(quads) == len(faces):
        return V, np.array(quads, np.int64)
    tris = []
    for a, b, c, d in faces:
        tris.append((a, b, c))
        if c != d:
            tris.append((a, c, d))
    return V, np.array(tris, np.int64)


def surface_arrays(srf, samples: int = SURFACE_SAMPLES) -> tuple[np.ndarray, np.ndarray]:
    """A quad mesh ``(V, F)`` of ``samples x samples`` points of a rhino3dm surface (or the
    first face of a Brep) on its parameter domain."""
    from gridshell.geometry.grid import grid_quads

    if hasattr(srf, "Faces") and hasattr(srf, "Surfaces"):       # a Brep
        if len(srf.Faces) != 1:
            raise InputError(f"the Brep has {len(srf.Faces)} faces; connect one surface")
        srf = srf.Faces[0].UnderlyingSurface()
    du, dv = srf.Domain(0), srf.Domain(1)
    u = np.linspace(du.T0, du.T1, samples)
    v = np.linspace(dv.T0, dv.T1, samples)
    P = np.array([[[(p := srf.PointAt(a, b)).X, p.Y, p.Z] for b in v] for a in u], float)
    return P.reshape(-1, 3), grid_quads(samples, samples)


def target_arrays(obj) -> tuple[np.ndarray, np.ndarray]:
    """``(V, F)`` of a target: a mesh as it is, a surface or Brep sampled."""
    import rhino3dm

    if isinstance(obj, rhino3dm.Mesh):
        V, F = mesh_arrays(obj)
    elif hasattr(obj, "PointAt") or isinstance(obj, rhino3dm.Brep):
        V, F = surface_arrays(obj)
    else:
        raise InputError(f"a {type(obj).__name__} is not a target surface; connect a mesh or "
                         "a surface")
    if not np.all(np.isfinite(V)):
        raise InputError("the target has non-finite vertex coordinates; clean the mesh")
    return V, F


def to_mesh(V: np.ndarray, F: np.ndarray):
    """A rhino3dm Mesh of ``V (n,3)`` and faces ``F (m,3|4)``."""
    return _mesh(V, F)


def to_polyline(P: np.ndarray):
    """A rhino3dm PolylineCurve through ``P (k,2|3)`` (z = 0 for 2D points)."""
    import rhino3dm

    P = np.asarray(P, float)
    if P.shape[1] == 2:
        P = np.column_stack([P, np.zeros(len(P))])
    return rhino3dm.PolylineCurve([rhino3dm.Point3d(*map(float, p)) for p in P])


def to_circle(c: np.ndarray, r: float):
    """A rhino3dm NurbsCurve of the circle of centre ``c (2,)`` and radius ``r`` (z = 0)."""
    import rhino3dm

    return rhino3dm.Circle(rhino3dm.Point3d(float(c[0]), float(c[1]), 0.0),
                           float(r)).ToNurbsCurve()
