"""One Rhino object, one design: a Rhino mesh and a NURBS surface give the same arrays and the
same design through the Hops components (what Grasshopper sends, JSON-encoded) as through the
CLI reading the same object from a .3dm; a .3dm mesh keeps its double-precision vertices."""
from __future__ import annotations

import json

import numpy as np
import pytest
from tests.helpers.io_cases import hill_ctrl, rhino_nurbs, write_3dm
from tests.helpers.ncp_cases import torus

rhino3dm = pytest.importorskip("rhino3dm")

from gridshell.cli.main import main  # noqa: E402
from gridshell.design.bundle import read_bundle  # noqa: E402
from gridshell.geometry import rhino_adapter as rh  # noqa: E402
from gridshell.geometry.grid import grid_quads  # noqa: E402
from gridshell.io.read import read_input  # noqa: E402
from gridshell.io.rhino import read_3dm  # noqa: E402
from gridshell.server import components, rhino  # noqa: E402

#: coordinates a float32 cannot hold (~1e-6 relative): 12345.678901234 mm and its like
OFFSET_MM = np.array([12345.678901234, -2345.678901234, 345.678901234])
#: small CNC settings, the same through the CLI's options and the component's Options
NCP_CLI = ["--mode", "cnc", "--curves", "6", "--samples", "24", "24", "--levelset-ctrl", "8",
           "8", "--omega-f", "0.01", "--collapse-samples", "200", "200", "--rounds", "1",
           "--frames", "2", "--no-render"]
NCP_OPTIONS = {"samples": [24, 24], "levelset_ctrl": [8, 8], "omega_f": 0.01,
               "collapse_samples": [200, 200], "postopt_rounds": 1, "frames": 2}


def hops_roundtrip(obj):
    """``obj`` as the server receives it: encoded by Grasshopper to JSON, decoded by Hops."""
    return rhino3dm.CommonObject.Decode(json.loads(json.dumps(obj.Encode())))


def hill_mesh(n: int = 12, m: int = 10, offset_m=OFFSET_MM * 1e-3):
    """A 12 x 8 m hill, quads with the last row of faces split into triangles (a mixed mesh),
    shifted by ``offset_m`` (metres: far from the origin, as a site model is)."""
    x, y = np.linspace(-6, 6, n), np.linspace(-4, 4, m)
    X, Y = np.meshgrid(x, y, indexing="ij")
    Z = 2.5 * np.exp(-(X ** 2 / 30 + Y ** 2 / 14)) + 0.1 * X
    V = np.stack([X, Y, Z], -1).reshape(-1, 3) + offset_m
    Q = grid_quads(n, m)
    last = Q[-(m - 1):]
    T = np.concatenate([last[:, [0, 1, 2]], last[:, [0, 2, 3]]])
    F = np.full((len(Q) - len(last) + len(T), 4), -1, np.int64)
    F[:len(Q) - len(last)] = Q[:-(m - 1)]
    F[len(Q) - len(last):, :3] = T
    return V, F


def new_dir(root):
    return lambda kind: root / kind


def test_a_mm_3dm_mesh_keeps_its_double_precision_vertices(tmp_path):
    V, F = hill_mesh(offset_m=0.0)
    Vmm = V * 1000.0 + OFFSET_MM
    assert np.any(Vmm.astype(np.float32).astype(float) != Vmm)   # float32 would lose them
    path = write_3dm(tmp_path / "site.3dm", [(rh.mesh(Vmm, F), "hill", "site")], units="mm")
    r = read_3dm(path)
    assert np.array_equal(r.V, Vmm) and r.units.name == "mm"
    assert np.array_equal(r.P, F) and np.array_equal(r.sizes, np.where(F[:, 3] < 0, 3, 4))
    g = read_input(str(path))
    assert g.V.shape == Vmm.shape and g.V.dtype == np.float64
    # metres to the last bits (float32 would be ~1e-6 m off at 12 km from the origin)
    assert np.abs(np.sort(g.V, axis=0) - np.sort(Vmm, axis=0) / 1000.0).max() <= 4e-15 * 20
    # back in mm within one unit in the last place (x / 1000 * 1000 need not be x exactly:
    # numpy 2.4's exp gives this hill one such vertex)
    back, want = np.sort(g.V * 1000.0, axis=0), np.sort(Vmm, axis=0)
    assert np.all(np.abs(back - want) <= np.spacing(np.abs(want)))


def test_a_mesh_gives_the_same_arrays_through_the_server_and_the_cli(tmp_path):
    V, F = hill_mesh()
    assert np.any(V.astype(np.float32).astype(float) != V)
    mesh = rh.mesh(V, F)
    path = write_3dm(tmp_path / "hill.3dm", [(mesh, "hill", "target")])
    got = hops_roundtrip(mesh)
    Vs, Ps = rhino.mesh_arrays(got)
    assert Vs.dtype == np.float64 and np.array_equal(Vs, V) and np.array_equal(Ps, F)
    server, cli = rhino.target_input(got), read_input(str(path))
    assert server.surface is None and cli.surface is None
    assert server.V.dtype == np.float64
    assert np.array_equal(server.V, cli.V) and np.array_equal(server.F, cli.F)
    # io's rule for a mixed mesh: its 90 quads split in two, its 18 triangles kept
    assert server.F.shape == (2 * 90 + 18, 3)


def test_a_nurbs_surface_is_the_same_b_spline_through_the_server_and_the_cli(tmp_path):
    C = hill_ctrl(6, 5)
    ns = rhino_nurbs(C)
    path = write_3dm(tmp_path / "srf.3dm", [(ns, "hill", "target")])
    for obj in (hops_roundtrip(ns), hops_roundtrip(rhino3dm.Brep.CreateFromSurface(ns))):
        server, cli = rhino.target_input(obj), read_input(str(path))
        a, b = server.surface, cli.surface
        assert a is not None and (a.degree_u, a.degree_v) == (b.degree_u, b.degree_v) == (3, 3)
        assert np.array_equal(a.ctrl, b.ctrl) and np.array_equal(a.ctrl, C)  # not sampled
        assert np.array_equal(a.knots_u, b.knots_u) and np.array_equal(a.knots_v, b.knots_v)
        for k, n in ((a.knots_u, 6), (a.knots_v, 5)):     # clamped uniform on [0, 1]
            want = np.concatenate([[0.0] * 3, np.linspace(0, 1, n - 2), [1.0] * 3])
            assert np.allclose(k, want, rtol=0, atol=1e-15)
        assert np.array_equal(server.V, cli.V) and np.array_equal(server.F, cli.F)


def same_design(a, b):
    """The same net (joints to 1e-12 m, the same loops) and the same figures (every metric but
    the timings, to the last digit)."""
    assert a.kind == b.kind and a.net.joints.shape == b.net.joints.shape
    assert np.abs(a.net.joints - b.net.joints).max() <= 1e-12
    assert np.array_equal(a.net.loops, b.net.loops)
    assert {"n_joints", "deviation"} <= set(a.metrics) and set(a.metrics) == set(b.metrics)
    for key in sorted(set(a.metrics) - {"timings"}):
        assert json.dumps(a.metrics[key], sort_keys=True, default=str) == \
            json.dumps(b.metrics[key], sort_keys=True, default=str), key


def test_a_mesh_gives_the_same_gg_design_through_the_component_and_the_cli(tmp_path):
    V, F = hill_mesh()
    mesh = rh.mesh(V, F)
    path = write_3dm(tmp_path / "hill.3dm", [(mesh, "hill", "target")])
    reply = components.design_gg_component(new_dir(tmp_path), hops_roundtrip(mesh), 5, 10)
    assert main(["gg", str(path), "-o", str(tmp_path / "cli"), "--grid", "10", "10",
                 "--lamellae", "5", "--frames", "0", "--no-preview"]) == 0
    server = read_bundle(reply.values[-1])
    same_design(server, read_bundle(tmp_path / "cli"))
    assert json.loads(reply.values[3])["alignability"] == server.metrics["alignability"]


def test_a_nurbs_surface_gives_the_same_ncp_design_through_the_component_and_the_cli(tmp_path):
    t = torus()                       # a torus patch: distinct principal curvatures
    ns = rh.bspline_to_nurbs(t.degree_u, t.degree_v, t.knots_u, t.knots_v, t.ctrl)
    path = write_3dm(tmp_path / "srf.3dm", [(ns, "torus", "target")])
    reply = components.design_ncp_component(new_dir(tmp_path), None, "cnc", 6,
                                            json.dumps(NCP_OPTIONS), hops_roundtrip(ns))
    assert main(["ncp", str(path), "-o", str(tmp_path / "cli")] + NCP_CLI) == 0
    server = read_bundle(reply.values[-1])
    same_design(server, read_bundle(tmp_path / "cli"))
    assert server.kind == "CNC"


def test_a_target_is_one_mesh_or_one_surface():
    ns = rhino_nurbs(hill_ctrl(6, 5))
    with pytest.raises(Exception, match="input Target is missing"):
        components.design_gg_component(new_dir(None), None, 5, 10)
    with pytest.raises(Exception, match="both Reference and Surface"):
        components.design_ncp_component(new_dir(None), rh.mesh(*hill_mesh()), "cnc", 6, "{}",
                                        ns)


def test_the_surface_input_reaches_the_component_as_a_surface(tmp_path):
    """Through HTTP (a Hops solve request, the surface connected to Surface as Grasshopper sends
    a Brep): the design of the B-spline itself, the same as the CLI's of the .3dm."""
    pytest.importorskip("ghhops_server")
    ns = rhino_nurbs(hill_ctrl(6, 5))
    brep = rhino3dm.Brep.CreateFromSurface(ns)
    path = write_3dm(tmp_path / "srf.3dm", [(ns, "hill", "target")])
    client = components.make_app(tmp_path / "hops").test_client()
    body = {"pointer": "/gg", "values": [
        {"ParamName": "Surface", "InnerTree": {"{0}": [
            {"type": "Rhino.Geometry.Brep", "data": json.dumps(brep.Encode())}]}},
        {"ParamName": "Grid", "InnerTree": {"{0}": [{"type": "System.Int32", "data": "10"}]}},
        {"ParamName": "Lamellae", "InnerTree": {"{0}": [{"type": "System.Int32",
                                                          "data": "5"}]}}]}
    d = client.post("/solve", data=json.dumps(body)).get_json()
    assert not d.get("errors"), d
    out = {v["ParamName"]: v["InnerTree"]["0"][0]["data"] for v in d["values"]}
    server = read_bundle(json.loads(out["Bundle"]))
    assert server.params["input"]["surface"] == "NURBS"
    assert main(["gg", str(path), "-o", str(tmp_path / "cli"), "--grid", "10", "10",
                 "--lamellae", "5", "--frames", "0", "--no-preview"]) == 0
    same_design(server, read_bundle(tmp_path / "cli"))
