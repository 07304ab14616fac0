"""``gridshell export``: a design bundle as a Rhino ``.3dm`` model an architect can use."""
from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from gridshell.cli.values import checked, positive

HELP = ("export a design bundle to Rhino .3dm: lamellae as strips of their real width and "
        "thickness, joint holes, the surface, the collapsed state and the cut sheets, in the "
        "input's unit and frame")


def add_args(p: argparse.ArgumentParser) -> None:
    from gridshell.design.section import parse_scale
    from gridshell.fabrication.params import parse_sheet
    from gridshell.cli.common import add_bundle_arg

    add_bundle_arg(p)
    p.add_argument("-o", "--output", metavar="PATH",
                   help="the .3dm file (default DIR/<kind>.3dm, e.g. DIR/gg.3dm)")
    g = p.add_argument_group(
        "strips (mm of the cut model; default: DIR/fabrication/fabrication.json when "
        "'gridshell fabricate' wrote one, else 20 x 1 mm, 3 mm holes at 1:10)")
    g.add_argument("--width", type=positive, metavar="MM",
                   help="cut strip width; the strip's real width is width / scale")
    g.add_argument("--thickness", type=positive, metavar="MM",
                   help="cut strip (sheet) thickness; real thickness = thickness / scale")
    g.add_argument("--hole", type=positive, metavar="MM", help="joint hole diameter")
    g.add_argument("--scale",
                   type=checked(parse_scale, "scale"),
                   metavar="S", help="model scale, e.g. 1:10, 1:1 or 0.1")
    g.add_argument("--sheet",
                   type=checked(parse_sheet, "sheet"),
                   metavar="WxH", help="sheet size in mm, e.g. 600x400")
    p.add_argument("--units", metavar="UNIT",
                   help="unit of the Rhino model: m, cm, mm, in or ft (default: the unit the "
                        "design was made in, as design.json records it; metres if none)")
    p.add_argument("--no-sheets", action="store_true",
                   help="leave out the cut sheets (layers 'sheet 01', ...)")
    p.add_argument("--force", action="store_true",
                   help="draw the cut sheets of a design that fails its figures too")


def run(args: Any) -> int:
    from gridshell.core.atomic import check_output
    from gridshell.design.bundle import read_design_json
    from gridshell.api import export_3dm
    from gridshell.cli.common import Progress, print_summary

    progress = Progress(args)
    design = read_design_json(args.bundle)
    out = Path(args.output) if args.output else Path(args.bundle) / f"{design['kind'].lower()}.3dm"
    check_output(out, directory=False)
    progress(f"reading {args.bundle}")
    info = export_3dm(args.bundle, out, width=args.width, thickness=args.thickness,
                      hole=args.hole, scale=args.scale, sheet=args.sheet, units=args.units,
                      sheets=not args.no_sheets, force=args.force, progress=progress.callback)
    p = info["params"]
    u = info["units"]
    mpu = info["metres_per_unit"]
    summary = {
        "rhino": info["path"],
        "units": f"{u} (coordinates = metres / {mpu:g})",
        "strips": f"{info['strips']} of {info['strip_width_m'] / mpu:.4g} x "
                  f"{info['strip_thickness_m'] / mpu:.4g} {u} ({p['width']:g} x "
                  f"{p['thickness']:g} mm at {p['scale_text']})",
        "parameters from": info["params_source"],
        "holes": info["holes"],
        "cut sheets": ", ".join(s["layer"] for s in info["sheets"]) or "none",
        "layers": info["layers"],
    }
    for k, note in enumerate(info["notes"]):
        summary[f"note {k + 1}" if len(info["notes"]) > 1 else "note"] = note
    print_summary(args, "Rhino export", summary)
    return 0
