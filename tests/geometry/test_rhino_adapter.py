"""The rhino3dm adapter: Rhino meshes as double-precision arrays, NURBS surfaces as B-splines
exactly (checked against Rhino's own evaluation, ``NurbsSurface.PointAt``), and back."""
from __future__ import annotations

import numpy as np
import pytest
from tests.helpers.io_cases import hill_ctrl, rhino_nurbs
from tests.helpers.ncp_cases import torus

rhino3dm = pytest.importorskip("rhino3dm")

from gridshell.core.errors import InputError  # noqa: E402
from gridshell.geometry import rhino_adapter as rh  # noqa: E402


def test_a_mesh_round_trips_in_double_precision_with_its_polygons():
    rng = np.random.default_rng(3)
    V = rng.normal(size=(6, 3)) * 1e3 + 12345.678901234   # beyond float32
    F = np.array([[0, 1, 2, 3], [1, 4, 2, -1], [2, 4, 5, 3]])
    W, P, sizes = rh.mesh_arrays(rh.mesh(V, F))
    assert W.dtype == np.float64 and np.array_equal(W, V)
    assert np.array_equal(P, F) and sizes.tolist() == [4, 3, 4]


def test_a_single_precision_mesh_gives_its_float32_vertices_exactly():
    V = np.array([[0.1, 0.2, 0.3], [1.1, 0.2, 0.3], [1.1, 1.2, 0.3]])
    m = rhino3dm.Mesh()
    for x, y, z in V:
        m.Vertices.Add(float(x), float(y), float(z))
    m.Faces.AddFace(0, 1, 2)
    W, P, sizes = rh.mesh_arrays(m)
    assert np.array_equal(W, V.astype(np.float32).astype(np.float64))
    assert P.tolist() == [[0, 1, 2, -1]] and sizes.tolist() == [3]


def test_a_nurbs_surface_is_the_b_spline_rhino_evaluates():
    ns = rhino_nurbs(hill_ctrl(6, 5), degree=(3, 2))        # knots on [0, 10] in Rhino
    s = rh.nurbs_to_bspline(ns)
    assert (s.degree_u, s.degree_v) == (3, 2) and np.array_equal(s.ctrl, hill_ctrl(6, 5))
    rng = np.random.default_rng(0)
    uv = rng.uniform(0, 1, size=(40, 2))
    ours = np.array([s.evaluate_grid(np.array([a]), np.array([b]))[0, 0] for a, b in uv])
    theirs = np.array([[(p := ns.PointAt(10 * a, 10 * b)).X, p.Y, p.Z] for a, b in uv])
    assert np.abs(ours - theirs).max() < 1e-12 * np.abs(theirs).max()


def test_a_b_spline_goes_to_rhino_and_back_exactly():
    t = torus()
    ns = rh.bspline_to_nurbs(t.degree_u, t.degree_v, t.knots_u, t.knots_v, t.ctrl)
    back = rh.nurbs_to_bspline(ns)
    assert np.array_equal(back.ctrl, t.ctrl)
    assert np.array_equal(back.knots_u, t.knots_u) and np.array_equal(back.knots_v, t.knots_v)
    p = ns.PointAt(0.3, 0.7)
    q = t.evaluate_grid(np.array([0.3]), np.array([0.7]))[0, 0]
    assert np.allclose([p.X, p.Y, p.Z], q, rtol=0, atol=1e-12)


def test_a_rational_surface_has_no_b_spline_form():
    w = np.ones((6, 5))
    w[2, 2] = 2.0
    ns = rhino_nurbs(hill_ctrl(6, 5), weights=w)
    parts = rh.nurbs_parts(ns)
    assert parts.rational and np.allclose(parts.ctrl, hill_ctrl(6, 5), atol=1e-12)
    with pytest.raises(InputError, match="rational"):
        rh.nurbs_to_bspline(parts)
