"""rhino3dm geometry from numpy arrays: meshes, polylines, planar bulge paths, cylinders
(extrusions), NURBS surfaces. Coordinates are taken as given (the caller converts units).

``rhino3dm`` is imported inside each function, so importing this module is cheap.
"""
from __future__ import annotations

import numpy as np

from gridshell.core.errors import InputError

__all__ = ["mesh", "point_list", "bulge_curve", "circle", "cylinder",
           "nurbs_surface"]


def mesh(V: np.ndarray, F: np.ndarray, what: str = "surface"):
    """A ``rhino3dm.Mesh`` of vertices ``V (n,3)`` (double precision: read them back with
    ``Vertices.Point3dAt``) and triangle / quad faces ``F (m,3|4)`` (negative indices pad a
    triangle in a quad array)."""
    import rhino3dm

    V = np.asarray(V, float).reshape(-1, 3)
    F = np.asarray(F, np.int64)
    F = F.reshape(len(F), -1) if F.size else F.reshape(0, 3)
    m = rhino3dm.Mesh()
    verts, faces = m.Vertices, m.Faces   # one wrapper each (every attribute access makes one)
    verts.UseDoublePrecisionVertices = True     # float64 coordinates, as the bundle's
    # one Python-level call per vertex / face through map(), the arrays' columns as arguments
    # (rhino3dm 8 has no bulk constructor); same vertices and faces, same order, as adding
    # them one by one (tests/export/test_export_rhino.py)
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
    m.Compact()
    return m


def point_list(P: np.ndarray):
    """A ``rhino3dm.Point3dList`` of ``P (k,3)`` (or ``(k,2)``, z = 0)."""
    import rhino3dm

    P = np.asarray(P, float)
    if P.ndim == 2 and P.shape[1] == 2:
        P = np.column_stack([P, np.zeros(len(P))])
    pts = rhino3dm.Point3dList()
    # one Add per point through map(), the columns as arguments: the points of a loop
    # adding them one by one, in order, at ~2/3 of its time
    list(map(pts.Add, *P.reshape(-1, 3).T.tolist()))
    return pts


def _p3(p, z: float):
    import rhino3dm

    return rhino3dm.Point3d(float(p[0]), float(p[1]), float(z))


def bulge_curve(V: np.ndarray, B: np.ndarray, closed: bool, z: float = 0.0):
    """A planar curve at height ``z`` through ``V (n,2)`` whose span after vertex ``i`` is a
    straight segment (``B[i] = 0``) or the circular arc of bulge ``B[i]`` (DXF convention:
    included angle ``4 atan(b)``, counter-clockwise for ``b > 0``): a ``PolylineCurve`` when
    there is no arc, else a ``PolyCurve`` of lines and arcs (exact, as in the DXF)."""
    import rhino3dm

    from gridshell.fabrication.path import arc_geometry

    V = np.asarray(V, float).reshape(-1, 2)
    B = np.zeros(len(V)) if B is None else np.asarray(B, float).reshape(-1)
    n = len(V)
    spans = n if closed else n - 1
    if not np.any(B[:spans] != 0):
        P = np.vstack([V, V[:1]]) if closed else V
        return rhino3dm.PolylineCurve(point_list(P))
    pc = rhino3dm.PolyCurve()
    for i in range(spans):
        a, b = V[i], V[(i + 1) % n]
        if np.allclose(a, b):
            continue
        if B[i] == 0:
            pc.Append(rhino3dm.Line(_p3(a, z), _p3(b, z)))
            continue
        centre, r, theta = arc_geometry(a, b, float(B[i]))
        a0 = np.arctan2(a[1] - centre[1], a[0] - centre[0])
        mid = centre + r * np.array([np.cos(a0 + theta / 2), np.sin(a0 + theta / 2)])
        pc.Append(rhino3dm.Arc(_p3(a, z), _p3(mid, z), _p3(b, z)))
    return pc


def circle(centre, radius: float, z: float = 0.0):
    """A ``rhino3dm.Circle`` in the plane ``z``, centre ``(x, y)`` (``Objects.AddCircle``)."""
    import rhino3dm

    return rhino3dm.Circle(_p3(centre, z), float(radius))


def cylinder(centre: np.ndarray, axis: np.ndarray, radius: float, height: float):
    """A closed cylinder (capped, ``rhino3dm.Extrusion``: Rhino's own light representation
    of a cylinder, as its Cylinder command makes) of ``radius`` and ``height`` centred at
    ``centre (3,)`` along the unit ``axis (3,)``. The same solid as a capped Brep cylinder
    (``Cylinder.ToBrep``), at ~1/7 of its size in the file and ~1/5 of its write time."""
    import rhino3dm

    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    base = np.asarray(centre, float) - 0.5 * height * axis
    c = rhino3dm.Circle(float(radius))      # its plane replaced: centre and axis from here
    c.Plane = rhino3dm.Plane(rhino3dm.Point3d(*base.tolist()), rhino3dm.Vector3d(*axis.tolist()))
    return rhino3dm.Extrusion.CreateCylinderExtrusion(rhino3dm.Cylinder(c, float(height)),
                                                      True, True)


def nurbs_surface(degree_u: int, degree_v: int, knots_u: np.ndarray, knots_v: np.ndarray,
                  ctrl: np.ndarray):
    """A non-rational ``NurbsSurface`` from clamped full knot vectors (``n + degree + 1``
    values each, as :class:`gridshell.geometry.bspline.BSplineSurface` holds them) and control points
    ``ctrl (nu, nv, 3)``. Rhino drops the first and the last knot of each vector."""
    import rhino3dm

    ctrl = np.asarray(ctrl, float)
    nu, nv, _ = ctrl.shape
    ns = rhino3dm.NurbsSurface.Create(3, False, degree_u + 1, degree_v + 1, nu, nv)
    for k, t in enumerate(np.asarray(knots_u, float)[1:-1].tolist()):
        ns.KnotsU[k] = t
    for k, t in enumerate(np.asarray(knots_v, float)[1:-1].tolist()):
        ns.KnotsV[k] = t
    for i in range(nu):
        for j in range(nv):
            x, y, z = ctrl[i, j].tolist()
            ns.Points[i, j] = rhino3dm.Point4d(x, y, z, 1.0)
    return ns
