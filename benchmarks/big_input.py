"""``gridshell gg`` on a big target (issue 18 item 4): a 12 x 8 m hill at ~3k and ~200k
triangles, side by side, each in its own process (so the peak is the command's whole resident
memory, imports included, as a user sees it).

Prints per run: wall time, CPU time (user + system of the process: wall time is noisy on a
shared machine), peak resident memory (ru_maxrss), the load average before the run, and the
figures the design reports (deviation against the full target, verdict). Goal: the 200k run in
under 10 s and 300 MB on a quiet machine.

    .venv/bin/python benchmarks/big_input.py [--sizes 40 355] [--keep DIR]
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from gridshell.meshfile import write_mesh

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from io_cases import hill  # noqa: E402 - the tests' hill, one definition


def run(target: Path, out: Path) -> dict:
    load = os.getloadavg()[0]
    cmd = [sys.executable, "-m", "gridshell", "gg", str(target), "-o", str(out), "--no-preview",
           "--frames", "0", "-q", "--json"]
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    stdout = proc.stdout.read()
    proc.stderr.read()
    _, status, ru = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    res = json.loads(stdout or b"{}")
    return {"wall": wall, "cpu": ru.ru_utime + ru.ru_stime, "peak_mb": ru.ru_maxrss / 1024,
            "load": load, "exit": os.waitstatus_to_exitcode(status), "summary": res}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", nargs="+", type=int, default=[40, 355],
                    help="grid points along the 12 m side (40: ~2.4k triangles, 355: ~200k)")
    ap.add_argument("--keep", type=Path, help="keep the targets and bundles here")
    args = ap.parse_args()
    root = args.keep or Path(tempfile.mkdtemp(prefix="big_input_"))
    root.mkdir(parents=True, exist_ok=True)
    print(f"gg on a 12 x 8 m hill; {os.cpu_count()} CPUs, load average "
          f"{os.getloadavg()[0]:.1f} (shared machine: compare CPU times)")
    print(f"{'triangles':>10} {'wall s':>8} {'CPU s':>8} {'peak MB':>8} {'load':>5}  "
          "deviation mean/max [% diag]  verdict")
    for n in args.sizes:
        V, T = hill(n, int(n * 0.8))
        target = root / f"hill_{len(T)}.obj"
        write_mesh(target, V, T)
        r = run(target, root / f"gg_{len(T)}")
        s = r["summary"]
        dev = s.get("deviation [% diag]") or {}
        verdict = s.get("verdict", f"exit {r['exit']}")
        print(f"{len(T):>10} {r['wall']:>8.1f} {r['cpu']:>8.1f} {r['peak_mb']:>8.0f} "
              f"{r['load']:>5.1f}  {dev.get('mean', float('nan')):.3f} / "
              f"{dev.get('max', float('nan')):.3f}  {str(verdict)[:40]}")


if __name__ == "__main__":
    main()
