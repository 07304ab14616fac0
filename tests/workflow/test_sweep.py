"""gridshell sweep on Dask: a study on a local cluster, its re-run, an external cluster started
here, and a worker killed mid-study (issue 31). Figures are checked against each variant's own
files; the table's mass against the cut length, the section and the material's density."""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytest.importorskip("distributed")

from gridshell.data import __file__ as _data  # noqa: E402
from gridshell.structure.materials import get_material  # noqa: E402
from gridshell.workflow.study import Study  # noqa: E402
from gridshell.workflow.sweep import load_results, sweep  # noqa: E402

DOME = str(Path(_data).parent / "dome.obj")
SAME = ["key", "code", "stage", "delta_a_max_pct", "deviation_mean_pct", "max_utilisation",
        "sheets", "strip_length_m", "mass_kg", "n_lamellae", "n_joints"]


@pytest.fixture(scope="module")
def local(tmp_path_factory):
    out = tmp_path_factory.mktemp("study")
    st = Study(DOME, {"lamellae": [6, 8], "material": ["pp"]})
    return st, out, sweep(st, out, workers=2)


def test_every_variant_is_a_row_with_its_own_figures(local):
    st, out, res = local
    t = res.table
    assert len(t) == 2 and res.ran == 2 and list(t["code"]) == [0, 0]
    assert load_results(out).equals(t)
    rho = get_material("pp").density
    for rec in t.to_dict("records"):
        d = json.loads((out / "variants" / rec["key"] / "design" / "design.json").read_text())
        assert rec["delta_a_max_pct"] == pytest.approx(d["metrics"]["alignability"]["max"])
        fab = json.loads((out / "variants" / rec["key"] / "design" / "fabrication" /
                          "fabrication.json").read_text())
        length = sum(p["flat_length_mm"] for p in fab["pieces"]) / 1000
        assert rec["strip_length_m"] == pytest.approx(length)
        assert rec["mass_kg"] == pytest.approx(length * 0.020 * 0.001 * rho)
        assert rec["sheets"] == fab["n_sheets"]
    html = (out / "sweep.html").read_text()
    assert html.count("<tr") == 3 and "Pareto front" in html and (out / "sweep.png").is_file()


def test_a_rerun_designs_nothing(local):
    st, out, _ = local
    before = {p: p.stat().st_mtime_ns for p in (out / "variants").rglob("*") if p.is_file()}
    t0 = time.perf_counter()
    res = sweep(st, out, workers=2)
    assert time.perf_counter() - t0 < 5 and res.ran == 0 and res.reused == 2
    after = {p: p.stat().st_mtime_ns for p in (out / "variants").rglob("*") if p.is_file()}
    assert after == before


def _dask(*args, **kw):
    return subprocess.Popen([sys.executable, "-m", "distributed.cli." + args[0], *args[1:]],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, **kw)


def test_an_external_cluster_gives_the_same_table(local, tmp_path):
    st, _, res = local
    sched_file = tmp_path / "scheduler.json"
    procs = [_dask("dask_scheduler", "--scheduler-file", str(sched_file), "--port", "0",
                   "--no-dashboard")]
    try:
        for _ in range(100):
            if sched_file.is_file() and sched_file.stat().st_size:
                break
            time.sleep(0.1)
        address = json.loads(sched_file.read_text())["address"]
        procs += [_dask("dask_worker", address, "--nthreads", "1", "--no-dashboard")
                  for _ in range(2)]
        remote = sweep(st, tmp_path / "remote", scheduler=address, page=False).table
    finally:
        for p in procs:
            p.terminate()
        for p in procs:
            p.wait(10)
    assert remote[SAME].equals(res.table[SAME])


def test_a_killed_worker_loses_only_its_task(tmp_path):
    import distributed

    st = Study(DOME, {"lamellae": [6, 7, 8, 9]})
    killed = []

    def progress(msg):  # after the first variant: kill a worker that is running one
        if msg.startswith("1/") and not killed:
            client = distributed.default_client()
            busy = [w for w, keys in client.processing().items() if keys]
            pid = client.run(os.getpid, workers=busy[:1])[busy[0]]
            os.kill(pid, signal.SIGKILL)
            killed.append(pid)

    res = sweep(st, tmp_path / "s", workers=2, progress=progress, page=False)
    assert killed
    t = res.table
    assert len(t) == 4 and t["key"].is_unique and sorted(t["lamellae"]) == [6, 7, 8, 9]
    assert set(t["code"]) == {0}
    dirs = sorted(p.name for p in (tmp_path / "s" / "variants").iterdir())
    assert dirs == sorted(t["key"])            # no half-written variant left behind


def test_files_the_user_put_in_a_study_are_never_replaced_nor_claimed(local, tmp_path):
    import shutil

    from gridshell.core.errors import OutputError
    from gridshell.core.manifest import read

    st, out, _ = local
    mine = tmp_path / "study"
    shutil.copytree(out, mine)
    (mine / "notes.txt").write_text("my notes")
    sweep(st, mine, workers=1, page=False)             # nothing to run: table rewritten
    assert "notes.txt" not in read(mine)["files"] and (mine / "notes.txt").is_file()
    (mine / "sweep.html").write_text("my page")
    with pytest.raises(OutputError, match="sweep.html"):
        sweep(st, mine, workers=1)
    assert (mine / "sweep.html").read_text() == "my page"
    stranger = tmp_path / "other"
    stranger.mkdir()
    (stranger / "data.csv").write_text("1")
    with pytest.raises(OutputError, match="not a study"):
        sweep(st, stranger, workers=1)
    assert sorted(p.name for p in stranger.iterdir()) == ["data.csv"]
