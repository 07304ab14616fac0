"""The .3dm export's bulk mesh construction gives the mesh that adding vertices and faces one
by one gives (same double-precision vertices, same faces in the same order)."""
from __future__ import annotations

import numpy as np
import pytest
import rhino3dm

from gridshell.core.errors import InputError
from gridshell.export import rhino_geometry as geo


def _one_by_one(V, F):
    """The straightforward construction (the code before the bulk path)."""
    m = rhino3dm.Mesh()
    m.Vertices.UseDoublePrecisionVertices = True
    for x, y, z in np.asarray(V, float).tolist():
        m.Vertices.AddPoint3d(x, y, z)
    for f in np.asarray(F, np.int64).tolist():
        f = [i for i in f if i >= 0]
        m.Faces.AddFace(*f)
    m.Normals.ComputeNormals()
    m.Compact()
    return m


def _arrays(m):
    V = np.array([[p.X, p.Y, p.Z] for p in
                  (m.Vertices.Point3dAt(i) for i in range(len(m.Vertices)))])
    F = np.array([list(m.Faces[i]) for i in range(m.Faces.Count)])
    N = np.array([[n.X, n.Y, n.Z] for n in (m.Normals[i] for i in range(len(m.Normals)))])
    return V, F, N


@pytest.mark.parametrize("shape", ["tri", "quad", "mixed"])
def test_bulk_mesh_equals_one_by_one(shape):
    rng = np.random.default_rng(3)
    V = rng.normal(size=(60, 3)) * 1e3 + 1e-7 * rng.normal(size=(60, 3))  # float64 digits
    if shape == "tri":
        F = rng.integers(0, 60, (80, 3))
    elif shape == "quad":
        F = rng.integers(0, 60, (80, 4))
    else:
        F = rng.integers(0, 60, (80, 4))
        F[::3, 3] = -1
        F[1::6, 1] = -1      # a padding index not at the end (rows 1 mod 3)
    fast, slow = geo.mesh(V, F), _one_by_one(V, F)
    (Vf, Ff, Nf), (Vs, Fs, Ns) = _arrays(fast), _arrays(slow)
    assert np.array_equal(Vf, Vs) and np.array_equal(Ff, Fs) and np.array_equal(Nf, Ns)
    # double precision kept: every vertex left after Compact() is one of V, bit for bit
    assert (Vf[:, None, :] == V[None, :, :]).all(axis=2).any(axis=1).all()
    assert fast.Faces.Count == len(F) and fast.Faces.QuadCount == slow.Faces.QuadCount


def test_bulk_mesh_rejects_faces_that_are_not_triangles_or_quads():
    V = np.zeros((5, 3))
    with pytest.raises(InputError, match="2 corners"):
        geo.mesh(V, np.array([[0, 1, -1, -1]]))
    with pytest.raises(InputError, match="5 corners"):
        geo.mesh(V, np.array([[0, 1, 2, 3, 4]]))


def test_unwelded_sides_equal_the_row_wise_unique():
    """The integer-key unique gives what np.unique over (side, vertex) rows gives."""
    from gridshell.export.rhino import unwelded_sides
    from gridshell.geometry.strips3d import strip_solid

    t = np.linspace(0, 1, 17)
    P = np.column_stack([t, np.sin(2 * t), 0.1 * t])
    V, F = strip_solid(P, np.tile([0.0, 0.3, 1.0], (17, 1)), 0.2, 0.01, False)
    n_side = (len(F) - 4) // 4
    side = np.concatenate([np.repeat(np.arange(4), n_side), [4, 4, 5, 5]])
    key = np.stack([np.repeat(side, 3), np.asarray(F, np.int64).reshape(-1)], axis=1)
    uniq, inverse = np.unique(key, axis=0, return_inverse=True)
    V2, F2 = unwelded_sides(V, F)
    assert np.array_equal(V2, np.asarray(V, float)[uniq[:, 1]])
    assert np.array_equal(F2, inverse.reshape(-1, 3))
    assert np.array_equal(V2[F2], np.asarray(V, float)[F])     # the same triangles


def _attributes(obj):
    a = obj.Attributes
    return (a.LayerIndex, a.Name, a.GetUserStrings(), a.Visible, a.Mode, a.ColorSource,
            str(a.ObjectColor), a.PlotColorSource, a.PlotWeight)


def test_shared_attributes_equal_one_set_per_object(tmp_path):
    """Objects added with one shared set of attributes (_Model.shared, _Model.again: a part's
    holes and labels, a strip and its axis) read back with the attributes one new set per
    object gives, each object its own (distinct ids, the name it was added with); counts per
    layer as with one set each."""
    from gridshell.export.rhino import _Model
    from gridshell.core.units import parse_units

    def model(shared: bool):
        m = _Model(parse_units("mm"))
        m.layer("a", (1, 2, 3, 255))
        m.layer("b", (4, 5, 6, 255))
        strings = {"lamella_id": 3, "family": 1, "joints": "1 2 3"}
        circles = [geo.circle((float(i), 0.0), 0.5, 1.0) for i in range(3)]
        if shared:
            a = m.shared(3, "a", "L3 hole", role="hole", **strings)
            for c in circles:
                m.model.Objects.AddCircle(c, a)
            a = m.attrs("a", "L3", **strings)
            m.model.Objects.AddPoint(rhino3dm.Point3d(0, 0, 0), a)
            m.model.Objects.AddPoint(rhino3dm.Point3d(1, 0, 0), m.again(a, "b", "L3 axis"))
            a = m.shared(0, "b", "", joint_id="-", lamellae="-")
            for j, lams in joints:
                m.model.Objects.AddPoint(rhino3dm.Point3d(j, 1, 0),
                                         m.again(a, "b", f"J{j}", joint_id=j, lamellae=lams))
        else:
            for c in circles:
                m.model.Objects.AddCircle(c, m.attrs("a", "L3 hole", role="hole", **strings))
            m.model.Objects.AddPoint(rhino3dm.Point3d(0, 0, 0), m.attrs("a", "L3", **strings))
            m.model.Objects.AddPoint(rhino3dm.Point3d(1, 0, 0),
                                     m.attrs("b", "L3 axis", **strings))
            for j, lams in joints:
                m.model.Objects.AddPoint(rhino3dm.Point3d(j, 1, 0),
                                         m.attrs("b", f"J{j}", joint_id=j, lamellae=lams))
        path = tmp_path / f"{shared}.3dm"
        assert m.model.Write(str(path), 8)
        return rhino3dm.File3dm.Read(str(path)), m.counts

    # a joint on no lamella has no "lamellae" string (an empty value sets none, and removes
    # one the shared set had): the same keys in the same order as a new set each
    joints = [(0, "1 2"), (1, ""), (2, "3"), (3, "")]
    (one, counts1), (each, counts2) = model(True), model(False)
    assert counts1 == counts2 == {"a": 4, "b": 5}
    assert len(one.Objects) == len(each.Objects) == 9
    assert [_attributes(o) for o in one.Objects] == [_attributes(o) for o in each.Objects]
    assert [o.Attributes.Name for o in one.Objects] == \
        ["L3 hole"] * 3 + ["L3", "L3 axis"] + [f"J{j}" for j in range(4)]
    assert [o.Attributes.GetUserStrings() for o in one.Objects][5:7] == \
        [(("joint_id", "0"), ("lamellae", "1 2")), (("joint_id", "1"),)]
    assert len({str(o.Attributes.Id) for o in one.Objects}) == 9
    assert [o.Geometry.Encode()["data"] for o in one.Objects] == \
        [o.Geometry.Encode()["data"] for o in each.Objects]


@pytest.mark.parametrize("shape", [(0, 3), (1, 3), (57, 3), (9, 2)])
def test_point_list_equals_one_by_one(shape):
    """point_list (points added through map) holds the points a loop adding them one by one
    holds, in order (z = 0 for 2-d input), and makes the same polyline curve."""
    P = np.random.default_rng(3).normal(size=shape) * 1e3
    ref = rhino3dm.Point3dList()
    for p in P.tolist():
        ref.Add(p[0], p[1], p[2] if len(p) == 3 else 0.0)
    pts = geo.point_list(P)
    assert pts.Count == ref.Count == shape[0]
    assert [(q.X, q.Y, q.Z) for q in (pts[i] for i in range(pts.Count))] == \
        [(q.X, q.Y, q.Z) for q in (ref[i] for i in range(ref.Count))]
    if shape[0] >= 2:
        assert rhino3dm.PolylineCurve(pts).Encode()["data"] == \
            rhino3dm.PolylineCurve(ref).Encode()["data"]


def test_cylinder_equals_the_circle_at_its_centre_construction():
    """geo.cylinder (a circle of the radius given its plane) writes the extrusion that a
    circle made at the base centre and then given the same plane makes."""
    rng = np.random.default_rng(5)
    for centre, axis in zip(rng.normal(size=(20, 3)), rng.normal(size=(20, 3))):
        a = axis / np.linalg.norm(axis)
        base = centre - 0.5 * 0.01 * a
        c = rhino3dm.Circle(rhino3dm.Point3d(*base.tolist()), 0.015)
        c.Plane = rhino3dm.Plane(rhino3dm.Point3d(*base.tolist()), rhino3dm.Vector3d(*a.tolist()))
        ref = rhino3dm.Extrusion.CreateCylinderExtrusion(rhino3dm.Cylinder(c, 0.01), True, True)
        assert geo.cylinder(centre, axis, 0.015, 0.01).Encode()["data"] == ref.Encode()["data"]
