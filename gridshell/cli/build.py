"""``gridshell build``: the whole chain from a model to a build pack in one command
(:func:`gridshell.workflow.build.build`)."""
from __future__ import annotations

import argparse
from typing import Any

from gridshell.cli.values import count, number

HELP = ("the whole chain in one command: analyse the model, choose the pipeline and mode, "
        "design, verify, choose the section, check, simulate, fabricate, export the .3dm and "
        "write report.html into one pack; a re-run reuses what is unchanged")


def add_args(p: argparse.ArgumentParser) -> None:
    from gridshell.cli.common import add_input_args
    from gridshell.design.section import parse_scale
    from gridshell.cli.values import checked
    from gridshell.fabrication.params import parse_sheet
    from gridshell.structure.materials import MATERIALS
    from gridshell.workflow.build import KINDS

    p.add_argument("model", help="the model: a mesh (OBJ, PLY, OFF) or a Rhino .3dm (mesh, "
                                 "NURBS surface or single-face Brep), one disk")
    p.add_argument("-o", "--output", metavar="DIR", required=True,
                   help="the build pack (a design bundle with its structure, equilibrium, "
                        "fabrication/, model.3dm and report.html); a re-run with the same "
                        "arguments reuses every stage whose inputs are unchanged")
    add_input_args(p)
    p.add_argument("--kind", choices=KINDS, default="auto",
                   help="the pipeline and mode: auto (the analysis chooses; default), gg, or "
                        "an NCP mode phlw / cnc / aa")
    p.add_argument("--lamellae", type=count(2), metavar="N",
                   help="lamellae per family (default 10 for GG, the NCP default for NCP)")
    p.add_argument("--material", choices=tuple(MATERIALS), default=None, metavar="NAME",
                   help="strip material preset: " + ", ".join(MATERIALS) + " (default pp); "
                        "the thinnest stock thickness of it that stays elastic is chosen")
    p.add_argument("--scale", type=checked(parse_scale, "scale"), metavar="1:N",
                   help="model scale (default 1:10; 1:1 full size)")
    p.add_argument("--width", type=number(0.0, strict=True), metavar="MM",
                   help="strip width as cut, mm (default 20)")
    p.add_argument("--sheet", type=checked(parse_sheet, "sheet"), metavar="WxH",
                   help="sheet size, mm (default 600x400)")
    p.add_argument("--max-deviation", type=number(0.0), metavar="PCT",
                   help="refuse (exit 4) a net whose joints lie farther from the model than "
                        "this on average, %% of its diagonal (default: no gate)")
    p.add_argument("--frames", type=count(0, "0: no alignment sequence"), default=12,
                   metavar="N", help="states of the alignment sequence (default 12; 0: none)")


def run(args: Any) -> int:
    from gridshell.cli.common import Progress, print_summary
    from gridshell.measure.fidelity import fidelity_line
    from gridshell.workflow.build import build

    progress = Progress(args)
    res = build(args.model, args.output, kind=args.kind, material=args.material,
                lamellae=args.lamellae, scale=args.scale, width=args.width, sheet=args.sheet,
                units=args.units, obj=args.object, frames=args.frames,
                max_deviation=args.max_deviation,
                progress=progress.callback)
    st, sec = res.stages, res.section
    d, c, e, f = st["design"], st["check"], st["simulate"], st["fabricate"]
    n = d.get("n_lamellae") or {}
    summary = {
        "pack": str(res.out),
        "kind": f"{d.get('kind', res.kind)} ({res.why})",
        "net": f"{' + '.join(str(v) for v in n.values()) or '?'} lamellae, "
               f"{d.get('n_joints')} joints",
        "figures": "verified (every figure within the paper's thresholds)",
        "fidelity": fidelity_line(d.get("fidelity")),
        "section": f"{sec['width_mm']:g} x {sec['thickness_mm']:g} mm {sec['material']} at "
                   f"{sec['scale']} (thinnest stock thickness that holds)",
        "structure": f"{c['verdict']}, max utilisation {c['max_utilisation']:.2f} "
                     f"({c['governing_state']})",
        "equilibrium": f"self-weight, deviation max {e.get('deviation_max_pct', 0):.3g} % of "
                       f"the diagonal, utilisation {e.get('utilisation_peak', 0):.2f}",
        "sheets": f"{f['sheets']} ({f['material_used_pct']:.0f} % used), {f['pieces']} "
                  f"pieces, {f['strip_length_m']:.2f} m of strip, {f['mass_kg']:.3g} kg",
        "stages": ", ".join(f"{k} {v['seconds']:.1f} s" + (" (reused)" if v.get("reused")
                                                           else "")
                            for k, v in st.items()),
        "time": f"{res.seconds:.1f} s",
        "open": str(res.out / "report.html"),
    }
    print_summary(args, "gridshell build", summary)
    return 0
