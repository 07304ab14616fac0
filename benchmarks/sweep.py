"""A 24-variant design study on the demo dome, three ways in one run (issue 31).

The study: ``lamellae`` 6, 8, 10 x ``kind`` gg, cnc x ``material`` pp, petg, spruce, gfrp on
``gridshell/data/dome.obj`` (every variant designed, verified, checked and cut), run

1. ``gridshell sweep`` on a LocalCluster of ``--workers`` processes (default: the cores),
2. ``gridshell sweep --workers 1`` (one worker process: the same engine, no parallelism),
3. as 24 x 4 sequential ``gridshell`` calls, one variant after the other, as a user would type
   them: ``gridshell gg|ncp TARGET -o D`` (``--no-preview`` / ``--no-render``: the sweep's
   bundles have no pictures either), ``gridshell verify D``, ``gridshell check D --material M``,
   ``gridshell fabricate D -o D/fabrication --material M``.

Each way starts in an empty directory (nothing reused) and is timed by the wall clock
(``time.perf_counter``) around the whole command, cluster start-up included. Printed: the wall
time of each, the speed-up of the sweep over ``--workers 1`` and the ratio of ``--workers 1``
to the sequential calls, and whether the three agree on every variant's exit code (the
results table against the calls' exit codes).

    .venv/bin/python benchmarks/sweep.py                   # ~7 min on 2 cores
    .venv/bin/python benchmarks/sweep.py --lamellae 6 --materials pp   # a quick look
    .venv/bin/python benchmarks/sweep.py --skip-sequential --json out/sweep.json
"""
from __future__ import annotations

import argparse
import itertools
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from _measure import gridshell_env as _env  # noqa: E402

DOME = ROOT / "gridshell" / "data" / "dome.obj"


def _gridshell(*argv: str) -> tuple[int, float]:
    """``python -m gridshell ARGV``: exit code and wall seconds."""
    t0 = time.perf_counter()
    p = subprocess.run([sys.executable, "-m", "gridshell", *argv], env=_env(),
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return p.returncode, time.perf_counter() - t0


def run_sweep(target: Path, out: Path, axes: dict[str, list[str]], workers: int) -> tuple[float, dict]:
    """``gridshell sweep`` with ``workers``: wall seconds and exit code per variant label."""
    vary = [a for k, v in axes.items() for a in ("--vary", f"{k}={','.join(v)}")]
    code, sec = _gridshell("sweep", str(target), *vary, "-o", str(out), "--workers",
                           str(workers), "--no-page", "-q")
    if code != 0:
        raise SystemExit(f"gridshell sweep --workers {workers} exited {code}")
    rows = [json.loads(p.read_text()) for p in sorted((out / "variants").glob("*/row.json"))]
    return sec, {_label(r, axes): r["code"] for r in rows}


def _label(params: dict[str, Any], axes: dict[str, list[str]]) -> str:
    return " ".join(f"{k}={params[k]}" for k in axes)


def run_sequential(target: Path, work: Path, axes: dict[str, list[str]]) -> tuple[float, dict]:
    """Each variant as the user's command chain; wall seconds and the exit code per variant
    (the first stage that does not exit 0 ends the chain, as in the sweep)."""
    codes: dict[str, int] = {}
    t0 = time.perf_counter()
    for i, combo in enumerate(itertools.product(*axes.values())):
        p = dict(zip(axes, combo))
        d = work / f"v{i:02d}"
        n = p.get("lamellae", "10")
        design = (["gg", str(target), "-o", str(d), "--lamellae", n, "--no-preview"]
                  if p["kind"] == "gg" else
                  ["ncp", str(target), "-o", str(d), "--mode", p["kind"], "--curves", n,
                   "--no-render"])
        mat = ["--material", p["material"]] if "material" in p else []
        chain = [design, ["verify", str(d)], ["check", str(d), *mat],
                 ["fabricate", str(d), "-o", str(d / "fabrication"), *mat]]
        code = 0
        for argv in chain:
            code, _ = _gridshell(*argv)
            if code != 0:
                break
        codes[_label(p, axes)] = code
    return time.perf_counter() - t0, codes


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--target", type=Path, default=DOME)
    ap.add_argument("--lamellae", default="6,8,10")
    ap.add_argument("--kinds", default="gg,cnc")
    ap.add_argument("--materials", default="pp,petg,spruce,gfrp")
    ap.add_argument("--workers", type=int, default=os.cpu_count() or 2)
    ap.add_argument("--skip-sequential", action="store_true",
                    help="leave out the sequential gridshell calls")
    ap.add_argument("--json", metavar="OUT", help="also write the figures to OUT")
    args = ap.parse_args(argv)
    axes = {"lamellae": args.lamellae.split(","), "kind": args.kinds.split(","),
            "material": args.materials.split(",")}
    n = len(list(itertools.product(*axes.values())))
    print(f"{n} variants on {args.target.name}: " + " x ".join(
        f"{k} {','.join(v)}" for k, v in axes.items()) + f"; {os.cpu_count()} cores", flush=True)
    fig: dict[str, Any] = {"variants": n, "cores": os.cpu_count(), "workers": args.workers}
    with tempfile.TemporaryDirectory(prefix="gridshell-sweep-bench-") as tmp:
        tmp = Path(tmp)
        fig["sweep_s"], c_par = run_sweep(args.target, tmp / "par", axes, args.workers)
        print(f"gridshell sweep --workers {args.workers}: {fig['sweep_s']:7.1f} s", flush=True)
        fig["sweep_1_s"], c_one = run_sweep(args.target, tmp / "one", axes, 1)
        print(f"gridshell sweep --workers 1: {fig['sweep_1_s']:7.1f} s", flush=True)
        fig["speedup"] = fig["sweep_1_s"] / fig["sweep_s"]
        same = c_par == c_one
        if not args.skip_sequential:
            fig["sequential_s"], c_seq = run_sequential(args.target, tmp / "seq", axes)
            fig["workers1_over_sequential"] = fig["sweep_1_s"] / fig["sequential_s"]
            same = same and c_par == c_seq
            print(f"{n} sequential variants ({4 * n} gridshell calls at most): "
                  f"{fig['sequential_s']:7.1f} s", flush=True)
        fig["same_exit_codes"] = same
        fig["exit_codes"] = {str(c): list(c_par.values()).count(c) for c in sorted(set(c_par.values()))}
    print(f"speed-up over --workers 1: {fig['speedup']:.2f}x (goal >= 1.7x)")
    if "sequential_s" in fig:
        print(f"--workers 1 / sequential calls: {fig['workers1_over_sequential']:.2f} "
              "(goal <= 1.10)")
    print(f"exit codes of the variants {fig['exit_codes']}; the same every way: {same}")
    if args.json:
        Path(args.json).parent.mkdir(parents=True, exist_ok=True)
        Path(args.json).write_text(json.dumps(fig, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
