"""``gridshell analyze`` on the 12 x 8 m hill at ~2.4k and ~200k triangles, in millimetres,
each run in its own process as a user runs it (python start and imports included).

Prints per size: wall time, CPU time (user + system of the child), the load average before the
run and what the analysis found (near-umbilic share, the largest patch of PHLW / AA, the GG
trial's deviation, the recommendation). Goal: under 5 s at 200k triangles on a quiet 2-core
machine.

    .venv/bin/python benchmarks/analyze.py [--sizes 40 355] [--keep DIR]
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def run(target: Path, out: Path) -> dict:
    """One ``gridshell analyze TARGET --units mm --json -o OUT`` in a child process."""
    load = os.getloadavg()[0]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run([sys.executable, "-m", "gridshell", "analyze", str(target), "--units",
                        "mm", "--json", "-q", "-o", str(out)], capture_output=True, text=True,
                       cwd=ROOT)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    summary = json.loads(p.stdout) if p.stdout.strip() else {"error": p.stderr.strip()}
    return {"wall": wall, "cpu": cpu, "load": load, "exit": p.returncode, "summary": summary}


def main() -> None:
    from gridshell.geometry.meshfile import write_mesh
    from tests.helpers.io_cases import hill

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", nargs="+", type=int, default=[40, 355],
                    help="grid points along the 12 m side (40: ~2.4k triangles, 355: ~200k)")
    ap.add_argument("--keep", type=Path, help="keep the targets and analyses here")
    args = ap.parse_args()
    root = args.keep or Path(tempfile.mkdtemp(prefix="analyze_"))
    root.mkdir(parents=True, exist_ok=True)
    print(f"analyze on a 12 x 8 m hill in mm; {os.cpu_count()} CPUs, load average "
          f"{os.getloadavg()[0]:.1f}")
    print(f"{'triangles':>10} {'wall s':>7} {'CPU s':>7} {'load':>5} {'exit':>4}  "
          "umbilic %  PHLW/AA patch %  GG dev %  recommended")
    for n in args.sizes:
        V, T = hill(n, int(n * 0.8), scale=1000.0)
        target = root / f"hill_{len(T)}.obj"
        write_mesh(target, V, T)
        r = run(target, root / f"hill_{len(T)}-analysis")
        s = r["summary"]
        cls = s.get("classes [%]", {})
        cov = s.get("NCP largest regular patch [%]", {})
        print(f"{len(T):>10} {r['wall']:>7.2f} {r['cpu']:>7.2f} {r['load']:>5.1f} "
              f"{r['exit']:>4}  {cls.get('near umbilic', float('nan')):>9.1f}  "
              f"{cov.get('phlw', float('nan')):>6.1f} / {cov.get('aa', float('nan')):<6.1f}  "
              f"{str(s.get('GG trial', ''))[10:22]:>8}  {s.get('recommended', s.get('error'))}",
              flush=True)


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    main()
