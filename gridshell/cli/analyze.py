"""``gridshell analyze``: before any design, where each kind of net can exist on a target and
which pipeline and mode to run (:func:`gridshell.api.analyze`)."""
from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from gridshell.cli.values import count, number

HELP = ("before any design: where GG and each NCP mode can exist on a target (K sign, umbilic "
        "regions, the largest admissible patch, a quick GG trial), the pipeline to run; writes "
        "analysis.json and analysis.png")


def add_args(p: argparse.ArgumentParser) -> None:
    from gridshell.analysis.recommend import MIN_COVERAGE
    from gridshell.cli.common import add_input_args

    p.add_argument("target", help="target surface: a mesh (OBJ, PLY, OFF) or a Rhino .3dm (mesh, "
                                  "NURBS surface or single-face Brep), one disk")
    add_input_args(p)
    p.add_argument("-o", "--output", metavar="DIR",
                   help="directory for analysis.json and analysis.png (default: TARGET's name "
                        "+ '-analysis' in the current directory; replaced only if it is an "
                        "earlier analysis or empty)")
    p.add_argument("--samples", type=count(8, maximum=400), default=64, metavar="N",
                   help="samples of the fitted surface per parameter direction (8..400; "
                        "default 64)")
    p.add_argument("--min-coverage", type=number(0.0, maximum=100.0), default=MIN_COVERAGE, metavar="PCT",
                   help="share of the target an NCP mode's largest regular patch must cover to "
                        f"be recommended, %% (default {MIN_COVERAGE:g})")
    p.add_argument("--no-trial", action="store_true",
                   help="skip the quick coarse GG design (then GG's deviation is not known)")
    p.add_argument("--no-files", action="store_true",
                   help="print the summary only; write nothing")


def _check(args: Any) -> Path | None:
    """The output directory (None with --no-files); the options were checked when parsed."""
    from gridshell.core.atomic import check_output
    if args.no_files:
        return None
    out = Path(args.output) if args.output else Path(f"{Path(args.target).stem}-analysis")
    return check_output(out, owner="analyze")


def run(args: Any) -> int:
    from gridshell.analysis.analyze import summary_of
    from gridshell.api import analyze
    from gridshell.cli.common import Progress, input_options, print_summary

    out = _check(args)
    progress = Progress(args)
    progress(f"analysing {args.target}")
    a = analyze(args.target, **input_options(args), samples=args.samples,
                trial=not args.no_trial, min_coverage=args.min_coverage, output=out)
    summary = summary_of(a)
    if out is not None:
        summary["files"] = f"{out / 'analysis.json'}, {out / 'analysis.png'}"
    print_summary(args, f"gridshell analyze: {args.target}", summary)
    return 0
