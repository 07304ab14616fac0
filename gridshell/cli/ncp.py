"""``gridshell ncp``: design a normal-curvature-preserving alignable gridshell (paper 4.2)."""
from __future__ import annotations

import argparse
from typing import Any

from gridshell.cli.common import choice_help
from gridshell.cli.values import count, nonnegative, number, positive

HELP = ("trace a normal-curvature-preserving alignable net on a PHLW / CNC / PK surface, "
        "post-optimize it, simulate its alignment and write a design bundle (NCP, CNC or AA)")

#: what each mode of :data:`gridshell.ncp.pipeline.KIND` designs (the choices come from KIND)
MODE_HELP = {"phlw": "normal curvature per principal line",
             "cnc": "one normal curvature, collapses into a circle",
             "aa": "asymptotic net on a PK surface, collapses into a line"}


def add_args(p: argparse.ArgumentParser) -> None:
    from gridshell.ncp.pipeline import KIND

    from gridshell.cli.common import add_input_args

    p.add_argument("reference", help="a surface.json written by 'gridshell phlw', or a reference "
                                     "mesh (OBJ, PLY, OFF) or Rhino .3dm (a NURBS surface is "
                                     "the initial B-spline): the PHLW step runs first")
    add_input_args(p)
    p.add_argument("-o", "--output", required=True, metavar="DIR",
                   help="output design bundle directory (replaced atomically)")
    modes = tuple(KIND)
    p.add_argument("--mode", choices=modes, default=modes[0],
                   help=choice_help(MODE_HELP, modes, modes[0],
                                    lambda m: f"{MODE_HELP.get(m, m)} (kind {KIND[m]})"))
    g = p.add_mutually_exclusive_group()
    g.add_argument("--curves", type=count(1), metavar="N",
                   help="curves per family, uniformly subdivided level values (default 10)")
    g.add_argument("--spacing", type=positive, metavar="M",
                   help="spacing of the curves, metres")
    p.add_argument("--n", type=number(), metavar="1/M",
                   help="cnc: the normal curvature of the net (default: fitted)")
    p.add_argument("--samples", nargs=2, type=count(4), default=(48, 48), metavar=("RU", "RV"),
                   help="direction samples of the level-set fit (default 48 48)")
    p.add_argument("--levelset-ctrl", nargs=2, type=count(4), default=(12, 12),
                   metavar=("NU", "NV"),
                   help="control points of the level functions (default 12 12)")
    p.add_argument("--omega-f", type=nonnegative, default=0.01, metavar="W",
                   help="fairness weight of the level functions (default 0.01; the paper uses 0.1)")
    p.add_argument("--collapse-samples", nargs=2, type=count(4), default=(1200, 1200),
                   metavar=("RU", "RV"), help="collapse-curve sampling (default 1200 1200)")
    p.add_argument("--rounds", type=count(0, "0: no post-optimization"), default=3,
                   help="post-optimization rounds (default 3)")
    p.add_argument("--frames", default=12, metavar="N",
                   type=count(1, "the simulated path to the collapsed state is part of the design",
                              maximum=1000),
                   help="steps of the simulated alignment sequence, at least 1: the simulation "
                        "is the proof that the design collapses (default 12)")
    p.add_argument("--no-render", action="store_true",
                   help="skip the PNG pictures, PNG frames and alignment.gif")
    p.add_argument("--phlw-ctrl", nargs=2, type=count(4), default=(9, 9), metavar=("NU", "NV"),
                   help="mesh input: control points of the PHLW B-spline (default 9 9)")
    p.add_argument("--phlw-samples", nargs=2, type=count(4), default=(18, 18), metavar=("RU", "RV"),
                   help="mesh input: PHLW optimization samples (default 18 18)")
    p.add_argument("--phlw-outer", type=count(1), default=4,
                   help="mesh input: PHLW outer rounds (default 4)")
    p.add_argument("--phlw-max-iter", type=count(1), default=40,
                   help="mesh input: PHLW iterations per round (default 40)")
    p.add_argument("--phlw-align", action="store_true",
                   help="mesh input: turn the reference's parametrization onto its mean principal "
                        "directions (as far as coverage allows) before the PHLW step (default: "
                        "keep it)")
    p.add_argument("--max-deviation", type=nonnegative, metavar="PCT",
                   help="refuse (exit 4, nothing written) a net whose joints lie farther from "
                        "the target than this on average, %% of its diagonal (default: no gate)")
    p.add_argument("--min-coverage", type=number(0.0, maximum=100.0), metavar="PCT",
                   help="refuse (exit 3, nothing written) a net covering less of a target "
                        "file than this (%% of its area within 2 %% of the diagonal from the "
                        "net), after trying the ring around its umbilic; 0: no gate (default: "
                        "60 where the analysis finds no regular patch of the mode - a dome, a "
                        "hill - else none)")
    p.add_argument("--allow-unconverged", action="store_true",
                   help="write a design whose figures (Delta_a mean / max after the "
                        "post-optimization, Delta_l max, Delta_n max, the collapse error) miss "
                        "the paper's thresholds, marked as failing in design.json (default: exit "
                        "4 and write nothing)")
    p.add_argument("--strict", action="store_true",
                   help="deprecated (the figures decide now): also exit 4 when an optimizer "
                        "(PHLW step, level-set fit, post-optimization) misses its own "
                        "tolerances although the figures hold")


def _unconverged(bundle: Any, report: dict) -> list[str]:
    """Names of the optimizers of an NCP design that stopped without meeting their tolerances."""
    out = ["PHLW step"] if bundle.params.get("phlw_converged") is False else []
    out += [f"level-set fit {f}" for f, r in report["levelset"].items() if not r["converged"]]
    return out + ([] if report["postopt"]["converged"] else ["post-optimization"])


def run(args: Any) -> int:
    from gridshell.core.atomic import check_output
    from gridshell.workflow.cut import require_no_made_from
    from gridshell.api import design_ncp, write
    from gridshell.cli.common import Progress, input_line, input_options, print_gates

    check_output(args.output, marker="design.json")
    require_no_made_from(args.output)
    progress = Progress(args)
    progress(f"reading {args.reference}")
    phlw = {"ctrl": tuple(args.phlw_ctrl), "samples": tuple(args.phlw_samples),
            "outer": args.phlw_outer, "max_iter": args.phlw_max_iter,
            "align": args.phlw_align}
    curves = args.curves              # None with no --spacing either: 10 (a ring: its own)
    design = design_ncp(args.reference, mode=args.mode, curves=curves,
                        spacing=args.spacing, n=args.n, samples=tuple(args.samples),
                        levelset_ctrl=tuple(args.levelset_ctrl), omega_f=args.omega_f,
                        collapse_samples=tuple(args.collapse_samples),
                        postopt_rounds=args.rounds, frames=args.frames,
                        phlw_options=phlw, strict=args.strict,
                        allow_unconverged=args.allow_unconverged,
                        min_coverage=args.min_coverage, **input_options(args),
                        progress=progress.callback)
    bundle, report = design
    failed = _unconverged(bundle, report)
    for name in failed:
        progress(f"note: the {name} stopped short of its own tolerances; the figures below "
                 "decide")
    quality = bundle.metrics["quality"]
    if not quality["ok"]:
        progress(f"warning: the design misses the paper's figures ({quality['summary']}); "
                 "written because of --allow-unconverged, marked as failing")
    from gridshell.measure.fidelity import require_fidelity

    require_fidelity(design.bundle.metrics, args.max_deviation)
    progress(f"writing {args.output}")
    out = write(args.output, design, render=not args.no_render, progress=progress.callback)
    m = bundle.metrics
    from gridshell.measure.fidelity import fidelity_line
    from gridshell.measure.fidelity import region_line
    summary = {
        "bundle": str(out),
        "kind": bundle.kind,
        "input": input_line(bundle.params.get("input")),
        "converged": not failed,
        "not converged": ", ".join(failed) or "none",
        "joints / loops / lamellae": f"{m['n_joints']} / {m['n_loops']} / "
                                     f"{m['n_lamellae']['C1']} + {m['n_lamellae']['C3']}",
        "Delta_a before [%]": m["delta_a_before"],
        "Delta_a after [%]": m["delta_a_after"],
        "Delta_l [%]": m["delta_l"],
        "Delta_n [%]": m["delta_n"],
        "fidelity to the target": fidelity_line(m.get("fidelity")),
        "region": region_line(m.get("region")),
        "deviation [% diag]": m["deviation"],
        "crossing kn difference [%]": {"mean": m["crossing_kn"]["mean"],
                                       "max": m["crossing_kn"]["max"]},
        "alignment sequence": f"joint-to-joint lengths within {m['sequence_length_error']:.2g} "
                              "% of the deployed net in every state",
    }
    if "n" in m:
        summary["n [1/m]"] = m["n"]
        summary["collapse radius [m]"] = m["collapse_radius"]
        summary["aligned radius error [%]"] = m["aligned_radius_error"]
    if "aligned_line_error" in m:
        summary["aligned line error [% span]"] = m["aligned_line_error"]
    summary["time [s]"] = {k: v for k, v in m["timings"].items() if k != "metrics"}
    print_gates(args, summary, f"{bundle.kind} design", quality)
    return 0
