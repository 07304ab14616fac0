"""``gridshell simulate``: the elastic equilibrium of a deployed gridshell (discrete elastic rods)."""
from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

HELP = ("elastic equilibrium of the deployed gridshell: every lamella a discrete elastic rod of "
        "the real strip, joints that turn about their axis only, supports held at the design; "
        "writes the equilibrium as OBJ with a picture over the design and prints its deviation, "
        "support reactions, energy and stresses")


def add_args(p: argparse.ArgumentParser) -> None:
    from gridshell.structure.materials import material_names
    from gridshell.cli.common import add_bundle_arg

    add_bundle_arg(p)
    p.add_argument("-o", "--out", metavar="OUT",
                   help="output directory, replaced atomically (default DIR/equilibrium)")
    g = p.add_argument_group("strip (as 'gridshell fabricate': mm of the model)")
    g.add_argument("--material", default="pp",
                   help=f"strip material: {', '.join(material_names())} (default pp)")
    g.add_argument("--width", type=float, default=20.0, help="strip width, mm (default 20)")
    g.add_argument("--thickness", type=float, default=1.0,
                   help="strip thickness, mm (default 1)")
    g.add_argument("--scale", default="1:10", help="model scale, e.g. 1:10 (default), 1:1 or 0.1")
    g = p.add_argument_group("model")
    g.add_argument("--supports", default="boundary",
                   help="joints held at their design positions: 'boundary' (default: the joints "
                        "on the net's boundary) or joint indices such as 0,5,17")
    g.add_argument("--gravity", action="store_true", help="add the strips' self-weight (-z)")
    g.add_argument("--per-bay", type=int, default=3,
                   help="rod elements between neighbouring joints (default 3)")
    g.add_argument("--max-iter", type=int, default=100,
                   help="Newton iterations at most (default 100)")


def parse_supports(text: str):
    """'boundary' or a comma-separated list of joint indices."""
    from gridshell.core.errors import InputError

    text = str(text).strip()
    if text == "boundary":
        return text
    try:
        ids = [int(t) for t in text.replace(" ", "").split(",") if t]
    except ValueError:
        raise InputError(f"--supports {text!r}: give 'boundary' or joint indices separated by "
                         "commas, e.g. 0,5,17") from None
    if not ids:
        raise InputError("--supports: give 'boundary' or at least three joint indices")
    return ids


def run(args: Any) -> int:
    from gridshell.fabrication.params import parse_scale

    from gridshell.core.atomic import atomic_dir, check_output
    from gridshell.design.bundle import finite_json, read_bundle
    from gridshell.core.errors import InputError
    from gridshell.geometry.meshfile import write_mesh, write_polylines
    from gridshell.render.equilibrium import render_equilibrium
    from gridshell.structure.equilibrium import simulate
    from gridshell.structure.materials import get_material
    from gridshell.structure.section import Section
    from gridshell.cli.common import Progress, print_summary

    progress = Progress(args)
    bundle_dir = Path(args.bundle)
    b = read_bundle(bundle_dir)
    out = Path(args.out) if args.out else bundle_dir / "equilibrium"
    check_output(out)
    if args.per_bay < 1 or args.max_iter < 1:
        raise InputError("--per-bay and --max-iter must be at least 1")
    material = get_material(args.material)
    section = Section(args.width, args.thickness, parse_scale(args.scale))
    supports = parse_supports(args.supports)
    progress(f"equilibrium of {b.kind} {bundle_dir} in {args.width:g} x {args.thickness:g} mm "
             f"{material.label} at {args.scale}")
    eq = simulate(b, material, section, supports=supports, gravity=args.gravity,
                  per_bay=args.per_bay, max_iter=args.max_iter, progress=progress)
    fig = eq.figures
    family = {lm.id: lm.family for lm in b.net.lamellae}
    fams = [family[i] for i in eq.model.lamella_ids]
    record = {
        "format": "gridshell.equilibrium", "version": 1,
        "units": {"positions": "m of the design", "reactions": "N on the model",
                  "energy": "J on the model", "deviation": "% of the design's bbox diagonal"},
        "figures": fig,
        "material": material.to_json(), "section": section.to_json(),
        "supports": eq.supports.tolist(), "reactions_N": eq.reactions.tolist(),
        "deviation_pct": eq.deviation.tolist(),
        "stresses": eq.stresses,
        "newton": eq.result.history,
    }
    progress(f"writing {out}")
    with atomic_dir(out, owner="simulate", kind="elastic equilibrium") as tmp:
        if len(b.net.loops):
            write_mesh(tmp / "equilibrium.obj", eq.joints, b.net.loops)
        write_polylines(tmp / "axes.obj", eq.axes)
        (tmp / "equilibrium.json").write_text(
            json.dumps(finite_json(record), indent=1, allow_nan=False), encoding="utf-8")
        title = (f"{b.kind} equilibrium, {args.width:g} x {args.thickness:g} mm "
                 f"{material.name} at {args.scale}: deviation max "
                 f"{fig['deviation_max_pct']:.3g} % of diagonal, peak utilisation "
                 f"{fig['utilisation_peak']:.2f}")
        render_equilibrium(tmp / "equilibrium.png", eq.axes0, eq.axes, fams, b.net.joints,
                           eq.joints, eq.deviation, eq.supports, title=title)
    summary = {
        "bundle": str(bundle_dir), "kind": b.kind, "strip": fig["section"],
        "material": material.label, "rest state": fig["rest state"],
        "gravity": fig["gravity"], "rod model": fig["rod model"],
        "supports": f"{fig['supports']} joints held",
        "newton": fig["newton"],
        "deviation": f"mean {fig['deviation_mean_pct']:.3g} %, max "
                     f"{fig['deviation_max_pct']:.3g} % of the diagonal (joint "
                     f"{fig['deviation_max_joint']})",
        "reactions": f"largest {fig['reaction_max_N']:.3g} N; sum "
                     + ", ".join(f"{v:.3g}" for v in fig["reaction_sum_N"])
                     + f" N (self-weight {fig['weight_N']:.3g} N)",
        "energy stored": f"{fig['energy_J']:.4g} J (" + ", ".join(
            f"{k} {v:.3g}" for k, v in fig["energy_parts_J"].items()) + ")",
        "utilisation": f"peak {fig['utilisation_peak']:.3g} at equilibrium (lamella "
                       f"{fig['utilisation_lamella']}; sigma {fig['sigma_peak_MPa']:.3g} MPa, "
                       f"tau {fig['tau_peak_MPa']:.3g} MPa), {fig['utilisation_design']:.3g} "
                       "in the design shape",
        "time": f"{fig['wall_s']:.1f} s wall, {fig['cpu_s']:.1f} s CPU",
        "output": str(out),
    }
    if getattr(args, "json", False):
        summary = {**summary, "figures": fig}
    print_summary(args, "Simulate", summary)
    return 0
