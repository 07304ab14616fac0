"""Rhino .3dm input (gridshell.io.rhino, through gridshell.io.read.read_input), files built
with rhino3dm in the tests; surfaces checked against rhino3dm's own evaluator."""
from __future__ import annotations

import numpy as np
import pytest
from tests.helpers.io_cases import hill, hill_ctrl, rhino_mesh, rhino_nurbs, write_3dm

from gridshell.core.errors import InputError
from gridshell.io.read import read_input

rhino3dm = pytest.importorskip("rhino3dm")


def _rhino_points(ns, s, t):
    """rhino3dm's evaluation at normalized parameters ``s, t`` in [0, 1] (file units)."""
    (u0, u1), (v0, v1) = (ns.Domain(0).T0, ns.Domain(0).T1), (ns.Domain(1).T0, ns.Domain(1).T1)
    return np.array([[_xyz(ns.PointAt(u0 + a * (u1 - u0), v0 + b * (v1 - v0))) for b in t]
                     for a in s])


def _xyz(p):
    return (p.X, p.Y, p.Z)


def test_a_mesh_in_millimetres_is_read_as_metres(tmp_path):
    V, T = hill(10, 8, scale=1000.0)
    f = write_3dm(tmp_path / "hill_mm.3dm", [(rhino_mesh(V, T), "hill", "Shell")], units="mm")
    geo = read_input(f)
    assert geo.units.name == "mm" and geo.units_source == "file"
    # Rhino stores mesh vertices in single precision: ~1e-7 relative
    np.testing.assert_allclose(geo.V, V / 1000.0, rtol=0, atol=1e-6)
    np.testing.assert_array_equal(geo.F, T)
    assert "hill" in geo.object


def test_quads_and_triangles_of_a_rhino_mesh(tmp_path):
    V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0.1], [0, 1, 0], [2, 0, 0.2], [2, 1, 0]], float)
    F = [[0, 1, 2, 3], [1, 4, 5, 2]]
    f = write_3dm(tmp_path / "q.3dm", [(rhino_mesh(V, np.array(F)), "q", "L")])
    geo = read_input(f)
    assert geo.F.shape == (2, 4)


@pytest.mark.parametrize("units, factor", [("m", 1.0), ("mm", 0.001), ("ft", 0.3048)])
def test_a_nurbs_surface_matches_rhinos_evaluation(tmp_path, units, factor):
    ns = rhino_nurbs(hill_ctrl(6, 5, scale=1.0 / factor))
    f = write_3dm(tmp_path / "s.3dm", [(ns, "roof", "Shell")], units=units)
    geo = read_input(f)
    surf = geo.surface
    assert surf.degree_u == 3 and surf.shape == (6, 5)
    assert len(surf.knots_u) == 6 + 3 + 1  # Rhino's count + order - 2, plus the two end knots
    s, t = np.linspace(0, 1, 7), np.linspace(0, 1, 6)
    model = rhino3dm.File3dm.Read(str(f))
    ref = _rhino_points(model.Objects[0].Geometry, s, t) * factor
    np.testing.assert_allclose(surf.evaluate_grid(s, t), ref, atol=1e-9 * 15)
    # the mesh the commands sample lies on it, metres
    assert geo.F.shape[1] == 4 and abs(np.ptp(geo.V[:, 0]) - 12.0) < 1e-9


def test_a_rational_surface_is_approximated_and_the_error_said(tmp_path):
    w = np.ones((6, 5))
    w[2:4, 1:4] = 1.8
    ns = rhino_nurbs(hill_ctrl(6, 5), weights=w)
    f = write_3dm(tmp_path / "r.3dm", [(ns, "rational", "Shell")])
    geo = read_input(f)
    note = " ".join(geo.notes)
    assert "rational" in note and "largest distance" in note
    s, t = np.linspace(0, 1, 23), np.linspace(0, 1, 19)
    model = rhino3dm.File3dm.Read(str(f))
    ref = _rhino_points(model.Objects[0].Geometry, s, t)
    err = np.linalg.norm(geo.surface.evaluate_grid(s, t) - ref, axis=-1).max()
    assert err < 1e-3 * 14.6   # within 0.1 % of the diagonal
    said = float(note.split("largest distance ")[1].split()[0])
    assert err <= said * 1.5 + 1e-12


def test_a_single_face_brep(tmp_path):
    ns = rhino_nurbs(hill_ctrl(5, 5))
    brep = rhino3dm.Brep.CreateFromSurface(ns)
    f = write_3dm(tmp_path / "b.3dm", [(brep, "face", "Shell")])
    geo = read_input(f)
    assert geo.surface is not None and "Brep" in geo.object


def _three(tmp_path):
    V, T = hill(8, 6)
    objs = [(rhino_mesh(V, T), "mesh roof", "Meshes"), (rhino_nurbs(hill_ctrl()), "nurbs roof",
                                                        "Surfaces"),
            (rhino3dm.Brep.CreateFromSurface(rhino_nurbs(hill_ctrl(5, 4))), "brep roof",
             "Breps"),
            (rhino3dm.LineCurve(rhino3dm.Point3d(0, 0, 0), rhino3dm.Point3d(1, 0, 0)), "edge",
             "Curves")]
    return write_3dm(tmp_path / "three.3dm", objs)


def test_three_objects_are_listed_and_picked_by_name_id_or_layer(tmp_path):
    f = _three(tmp_path)
    with pytest.raises(InputError) as exc:
        read_input(f)
    msg = str(exc.value)
    assert "3 objects" in msg and "--object" in msg
    for name in ("mesh roof", "nurbs roof", "brep roof"):
        assert name in msg
    assert "edge" not in msg  # a curve is not a candidate
    assert read_input(f, obj="nurbs roof").surface is not None
    assert read_input(f, obj="Meshes").surface is None            # by layer
    ident = rhino3dm.File3dm.Read(str(f)).Objects[2].Attributes.Id
    assert "brep roof" in read_input(f, obj=str(ident)).object     # by id
    with pytest.raises(InputError, match="no object named 'roof'"):
        read_input(f, obj="roof")
    with pytest.raises(InputError, match="curve on layer .Curves.*not a mesh"):
        read_input(f, obj="edge")


def test_units_of_the_file_win_over_a_contradicting_option(tmp_path):
    V, T = hill(8, 6, scale=1000.0)
    f = write_3dm(tmp_path / "mm.3dm", [(rhino_mesh(V, T), "hill", "L")], units="mm")
    assert read_input(f, units="mm").units.name == "mm"
    with pytest.raises(InputError, match="drawn in millimetres.*--units m"):
        read_input(f, units="m")


def test_a_file_without_units_takes_the_option_or_the_plausibility_check(tmp_path):
    V, T = hill(8, 6, scale=1000.0)
    f = write_3dm(tmp_path / "none.3dm", [(rhino_mesh(V, T), "hill", "L")], units="none")
    with pytest.raises(InputError, match="as metres.*as millimetres"):
        read_input(f)
    assert read_input(f, units="mm").units.name == "mm"


@pytest.mark.parametrize("case, words", [
    ("corrupt", ["not a readable Rhino .3dm"]),
    ("empty_file", ["the file is empty"]),
    ("no_objects", ["no mesh, NURBS surface or single-face Brep", "no objects"]),
    ("curves_only", ["no mesh, NURBS surface or single-face Brep", "2 curves"]),
    ("missing", ["no such file"]),
])
def test_bad_3dm_files(tmp_path, case, words):
    f = tmp_path / f"{case}.3dm"
    if case == "corrupt":
        good = _three(tmp_path).read_bytes()
        f.write_bytes(good[:200] + b"\x00garbage" * 50)
    elif case == "empty_file":
        f.write_bytes(b"")
    elif case == "no_objects":
        write_3dm(f, [])
    elif case == "curves_only":
        c = rhino3dm.LineCurve(rhino3dm.Point3d(0, 0, 0), rhino3dm.Point3d(1, 0, 0))
        write_3dm(f, [(c, "a", "L"), (c, "b", "L")])
    with pytest.raises(InputError) as exc:
        read_input(f)
    msg = str(exc.value)
    assert "\n" not in msg
    for w in words:
        assert w in msg, msg
