"""benchmarks/side_by_side.py: a base checkout run with its own runner, medians over repeats."""
import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def _module():
    spec = importlib.util.spec_from_file_location("side_by_side", ROOT / "benchmarks" / "side_by_side.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_own_runner_runs_the_base_script_in_its_checkout(tmp_path):
    sbs = _module()
    (tmp_path / "benchmarks").mkdir()
    runner = tmp_path / "benchmarks" / "run_all.py"
    # the base's own worker: reports its working directory and PYTHONPATH through the figures
    runner.write_text(
        "import json, os, sys\n"
        "assert sys.argv[1:] == ['--worker', 'phlw', '1'], sys.argv\n"
        "print('noise line')\n"
        "print(json.dumps({'seconds': 2.5, 'cwd_ok': float(os.getcwd() == %r),\n"
        "                  'path_ok': float(os.environ['PYTHONPATH'] == %r)}))\n"
        % (str(tmp_path), str(tmp_path)))
    r = sbs.run(tmp_path, "phlw", 1, 60.0, runner)
    assert r == {"seconds": 2.5, "cwd_ok": 1.0, "path_ok": 1.0}


def test_failed_worker_reports_its_last_error_line(tmp_path):
    sbs = _module()
    (tmp_path / "benchmarks").mkdir()
    runner = tmp_path / "benchmarks" / "run_all.py"
    runner.write_text("import sys\nsys.exit('ImportError: no such name')\n")
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
