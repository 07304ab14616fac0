"""The ``/build`` Hops component: ``gridshell build`` of a Rhino document drawn in millimetres
(the Units input), its pack the same as the CLI's on the .3dm it stored, and bad inputs refused
before any work; Units on the design components (Options)."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("ghhops_server")

from gridshell.server.components import make_app  # noqa: E402
from tests.faces.test_server import item, mesh_item, request, solve, text  # noqa: E402
from tests.helpers.io_cases import hill  # noqa: E402

MM = 1000.0


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    work = tmp_path_factory.mktemp("hops-build")
    client = make_app(work).test_client()
    V, F = hill(13, 9, scale=MM)                             # the 12 x 8 m hill in mm
    d, out = solve(client, request("/build", Target=mesh_item(V, F), Units=text("mm"),
                                   Lamellae=[item("System.Int32", "6")]))
    return work, d, out


def test_build_component_makes_the_pack_of_a_millimetre_document(built):
    from gridshell.design.verification import verify_bundle
    from gridshell.io.read import read_input

    work, d, out = built
    assert not d.get("errors"), d.get("errors")
    pack = Path(json.loads(out["Pack"][0]))
    assert pack.is_relative_to(work) and (pack / "report.html").is_file()
    assert Path(json.loads(out["Report"][0])) == pack / "report.html"
    assert verify_bundle(pack)["ok"]
    rec = json.loads(json.loads(out["Build"][0]))
    assert rec == json.loads((pack / "build.json").read_text())
    stored = read_input(str(pack.parent / "target.3dm"))     # the unit went into the file
    assert stored.units.name == "mm"
    assert np.ptp(stored.V[:, 0]) == pytest.approx(12.0, rel=1e-9)     # read as 12 m
    summary = [json.loads(x) for x in out["Summary"]]
    assert any(s.startswith("section:") for s in summary)
    made = max(rec["stages"]["design"]["n_lamellae"].values())
    count = json.loads((pack / "design.json").read_text())["metrics"]["lamellae_count"]
    assert count["asked"] == 6 and count["made"] == made       # as asked, or said why not
    assert made == 6 or "nearest" in count["why"]


@pytest.mark.parametrize("inputs,message", [
    ({"Kind": text("xx")}, "Kind"), ({"Material": text("steel")}, "steel"),
    ({"Lamellae": [item("System.Int32", "1")]}, "Lamellae 1"),
    ({"Units": text("km")}, "Units"), ({"Scale": text("1:0")}, "scale"),
])
def test_build_component_refuses_before_any_work(tmp_path, inputs, message):
    work = tmp_path / "work"
    client = make_app(work).test_client()
    V, F = hill(9, 7, scale=MM)
    d, _ = solve(client, request("/build", Target=mesh_item(V, F), **inputs))
    assert any(message in e for e in d.get("errors", [])), d.get("errors")
    assert not list(work.glob("build-*"))


def test_a_millimetre_model_without_units_names_the_fix(tmp_path):
    client = make_app(tmp_path / "work").test_client()
    V, F = hill(9, 7, scale=MM)
    d, _ = solve(client, request("/gg", Target=mesh_item(V, F)))
    assert any("units" in e.lower() for e in d.get("errors", [])), d.get("errors")
    d, out = solve(client, request("/gg", Target=mesh_item(V, F), Options=text('{"units": "mm"}'),
                                   Lamellae=[item("System.Int32", "6")]))
    assert not d.get("errors"), d.get("errors")
