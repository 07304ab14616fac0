"""Stages of ``run_all.py`` measured side by side: this checkout against another one (e.g. the
code before a change, ``git worktree add ../base main``), alternating, in one run.

Each (root, stage, size) runs in its own process through ``run_all.py --worker`` with
``PYTHONPATH`` set to that root, so both use the inputs and the measurement of this
checkout's ``run_all.py`` and differ only in the ``gridshell`` they import. Prints wall time
and CPU time (all threads of the process; on a loaded machine wall time grows with the load,
CPU time much less) and the ratio, base / this.

    .venv/bin/python benchmarks/side_by_side.py --base ../base phlw:0 phlw:1 ncp_e2e:0
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent


def run(root: Path, stage: str, index: int, timeout: float) -> dict:
    env = dict(os.environ, PYTHONPATH=str(root), MPLBACKEND="Agg")
    try:
        p = subprocess.run([sys.executable, str(HERE / "run_all.py"), "--worker", stage,
                            str(index)], capture_output=True, text=True, env=env,
                           timeout=timeout)
    except subprocess.TimeoutExpired:
        return {"error": f"stopped after {timeout:g} s"}
    lines = [ln for ln in p.stdout.splitlines() if ln.startswith("{")]
    if p.returncode or not lines:
        return {"error": (p.stderr.strip().splitlines() or [f"exit {p.returncode}"])[-1]}
    return json.loads(lines[-1])


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", nargs="+", metavar="STAGE:SIZE", help="e.g. phlw:1 (size index)")
    ap.add_argument("--base", required=True, help="the other checkout's root directory")
    ap.add_argument("--timeout", type=float, default=1800.0)
    ap.add_argument("--json", help="write the figures to this file")
    a = ap.parse_args(argv)
    out = []
    print(f"{'stage':<16} {'size':>4} {'base wall':>10} {'base cpu':>9} {'this wall':>10} "
          f"{'this cpu':>9} {'cpu ratio':>9}")
    for spec in a.runs:
        stage, _, idx = spec.partition(":")
        b = run(Path(a.base).resolve(), stage, int(idx or 0), a.timeout)
        t = run(ROOT, stage, int(idx or 0), a.timeout)
        out.append({"stage": stage, "size": int(idx or 0), "base": b, "this": t})

        def f(d: dict, k: str) -> str:
            return f"{d[k]:.2f}" if k in d else "-"
        ratio = (f"{b['cpu_seconds'] / t['cpu_seconds']:.1f}x" if "cpu_seconds" in b and
                 "cpu_seconds" in t and t["cpu_seconds"] > 0 else b.get("error", t.get("error", "-")))
        print(f"{stage:<16} {idx or 0:>4} {f(b, 'seconds'):>10} {f(b, 'cpu_seconds'):>9} "
              f"{f(t, 'seconds'):>10} {f(t, 'cpu_seconds'):>9} {ratio:>9}", flush=True)
    if a.json:
        Path(a.json).write_text(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
