"""``gridshell gg``: design a geodesic alignable gridshell on a target surface (paper 4.1)."""
from __future__ import annotations

import argparse
import math
from typing import Any

from gridshell.cli.values import angle_between, count, fraction, nonnegative, number, positive

HELP = "design a geodesic (GG) alignable gridshell on a target surface and write a design bundle"


def add_args(p: argparse.ArgumentParser) -> None:
    from gridshell.cli.common import add_input_args

    p.add_argument("target", help="target surface: a mesh (OBJ, PLY, OFF) or a Rhino .3dm (mesh, "
                                  "NURBS surface or single-face Brep), one disk")
    add_input_args(p)
    p.add_argument("-o", "--output", required=True, metavar="DIR",
                   help="output design bundle directory (replaced atomically)")
    p.add_argument("--meridians", choices=("rows", "cols"), default="cols",
                   help="for a quad-grid target: grid lines that become the meridians "
                        "(geodesics of the designed surface); default cols")
    p.add_argument("--grid", nargs=2, type=count(4), metavar=("R", "C"),
                   help="resolution of the designed mesh: R parallels x C meridians")
    p.add_argument("--direction", type=number(), metavar="DEG",
                   help="meridian direction in degrees, for triangle-mesh targets")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--lamellae", type=count(2), metavar="N",
                   help="lamellae made per family: the evenly spaced geodesics that reach "
                        "the surface, as many as asked where the shape allows (default: the "
                        "spacing that puts 10 of each family across the reference parallel; "
                        "the summary says what was made)")
    g.add_argument("--spacing", type=positive, metavar="M",
                   help="spacing of the lamellae along the reference parallel, metres")
    g.add_argument("--offsets", nargs="+", type=number(), metavar="M",
                   help="non-uniform spacing (paper Fig. 18): positions of the lamellae of both "
                        "families on the reference parallel, metres of arc length from the "
                        "first meridian, at least 2; --offsets1 / --offsets3 override one family")
    p.add_argument("--offsets1", nargs="+", type=number(), metavar="M",
                   help="positions of the C1 lamellae only (metres, as --offsets)")
    p.add_argument("--offsets3", nargs="+", type=number(), metavar="M",
                   help="positions of the C3 lamellae only (metres, as --offsets)")
    p.add_argument("--angle", type=angle_between(0.0, 180.0), default=90.0, metavar="DEG",
                   help="crossing angle of the two families on the reference parallel, "
                        "degrees (default 90)")
    p.add_argument("--at", type=fraction, default=0.5, metavar="FRAC",
                   help="reference parallel as a fraction of the meridian length (default 0.5)")
    p.add_argument("--rounds", type=count(1), default=10, metavar="N",
                   help="outer rounds of the surface optimization (default 10)")
    p.add_argument("--polish", type=count(0, "0: no final projection"), default=20, metavar="N",
                   help="most iterations of the final projection onto the constraints; it "
                        "stops once the figures hold and stagnate (default 20)")
    p.add_argument("--max-deviation", type=nonnegative, metavar="PCT",
                   help="refuse (exit 4, nothing written) a net whose joints lie farther from "
                        "the target than this on average, %% of its diagonal (default: no gate)")
    p.add_argument("--allow-unconverged", action="store_true",
                   help="write the design even if it misses the paper's figures (Delta_a mean "
                        "< 1 %%, max < 3 %%; default: exit code 4, nothing written); the bundle "
                        "is marked as failing")
    p.add_argument("--frames", type=count(0, "0: no sequence", maximum=1000), default=12,
                   metavar="N",
                   help="steps of the alignment sequence from the deployed to the collapsed net "
                        "(sequence/frame_*.obj, with pictures alignment.gif and states.png); "
                        "0: none (default 12)")
    p.add_argument("--no-preview", action="store_true",
                   help="do not render preview.png nor the pictures of the alignment sequence")


def _offsets(args: Any) -> tuple[list[float], list[float]] | None:
    """The (C1, C3) positions of ``--offsets`` / ``--offsets1`` / ``--offsets3``, validated."""
    from gridshell.core.errors import InputError
    from gridshell.gg.pipeline import check_offsets

    o1 = args.offsets1 if args.offsets1 is not None else args.offsets
    o3 = args.offsets3 if args.offsets3 is not None else args.offsets
    if o1 is None and o3 is None:
        return None
    if args.lamellae is not None or args.spacing is not None:
        raise InputError("--offsets1 / --offsets3 replace --lamellae and --spacing; give one way "
                         "of placing the lamellae")
    if o1 is None or o3 is None:
        missing = "--offsets1" if o1 is None else "--offsets3"
        raise InputError(f"{missing} is missing: give the positions of both families "
                         "(--offsets for both, or --offsets1 and --offsets3)")
    a1, a3 = check_offsets((o1, o3))
    return a1.tolist(), a3.tolist()


def run(args: Any) -> int:
    from gridshell.core.atomic import check_output
    from gridshell.workflow.cut import require_no_made_from
    from gridshell.api import design_gg, write

    from gridshell.cli.common import (Progress, input_line, input_options, print_summary,
                                      quality_lines)

    offsets = _offsets(args)
    if not 0 <= args.frames <= 1000:
        from gridshell.core.errors import InputError
        raise InputError(f"--frames must be in 0 .. 1000 (each state is an optimization), got "
                         f"{args.frames}; e.g. 12")
    check_output(args.output, marker="design.json")
    require_no_made_from(args.output)
    progress = Progress(args)
    n = args.lamellae
    design = design_gg(args.target, meridians=args.meridians,
                       grid=tuple(args.grid) if args.grid else None,
                       direction=args.direction, n_lamellae=n, spacing=args.spacing,
                       offsets=offsets, crossing_angle=args.angle, at_parallel=args.at,
                       rounds=args.rounds, polish_iter=args.polish,
                       allow_unconverged=args.allow_unconverged,
                       frames=args.frames, **input_options(args),
                       progress=progress.callback)
    from gridshell.measure.fidelity import require_fidelity

    require_fidelity(design.bundle.metrics, args.max_deviation)
    progress(f"writing {args.output}")
    out = write(args.output, design, render=not args.no_preview, progress=progress.callback)
    bundle, report = design
    m = bundle.metrics
    from gridshell.measure.fidelity import fidelity_line
    seq = report["sequence"]
    quality = bundle.params["quality"]

    surf = bundle.params["surface"]
    summary = {
        "bundle": str(out),
        "input": input_line(bundle.params.get("input")),
        "surface optimization": f"geodesic residual {surf['geodesic_residual_max']:.2e} rad, "
                                f"edge-length spread {surf['length_residual_rel_max']:.2e}, "
                                f"polish stopped: {surf['polish_stop']}",
        "joints / loops / lamellae": f"{m['n_joints']} / {m['n_loops']} / "
                                     f"{m['n_lamellae']['C1']} + {m['n_lamellae']['C3']}"
                                     + _asked(m.get("lamellae_count")),
        "Delta_a straight [%]": m["alignability"],
        "Delta_a arc [%]": m["alignability_arc"],
        "geodesic turning [%]": m["geodesic_turning"],
        "fidelity to the target": fidelity_line(m.get("fidelity")),
        "deviation [% diag]": m.get("deviation", {}),
        "deviation target->surface [% diag]": m.get("deviation_target", {}),
        "coverage [% of target area]": m.get("coverage", float("nan")),
        "surface of revolution": {"total_angle_deg": math.degrees(bundle.params["total_angle"]),
                                  "choice": report["revolution"]["method"]},
        "alignment sequence": (f"{len(seq.V)} states, joint-to-joint lengths within "
                               f"{m['sequence_length_error']:.2g} % of the deployed net"
                               if seq is not None else "none (--frames 0)"),
    }
    verdict = ("PASS: " if quality["ok"] else "FAIL (written with --allow-unconverged): ") + \
        quality["summary"]
    if getattr(args, "json", False):
        print_summary(args, "GG design", {**summary, "ok": quality["ok"],
                                          "gates": quality["gates"], "verdict": verdict})
    else:
        print_summary(args, "GG design", summary)
        print("  quality (the paper's figures on the traced net):")
        for line in quality_lines(quality["gates"]):
            print(f"    {line}")
        print(f"  verdict: {verdict}")
    return 0


def _asked(counted: dict | None) -> str:
    """`` (10 asked: ...)`` where the lamellae made per family differ from those asked."""
    if not counted or counted.get("made") == counted.get("asked"):
        return ""
    return f" ({counted['asked']} asked: {counted.get('why', 'the nearest possible')})"
