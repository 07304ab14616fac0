"""Hops components through the server's HTTP interface (Flask test client), in the Hops JSON
request format; outputs checked against the Python API's results on the same input."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from tests.helpers.gg_cases import helicoid_grid
from tests.helpers.ncp_cases import torus_grid

pytest.importorskip("ghhops_server")
import rhino3dm  # noqa: E402

from gridshell.design.bundle import read_bundle  # noqa: E402
from gridshell.geometry.grid import grid_quads  # noqa: E402
from gridshell.server.components import make_app  # noqa: E402
from gridshell.server.rhino import mesh_arrays, to_mesh  # noqa: E402

NCP_SMALL = {"samples": [24, 24], "collapse_samples": [200, 200], "frames": 2,
             "postopt_rounds": 1, "phlw_options": {"ctrl": [6, 6], "samples": [7, 7],
                                                   "outer": 1, "max_iter": 3}}


def item(type_, data):
    return {"type": type_, "data": data}


def request(pointer, **inputs):
    """A Hops /solve request body: one branch {0} per input."""
    return {"pointer": pointer, "values": [{"ParamName": k, "InnerTree": {"{0}": v}}
                                           for k, v in inputs.items()]}


def mesh_item(V, F):
    return [item("Rhino.Geometry.Mesh", json.dumps(to_mesh(V, F).Encode()))]


def text(s):
    return [item("System.String", json.dumps(s))]


def solve(client, body):
    r = client.post("/solve", data=json.dumps(body))
    assert r.status_code == 200
    d = r.get_json()
    out = {}
    for v in d["values"]:
        out[v["ParamName"]] = [x["data"] for x in v["InnerTree"]["0"]]
    return d, out


def decode(data):
    return rhino3dm.CommonObject.Decode(json.loads(data))


def curve_points(c):
    pl = c.ToPolyline() if hasattr(c, "ToPolyline") else None
    if pl is None:
        return None
    return np.array([[pl[i].X, pl[i].Y, pl[i].Z] for i in range(len(pl))])


@pytest.fixture(scope="module")
def client(tmp_path_factory):
    app = make_app(tmp_path_factory.mktemp("hops"))
    return app.test_client()


@pytest.fixture(scope="module")
def gg_solved(client):
    n = 12
    P = helicoid_grid(n, n, c=0.5)
    V, F = P.reshape(-1, 3), grid_quads(n, n)
    body = request("/gg", Target=mesh_item(V, F), Lamellae=[item("System.Int32", "8")],
                   Grid=[item("System.Int32", "12")])
    d, out = solve(client, body)
    return mesh_arrays(to_mesh(V, F)), d, out     # what the server reads (rhino3dm floats)


def test_components_are_listed(client):
    r = client.get("/")
    assert r.status_code == 200
    uris = {c["Uri"] for c in r.get_json()}
    assert {"/gg", "/ncp", "/verify", "/fabricate"} <= uris
    gg = client.get("/gg").get_json()
    assert [p["Name"] for p in gg["Inputs"]] == ["Target", "Lamellae", "Grid", "Options",
                                                 "Surface"]
    assert [p["Name"] for p in gg["Outputs"]] == ["Net", "Lamellae", "Aligned", "Metrics",
                                                  "Bundle"]


def test_gg_component_matches_the_api(gg_solved):
    from gridshell.gg.pipeline import design_gg

    (V, F), d, out = gg_solved
    assert not d.get("errors"), d
    bundle, _ = design_gg((V, F), grid=(12, 12), n_lamellae=8, frames=0)
    net = decode(out["Net"][0])
    assert len(net.Vertices) == len(bundle.net.joints) and len(net.Faces) == len(bundle.net.loops)
    J = np.array([[net.Vertices[i].X, net.Vertices[i].Y, net.Vertices[i].Z]
                  for i in range(len(net.Vertices))])
    assert np.allclose(J, bundle.net.joints, atol=1e-5)
    assert len(out["Lamellae"]) == len(bundle.net.lamellae) == len(out["Aligned"])
    for data, lam in zip(out["Lamellae"], bundle.net.lamellae):
        assert np.allclose(curve_points(decode(data)), lam.axis, atol=1e-5)
    metrics = json.loads(json.loads(out["Metrics"][0]))
    assert metrics["alignability"]["max"] == pytest.approx(
        bundle.metrics["alignability"]["max"], rel=1e-6, abs=1e-12)
    b = read_bundle(json.loads(out["Bundle"][0]))
    assert b.kind == "GG" and np.allclose(b.net.joints, bundle.net.joints, atol=1e-9)


def test_verify_and_fabricate_components_match_the_api(client, gg_solved, tmp_path):
    from gridshell.fabrication import FabParams, fabricate
    from gridshell.design.verification import verify_bundle

    _, _, out = gg_solved
    path = json.loads(out["Bundle"][0])
    d, v = solve(client, request("/verify", Bundle=text(path)))
    assert not d.get("errors")
    res = verify_bundle(path)
    assert json.loads(v["OK"][0]) is res["ok"] is True
    assert [json.loads(c) for c in v["Checks"]] == res["checks"] + res["problems"]
    d, f = solve(client, request("/fabricate", Bundle=text(path), Scale=text("1:10"),
                                 Sheet=text("600x400"),
                                 Width=[item("System.Double", "20")]))
    assert not d.get("errors"), d
    rep = fabricate(path, tmp_path / "fab", FabParams(scale="1:10", sheet="600x400"),
                    plan=False, keep_layout=True)
    layout = rep["layout"]
    n_holes = sum(len(p.holes) for p in layout.parts)
    assert len(f["Cut"]) == len(layout.parts) + n_holes
    assert len(f["Engrave"]) == sum(len(p.engrave) for p in layout.parts)
    assert len(f["Sheets"]) == rep["n_sheets"]
    summary = json.loads(json.loads(f["Report"][0]))
    assert summary["n_sheets"] == rep["n_sheets"]
    assert summary["material_used"] == pytest.approx(rep["material_used"])
    # the outlines are the nested parts' outlines, in mm, where the layout puts them
    outlines = [curve_points(decode(c)) for c in f["Cut"]]
    outlines = [o for o in outlines if o is not None]
    got = sorted(tuple(np.round(o[:, :2].min(axis=0), 3)) for o in outlines)
    want = sorted(tuple(np.round(np.asarray(p.polygon(0.01).bounds[:2]), 3))
                  for p in layout.parts)
    assert got == want


def test_ncp_component_matches_the_api(client):
    from gridshell.ncp.pipeline import design_ncp

    n = 12
    V, F = torus_grid(n, n).reshape(-1, 3), grid_quads(n, n)
    body = request("/ncp", Reference=mesh_item(V, F), Mode=text("cnc"),
                   Curves=[item("System.Int32", "6")], Options=text(json.dumps(NCP_SMALL)))
    d, out = solve(client, body)
    assert not d.get("errors"), d
    kw = dict(NCP_SMALL, samples=(24, 24), collapse_samples=(200, 200))
    bundle, _ = design_ncp(mesh_arrays(to_mesh(V, F)), mode="cnc", curves=6, **kw)
    net = decode(out["Net"][0])
    assert len(net.Vertices) == len(bundle.net.joints)
    assert len(out["Lamellae"]) == len(bundle.net.lamellae)
    metrics = json.loads(json.loads(out["Metrics"][0]))
    assert metrics["n"] == pytest.approx(bundle.metrics["n"], rel=1e-6)
    assert read_bundle(json.loads(out["Bundle"][0])).kind == "CNC"


@pytest.mark.parametrize("body, message", [
    (request("/gg", Target=[item("System.String", json.dumps("not a mesh"))]),
     "is not a target surface"),
    (request("/gg", Lamellae=[item("System.Int32", "5")]), "input Target is missing"),
    (request("/verify", Bundle=text("/no/such/bundle")), "is not a design bundle folder"),
    (request("/gg", Target=mesh_item(np.zeros((4, 3)), np.array([[0, 1, 2, 3]])),
             Options=text('{"colour": 1}')), "unknown keys colour"),
    (request("/ncp", Reference=mesh_item(*((torus_grid(6, 6).reshape(-1, 3),
                                            grid_quads(6, 6)))), Mode=text("xyz")),
     "unknown mode"),
])
def test_bad_input_returns_the_tools_message(client, body, message):
    """A bad input answers 200 with the tool's one-line message in ``errors`` (Hops shows it
    on the component) and no outputs; never a traceback."""
    r = client.post("/solve", data=json.dumps(body))
    assert r.status_code == 200
    d = r.get_json()
    assert d["values"] == [] and len(d["errors"]) == 1
    assert message in d["errors"][0] and "Traceback" not in d["errors"][0]


def test_fabricate_of_a_failing_design_is_refused_unless_forced(client, gg_solved, tmp_path):
    import shutil

    _, _, out = gg_solved
    src = json.loads(out["Bundle"][0])
    bad = Path(src).parent / f"bad-{tmp_path.name}"   # inside the server's work directory
    shutil.copytree(src, bad)
    d = json.loads((bad / "design.json").read_text())
    d["n_joints"] = d["n_joints"] + 1          # the files disagree with design.json
    (bad / "design.json").write_text(json.dumps(d))
    r, _ = solve(client, request("/fabricate", Bundle=text(str(bad))))
    assert "fails its checks" in r["errors"][0] and "Force" in r["errors"][0] or \
        "force" in r["errors"][0]


def test_serve_command_refuses_a_bad_port(capsys):
    from gridshell.cli.main import main

    assert main(["serve", "--port", "70000"]) == 2
    err = capsys.readouterr().err
    assert "--port" in err and "70000" in err and "1 to 65535" in err and "Traceback" not in err
