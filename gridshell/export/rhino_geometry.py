"""Rhino geometry from numpy arrays for the .3dm export: meshes, polylines, planar bulge paths,
cylinders (extrusions), NURBS surfaces. Coordinates are taken as given (the caller converts
units).

The Rhino objects themselves are built by :mod:`gridshell.geometry.rhino_adapter` (the one
module that imports rhino3dm); this module adds what only the export needs: a cut path of
straight spans and DXF bulge arcs (:func:`bulge_curve`).
"""
from __future__ import annotations

from typing import Any

import numpy as np

from gridshell.geometry import rhino_adapter as rh

__all__ = ["mesh", "point_list", "bulge_curve", "circle", "cylinder",
           "nurbs_surface"]

#: a Rhino mesh of ``V (n,3)`` (double precision) and faces ``F (m,3|4)``
mesh = rh.mesh
#: a ``Point3dList`` of ``P (k,3)`` (or ``(k,2)``, z = 0)
point_list = rh.point_list
#: a ``Circle`` in the plane ``z``, centre ``(x, y)``
circle = rh.circle
#: a capped cylinder (``Extrusion``) of a radius and a height about a centre and an axis
cylinder = rh.cylinder
#: a non-rational ``NurbsSurface`` of full knot vectors and control points ``(nu, nv, 3)``
nurbs_surface = rh.bspline_to_nurbs


def bulge_curve(V: np.ndarray, B: np.ndarray | None, closed: bool, z: float = 0.0) -> Any:
    """A planar curve at height ``z`` through ``V (n,2)`` whose span after vertex ``i`` is a
    straight segment (``B[i] = 0``) or the circular arc of bulge ``B[i]`` (DXF convention:
    included angle ``4 atan(b)``, counter-clockwise for ``b > 0``): a ``PolylineCurve`` when
    there is no arc, else a ``PolyCurve`` of lines and arcs (exact, as in the DXF)."""
    V = np.asarray(V, float).reshape(-1, 2)
    B = np.zeros(len(V)) if B is None else np.asarray(B, float).reshape(-1)
    n = len(V)
    spans = n if closed else n - 1
    if not np.any(B[:spans] != 0):
        P = np.vstack([V, V[:1]]) if closed else V
        return rh.polyline_curve(np.column_stack([P, np.full(len(P), float(z))]))
    return rh.polycurve(bulge_spans(V, B, closed, z))


def bulge_spans(V: np.ndarray, B: np.ndarray, closed: bool,
                z: float = 0.0) -> list[tuple[np.ndarray, ...]]:
    """The spans of the bulge path ``V (n,2)``, ``B (n,)`` at height ``z`` as
    :func:`gridshell.geometry.rhino_adapter.polycurve` takes them: ``(a, b)`` for a straight
    span, ``(a, mid, b)`` (points ``(3,)``) for an arc; spans of zero length left out."""
    from gridshell.fabrication.path import arc_geometry

    n = len(V)
    out: list[tuple[np.ndarray, ...]] = []
    for i in range(n if closed else n - 1):
        a, b = V[i], V[(i + 1) % n]
        if np.allclose(a, b):
            continue
        if B[i] == 0:
            out.append((np.append(a, z), np.append(b, z)))
            continue
        centre, r, theta = arc_geometry(a, b, float(B[i]))
        a0 = np.arctan2(a[1] - centre[1], a[0] - centre[0])
        mid = centre + r * np.array([np.cos(a0 + theta / 2), np.sin(a0 + theta / 2)])
        out.append((np.append(a, z), np.append(mid, z), np.append(b, z)))
    return out
