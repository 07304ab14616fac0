"""``gridshell phlw``: design a PHLW / CNC / PK surface from a reference (paper 3.4, 4.2.1)."""
from __future__ import annotations

import argparse
from typing import Any

from gridshell.cli.common import choice_help
from gridshell.cli.values import count, nonnegative

HELP = ("optimize a B-spline towards a PHLW (phlw), constant-normal-curvature (cnc) or "
        "PK (aa) surface near a reference mesh; writes surface.json/.obj, rows.csv, "
        "report.json and the curvature diagram")

#: what each mode of :data:`gridshell.ncp.phlw.MODES` optimizes towards (the choices come
#: from MODES)
MODE_HELP = {"phlw": "(n_u, t_u) per principal line",
             "cnc": "one normal curvature n",
             "aa": "n = 0, asymptotic net on a PK surface"}


def add_args(p: argparse.ArgumentParser) -> None:
    from gridshell.ncp.phlw import MODES

    from gridshell.cli.common import add_input_args

    p.add_argument("reference", help="reference surface: a mesh (OBJ, PLY, OFF; a structured quad "
                                     "grid is fitted directly, rows -> u), a Rhino .3dm (a NURBS "
                                     "surface is the initial B-spline as it is) or a B-spline "
                                     ".json")
    add_input_args(p)
    p.add_argument("-o", "--output", required=True, metavar="DIR",
                   help="output directory (replaced atomically)")
    p.add_argument("--mode", choices=MODES, default=MODES[0],
                   help=choice_help(MODE_HELP, MODES, MODES[0]))
    p.add_argument("--degree", nargs=2, type=count(1), default=(4, 4), metavar=("DU", "DV"),
                   help="B-spline bi-degree (default 4 4)")
    p.add_argument("--ctrl", nargs=2, type=count(2), default=(9, 9), metavar=("NU", "NV"),
                   help="control points in u and v (default 9 9)")
    p.add_argument("--samples", nargs=2, type=count(4), default=(18, 18), metavar=("RU", "RV"),
                   help="optimization samples in u and v (default 18 18)")
    p.add_argument("--check-samples", nargs=2, type=count(4), default=(60, 60),
                   metavar=("RU", "RV"),
                   help="denser sampling for the check and surface.obj (default 60 60)")
    p.add_argument("--transpose", action="store_true",
                   help="swap u and v of the reference grid (rows follow the other family)")
    p.add_argument("--align", action="store_true",
                   help="turn the reference's parametrization onto its mean principal directions "
                        "(as far as coverage allows) before the PHLW step (default: keep it)")
    p.add_argument("--outer", type=count(1), default=4,
                   help="outer rounds (closest points refreshed) (default 4)")
    p.add_argument("--max-iter", type=count(1), default=60,
                   help="Levenberg-Marquardt iterations per round (default 60)")
    p.add_argument("--allow-unconverged", action="store_true",
                   help="write a surface whose optimization did not converge, raised its "
                        "energy, relation error or principal angle, marked as failing in "
                        "report.json (default: exit 4 and write nothing)")
    p.add_argument("--strict", action="store_true",
                   help="deprecated, the default now: a surface that misses its figures exits "
                        "4 unless --allow-unconverged")
    for key, default in (("closeness", None), ("gliding", None), ("target", None), ("beta", None),
                         ("constraints", None)):
        p.add_argument(f"--w-{key}", type=nonnegative, default=default, metavar="W",
                       help=f"weight of the {key} term (default: see gridshell.ncp.phlw."
                            "DEFAULT_WEIGHTS)")


def _load_reference(path: str, args: Any) -> tuple[Any, Any, Any, Any]:
    """(initial surface, V, F, input) from a mesh, a .3dm or a B-spline JSON; ``input`` is the
    :class:`gridshell.io.read.InputGeometry` (None for a JSON)."""
    from gridshell.geometry.bspline import BSplineSurface
    from gridshell.io.read import read_input
    from gridshell.ncp.reference import initial_surface
    from gridshell.cli.common import input_options

    if str(path).lower().endswith(".json"):
        if args.units is not None or args.object is not None:
            from gridshell.core.errors import InputError

            raise InputError(f"{path}: a B-spline .json is in metres: drop --units / --object")
        surf = BSplineSurface.load(path)
        mesh = surf.sample(*args.check_samples)
        return surf, mesh.V, mesh.F, None
    geo = read_input(path, **input_options(args), what="the reference")
    if geo.surface is not None:  # a NURBS surface is the initial B-spline as it is
        from gridshell.io.read import swap_uv

        srf = swap_uv(geo.surface) if args.transpose else geo.surface
        mesh = srf.sample(*args.check_samples)
        return srf, mesh.V, mesh.F, geo
    fit = initial_surface(geo.V, geo.F, n_ctrl=tuple(args.ctrl), degree=tuple(args.degree),
                          transpose=args.transpose, align=args.align)
    return fit, geo.V, geo.F, geo


def run(args: Any) -> int:
    from gridshell.core.atomic import check_output
    from gridshell.geometry.bspline import uniform_params
    from gridshell.core.errors import ConvergenceError
    from gridshell.api import optimize_phlw
    from gridshell.ncp.phlw import row_relation_residual, write_phlw
    from gridshell.ncp.phlw.gates import phlw_gates
    from gridshell.cli.common import Progress, input_line, print_gates

    check_output(args.output, marker="report.json")
    progress = Progress(args)
    progress(f"reading {args.reference}")
    init, V, F, geo = _load_reference(args.reference, args)
    if geo is not None:
        progress(f"input: {geo.summary()}")
    surf = getattr(init, "surface", init)
    if hasattr(init, "rms"):
        progress(f"initial B-spline: {init.method} fit, rms {init.rms:.3g} m")
    weights = {k: getattr(args, f"w_{k}") for k in ("closeness", "gliding", "target", "beta",
                                                    "constraints")
               if getattr(args, f"w_{k}") is not None}
    res = optimize_phlw(surf, (V, F), mode=args.mode, samples=tuple(args.samples),
                        weights=weights or None, outer=args.outer, max_iter=args.max_iter,
                        check_samples=tuple(args.check_samples), progress=progress.callback)
    for line in res.diagnostics:
        progress(f"note: {line}")
    gates = phlw_gates(res.report_before, res.report_after, res.converged,
                       len(res.u_rows) * len(res.v_samples))
    quality = {"ok": all(g.ok for g in gates), "gates": [g.as_dict() for g in gates]}
    if not quality["ok"]:
        last = res.history[-1] if res.history else {"message": "no round run"}
        bad = "; ".join(g.line().split("  ", 1)[1] for g in gates if not g.ok)
        msg = (f"the PHLW optimization did not converge ({bad}; last round: {last['message']}, "
               f"{args.outer} round(s) of at most {args.max_iter} iterations)")
        if args.strict or not args.allow_unconverged:
            raise ConvergenceError(f"{msg}; raise --outer / --max-iter, change the weights "
                                   "(--w-closeness, --w-gliding), or pass --allow-unconverged "
                                   "to write the surface anyway, marked as failing")
        progress(f"warning: {msg}; written because of --allow-unconverged")
    u, v = uniform_params(res.surface, tuple(args.check_samples))
    dense = row_relation_residual(res.surface, u, v, mode=args.mode)
    progress(f"writing {args.output}")
    files = write_phlw(args.output, res, sample_grid=tuple(args.check_samples),
                       units=geo.units if geo is not None else None,
                       source=geo.info() if geo is not None else None)
    _add_quality(args.output, quality)
    b, a = res.report_before, res.report_after
    summary = {
        "output": args.output,
        "input": input_line(geo.info() if geo is not None else None),
        "mode": args.mode,
        "converged": res.converged,
        "E_PHLW before -> after": f"{b['E_PHLW']['total']:.4g} -> {a['E_PHLW']['total']:.4g}",
        "relation max rel (samples)": f"{b['relation_max_rel']:.3g} -> {a['relation_max_rel']:.3g}",
        f"relation max rel ({args.check_samples[0]}x{args.check_samples[1]}, refit)":
            float(max(dense.max(), 0.0)),
        "principal angle max [deg]": f"{b['angle_max_deg']:.3g} -> {a['angle_max_deg']:.3g}",
        "deviation [% diag]": res.deviation,
        "n_u range [1/m]": f"{res.n_rows.min():.4g} .. {res.n_rows.max():.4g}",
        "t_u range [1/m]": f"{res.t_rows.min():.4g} .. {res.t_rows.max():.4g}",
        "diagnostics": len(res.diagnostics),
        "diagram": files["curvature_diagram"],
    }
    print_gates(args, summary, "PHLW surface design", quality)
    return 0


def _add_quality(directory: str, quality: dict) -> None:
    """``report.json`` of the written design gains ``"quality": {"ok", "gates"}``."""
    import json
    from pathlib import Path

    from gridshell.core.atomic import write_text

    path = Path(directory) / "report.json"
    report = json.loads(path.read_text())
    report["quality"] = quality
    write_text(path, json.dumps(report, indent=1) + "\n")
