"""``gridshell gg``: design a geodesic alignable gridshell on a target surface (paper 4.1)."""
from __future__ import annotations

import argparse
import math
from typing import Any

HELP = "design a geodesic (GG) alignable gridshell on a target surface and write a design bundle"


def add_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("target", help="target surface mesh (OBJ, PLY, OFF), metres, one disk")
    p.add_argument("-o", "--output", required=True, metavar="DIR",
                   help="output design bundle directory (replaced atomically)")
    p.add_argument("--meridians", choices=("rows", "cols"), default="cols",
                   help="for a quad-grid target: grid lines that become the meridians "
                        "(geodesics of the designed surface); default cols")
    p.add_argument("--grid", nargs=2, type=int, metavar=("R", "C"),
                   help="resolution of the designed mesh: R parallels x C meridians")
    p.add_argument("--direction", type=float, metavar="DEG",
                   help="meridian direction in degrees, for triangle-mesh targets")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--lamellae", type=int, metavar="N",
                   help="lamellae per family crossing the reference parallel (default 10)")
    g.add_argument("--spacing", type=float, metavar="M",
                   help="spacing of the lamellae along the reference parallel, metres")
    p.add_argument("--angle", type=float, default=90.0, metavar="DEG",
                   help="crossing angle of the two families on the reference parallel, "
                        "degrees (default 90)")
    p.add_argument("--at", type=float, default=0.5, metavar="FRAC",
                   help="reference parallel as a fraction of the meridian length (default 0.5)")
    p.add_argument("--rounds", type=int, default=10, metavar="N",
                   help="outer rounds of the surface optimization (default 10)")
    p.add_argument("--polish", type=int, default=20, metavar="N",
                   help="iterations of the final projection onto the constraints (default 20)")
    p.add_argument("--allow-unconverged", action="store_true",
                   help="write the design even if the surface optimization misses its "
                        "tolerances (default: exit code 4, nothing written)")
    p.add_argument("--no-preview", action="store_true", help="do not render preview.png")


def run(args: Any) -> int:
    from ..atomic import check_output
    from ..gg.pipeline import design_gg, write_gg
    from .common import Progress, print_summary

    check_output(args.output, marker="design.json")
    progress = Progress(args)
    n = args.lamellae if args.lamellae is not None or args.spacing is not None else 10
    bundle, report = design_gg(args.target, meridians=args.meridians,
                               grid=tuple(args.grid) if args.grid else None,
                               direction=args.direction, n_lamellae=n, spacing=args.spacing,
                               crossing_angle=args.angle, at_parallel=args.at,
                               rounds=args.rounds, polish_iter=args.polish,
                               allow_unconverged=args.allow_unconverged,
                               progress=progress.callback)
    progress(f"writing {args.output}")
    out = write_gg(args.output, bundle, preview=not args.no_preview)
    m = bundle.metrics
    summary = {
        "bundle": str(out),
        "surface optimization": "converged" if bundle.params["converged"]
                                else "did NOT converge (--allow-unconverged)",
        "joints / loops / lamellae": f"{m['n_joints']} / {m['n_loops']} / "
                                     f"{m['n_lamellae']['C1']} + {m['n_lamellae']['C3']}",
        "Delta_a straight [%]": m["alignability"],
        "Delta_a arc [%]": m["alignability_arc"],
        "geodesic turning [%]": m["geodesic_turning"],
        "deviation [% diag]": m.get("deviation", {}),
        "surface of revolution": {"total_angle_deg": math.degrees(bundle.params["total_angle"]),
                                  "choice": report["revolution"]["method"]},
    }
    print_summary(args, "GG design", summary)
    return 0
