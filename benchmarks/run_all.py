"""``make bench``: every stage of the GG and NCP pipelines, fabrication and the solver, at the
paper's sizes and at about 4x and 16x more unknowns; wall time (s) and peak memory (MB) per
stage.

Each (stage, size) runs in its own process (``--worker``), so the memory figure is that
stage's alone: peak resident memory while the stage ran above the resident memory just before
it, MB = 2^20 bytes (see ``_measure.py``); building the inputs is not timed. A stage of the
default pipelines that takes more than 10 s at a default size (the paper's, and the GG
pipeline at 100 x 100, issue #3) is flagged ``OVER 10 s``. Sizes whose run would
take far longer than the budget (``make bench`` under ~15 minutes on 2 cores) are capped: the
table says so and why. The solver section runs ``solver.py`` (iterations at 1e3/1e4/1e5
unknowns, the side-by-side run against ``scipy.optimize.least_squares`` with the ratio, and
the linear-solver record).

Inputs (from the per-stage scripts): GG - the elliptic dome grid of ``gg_design.py`` (design
alone) and the helicoid grid of ``gg_pipeline.py`` (net stages, whole pipeline, isometric to a
catenoid); PHLW - the saddle of ``phlw.py``, 9 x 9 control points, bi-degree 4; NCP - the
pseudosphere patch of ``ncp.py`` (mode ``aa``, a PK surface); fabrication - the GG bundle of a
30 x 30 helicoid design, the model scale growing with the number of lamellae so that the
joints stay as far apart on the strips (the default 1:10 is too small for 40 lamellae).

    .venv/bin/python benchmarks/run_all.py [--quick] [--only STAGE ...] [--list]
"""
from __future__ import annotations

import argparse
import atexit
import json
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

# The ncp_e2e stage times the command as a user runs it: `gridshell` sets one BLAS thread
# (gridshell/cli/main.py) before numpy loads OpenBLAS, which calling main() in-process after
# numpy is imported here could not do (its worker then timed OpenBLAS threads spinning).
if sys.argv[1:3] == ["--worker", "ncp_e2e"]:
    import os

    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from _measure import compile_tree, measure, run_worker  # noqa: E402

LIMIT = 10.0          # seconds: the goal for every stage of the default pipelines
WORKER_TIMEOUT = 900  # seconds: a worker still running then is stopped and reported


@dataclass
class Size:
    """One size of a stage: ``label`` (paper / 4x / 16x / ...), ``param`` passed to the stage,
    ``unknowns`` (what scales), ``capped`` (why it is not run, or None), ``default`` (a size
    the default pipeline runs at, where more than 10 s is flagged; default: the paper's)."""

    label: str
    param: Any
    unknowns: str
    capped: str | None = None
    default: bool | None = None

    def __post_init__(self) -> None:
        if self.default is None:
            self.default = self.label == "paper"


@dataclass
class Stage:
    """A benchmark stage: ``setup(param)`` builds the inputs (not timed) and returns the call
    to time; ``default`` marks the stages of the default pipelines (flagged above 10 s)."""

    name: str
    title: str
    setup: Callable[[Any], Callable[[], Any]]
    sizes: list[Size] = field(default_factory=list)
    default: bool = True


# ============================================================================ GG

def _gg_design(n: int) -> Callable[[], Any]:
    from gg_design import dome_grid

    from gridshell.gg.design import design_gg_surface
    from gridshell.gg.pipeline import gg_score
    from gridshell.geometry.grid import grid_quads

    P0 = dome_grid(n, n)
    V, F = P0.reshape(-1, 3), grid_quads(n, n)
    return lambda: design_gg_surface(V, F, P0, evaluate=gg_score)  # judged as `gridshell gg`


def _gg_net(p: tuple[int, int]) -> Callable[[], Any]:
    from gg_pipeline import helicoid

    from gridshell.gg.pipeline import gg_net_from_mesh

    n, lamellae = p
    P = helicoid(n)
    return lambda: gg_net_from_mesh(P, n_lamellae=lamellae, crossing_angle=80.0)


def _gg_pipeline(n: int) -> Callable[[], Any]:
    from gg_pipeline import helicoid

    from gridshell.gg.pipeline import design_gg
    from gridshell.geometry.grid import grid_quads

    P = helicoid(n)
    V, F = P.reshape(-1, 3), grid_quads(n, n)
    return lambda: design_gg((V, F), grid=(n, n), n_lamellae=12, crossing_angle=80.0)


# ============================================================================ PHLW and NCP

def _phlw(m: int) -> Callable[[], Any]:
    from phlw import saddle

    from gridshell.ncp.phlw import optimize_phlw
    from gridshell.ncp.reference import initial_surface

    V, F = saddle()
    surf = initial_surface(V, F, n_ctrl=(9, 9), degree=(4, 4)).surface
    return lambda: optimize_phlw(surf, (V, F), samples=(m, m))  # library defaults otherwise


def _pseudosphere():
    from ncp import pseudosphere

    return pseudosphere()


def _tracing(p: tuple[int, int, int]) -> Callable[[], Any]:
    from gridshell.ncp.directions import net_directions, uniform_params
    from gridshell.ncp.levelset import trace

    samples, ctrl, curves = p
    surf = _pseudosphere()

    def run() -> Any:
        u, v = uniform_params(surf, (samples, samples))
        return trace(surf, net_directions(surf, u, v, mode="aa"), curves=curves,
                     n_ctrl=(ctrl, ctrl))
    return run


def _collapse(m: int) -> Callable[[], Any]:
    from gridshell.ncp.collapse import collapse_curve

    surf = _pseudosphere()
    return lambda: collapse_curve(surf, mode="aa", samples=(m, m))


def _traced_net(curves: int):
    from gridshell.ncp.collapse import collapse_curve
    from gridshell.ncp.directions import net_directions, uniform_params
    from gridshell.ncp.levelset import trace

    surf = _pseudosphere()
    u, v = uniform_params(surf, (48, 48))
    tn = trace(surf, net_directions(surf, u, v, mode="aa"), curves=curves)
    return surf, tn, collapse_curve(surf, mode="aa", samples=(1200, 1200))


def _postopt(curves: int) -> Callable[[], Any]:
    from gridshell.ncp.postopt import post_optimize

    surf, tn, col = _traced_net(curves)
    return lambda: post_optimize(surf, tn.net, tn.joint_uv, col)


def _simulation(curves: int) -> Callable[[], Any]:
    from gridshell.ncp.postopt import post_optimize
    from gridshell.ncp.alignment import collapse_direction, simulate_alignment

    surf, tn, col = _traced_net(curves)
    post = post_optimize(surf, tn.net, tn.joint_uv, col)
    E, d = tn.net.edges(), collapse_direction(surf)
    return lambda: simulate_alignment(post.V, post.r, E, d, aligned=(post.Vt, post.rt),
                                      frames=12)


def _ncp_e2e(n: int) -> Callable[[], Any]:
    """``gridshell ncp SADDLE.obj -o DIR --mode phlw`` with the defaults (PHLW step, tracing,
    collapse, post-optimization, simulation, the bundle with pictures and GIF), in-process,
    from an ``n x n`` grid of the saddle of ``phlw.py``."""
    from phlw import saddle

    from gridshell.cli.main import main
    from gridshell.geometry.meshfile import write_mesh

    V, F = saddle(n)
    tmp = _tmpdir()
    write_mesh(tmp / "saddle.obj", V, F)
    return lambda: main(["ncp", str(tmp / "saddle.obj"), "-o", str(tmp / "out"), "--mode",
                         "phlw", "-q"])


def _ncp_pipeline(curves: int) -> Callable[[], Any]:
    from gridshell.ncp.pipeline import design_ncp

    surf = _pseudosphere()
    return lambda: design_ncp(surf, mode="aa", curves=curves)


# ============================================================================ output

def _tmpdir() -> Path:
    tmp = tempfile.mkdtemp(prefix="gridshell-bench-")
    atexit.register(shutil.rmtree, tmp, ignore_errors=True)  # after the timed call
    return Path(tmp)


def _ncp_write(curves: int) -> Callable[[], Any]:
    from gridshell.api import design_ncp, write

    design = design_ncp(_pseudosphere(), mode="aa", curves=curves)
    out = _tmpdir() / "ncp"
    return lambda: write(out, design, render=True)


def _outputs(p: int | tuple) -> Callable[[], Any]:
    """render.png, report.html and the .3dm of a written NCP bundle, as ``gridshell render
    --report --3dm`` makes them (:func:`gridshell.workflow.outputs.write_outputs`: the .3dm built in a
    second process while the pictures and the report are made); ``p`` the curves per family,
    or ``(curves, sheets)`` with ``sheets=False`` for a .3dm without the cut sheets and their
    design check (``--no-sheets``: the content nearest to the row of 2026-11-23, whose .3dm had
    neither), or ``(curves, sheets, "serial")`` for the three calls one after the other
    (render_bundle, export_3dm, write_report: the row as it was timed until 2026-12-03)."""
    from gridshell.api import design_ncp, write

    curves, sheets, how = (*p, "outputs")[:3] if isinstance(p, tuple) else (p, True, "outputs")
    out = write(_tmpdir() / "ncp", design_ncp(_pseudosphere(), mode="aa", curves=curves))
    if how == "serial":
        from gridshell.export import export_3dm
        from gridshell.render.report import write_report
        from gridshell.render.ribbons import render_bundle

        def serial() -> Any:
            render_bundle(out)
            export_3dm(out, out / "ncp.3dm", sheets=sheets)
            return write_report(out)
        return serial
    from gridshell.workflow.outputs import write_outputs

    return lambda: write_outputs(out, report=True, rhino=out / "ncp.3dm",
                                 rhino_options={"sheets": sheets})


# ============================================================================ fabrication

def _fabrication(p: tuple[int, float]) -> Callable[[], Any]:
    """``fabricate`` of a GG bundle. The DXF writer (ezdxf, ~0.2 s to import) is imported in
    the set-up, as ``gridshell.fabrication.pipeline`` itself imported it until 2026-12-02 (it is lazy
    since, for the .3dm export): the row times fabricating, not importing."""
    import gridshell.fabrication.dxf  # noqa: F401
    from gridshell.fabrication.pipeline import fabricate
    from gg_pipeline import helicoid

    from gridshell.gg.pipeline import design_gg
    from gridshell.geometry.grid import grid_quads

    n_lamellae, scale = p
    P = helicoid(30)
    bundle, _ = design_gg((P.reshape(-1, 3), grid_quads(30, 30)), grid=(30, 30),
                          n_lamellae=n_lamellae, crossing_angle=80.0)
    tmp = tempfile.mkdtemp(prefix="gridshell-bench-")
    atexit.register(shutil.rmtree, tmp, ignore_errors=True)  # after the timed call

    def run() -> Any:
        return fabricate(bundle, Path(tmp) / "fab", params={"scale": scale})
    return run


# ============================================================================ the registry

def _max_samples() -> int:
    try:
        from gridshell.geometry.bspline import MAX_SAMPLES
    except ImportError:
        return 5_000_000
    return int(MAX_SAMPLES)


_MAX_SAMPLES = _max_samples()
_M = int(np.sqrt(_MAX_SAMPLES))  # densest square sampling the library accepts


def _grid(n: int) -> str:
    return f"{n}x{n} grid, {3 * n * n + 2 * n - 1} unknowns"


STAGES: list[Stage] = [
    Stage("gg_design", "GG surface design (design_gg_surface)", _gg_design,
          [Size("paper", 30, _grid(30)), Size("4x", 60, _grid(60)),
           Size("16x", 120, _grid(120))]),
    Stage("gg_net", "GG net: rebuild + trace + map back (gg_net_from_mesh)", _gg_net,
          [Size("paper", (30, 12), "30x30 mesh, 12 lamellae per family"),
           Size("4x", (60, 24), "60x60 mesh, 24 lamellae (4x joints)"),
           Size("16x", (120, 48), "120x120 mesh, 48 lamellae (16x joints)")]),
    Stage("gg_pipeline", "GG whole pipeline (design_gg)", _gg_pipeline,
          [Size("paper", 30, "30x30 mesh"), Size("4x", 60, "60x60 mesh"),
           Size("issue #3", 100, "100x100 mesh", default=True),
           Size("16x", 120, "120x120 mesh",
                capped="the design stage is > 95 % of it (gg_design at 120x120: 225 s); the "
                       "100x100 run above shows the trend; run it with --only gg_pipeline --full")]),
    Stage("phlw", "PHLW optimization (optimize_phlw, 9x9 ctrl, bi-degree 4)", _phlw,
          [Size("paper", 18, "18x18 samples, ~4.5k unknowns"),
           Size("4x", 36, "36x36 samples, ~17k unknowns"),
           Size("16x", 72, "72x72 samples, ~67k unknowns",
                capped="the 4x run takes ~2-3 min and the cost per iteration grows ~4x per 4x "
                       "unknowns (~10 min): over the budget; run it with --only phlw --full")]),
    Stage("ncp_tracing", "NCP tracing: directions + level fits + trace", _tracing,
          [Size("paper", (48, 12, 10), "48x48 samples, 12x12 ctrl, 10 curves"),
           Size("4x", (96, 24, 20), "96x96 samples, 24x24 ctrl, 20 curves"),
           Size("16x", (192, 48, 40), "192x192 samples, 48x48 ctrl, 40 curves")]),
    Stage("ncp_collapse", "NCP collapse curve", _collapse,
          [Size("paper", 1200, "1200x1200 samples"),
           Size("3.5x", _M, f"{_M}x{_M} samples (the library's limit)"),
           Size("16x", 4800, "4800x4800 samples",
                capped=f"gridshell.geometry.bspline refuses more than {_MAX_SAMPLES} samples (4x would be "
                       "2400x2400); 4800x4800 took 9.4 s and 279 MB before that limit")]),
    Stage("ncp_postopt", "NCP post-optimization", _postopt,
          [Size("paper", 10, "10 curves per family"), Size("4x", 20, "20 curves (4x joints)"),
           Size("16x", 40, "40 curves (16x joints)")]),
    Stage("ncp_simulation", "NCP alignment simulation (12 frames)", _simulation,
          [Size("paper", 10, "10 curves per family"), Size("4x", 20, "20 curves"),
           Size("16x", 40, "40 curves")]),
    Stage("ncp_pipeline", "NCP whole pipeline (design_ncp from the B-spline)", _ncp_pipeline,
          [Size("paper", 10, "10 curves per family"), Size("4x", 20, "20 curves"),
           Size("16x", 40, "40 curves",
                capped="post-optimization + simulation are > 95 % of it and are measured at "
                       "40 curves above (74 s in all on 2026-11-23); run it with --only "
                       "ncp_pipeline --full")]),
    Stage("ncp_e2e", "NCP end to end: gridshell ncp REF.obj --mode phlw (defaults)", _ncp_e2e,
          [Size("paper", 40, "40x40 saddle reference grid")]),
    Stage("ncp_write", "NCP bundle written with pictures, frames and GIF (write)", _ncp_write,
          [Size("paper", 10, "10 curves per family, 12 frames"), Size("4x", 20, "20 curves"),
           Size("16x", 40, "40 curves",
                capped="design_ncp at 40 curves takes ~74 s to build the input; the write "
                       "grows with the frames' size only; run it with --only ncp_write --full")]),
    Stage("outputs", "render.png + report.html + .3dm of an NCP bundle", _outputs,
          [Size("paper", 10, "10 curves per family"), Size("4x", 20, "20 curves"),
           Size("4x-no-sheets", (20, False), "20 curves, .3dm without cut sheets"),
           Size("4x-serial", (20, True, "serial"), "20 curves, the three calls in turn")]),
    Stage("fabrication", "fabrication (fabricate, GG bundle, with plan)", _fabrication,
          [Size("paper", (10, 0.1), "10 lamellae per family, scale 1:10"),
           Size("4x", (20, 0.2), "20 lamellae (4x joints), scale 1:5"),
           Size("16x", (40, 0.4), "40 lamellae (16x joints), scale 1:2.5")]),
]
BY_NAME = {s.name: s for s in STAGES}
NAMES = [s.name for s in STAGES] + ["solver"]


# ============================================================================ running

def worker(name: str, index: int) -> None:
    """Run one (stage, size) in this process and print its figures as one JSON line."""
    stage = BY_NAME[name]
    call = stage.setup(stage.sizes[index].param)
    m = measure(call)   # CPU: all threads (BLAS included) and the processes the call waited for
    print(json.dumps({"seconds": m.seconds, "cpu_seconds": m.cpu_seconds, "peak_mb": m.peak_mb,
                      "rss_peak_mb": m.rss_peak_mb}))


def _row(stage: str, size: str, what: str, seconds: float | None, peak: float | None,
         note: str = "") -> None:
    t = f"{seconds:9.2f}" if seconds is not None else f"{'-':>9}"
    p = f"{peak:9.0f}" if peak is not None else f"{'-':>9}"
    print(f"{stage:<15} {size:<9} {what:<40} {t} {p}  {note}", flush=True)


def run_stage(stage: Stage, quick: bool, full: bool, results: list[dict]) -> None:
    for k, size in enumerate(stage.sizes):
        if quick and size.label != "paper":
            continue
        if size.capped and not full:
            _row(stage.name, size.label, size.unknowns, None, None, f"CAPPED: {size.capped}")
            results.append({"stage": stage.name, "size": size.label, "capped": size.capped})
            continue
        d = run_worker(Path(__file__), [stage.name, str(k)], WORKER_TIMEOUT)
        if d is None or "error" in d:
            why = f"stopped after {WORKER_TIMEOUT} s" if d is None else f"FAILED: {d['error']}"
            _row(stage.name, size.label, size.unknowns, None, None, why)
            results.append({"stage": stage.name, "size": size.label, "error": why})
            continue
        over = stage.default and size.default and d["seconds"] > LIMIT
        flag = "OVER 10 s" if over else ("> 10 s (not a default size)"
                                         if d["seconds"] > LIMIT else "")
        flag = f"cpu {d['cpu_seconds']:.2f} s" + (f"; {flag}" if flag else "") \
            if "cpu_seconds" in d else flag
        _row(stage.name, size.label, size.unknowns, d["seconds"], d["peak_mb"], flag)
        results.append({"stage": stage.name, "size": size.label, "unknowns": size.unknowns,
                        "over": over, **d})


def run_solver(quick: bool, results: list[dict]) -> None:
    """``solver.py`` in a subprocess (its own tables), plus its LM and least_squares rows."""
    args = ["--sizes", "1e3", "1e4", "1e5", "--lsq-sizes", "1e3", "1e4", "1e5",
            "--lsq-1e5-problems", "gg_round", "--linear-sizes", "1e3", "1e4"]
    if quick:
        args = ["--sizes", "1e3", "1e4", "--lsq-sizes", "1e3", "1e4", "--linear-sizes", "1e3",
                "--section", "iterations", "least_squares", "linear"]
    with tempfile.TemporaryDirectory() as tmp:
        js = Path(tmp) / "solver.json"
        p = subprocess.run([sys.executable, str(HERE / "solver.py"), *args, "--json", str(js)],
                           capture_output=True, text=True)
        solver_out = p.stdout + (p.stderr if p.returncode else "")
        data = json.loads(js.read_text()) if js.exists() else {}
    for d in data.get("iterations", []):
        _row("solver_lm", d["size"], f"{d['unknowns']} unknowns, {d['iterations']} LM its",
             d["seconds"], d["peak_mb"], f"{d['s_per_it']:.3f} s/it")
        results.append({"stage": "solver_lm", **d})
    for d in data.get("least_squares", []):
        ls = min(d["least_squares"].values(), key=lambda v: v["seconds"])
        _row("least_squares", d["size"], f"{d['problem']}, {d['unknowns']} unknowns",
             ls["seconds"], None,
             f"ours {d['ours']['seconds']:.2f} s; ratio lsq/ours "
             f"{'>= ' if d.get('ratio_lower_bound') else ''}{d.get('ratio', float('nan')):.2f}x "
             f"(goal >= 5x at 1e4+)")
        results.append({"stage": "least_squares", **d})
    for d in data.get("pipelines", []):
        _row("lsq_pipeline", "1e4+", f"{d['pipeline']}, {d['n_calls']} solves, "
             f"{d['unknowns']} unknowns", d["least_squares"], None,
             f"ours {d['ours']:.2f} s; ratio lsq/ours {'>= ' if d['ratio_lower_bound'] else ''}"
             f"{d['ratio']:.1f}x (goal >= 5x)")
        results.append({"stage": "lsq_pipeline", **d})
    print()
    print("solver.py:")
    print("\n".join("  " + ln for ln in solver_out.rstrip().splitlines()))


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="the paper's sizes only")
    ap.add_argument("--only", nargs="+", choices=NAMES, metavar="STAGE",
                    help=f"run only these stages: {', '.join(NAMES)}")
    ap.add_argument("--full", action="store_true", help="also run the capped sizes")
    ap.add_argument("--json", help="write every figure to this JSON file")
    ap.add_argument("--list", action="store_true", help="list the stages and sizes and exit")
    a = ap.parse_args(argv)
    if a.list:
        for s in STAGES:
            print(f"{s.name:<15} {s.title}")
            for z in s.sizes:
                print(f"  {z.label:<9} {z.unknowns}" + (f"  (capped: {z.capped})" if z.capped else ""))
        print(f"{'solver':<15} solver.py: LM at 1e3/1e4/1e5, least_squares, linear solvers")
        return
    names = a.only or NAMES
    compile_tree(HERE.parent)                 # bytecode, as an installed package has it
    t0 = time.perf_counter()
    print(f"gridshell benchmarks ({'paper sizes' if a.quick else 'paper, 4x, 16x'}); time s, "
          f"peak MB above the start of the stage; each stage in its own process")
    print(f"{'stage':<15} {'size':<9} {'what scales':<40} {'time (s)':>9} {'peak MB':>9}")
    results: list[dict] = []
    for name in names:
        if name == "solver":
            run_solver(a.quick, results)
        else:
            run_stage(BY_NAME[name], a.quick, a.full, results)
    over = [f"{r['stage']} ({r['size']}, {r['seconds']:.1f} s)" for r in results if r.get("over")]
    print()
    print("stages of the default pipelines over 10 s (paper sizes, and GG at 100x100): "
          + (", ".join(over) if over else "none"))
    print(f"total wall time {time.perf_counter() - t0:.0f} s")
    if a.json:
        Path(a.json).write_text(json.dumps(results, indent=1, default=float))


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--worker":
        worker(sys.argv[2], int(sys.argv[3]))
    else:
        main()
