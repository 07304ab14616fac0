"""The ``/sweep`` Hops component: a small study on the same engine as ``gridshell sweep``, its
rows those of the variants' own files, the target stored as the .3dm the CLI would read, and a
study too large or badly written refused before any work."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("ghhops_server")
pytest.importorskip("distributed")

from gridshell.server.components import MAX_SWEEP, make_app  # noqa: E402
from tests.faces.test_server import item, mesh_item, request, solve, text  # noqa: E402
from tests.helpers.gg_cases import helicoid_grid  # noqa: E402
from gridshell.geometry.grid import grid_quads  # noqa: E402


def _vary(*items):
    return [item("System.String", json.dumps(s)) for s in items]


@pytest.fixture(scope="module")
def target():
    n = 12
    return helicoid_grid(n, n, c=0.5).reshape(-1, 3), grid_quads(n, n)


def test_sweep_component_rows_are_the_variants_files(tmp_path, target):
    from gridshell.io.read import read_input

    work = tmp_path / "work"
    client = make_app(work).test_client()
    V, F = target
    d, out = solve(client, request("/sweep", Target=mesh_item(V, F),
                                   Vary=_vary("lamellae=4,5"),
                                   Workers=[item("System.Int32", "1")]))
    assert not d.get("errors"), d.get("errors")
    rows = json.loads(json.loads(out["Table"][0]))
    folder = Path(json.loads(out["Folder"][0]))
    assert folder.is_relative_to(work)
    assert sorted(r["lamellae"] for r in rows) == [4, 5]
    for r in rows:                       # each row is the one its variant wrote
        own = json.loads((folder / "variants" / r["key"] / "row.json").read_text())
        assert own["code"] == r["code"] and own["n_joints"] == r["n_joints"]
    cut = [r for r in rows if r["code"] == 0]
    assert cut, [r["message"] for r in rows]        # a helicoid at 1:10 in pp is cut
    best = json.loads(out["Best"][0])
    if cut:
        low = min(cut, key=lambda r: r["max_utilisation"])
        assert f"key {low['key']}" in best
    assert Path(json.loads(out["Page"][0])).is_file()
    stored = read_input(str(folder.parent / "target.3dm"))      # read as the CLI reads it
    assert stored.V.shape == V.shape
    assert np.abs(stored.V - V).max() < 1e-9 * np.ptp(V, axis=0).max()


@pytest.mark.parametrize("vary,workers,message", [
    (["lamellae=4,5,6,7,8", "material=pp,petg,spruce,gfrp,birch-plywood"], "1",
     f"more than the server's {MAX_SWEEP}"),
    (["lamelae=4,5"], "1", "lamelae"),
    (["angle=60:120"], "1", "ranges"),
    (["lamellae=4,5"], "0", "Workers 0"),
])
def test_sweep_component_refuses_before_any_work(tmp_path, target, vary, workers, message):
    work = tmp_path / "work"
    client = make_app(work).test_client()
    V, F = target
    d, out = solve(client, request("/sweep", Target=mesh_item(V, F), Vary=_vary(*vary),
                                   Workers=[item("System.Int32", workers)]))
    assert any(message in e for e in d.get("errors", [])), d.get("errors")
    assert not list(work.glob("sweep-*"))
