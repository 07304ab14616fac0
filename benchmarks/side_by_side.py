"""Stages of ``run_all.py`` measured side by side: this checkout against another one (e.g. the
code before a change, ``git worktree add ../base main``), alternating, in one run.

Each (root, stage, size) runs in its own process through ``run_all.py --worker`` with
``PYTHONPATH`` set to that root, so both use the inputs and the measurement of this
checkout's ``run_all.py`` and differ only in the ``gridshell`` they import. Prints wall time
and CPU time (all threads of the process and the processes it waited for; on a loaded machine
wall time grows with the load, CPU time much less) and the ratios base / this of both (work done
in a second process, as the .3dm export's cut sheets, shortens the wall time, not the CPU time).

    .venv/bin/python benchmarks/side_by_side.py --base ../base phlw:0 phlw:1 ncp_e2e:0

``--own-runner`` runs the base's rows as its own ``run_all.py`` defines them (e.g. the code of an
older figures table whose library lacks today's names), measured by this checkout's clock;
``--repeat N`` alternates N times and prints the medians.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))

from _measure import compile_tree, measure  # noqa: E402


def run(root: Path, stage: str, index: int, timeout: float, runner: Path | None = None) -> dict:
    """One (stage, size) importing the ``gridshell`` of ``root``, in its own process: the
    worker's JSON figures. The row is this checkout's ``run_all.py`` row, or with ``runner``
    (another checkout's ``run_all.py``) that checkout's row, measured by this checkout's
    :func:`_measure.measure` (:func:`rows_of`)."""
    env = dict(os.environ, PYTHONPATH=str(root), MPLBACKEND="Agg")
    if runner is None:
        cmd = [sys.executable, str(HERE / "run_all.py"), "--worker", stage, str(index)]
    else:
        cmd = [sys.executable, str(Path(__file__).resolve()), "--rows-of", str(runner), stage,
               str(index)]
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=timeout,
                           cwd=(runner or HERE / "run_all.py").parent.parent)
    except subprocess.TimeoutExpired:
        return {"error": f"stopped after {timeout:g} s"}
    lines = [ln for ln in p.stdout.splitlines() if ln.startswith("{")]
    if p.returncode or not lines:
        return {"error": (p.stderr.strip().splitlines() or [f"exit {p.returncode}"])[-1]}
    return json.loads(lines[-1])


def rows_of(runner: Path, stage: str, index: int) -> dict:
    """Build row ``stage`` size ``index`` as the ``run_all.py`` at ``runner`` defines it (its
    ``STAGES``, each with ``setup(param)``) and measure it with this checkout's ``measure``:
    the same clock, CPU figure and garbage collection on both sides."""
    import importlib.util

    sys.path.insert(0, str(runner.parent))    # its helpers (this checkout's _measure is loaded)
    spec = importlib.util.spec_from_file_location("base_run_all", runner)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod              # its dataclasses look their module up
    spec.loader.exec_module(mod)
    st = mod.BY_NAME[stage]
    call = st.setup(st.sizes[index].param)
    m = measure(call)
    return {"seconds": m.seconds, "cpu_seconds": m.cpu_seconds, "peak_mb": m.peak_mb,
            "rss_peak_mb": m.rss_peak_mb}


def median(runs: list[dict]) -> dict:
    """The median of each figure over the runs without an error (the first error otherwise)."""
    ok = [r for r in runs if "error" not in r]
    if not ok:
        return runs[0]
    keys = set.intersection(*(set(r) for r in ok))
    return {k: float(np.median([r[k] for r in ok])) for k in keys
            if all(isinstance(r[k], (int, float)) for r in ok)}


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", nargs="+", metavar="STAGE:SIZE", help="e.g. phlw:1 (size index)")
    ap.add_argument("--base", required=True, help="the other checkout's root directory")
    ap.add_argument("--timeout", type=float, default=1800.0)
    ap.add_argument("--json", help="write the figures to this file")
    ap.add_argument("--own-runner", action="store_true",
                    help="run the base with its own benchmarks/run_all.py (its row definitions)")
    ap.add_argument("--repeat", type=int, default=1, help="alternate this many times; medians")
    a = ap.parse_args(argv)
    base = Path(a.base).resolve()
    base_runner = base / "benchmarks" / "run_all.py" if a.own_runner else None
    for root in (base, ROOT):                 # bytecode, as an installed package has it
        compile_tree(root)
    out = []
    print(f"{'stage':<16} {'size':>4} {'base wall':>10} {'base cpu':>9} {'this wall':>10} "
          f"{'this cpu':>9} {'ratio wall':>10} {'ratio cpu':>9}")
    for spec in a.runs:
        stage, _, idx = spec.partition(":")
        bs, ts = [], []
        for _ in range(max(1, a.repeat)):
            bs.append(run(base, stage, int(idx or 0), a.timeout, base_runner))
            ts.append(run(ROOT, stage, int(idx or 0), a.timeout))
        b, t = median(bs), median(ts)
        out.append({"stage": stage, "size": int(idx or 0), "base": b, "this": t})

        def f(d: dict, k: str) -> str:
            return f"{d[k]:.2f}" if k in d else "-"
        def ratio(k: str) -> str:
            if k in b and k in t and t[k] > 0:
                return f"{b[k] / t[k]:.2f}x"
            return b.get("error", t.get("error", "-"))
        print(f"{stage:<16} {idx or 0:>4} {f(b, 'seconds'):>10} {f(b, 'cpu_seconds'):>9} "
              f"{f(t, 'seconds'):>10} {f(t, 'cpu_seconds'):>9} {ratio('seconds'):>10} "
              f"{ratio('cpu_seconds'):>9}", flush=True)
    if a.json:
        Path(a.json).write_text(json.dumps(out, indent=1))


if __name__ == "__main__":
    if len(sys.argv) == 5 and sys.argv[1] == "--rows-of":
        print(json.dumps(rows_of(Path(sys.argv[2]), sys.argv[3], int(sys.argv[4]))))
    else:
        main()
