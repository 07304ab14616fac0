"""``gridshell gg`` on a big target (issue 18 item 4): a 12 x 8 m hill at ~2.4k and ~200k
triangles, side by side, each in its own process (so the peak is the command's whole resident
memory, imports included, as a user sees it).

Prints per run: wall time, CPU time (user + system of the process: wall time is noisy on a
shared machine), peak resident memory (ru_maxrss), the load average before the run, and the
figures the design reports (deviation against the full target, verdict); then where the time
went, per stage, wall and CPU (the child process wraps the stages' functions and the CLI's
entry; a stage's time excludes the stages nested in it, e.g. the net traced inside the
design's checks counts as tracing). Goal: the 200k run in under 10 s and 300 MB on a quiet
machine.

    .venv/bin/python benchmarks/big_input.py [--sizes 40 355] [--modes design defaults]
        [--repeat N] [--keep DIR]
"""
from __future__ import annotations

import argparse
import functools
import importlib
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

#: the stages of ``gridshell gg``: (module, function, label), in pipeline order
STAGES = [
    ("gridshell.geometry.meshfile", "read_polygons", "read the file"),
    ("gridshell.io.read", "read_input", "clean + checks (full mesh)"),
    ("gridshell.io.working", "working_mesh", "working copy (pymeshlab)"),
    ("gridshell.gg.initial", "initial_grid", "initial grid"),
    ("gridshell.gg.design", "design_gg_surface", "surface design (LM, excl. tracing)"),
    ("gridshell.gg.pipeline", "gg_net_from_mesh", "trace the net"),
    ("gridshell.geometry.igl_adapter", "closest_points", "closest points (igl AABB)"),
    ("gridshell.gg.pipeline", "gg_metrics", "figures (excl. closest points)"),
    ("gridshell.gg.pipeline", "gg_alignment_sequence", "alignment sequence"),
    ("gridshell.api", "write", "bundle writing"),
    ("gridshell.render.net_preview", "net_preview", "pictures"),
    ("gridshell.render.state_sheet", "sequence_pngs", "pictures"),
    ("gridshell.render.state_sheet", "states_png", "pictures"),
    ("gridshell.render.ncp_maps", "gif", "pictures"),
]

#: the runs per size: name -> options of ``gridshell gg``
MODES = {
    "design": ["--no-preview", "--frames", "0"],  # the design and its bundle (the goal's run)
    "defaults": [],  # as a user runs it: also the 12-step alignment sequence and the pictures
}


def _child(argv: list[str], marks_path: str) -> int:
    """Run ``gridshell gg`` in this process with the stages' functions timed."""
    w0, c0 = time.perf_counter(), time.process_time()
    from gridshell.cli.main import main  # the CLI's own imports

    # the modules the gg command loads anyway (the pictures' only when it draws them)
    stages = [st for st in STAGES
              if "--no-preview" not in argv or not st[0].startswith("gridshell.render")]
    for mod, _, _ in stages:
        importlib.import_module(mod)
    w1, c1 = time.perf_counter(), time.process_time()
    totals: dict[str, list[float]] = {"imports": [w1 - w0, c1 - c0, 1]}
    stack: list[list[float]] = []  # [wall, cpu] spent in nested stages, per open stage

    def timed(fn, label):  # noqa: ANN001, ANN202
        @functools.wraps(fn)
        def wrapper(*a, **k):  # noqa: ANN002, ANN003, ANN202
            stack.append([0.0, 0.0])
            ws, cs = time.perf_counter(), time.process_time()
            try:
                return fn(*a, **k)
            finally:
                dw, dc = time.perf_counter() - ws, time.process_time() - cs
                inner = stack.pop()
                t = totals.setdefault(label, [0.0, 0.0, 0])
                t[0] += dw - inner[0]
                t[1] += dc - inner[1]
                t[2] += 1
                if stack:
                    stack[-1][0] += dw
                    stack[-1][1] += dc
        return wrapper

    for mod, name, label in stages:
        m = sys.modules[mod]
        setattr(m, name, timed(getattr(m, name), label))
    stack.append([0.0, 0.0])
    code = main(argv)
    inner = stack.pop()
    w2, c2 = time.perf_counter(), time.process_time()
    totals["other (CLI, collapse, gates)"] = [w2 - w1 - inner[0], c2 - c1 - inner[1], 1]
    Path(marks_path).write_text(json.dumps(totals))
    return code


def run(target: Path, out: Path, options: list[str]) -> dict:
    load = os.getloadavg()[0]
    marks = out.with_suffix(".stages.json")
    gg = ["gg", str(target), "-o", str(out), *options, "-q", "--json"]
    cmd = [sys.executable, __file__, "--child", str(marks), *gg]
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    stdout = proc.stdout.read()
    stderr = proc.stderr.read()
    _, status, ru = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    try:
        res = json.loads(stdout or b"{}")
    except json.JSONDecodeError:
        res = {"verdict": stderr.decode(errors="replace").strip().splitlines()[-1:]}
    stages = json.loads(marks.read_text()) if marks.exists() else {}
    cpu = ru.ru_utime + ru.ru_stime
    if stages:  # the interpreter's start and exit, outside the child's clock
        spent = [sum(v[i] for v in stages.values()) for i in (0, 1)]
        stages["python start + exit"] = [wall - spent[0], cpu - spent[1], 1]
    return {"wall": wall, "cpu": cpu, "peak_mb": ru.ru_maxrss / 1024, "load": load,
            "exit": os.waitstatus_to_exitcode(status), "summary": res, "stages": stages}


def main() -> None:
    if len(sys.argv) > 2 and sys.argv[1] == "--child":
        sys.exit(_child(sys.argv[3:], sys.argv[2]))
    from gridshell.geometry.meshfile import write_mesh

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
    from io_cases import hill  # the tests' hill, one definition

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", nargs="+", type=int, default=[40, 355],
                    help="grid points along the 12 m side (40: ~2.4k triangles, 355: ~200k)")
    ap.add_argument("--modes", nargs="+", choices=tuple(MODES), default=list(MODES),
                    help="design: --no-preview --frames 0 (the goal's run); defaults: the "
                         "command as a user runs it, with the alignment sequence and pictures")
    ap.add_argument("--repeat", type=int, default=1, metavar="N",
                    help="run each N times and show the one with the least CPU time")
    ap.add_argument("--keep", type=Path, help="keep the targets and bundles here")
    args = ap.parse_args()
    root = args.keep or Path(tempfile.mkdtemp(prefix="big_input_"))
    root.mkdir(parents=True, exist_ok=True)
    print(f"gg on a 12 x 8 m hill; {os.cpu_count()} CPUs, load average "
          f"{os.getloadavg()[0]:.1f} (shared machine: compare CPU times)")
    print(f"{'triangles':>10} {'run':>9} {'wall s':>8} {'CPU s':>8} {'peak MB':>8} {'load':>5}  "
          "deviation mean/max [% diag]  verdict")
    runs = []
    for n in args.sizes:
        V, T = hill(n, int(n * 0.8))
        target = root / f"hill_{len(T)}.obj"
        write_mesh(target, V, T)
        for mode in args.modes:
            # the run with the least CPU time of --repeat (on a loaded machine the least
            # disturbed one)
            r = min((run(target, root / f"gg_{len(T)}_{mode}", MODES[mode])
                     for _ in range(args.repeat)), key=lambda r: r["cpu"])
            runs.append((f"{len(T)} {mode}", r))
            s = r["summary"]
            dev = s.get("deviation [% diag]") or {}
            verdict = s.get("verdict", f"exit {r['exit']}")
            print(f"{len(T):>10} {mode:>9} {r['wall']:>8.1f} {r['cpu']:>8.1f} "
                  f"{r['peak_mb']:>8.0f} {r['load']:>5.1f}  {dev.get('mean', float('nan')):.3f}"
                  f" / {dev.get('max', float('nan')):.3f}  {str(verdict)[:40]}", flush=True)
    print("\nper stage, wall / CPU seconds (calls)")
    labels = ["python start + exit", "imports"] + list(dict.fromkeys(
        lab for _, _, lab in STAGES)) + ["other (CLI, collapse, gates)"]
    print(f"{'stage':<38}" + "".join(f"{name:>22}" for name, _ in runs))
    for lab in labels:
        cells = []
        for _, r in runs:
            v = r["stages"].get(lab)
            cells.append(f"{v[0]:6.2f} / {v[1]:5.2f} ({v[2]:2d})" if v else "-")
        print(f"{lab:<38}" + "".join(f"{c:>22}" for c in cells))


if __name__ == "__main__":
    main()
