"""The ``/analyze`` Hops component: the same analysis as the API on the same mesh, its files
in the server's work directory, and a bad input as the tool's message."""
from __future__ import annotations

import json

import pytest
from tests.analysis.test_analysis import paraboloid

pytest.importorskip("ghhops_server")

from gridshell.server.components import make_app  # noqa: E402
from tests.faces.test_server import item, mesh_item, request, solve  # noqa: E402


@pytest.fixture
def client(tmp_path):
    return make_app(tmp_path / "work").test_client()


def test_analyze_component_matches_the_api(client, tmp_path):
    from gridshell import api

    V, F = paraboloid()
    body = request("/analyze", Target=mesh_item(V, F), Samples=[item("System.Int32", "32")])
    d, out = solve(client, body)
    assert not d.get("errors"), d.get("errors")
    report = json.loads(json.loads(out["Report"][0]))
    a = api.analyze((V, F), units="m", samples=32)
    assert report["classes_percent"]["near umbilic"] == pytest.approx(
        a.classes["near umbilic"], abs=0.01)
    assert report["ncp"]["aa"]["coverage_percent"] == 0.0
    assert json.loads(out["Recommended"][0]).startswith("gridshell gg")
    folder = json.loads(out["Folder"][0])
    assert folder.startswith(str(tmp_path / "work"))
    assert (tmp_path / "work").is_dir() and any((tmp_path / "work").glob("analysis-*/analysis.png"))


def test_analyze_component_refuses_bad_samples(client):
    V, F = paraboloid()
    d, _ = solve(client, request("/analyze", Target=mesh_item(V, F),
                                 Samples=[item("System.Int32", "2")]))
    assert any("Samples 2" in e for e in d.get("errors", []))
