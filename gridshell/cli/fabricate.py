"""``gridshell fabricate``: laser-ready DXF/SVG sheets, cut list and plan of a design bundle."""
from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from gridshell.cli.common import add_bundle_arg, choice_help
from gridshell.cli.values import checked, nonnegative, positive

HELP = ("cut files of a design bundle: flat lamellae with joint holes, slots or marks and "
        "engraved ids, nested on sheets as DXF and SVG with PNG previews, with a cut list and an "
        "assembly plan")


#: what each choice of the option sets of :mod:`gridshell.fabrication.params` means (the choices and
#: defaults come from there)
AXIS_HELP = {"centre": "on the centre line",
             "edge": "on one edge (orthogonal lamellae standing on the surface; not GG)"}
JOINT_HELP = {"hole": "a hole on the axis",
              "slots": "cross-halving notches (orthogonal lamellae)",
              "marks": "score lines across the strip"}
DXF_HELP = {"R2010": "AutoCAD 2010", "R12": "through ezdxf's R12 export"}


def add_args(p: argparse.ArgumentParser) -> None:
    from gridshell.structure.materials import get_material
    from gridshell.design.section import parse_scale
    from gridshell.fabrication.params import parse_sheet
    from gridshell.fabrication.params import AXIS_PLACES, DXF_VERSIONS, JOINT_STYLES, ROTATIONS, FabParams
    from gridshell.design.section import DEFAULTS, scale_text

    add_bundle_arg(p)
    p.add_argument("-o", "--out", metavar="OUT",
                   help="output directory, replaced atomically (default DIR/fabrication)")
    g = p.add_argument_group("strips (mm of the model)")
    g.add_argument("--width", type=positive, default=None,
                   help=f"strip width (default {DEFAULTS['width']:g})")
    g.add_argument("--thickness", type=positive, default=None,
                   help=f"sheet thickness (default {DEFAULTS['thickness']:g})")
    g.add_argument("--margin", type=nonnegative, default=FabParams.margin,
                   help=f"strip length beyond the end joints (default {FabParams.margin:g})")
    g.add_argument("--axis", choices=AXIS_PLACES, default=FabParams.axis,
                   help="place of the lamella axis on the strip: "
                        + choice_help(AXIS_HELP, AXIS_PLACES, FabParams.axis))
    g.add_argument("--scale", type=checked(parse_scale, "scale"), default=None,
                   help=f"model scale, e.g. {scale_text(DEFAULTS['scale'])} (default), 1:1 or 0.1")
    g = p.add_argument_group("joints")
    g.add_argument("--joints", choices=JOINT_STYLES, default=None,
                   help=choice_help(JOINT_HELP, JOINT_STYLES, FabParams.joints) +
                   "; by default joints too close for holes at this scale are engraved as "
                   "marks (with a warning), an explicit --joints refuses them instead")
    g.add_argument("--hole", type=nonnegative, default=FabParams.hole,
                   help=f"hole diameter, mm (default {FabParams.hole:g})")
    g.add_argument("--clearance", type=nonnegative, default=FabParams.clearance,
                   help=f"slot width = thickness + clearance, mm (default {FabParams.clearance:g})")
    g = p.add_argument_group("sheets and cutting")
    sheet = "x".join(f"{v:g}" for v in FabParams.sheet)
    g.add_argument("--sheet", type=checked(parse_sheet, "sheet"), default=sheet,
                   help=f"sheet size WIDTHxHEIGHT mm (default {sheet})")
    g.add_argument("--gap", type=nonnegative, default=FabParams.gap,
                   help=f"gap between parts and to the sheet edges, mm (default {FabParams.gap:g})")
    g.add_argument("--rotation", choices=ROTATIONS, default=FabParams.rotation,
                   help="how parts may turn on the sheet: free (any angle, isotropic sheets such "
                        "as polypropylene; default) or grain (along the sheet's long side, "
                        "turned by 180 degrees at most: plywood grain along the strips)")
    g.add_argument("--overlap", type=positive, default=None,
                   help="splice overlap of lamellae split to fit a sheet, mm (default: at a joint, "
                        "one joint spacing plus two margins, so the pieces share two joints; "
                         "between joints, two widths plus two margins); every splice holds "
                         "by two shared joints or two fasteners (one would be a hinge): a "
                         "lamella no such splice cuts is refused")
    g.add_argument("--kerf", type=nonnegative, default=FabParams.kerf,
                   help="laser kerf, mm: outlines move out and holes in by kerf/2 (default "
                        f"{FabParams.kerf:g}: off)")
    g.add_argument("--dxf-version", choices=DXF_VERSIONS, default=FabParams.dxf_version,
                   help="DXF version: " + choice_help(DXF_HELP, DXF_VERSIONS,
                                                      FabParams.dxf_version))
    g.add_argument("--segments", action="store_true",
                   help="write arcs as short segments instead of bulges")
    g.add_argument("--no-labels", action="store_true", help="do not engrave ids")
    p.add_argument("--material",
                   type=checked(get_material, "material"), default=None, metavar="NAME",
                   help="strip material of the structural check (gridshell check's presets; "
                        f"default {DEFAULTS['material']}): strips that would not stay elastic "
                        "are not cut")
    p.add_argument("--no-plan", action="store_true", help="do not draw plan.png / plan.svg")
    p.add_argument("--force", action="store_true",
                   help="cut a design whose recomputed figures miss the paper's thresholds, or "
                        "whose files disagree with design.json ('gridshell verify' lists them; "
                        "default: refused, exit 2), or whose strips would be overstressed in "
                        "the material ('gridshell check'; default: refused, exit 4)")


def _structure(bundle: str, params, material: str, force: bool,
               progress) -> dict[str, Any]:
    """The structural verdict of these strips before any file is written
    (:func:`gridshell.api.check_structure`, nothing written: deployed and collapsed states, the
    sequence too when the bundle has one): refused (exit 4,
    :func:`gridshell.structure.verdict.refuse_overstressed`) when overstressed, unless
    ``force``; the record ``fabrication.json`` keeps."""
    from gridshell.api import check_structure
    from gridshell.structure.verdict import refuse_overstressed, verdict_record

    progress("checking the strips' stresses")
    res = check_structure(bundle, material=material, width=params.width,
                          thickness=params.thickness, scale=params.scale, write=False,
                          picture=False).result
    refuse_overstressed(res, force, "pass --force to cut it anyway ('gridshell check "
                        "--suggest' lists the sections that hold)")
    if res["verdict"] != "ok":
        progress("warning: the strips are overstressed; cut anyway (--force)")
    return verdict_record(res, force)


def run(args: Any) -> int:
    from gridshell.fabrication import FabParams, fabricate

    from gridshell.core.atomic import check_output
    from gridshell.design.bundle import read_design_json
    from gridshell.design.verification import require_design
    from gridshell.cli.common import Progress, print_summary

    progress = Progress(args)
    from gridshell.design.section import resolve_section
    from gridshell.structure import get_material

    # the caller's strip, else the defaults: fabricate writes the bundle's fabrication report
    # and does not read a previous one back (a stale or broken one never blocks a new cut)
    strip = resolve_section(args.bundle, width=args.width, thickness=args.thickness,
                            scale=args.scale, material=args.material, stored=False)
    get_material(strip.material)  # an unknown name is refused before any work
    params = FabParams(width=strip.width_mm, thickness=strip.thickness_mm, hole=args.hole,
                       joints=args.joints or FabParams.joints,
                       fallback_marks=args.joints is None, clearance=args.clearance,
                       margin=args.margin,
                       axis=args.axis, scale=strip.scale, sheet=args.sheet, gap=args.gap,
                       rotation=args.rotation, overlap=args.overlap, kerf=args.kerf,
                       dxf_version=args.dxf_version,
                       segments=args.segments, labels=not args.no_labels)
    read_design_json(args.bundle)  # a bad bundle is named before its output location
    out = Path(args.out) if args.out else Path(args.bundle) / "fabrication"
    check_output(out)
    progress(f"verifying {args.bundle}")
    verdict = require_design(args.bundle, args.force, f"'gridshell verify {args.bundle}' shows "
                             "them - pass --force to cut it anyway")
    if not verdict.ok:
        progress("warning: the design fails its checks; cut anyway (--force)")
    structure = _structure(args.bundle, params, strip.material, args.force, progress)
    rep = fabricate(args.bundle, out, params, progress=progress.callback, plan=not args.no_plan,
                    structure=structure)
    from gridshell.measure.quality import gate_summary

    gates = list(verdict.gates)
    summary = {
        "output": str(out),
        "design": f"{rep['kind']} ({rep['shape']} strips)",
        "design checks": (gate_summary(gates) if verdict.ok else
                          "cut with --force: " + "; ".join(
                              [gate_summary(gates)] + list(verdict.problems))),
        "strips / pieces": f"{rep['n_strips']} / {rep['n_pieces']}",
        "joint marks": rep["n_joint_marks"],
        "sheets": f"{rep['n_sheets']} x {params.sheet[0]:g} x {params.sheet[1]:g} mm "
                  f"({rep['sheet_files']})",
        "utilisation [%]": 100.0 * rep["utilisation"],
        "material used [% of sheet area]": ", ".join(
            f"{100.0 * u:.1f}" for u in rep["material_used_per_sheet"])
            + f" (all sheets {100.0 * rep['material_used']:.1f})",
        "pieces split": ", ".join(f"L{d['lamella']} in {d['pieces']}"
                                  for d in rep["pieces_split"]) or "none",
        "files": ", ".join(rep["files"]),
    }
    summary["structure"] = (("cut with --force: " if structure["forced"] else "")
                            + structure["line"])
    if rep["joints_fallback"]:
        summary["warning"] = rep["joints_fallback"]
    if rep["labels_dropped"]:
        summary["labels dropped (no room)"] = rep["labels_dropped"]
    print_summary(args, "Fabrication", summary)
    return 0
