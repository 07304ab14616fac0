"""gridshell.export.rhino: write a .3dm, read it back with rhino3dm, measure what came back.

The bundles are the paraboloid cases of render_cases (z = 0.3 (x^2 + y^2), closed-form normal);
the strip section is checked against the fabrication parameters (cut width / scale), the
strips' faces against length x width, the sheets against fabricate()'s own report.
"""
from __future__ import annotations

import json

import numpy as np
import pytest
import rhino3dm
from tests.helpers.render_cases import N, make_bundle, write_case

from gridshell.design.bundle import write_bundle
from gridshell.core.errors import InputError
from gridshell.export import export_3dm
from gridshell.export.rhino import export_3dm as write_3dm
from gridshell.core.units import parse_units
from gridshell.core.units import Units

MM = {"name": "mm", "metres_per_unit": 0.001}


def _by_layer(model):
    names = [layer.Name for layer in model.Layers]
    out = {n: [] for n in names}
    for obj in model.Objects:
        out[names[obj.Attributes.LayerIndex]].append(obj)
    return names, out


def _read(path):
    model = rhino3dm.File3dm.Read(str(path))
    return (model, *_by_layer(model))


def _mesh_arrays(mesh):
    V = np.array([[p.X, p.Y, p.Z] for p in (mesh.Vertices.Point3dAt(i)
                                             for i in range(len(mesh.Vertices)))])
    F = []
    for i in range(mesh.Faces.Count):
        f = mesh.Faces[i]
        F.append(f[:3] if f[2] == f[3] else f)
    return V, F


def _tri_areas(V, F):
    out = []
    for f in F:
        tris = [f] if len(f) == 3 else [f[:3], [f[0], f[2], f[3]]]
        out.append(sum(0.5 * np.linalg.norm(np.cross(V[b] - V[a], V[c] - V[a]))
                       for a, b, c in tris))
    return np.array(out)


def _volume(V, F):
    """Signed volume of a closed triangle mesh (divergence theorem)."""
    return sum(np.dot(V[a], np.cross(V[b], V[c])) / 6.0 for a, b, c in F)


def _paraboloid_normal(P):
    n = np.column_stack([-0.6 * P[:, 0], -0.6 * P[:, 1], np.ones(len(P))])
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def _points(crv):
    if isinstance(crv, rhino3dm.PolylineCurve):
        return np.array([[crv.Point(i).X, crv.Point(i).Y, crv.Point(i).Z]
                         for i in range(crv.PointCount)])
    raise TypeError(type(crv))


def _foot(X, axis):
    """Foot points on the polyline ``axis`` (densely resampled) of the points ``X (m,3)``, and
    the unit tangent there."""
    from scipy.spatial import cKDTree

    s = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(axis, axis=0), axis=1))])
    d = np.linspace(0, s[-1], 200 * len(axis))
    A = np.stack([np.interp(d, s, axis[:, c]) for c in range(3)], axis=1)
    T = np.gradient(A, axis=0)
    _, k = cKDTree(A).query(X)
    return A[k], T[k] / np.linalg.norm(T[k], axis=1, keepdims=True)


def _faces(V, F, lam, kind):
    """Triangle areas, centroids, and which triangles are wide faces, narrow edges, end caps:
    from the triangle normals against the paraboloid's normal and the axis tangent."""
    A = _tri_areas(V, F)
    tri = V[np.asarray(F)]
    c = tri.mean(axis=1)
    nt = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    nt /= np.linalg.norm(nt, axis=1, keepdims=True)
    _, T = _foot(c, lam.axis)
    along_n = np.abs(np.sum(nt * _paraboloid_normal(c), axis=1))
    cap = np.abs(np.sum(nt * T, axis=1)) > 0.7
    across = (along_n > 0.7) if kind == "GG" else (along_n < 0.3)   # normal along thickness
    return A, c, across & ~cap, ~across & ~cap, cap


@pytest.mark.parametrize("kind", ["GG", "CNC"])
def test_strips_have_the_real_section(tmp_path, kind):
    """Each lamella is a closed strip of width 20 mm / 0.1 = 0.2 m and thickness 0.01 m
    (fabrication defaults): its two wide faces each have the area length x width (1 %), its
    edges length x thickness, its volume length x width x thickness; the wide faces lie
    tangent to the surface for GG (normal along the surface normal) and across it for CNC."""
    d = write_case(tmp_path / "b", kind)
    info = write_3dm(d, tmp_path / "m.3dm", sheets=False)
    assert info["params_source"] == "defaults"
    model, names, objs = _read(tmp_path / "m.3dm")
    b = make_bundle(kind)
    w, t = 0.2, 0.01
    assert len(objs["family 1"]) == N and len(objs["family 3"]) == N
    for fam in (1, 3):
        for obj, lam in zip(objs[f"family {fam}"], b.net.family(fam)):
            a = obj.Attributes
            assert a.GetUserString("lamella_id") == str(lam.id)
            assert a.GetUserString("family") == str(fam)
            assert float(a.GetUserString("length")) == pytest.approx(lam.length, rel=1e-6)
            assert a.GetUserString("joints").split() == [str(j) for j in lam.joints]
            assert float(a.GetUserString("width")) == pytest.approx(w)
            assert float(a.GetUserString("thickness")) == pytest.approx(t)
            mesh = obj.Geometry
            assert isinstance(mesh, rhino3dm.Mesh) and mesh.IsClosed
            V, F = _mesh_arrays(mesh)
            L = lam.length
            A, c, wide, edge, cap = _faces(V, F, lam, kind)
            assert A.sum() == pytest.approx(2 * L * (w + t) + 2 * w * t, rel=0.01)
            assert abs(_volume(V, F)) == pytest.approx(L * w * t, rel=0.01)
            assert A[wide].sum() == pytest.approx(2 * L * w, rel=0.01)
            assert A[edge].sum() == pytest.approx(2 * L * t, rel=0.01)
            assert A[cap].sum() == pytest.approx(2 * w * t, rel=0.01)
            if kind != "GG":
                # standing, centred on the axis (the area centroid moves off it only by the
                # bending of the axis: ~ kappa w^2 / 12, 1 % of w here; an edge axis: 50 %)
                foot, _ = _foot(c, lam.axis)
                off = np.sum(A[:, None] * (c - foot), axis=0) / A.sum()
                assert np.linalg.norm(off) < 0.02 * w


def test_gg_families_are_stacked_on_the_surface(tmp_path):
    """GG strips lie tangent, family 1 on the side of the surface normal and family 3 on the
    other: their centre lines are offset by +-t/2 along the normal, so crossing strips touch,
    not cross."""
    info = write_3dm(make_bundle("GG"), tmp_path / "m.3dm", sheets=False, thickness=2.0)
    t = info["strip_thickness_m"]
    assert t == pytest.approx(0.02)
    _, _, objs = _read(tmp_path / "m.3dm")
    b = make_bundle("GG")
    a, c, e = b.surface_V[b.surface_F[0, :3]]   # the side the surface's normals point to
    up = np.sign(np.cross(c - a, e - a)[2])
    for fam, sign in ((1, up), (3, -up)):
        for obj, lam in zip(objs[f"family {fam}"], b.net.family(fam)):
            V, F = _mesh_arrays(obj.Geometry)
            A, c, _, _, _ = _faces(V, F, lam, "GG")
            foot, _ = _foot(c, lam.axis)
            off = np.sum(A * np.sum((c - foot) * _paraboloid_normal(foot), axis=1)) / A.sum()
            assert off == pytest.approx(sign * t / 2, rel=0.02)


def test_units_of_the_input_millimetres(tmp_path):
    """A bundle whose design.json says mm: ModelUnitSystem Millimeters, every coordinate and
    length x1000, the sheets at their physical size in mm beside the model."""
    b = make_bundle("GG")
    b.units = Units.from_json(MM)
    d = write_bundle(tmp_path / "mm", b)
    assert json.loads((d / "design.json").read_text())["units"] == MM
    info = write_3dm(d, tmp_path / "mm.3dm", force=True)
    write_3dm(write_case(tmp_path / "m", "GG"), tmp_path / "m.3dm", force=True)
    model, names, objs = _read(tmp_path / "mm.3dm")
    ref, _, robjs = _read(tmp_path / "m.3dm")
    assert model.Settings.ModelUnitSystem == rhino3dm.UnitSystem.Millimeters
    assert ref.Settings.ModelUnitSystem == rhino3dm.UnitSystem.Meters
    assert info["units"] == "mm"
    J = np.array([[o.Geometry.Location.X, o.Geometry.Location.Y, o.Geometry.Location.Z]
                  for o in objs["joints"]])
    np.testing.assert_allclose(J, 1000.0 * b.net.joints, rtol=1e-12, atol=1e-9)
    V, _ = _mesh_arrays(objs["surface"][0].Geometry)
    np.testing.assert_allclose(V, 1000.0 * b.surface_V, rtol=1e-12, atol=1e-9)
    for obj, robj in zip(objs["family 1"], robjs["family 1"]):
        a, ra = obj.Attributes, robj.Attributes
        assert a.GetUserString("units") == "mm"
        assert float(a.GetUserString("length")) == pytest.approx(
            1000 * float(ra.GetUserString("length")), rel=1e-9)
        assert float(a.GetUserString("width")) == pytest.approx(200.0)
        np.testing.assert_allclose(_mesh_arrays(obj.Geometry)[0],
                                   1000 * _mesh_arrays(robj.Geometry)[0], rtol=1e-9, atol=1e-6)
    for layer, scale in ((objs["sheet 01"], 1.0), (robjs["sheet 01"], 1e-3)):
        border = next(o for o in layer if o.Attributes.GetUserString("role") == "border")
        bb = border.Geometry.GetBoundingBox()
        assert (bb.Max.X - bb.Min.X, bb.Max.Y - bb.Min.Y) == pytest.approx(
            (600 * scale, 400 * scale))
        assert bb.Min.X > 1000 * b.surface_V[:, 0].max() * scale  # beside the model


def test_units_override_and_unknown(tmp_path):
    write_3dm(make_bundle("GG"), tmp_path / "ft.3dm", units="ft", sheets=False)
    model, _, objs = _read(tmp_path / "ft.3dm")
    assert model.Settings.ModelUnitSystem == rhino3dm.UnitSystem.Feet
    loc = objs["joints"][5].Geometry.Location
    np.testing.assert_allclose([loc.X, loc.Y, loc.Z], make_bundle("GG").net.joints[5] / 0.3048)
    assert parse_units(None).metres_per_unit == 1.0
    assert parse_units({"metres_per_unit": 0.01}).name == "cm"
    assert parse_units("millimetres").name == "mm"
    with pytest.raises(InputError, match="unknown unit"):
        write_3dm(make_bundle("GG"), tmp_path / "x.3dm", units="furlong")
    with pytest.raises(InputError, match="metres_per_unit"):
        parse_units({"name": "mm", "metres_per_unit": -1})


def test_layers_objects_and_user_strings(tmp_path):
    d = write_case(tmp_path / "gg", "GG")
    out = export_3dm(d, tmp_path / "gg.3dm", force=True)["path"]
    model, names, objs = _read(out)
    assert names[:8] == ["surface", "family 1", "family 3", "axes", "joints", "holes",
                         "collapsed", "sheet 01"]
    b = make_bundle("GG")
    n_holes = sum(len(lam.joints) for lam in b.net.lamellae)
    counts = {n: len(o) for n, o in objs.items()}
    assert {k: counts[k] for k in ("surface", "family 1", "family 3", "axes", "joints",
                                   "holes", "collapsed")} == {
        "surface": 1, "family 1": N, "family 3": N, "axes": 2 * N, "joints": N * N,
        "holes": n_holes, "collapsed": 2 * N}
    mesh = objs["surface"][0].Geometry
    assert len(mesh.Vertices) == len(b.surface_V) and mesh.Faces.QuadCount == len(b.surface_F)
    for obj, lam in zip(objs["axes"], b.net.lamellae):
        np.testing.assert_allclose(_points(obj.Geometry), lam.axis, atol=1e-12)
        assert obj.Attributes.GetUserString("lamella_id") == str(lam.id)
    ids = [int(o.Attributes.GetUserString("joint_id")) for o in objs["joints"]]
    assert ids == list(range(N * N))
    assert objs["joints"][5].Attributes.GetUserString("lamellae").split() == ["1", str(N + 1)]
    # holes: 3 mm / 0.1 = 30 mm through each strip at its joints
    hole = objs["holes"][0]
    assert isinstance(hole.Geometry, rhino3dm.Extrusion) and hole.Geometry.IsSolid
    assert float(hole.Attributes.GetUserString("diameter")) == pytest.approx(0.03)
    bb = hole.Geometry.GetBoundingBox()
    centre = np.array([(bb.Min.X + bb.Max.X) / 2, (bb.Min.Y + bb.Max.Y) / 2,
                       (bb.Min.Z + bb.Max.Z) / 2])
    j = int(hole.Attributes.GetUserString("joint_id"))
    assert np.linalg.norm(centre - b.net.joints[j]) < 0.01
    col = objs["collapsed"][0]
    assert col.Attributes.GetUserString("state") == "collapsed"
    # in the input's frame: the aligned joints moved rigidly onto the deployed ones (issue 30)
    from gridshell.geometry.vectors import rigid_fit

    R, t = rigid_fit(b.aligned, b.net.joints)
    lam0 = b.net.lamellae[0].joints
    np.testing.assert_allclose(_points(col.Geometry), b.aligned[lam0] @ R.T + t, atol=1e-9)
    got = np.concatenate([_points(o.Geometry) for o in objs["collapsed"]])
    assert np.linalg.norm(got.mean(0) - b.net.joints.mean(0)) < \
        0.25 * np.linalg.norm(np.ptp(b.net.joints, axis=0))
    seg = lambda P: np.linalg.norm(np.diff(P, axis=0), axis=1)     # noqa: E731 (rigid)
    np.testing.assert_allclose(seg(_points(col.Geometry)), seg(b.aligned[lam0]), rtol=1e-9)
    assert model.Strings["gridshell.kind"] == "GG"
    assert not list(tmp_path.glob(".gg.3dm*"))  # atomic


def test_sheets_match_the_cut_files(tmp_path):
    """The sheet layers hold what fabricate() writes: one layer per sheet, one outline per
    piece on its sheet, outlines of the flat strip's size; parameters from fabrication.json."""
    from gridshell.fabrication import fabricate

    d = write_case(tmp_path / "gg", "GG")
    fab = fabricate(d, d / "fabrication", {"width": 30, "sheet": "300x200"}, plan=False)
    info = write_3dm(d, tmp_path / "gg.3dm", force=True)
    assert info["params_source"].endswith("fabrication.json")
    assert info["strip_width_m"] == pytest.approx(0.3)
    _, names, objs = _read(tmp_path / "gg.3dm")
    sheets = [n for n in names if n.startswith("sheet ")]
    assert sheets == [f"sheet {k:02d}" for k in range(1, fab["n_sheets"] + 1)]
    assert fab["n_sheets"] >= 2
    n_holes = 0
    for k, name in enumerate(sheets, 1):
        outlines = [o for o in objs[name] if o.Attributes.GetUserString("role") == "outline"]
        pieces = [p for p in fab["pieces"] if p["sheet"] == k]
        assert len(outlines) == len(pieces)
        for o in outlines:
            assert o.Geometry.IsClosed
            p = next(p for p in pieces if p["lamella"] == int(o.Attributes.GetUserString(
                "lamella_id")) and p["piece"] == int(o.Attributes.GetUserString("piece")))
            bb = o.Geometry.GetBoundingBox()
            dims = sorted([bb.Max.X - bb.Min.X, bb.Max.Y - bb.Min.Y])
            assert dims == pytest.approx(sorted([1e-3 * p["flat_length_mm"], 0.03]), rel=1e-6)
        holes = [o for o in objs[name] if o.Attributes.GetUserString("role") == "hole"]
        n_holes += len(holes)
        for h in holes:  # circles of 3 mm
            assert h.Geometry.IsClosed
            bb = h.Geometry.GetBoundingBox()
            assert [bb.Max.X - bb.Min.X, bb.Max.Y - bb.Min.Y] == pytest.approx([0.003] * 2)
    assert n_holes == fab["n_joint_marks"]


def test_cnc_arcs_and_bspline_surface(tmp_path):
    """CNC strips are arcs on the sheets (PolyCurves with arc spans), and surface.json comes
    in as a NURBS surface that evaluates like the B-spline (in mm)."""
    from gridshell.geometry.bspline import BSplineSurface

    u = np.linspace(-1.2, 1.2, 6)
    X, Y = np.meshgrid(u, u, indexing="ij")
    S = BSplineSurface.from_control_grid(np.stack([X, Y, 0.3 * (X * X + Y * Y)], -1), 3, 3)
    b = make_bundle("CNC")
    b.units = Units.from_json(MM)
    b.params["n"] = 0.5
    b.metrics["n"] = 0.5
    d = write_bundle(tmp_path / "cnc", b,
                     extra={"surface.json": json.dumps(S.to_json()).encode()})
    write_3dm(d, tmp_path / "cnc.3dm", force=True)
    _, names, objs = _read(tmp_path / "cnc.3dm")
    ns = objs["B-spline surface"][0].Geometry
    for uu, vv in ((0.2, 0.7), (0.5, 0.5), (0.9, 0.1)):
        p = ns.PointAt(uu, vv)
        np.testing.assert_allclose([p.X, p.Y, p.Z], 1000 * S.evaluate(np.array([uu]),
                                                                      np.array([vv]))[0],
                                   rtol=1e-12, atol=1e-9)
    outlines = [o for o in objs["sheet 01"] if o.Attributes.GetUserString("role") == "outline"]
    assert outlines and all(isinstance(o.Geometry, rhino3dm.PolyCurve) for o in outlines)
    assert all(o.Geometry.IsClosed for o in outlines)


def test_failing_design_has_no_sheets_unless_forced(tmp_path):
    d = write_case(tmp_path / "gg", "GG")  # made-up figures: verify finds a mismatch
    info = write_3dm(d, tmp_path / "a.3dm")
    assert info["sheets"] == [] and "fails its figures" in info["notes"][0]
    _, names, _ = _read(tmp_path / "a.3dm")
    assert not [n for n in names if n.startswith("sheet")]
    assert write_3dm(d, tmp_path / "b.3dm", force=True)["sheets"]
    # a caller that has verified these files (gridshell build) says so: not judged again
    info = write_3dm(d, tmp_path / "c.3dm", verified=True)
    assert info["sheets"] and not [n for n in info["notes"] if "figures" in n]


def test_3dm_with_revolution_and_errors(tmp_path):
    b = make_bundle("GG")
    # the surface of revolution in a frame of its own (turned and moved): placed back onto
    # the designed surface by the best rigid fit of the two grids
    c, s_ = np.cos(0.8), np.sin(0.8)
    Q = np.array([[c, -s_, 0.0], [s_, c, 0.0], [0.0, 0.0, 1.0]])
    b.revolution_V, b.revolution_F = b.surface_V @ Q.T + [5.0, -2.0, 1.0], b.surface_F
    out = export_3dm(b, tmp_path / "rev.3dm", sheets=False)["path"]
    _, names, objs = _read(out)
    assert "revolution" in names and len(objs["revolution"]) == 1
    mesh = objs["revolution"][0].Geometry
    V = np.array([[p.X, p.Y, p.Z] for p in mesh.Vertices])
    assert np.abs(V - b.surface_V).max() < 1e-5 * np.linalg.norm(np.ptp(b.surface_V, 0))
    with pytest.raises(InputError, match=".3dm"):
        export_3dm(b, tmp_path / "model.obj")
    with pytest.raises(InputError, match="not a design bundle"):
        export_3dm(tmp_path, tmp_path / "x.3dm")
    with pytest.raises(InputError, match="--width"):
        export_3dm(b, tmp_path / "x.3dm", width=-1)
    with pytest.raises(InputError, match="unknown fabrication parameter"):
        from gridshell.export.fabparams import export_params
        export_params(None, None, widht=3)


def test_cli_export(tmp_path, capsys):
    from gridshell.cli.main import main

    b = make_bundle("GG")
    b.units = Units.from_json(MM)
    d = write_bundle(tmp_path / "gg", b)
    assert main(["export", str(d), "--width", "40", "--thickness", "2", "--scale", "1:20",
                 "--no-sheets", "-q"]) == 0
    model, names, objs = _read(d / "gg.3dm")
    assert model.Settings.ModelUnitSystem == rhino3dm.UnitSystem.Millimeters
    a = objs["family 1"][0].Attributes
    assert (float(a.GetUserString("width")), float(a.GetUserString("thickness"))) == \
        pytest.approx((800.0, 40.0))
    assert "gg.3dm" in json.loads((d / "manifest.json").read_text())["files"]
    assert main(["export", str(d), "-o", str(tmp_path / "x.obj"), "-q"]) == 2
    assert main(["export", str(d), "--units", "m", "-o", str(tmp_path / "m.3dm"), "-q",
                 "--no-sheets"]) == 0
    assert rhino3dm.File3dm.Read(str(tmp_path / "m.3dm")).Settings.ModelUnitSystem == \
        rhino3dm.UnitSystem.Meters


def test_unwelded_sides_and_edge_axis(tmp_path):
    """Each side of a strip gets its own vertices (flat shading) and the triangles stay the
    same; with the axis on the edge (standing lamellae) the strip moves half a width off it."""
    from gridshell.export.rhino import unwelded_sides
    from gridshell.geometry.strips3d import strip_solid

    P = np.stack([np.linspace(0, 1, 9), np.zeros(9), np.zeros(9)], axis=1)
    V, F = strip_solid(P, np.tile([0.0, 0.0, 1.0], (9, 1)), 0.2, 0.01, True)
    V2, F2 = unwelded_sides(V, F)
    np.testing.assert_array_equal(V[F], V2[F2])
    assert len(V2) == 4 * 2 * 9 + 2 * 4             # 4 sides of 2 x 9 corners, 2 caps of 4
    b = make_bundle("CNC")
    write_3dm(b, tmp_path / "e.3dm", params={"axis": "edge"}, sheets=False)
    _, _, objs = _read(tmp_path / "e.3dm")
    lam = b.net.family(1)[1]
    V, F = _mesh_arrays(objs["family 1"][1].Geometry)
    A, c, _, _, _ = _faces(V, F, lam, "CNC")
    foot, _ = _foot(c, lam.axis)
    off = np.sum(A * np.sum((c - foot) * _paraboloid_normal(foot), axis=1)) / A.sum()
    assert abs(off) == pytest.approx(0.1, rel=0.05)       # centred: 0 (see above)


def _face_points(face, n=7):
    """Points ``(n * n, 3)`` of a Brep face's (untrimmed) surface over its domain."""
    du, dv = face.Domain(0), face.Domain(1)
    out = [face.PointAt(u, v) for u in np.linspace(du.T0, du.T1, n)
           for v in np.linspace(dv.T0, dv.T1, n)]
    return np.array([[p.X, p.Y, p.Z] for p in out])


def test_hole_cylinder_is_the_capped_cylinder():
    """The hole (an Extrusion) is the capped cylinder of the Brep it replaces: a closed solid
    of a side and two caps, the side at the radius from the axis over exactly +-h/2, the
    caps in the planes +-h/2, the edges the circles there (and the seam); the same holds for
    Cylinder.ToBrep (what the holes were)."""
    from gridshell.export.rhino_geometry import cylinder

    c, a, r, h = np.array([0.3, -0.2, 0.7]), np.array([1.0, 2.0, -0.5]), 0.015, 0.01
    e = cylinder(c, a, r, h)
    a = a / np.linalg.norm(a)
    base = c - 0.5 * h * a
    circ = rhino3dm.Circle(rhino3dm.Point3d(*base.tolist()), r)
    circ.Plane = rhino3dm.Plane(rhino3dm.Point3d(*base.tolist()), rhino3dm.Vector3d(*a))
    old = rhino3dm.Cylinder(circ, h).ToBrep(True, True)
    new = e.ToBrep(False)
    assert e.IsSolid and new.IsSolid and len(new.Faces) == len(old.Faces) == 3

    def local(X):
        X = X - c
        along = X @ a
        return along, np.linalg.norm(X - along[:, None] * a, axis=1)

    for brep in (new, old):
        kinds = []
        for face in brep.Faces:
            along, radial = local(_face_points(face))
            if np.ptp(along) < 1e-12:                      # a cap: a plane at +-h/2
                kinds.append(round(float(along[0]) / h, 9))
            else:                                          # the side
                np.testing.assert_allclose(radial, r, rtol=1e-9)
                assert (along.min(), along.max()) == pytest.approx((-h / 2, h / 2), abs=1e-12)
                kinds.append("side")
        assert sorted(map(str, kinds)) == ["-0.5", "0.5", "side"]
        for edge in brep.Edges:
            d = edge.Domain
            along, radial = local(np.array([[p.X, p.Y, p.Z] for p in (
                edge.PointAt(x) for x in np.linspace(d.T0, d.T1, 9))]))
            np.testing.assert_allclose(radial, r, rtol=1e-9)
            circle = np.ptp(along) < 1e-12            # else the side's seam, a line
            assert abs(abs(along[0]) - h / 2) < 1e-12 if circle else np.ptp(along) == \
                pytest.approx(h, abs=1e-12)


@pytest.mark.parametrize("kind", ["GG", "CNC"])
def test_strip_solids_have_only_the_rings_they_need(tmp_path, kind):
    """The strip meshes go through fewer rings than the axis has samples (solid_rings), and
    every full-resolution corner edge (the frame of the axis samples, as the export builds
    it) lies within ring_tolerance of the mesh's corner edge; the axis layer keeps every
    sample. The axes are the test bundle's, 8 times as densely sampled."""
    from gridshell.export.rhino import _clean_polyline
    from gridshell.geometry.igl_adapter import closest_points_with_normals
    from gridshell.geometry.strips3d import is_tangent, ring_tolerance, strip_frame

    b = make_bundle(kind)
    for lam in b.net.lamellae:       # 8 samples per span of the axis: straight stretches
        A = np.asarray(lam.axis, float)
        s = np.linspace(0.0, len(A) - 1, 8 * (len(A) - 1) + 1)
        lam.axis = np.stack([np.interp(s, np.arange(len(A)), A[:, c]) for c in range(3)], 1)
    info = write_3dm(b, tmp_path / "r.3dm", sheets=False)
    w, t = info["strip_width_m"], info["strip_thickness_m"]
    _, _, objs = _read(tmp_path / "r.3dm")
    rings = samples = 0
    for fam in (1, 3):
        for obj, lam in zip(objs[f"family {fam}"], b.net.family(fam)):
            P = _clean_polyline(lam.axis)
            N = closest_points_with_normals(P, b.surface_V, b.surface_F)[1]
            _, W, H = strip_frame(P, N, is_tangent(kind))
            if kind == "GG":
                P = P + (0.5 * t if fam == 1 else -0.5 * t) * H
                _, W, H = strip_frame(P, N, True)
            hw, ht = 0.5 * w * W, 0.5 * t * H
            full = [P - hw - ht, P + hw - ht, P + hw + ht, P - hw + ht]
            V, _ = _mesh_arrays(obj.Geometry)
            n = (len(V) - 8) // 8                  # unwelded: 4 sides of 2 n, 2 caps of 4
            side0, side2 = V[:2 * n].reshape(n, 2, 3), V[4 * n:6 * n].reshape(n, 2, 3)
            simple = [side0[:, 0], side0[:, 1], side2[:, 0], side2[:, 1]]
            for c in range(4):
                Q = simple[c]
                A, B = Q[:-1][None], Q[1:][None]
                D = B - A
                u = np.clip(np.einsum("nmi,nmi->nm", full[c][:, None] - A, D)
                            / np.einsum("nmi,nmi->nm", D, D), 0.0, 1.0)
                d = np.linalg.norm(full[c][:, None] - A - u[..., None] * D, axis=-1).min(axis=1)
                assert d.max() <= ring_tolerance(t) * (1 + 1e-9) + 1e-12
            rings, samples = rings + n, samples + len(P)
    axes = {int(o.Attributes.GetUserString("lamella_id")): o for o in objs["axes"]}
    for lam in b.net.lamellae:
        assert len(_points(axes[lam.id].Geometry)) == len(_clean_polyline(lam.axis))
    assert rings < samples / 2


def test_joints_too_close_for_holes_become_marks_with_a_note(tmp_path):
    """At 1:200 the AA case's joints are closer than a hole needs: the cut sheets engrave
    marks (as ``gridshell fabricate`` does), the strips carry no hole cylinders, and the
    export says so in its notes instead of changing the joints silently."""
    d = write_case(tmp_path / "aa", "AA")
    info = write_3dm(d, tmp_path / "aa.3dm", force=True, scale=0.005)
    assert info["params"]["joints"] == "marks" and "holes" not in info["layers"]
    assert any("engraved as marks instead" in n and "1:200" in n for n in info["notes"])
    _, names, objs = _read(tmp_path / "aa.3dm")
    assert "holes" not in names
    roles = {o.Attributes.GetUserString("role") for n in names if n.startswith("sheet ")
             for o in objs[n]}
    assert "score" in roles and "hole" not in roles
    assert not any("marks" in n for n in write_3dm(d, tmp_path / "ok.3dm", force=True)["notes"])


@pytest.mark.parametrize("kind", ["AA", "CNC"])
def test_design_check_finds_the_closest_points_the_export_asked_ahead(tmp_path, kind,
                                                                       monkeypatch):
    """The .3dm export asks the axes' and the joints' closest points before its design check
    forks: the check of an NCP kind then asks igl nothing (it would otherwise build the
    surface's tree again in the second process)."""
    import gridshell.geometry.igl_adapter as ia
    from gridshell.design.bundle import read_bundle
    from gridshell.export.rhino import _ask_ahead
    from gridshell.design.verification import design_verdict

    monkeypatch.setattr(ia, "_QUERIES", ia.Recent(8, copy=ia._QUERIES.copy))   # empty
    calls = []
    real = ia.igl.point_mesh_squared_distance
    monkeypatch.setattr(ia.igl, "point_mesh_squared_distance",
                        lambda *a: calls.append(len(a[0])) or real(*a))
    d = write_case(tmp_path / kind, kind)
    design_verdict(d)                   # not asked ahead: the check asks igl
    assert calls
    monkeypatch.setattr(ia, "_QUERIES", ia.Recent(8, copy=ia._QUERIES.copy))
    _ask_ahead(read_bundle(d))
    calls.clear()
    design_verdict(d)
    assert calls == []
