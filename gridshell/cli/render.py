"""``gridshell render``: pictures, the self-contained report and a Rhino model of a bundle."""
from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from gridshell.cli.values import count, positive

HELP = ("render a design bundle: render.png (lamellae as strips of their real width), "
        "alignment.gif when the bundle has an alignment sequence, and optionally report.html "
        "(with an interactive 3D view) and a Rhino .3dm")


def add_args(p: argparse.ArgumentParser) -> None:
    from gridshell.cli.common import add_bundle_arg

    add_bundle_arg(p, "; files go into it")
    p.add_argument("--report", action="store_true",
                   help="also write DIR/report.html: one self-contained page of the design")
    p.add_argument("--pdf", action="store_true",
                   help="also write DIR/report.pdf: the pack on A4 pages (overview, assembly: "
                        "strips and the joints' order, cut sheets, structure)")
    p.add_argument("--3dm", dest="rhino", metavar="PATH",
                   help="also export the design to this Rhino .3dm file ('gridshell export' "
                        "with its defaults: strips, holes, surface, collapsed state, cut sheets)")
    p.add_argument("--width", type=positive, metavar="MM",
                   help="strip width in mm at full size (default the cut strip's width over "
                        "the scale, from DIR/fabrication/fabrication.json, else 20 mm at 1:10 "
                        "= 200 mm)")
    p.add_argument("--size", nargs=2, type=count(64, maximum=10000), default=(1200, 900), metavar=("W", "H"),
                   help="render.png size in pixels (default 1200 900)")
    p.add_argument("--no-sequence", action="store_true",
                   help="do not render the alignment sequence")
    p.add_argument("--force", action="store_true",
                   help="re-render alignment.gif even when it is newer than the sequence")


def _sequence_is_current(bundle: Path, gif: Path) -> bool:
    from gridshell.render.sequence import sequence_files

    files = sequence_files(bundle)
    return gif.is_file() and all(gif.stat().st_mtime >= f.stat().st_mtime for f in files)


def run(args: Any) -> int:
    from gridshell.core.atomic import check_output
    from gridshell.design.bundle import read_design_json
    from gridshell.core.errors import InputError
    from gridshell.api import write_outputs
    from gridshell.render.sequence import sequence_files
    from gridshell.cli.common import Progress, print_summary

    progress = Progress(args)
    bundle = Path(args.bundle)
    design = read_design_json(bundle)
    check_output(bundle / "render.png", directory=False)
    if args.rhino:
        check_output(args.rhino, directory=False)
    if args.width is not None and not args.width > 0:
        raise InputError(f"--width must be positive (mm), got {args.width}")
    if min(args.size) < 64 or max(args.size) > 10000:
        raise InputError(f"--size must be 64 to 10000 pixels each way, got {args.size}")
    written: list[str] = []

    frames = sequence_files(bundle)
    gif = bundle / "alignment.gif"
    sequence, animate = "none in the bundle", False
    if frames and args.no_sequence:
        sequence = f"{len(frames)} frames, not rendered (--no-sequence)"
    elif frames and _sequence_is_current(bundle, gif) and not args.force:
        sequence = f"{len(frames)} frames, alignment.gif up to date (--force re-renders)"
    elif frames:
        sequence, animate = f"{len(frames)} frames -> alignment.gif", True
    res = write_outputs(bundle, sequence=animate,
                        report=args.report, pdf=args.pdf, rhino=args.rhino,
                        width=None if args.width is None else args.width / 1000.0,
                        size=tuple(args.size), progress=progress.callback)
    out, report, info = res["render"], res["report"], res["rhino"]
    written.append(out.name)
    if res["sequence"] is not None:
        written += [f"sequence/frame_*.png ({len(res['sequence']['frames'])})", gif.name]
    if report is not None:
        written.append(report.name)
    if res["pdf"] is not None:
        written.append(res["pdf"].name)
    rhino = None
    if info is not None:
        rhino = info["path"]
        for note in info["notes"]:
            progress(f"note: {note}")
        written.append(str(rhino))

    summary = {
        "bundle": str(bundle),
        "kind": design["kind"],
        "lamellae": len(design["lamellae"]),
        "render": str(out),
        "alignment sequence": sequence,
        "report": str(report) if report else "not written (--report)",
        "pdf": str(res["pdf"]) if res["pdf"] else "not written (--pdf)",
        "rhino": str(rhino) if rhino else "not written (--3dm PATH)",
        "files": ", ".join(written),
    }
    print_summary(args, "Render", summary)
    return 0
