"""benchmarks/side_by_side.py: a base checkout run with its own runner, medians over repeats."""
import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _module():
    spec = importlib.util.spec_from_file_location("side_by_side", ROOT / "benchmarks" / "side_by_side.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_own_runner_builds_the_base_row_and_measures_it_here(tmp_path):
    """--own-runner: the row as the base's run_all.py defines it (setup(param) of its STAGES),
    run in the base checkout with its PYTHONPATH, timed by this checkout's measure (CPU too)."""
    sbs = _module()
    (tmp_path / "benchmarks").mkdir()
    runner = tmp_path / "benchmarks" / "run_all.py"
    runner.write_text(
        "import os, time\n"
        "from types import SimpleNamespace as NS\n"
        "def setup(param):\n"
        "    def call():\n"
        "        t = time.process_time()\n"
        "        while time.process_time() - t < param:\n"
        "            pass\n"
        "        open('ran.txt', 'w').write(os.getcwd() + '|' + os.environ['PYTHONPATH'])\n"
        "    return call\n"
        "BY_NAME = {'phlw': NS(setup=setup, sizes=[NS(param=0.0), NS(param=0.2)])}\n")
    r = sbs.run(tmp_path, "phlw", 1, 60.0, runner)
    assert r["cpu_seconds"] >= 0.19 and r["seconds"] >= r["cpu_seconds"] * 0.9
    assert (tmp_path / "ran.txt").read_text() == f"{tmp_path}|{tmp_path}"


def test_failed_worker_reports_its_last_error_line(tmp_path):
    sbs = _module()
    (tmp_path / "benchmarks").mkdir()
    runner = tmp_path / "benchmarks" / "run_all.py"
    runner.write_text("raise ImportError('no such name')\n")
    assert sbs.run(tmp_path, "outputs", 0, 60.0, runner) == {"error": "ImportError: no such name"}


def test_median_of_repeats_skips_failed_runs():
    sbs = _module()
    runs = [{"seconds": 3.0, "cpu_seconds": 2.0}, {"error": "stopped"},
            {"seconds": 1.0, "cpu_seconds": 4.0}, {"seconds": 2.0, "cpu_seconds": 3.0}]
    assert sbs.median(runs) == {"seconds": 2.0, "cpu_seconds": 3.0}
    assert sbs.median([{"error": "x"}, {"error": "y"}]) == {"error": "x"}


def test_trees_are_compiled_before_measuring(tmp_path):
    """compile_tree writes the bytecode of gridshell/ and fabrication/ (PYTHONDONTWRITEBYTECODE
    aside), so lazily imported modules are not compiled inside a timed call."""
    import importlib.util as iu

    sbs = _module()
    for pkg in ("gridshell", "fabrication"):
        (tmp_path / pkg).mkdir()
        (tmp_path / pkg / "late.py").write_text("X = 1\n")
    sbs.compile_tree(tmp_path)
    for pkg in ("gridshell", "fabrication"):
        assert (tmp_path / pkg / iu.cache_from_source("late.py")).is_file()


def test_cpu_counts_the_processes_the_call_waited_for():
    """measure()'s CPU seconds include a child the call forked and reaped (the .3dm export's
    cut-sheet process): two children spinning 0.2 s each give >= 0.4 s of CPU."""
    import os
    import sys
    import time

    import pytest

    if not hasattr(os, "fork"):
        pytest.skip("no fork")
    sys.path.insert(0, str(ROOT / "benchmarks"))
    from _measure import measure

    def call():
        pids = []
        for _ in range(2):
            pid = os.fork()
            if pid == 0:
                t = time.process_time()
                while time.process_time() - t < 0.2:
                    pass
                os._exit(0)
            pids.append(pid)
        for pid in pids:
            os.waitpid(pid, 0)

    m = measure(call)
    assert m.cpu_seconds >= 0.38
