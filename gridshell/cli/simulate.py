"""``gridshell simulate``: the elastic equilibrium of a deployed gridshell (discrete elastic rods)."""
from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from gridshell.cli.values import checked, count, nonnegative, positive

HELP = ("elastic equilibrium of the deployed gridshell: every lamella a discrete elastic rod of "
        "the real strip, joints that turn about their axis only, supports held at the design; "
        "writes the equilibrium as OBJ with a picture over the design and prints its deviation, "
        "support reactions, energy and stresses")


def add_args(p: argparse.ArgumentParser) -> None:
    from gridshell.structure.materials import get_material
    from gridshell.design.section import parse_scale
    from gridshell.structure.materials import material_names
    from gridshell.cli.common import add_bundle_arg

    add_bundle_arg(p)
    p.add_argument("-o", "--out", metavar="OUT",
                   help="output directory, replaced atomically (default DIR/equilibrium)")
    g = p.add_argument_group("strip (mm of the model; default: DIR/fabrication's, else 20 x 1 "
                             "pp at 1:10)")
    g.add_argument("--material", type=checked(get_material, "material"), default=None,
                   help=f"strip material: {', '.join(material_names())} (default pp)")
    g.add_argument("--width", type=positive, default=None, help="strip width, mm")
    g.add_argument("--thickness", type=positive, default=None, help="strip thickness, mm")
    g.add_argument("--scale",
                   type=checked(parse_scale, "scale"),
                   default=None, help="model scale, e.g. 1:10, 1:1 or 0.1")
    g = p.add_argument_group("model")
    g.add_argument("--supports", default="boundary",
                   help="joints held at their design positions: 'boundary' (default: the joints "
                        "on the net's boundary) or joint indices such as 0,5,17")
    g.add_argument("--gravity", action="store_true", help="add the strips' self-weight (-z)")
    g.add_argument("--snow", type=nonnegative, default=None, metavar="KN_M2",
                   help="a uniform snow load, kN per m2 of plan area, on the simulated "
                        "structure (with self-weight; at --scale 1:1 the pavilion itself): "
                        "adds the deflection (mm), span / deflection and the bolts' shear (N)")
    g.add_argument("--per-bay", type=count(1), default=3,
                   help="rod elements between neighbouring joints (default 3)")
    g.add_argument("--max-iter", type=count(1), default=100,
                   help="Newton iterations at most (default 100)")
    g.add_argument("--state", type=count(0), default=None, metavar="K",
                   help="also check the alignment path: its state frame_K (sequence/"
                        "strips.npz) as rods of the strip as cut with every joint held; "
                        "prints how far the strips move from the state (%% of the diagonal)")


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
    from gridshell.api import simulate
    from gridshell.cli.common import Progress, print_summary

    progress = Progress(args)
    sim = simulate(args.bundle, args.out, material=args.material, width=args.width,
                   thickness=args.thickness, scale=args.scale,
                   supports=parse_supports(args.supports), gravity=args.gravity,
                   snow=args.snow, per_bay=args.per_bay, max_iter=args.max_iter,
                   state=args.state, progress=progress)
    print_summary(args, "Simulate", summary(args, sim))
    return 0


def summary(args: Any, sim: Any) -> dict[str, Any]:
    """The printed summary of a :class:`gridshell.workflow.structure.Simulation`."""
    fig = sim.figures
    summary = {
        "bundle": str(Path(args.bundle)), "kind": sim.bundle.kind, "strip": fig["section"],
        "material": sim.material.label, "rest state": fig["rest state"],
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
        "output": str(sim.out),
    }
    if "snow_kN_m2" in fig:
        summary["reactions"] = (f"largest {fig['reaction_max_N']:.3g} N; vertical sum "
                                f"{fig['reaction_sum_N'][2]:.4g} N = self-weight "
                                f"{fig['weight_N']:.4g} N + snow "
                                f"{1e3 * fig['snow_total_kN']:.4g} N")
        summary["deflection"] = (f"{fig['deflection_max_mm']:.3g} mm (vertical "
                                 f"{fig['deflection_vertical_max_mm']:.3g} mm), span "
                                 f"{fig['span_m']:.3g} m / deflection = "
                                 f"{fig['span_over_deflection']:.0f}")
        summary["bolts"] = (f"largest shear {fig['bolt_shear_max_N']:.3g} N (joint "
                            f"{fig['bolt_shear_max_joint']}), mean "
                            f"{fig['bolt_shear_mean_N']:.3g} N")
    if "path_state" in fig:
        ps = fig["path_state"]
        summary["path check"] = (
            f"{ps['state']} (t = {ps['t']:.3g}) with its {ps['held_joints']} joints held: the "
            f"strips move at most {ps['deviation_max_pct']:.3g} % (mean "
            f"{ps['deviation_mean_pct']:.2g} %) of the diagonal, utilisation "
            f"{ps['utilisation_peak']:.3g}" + ("" if ps["converged"] else " (not converged)"))
    u = fig["utilisation_peak"]
    summary["verdict"] = (f"{'elastic' if u <= 1 else 'OVERSTRESSED'}: peak utilisation "
                          f"{u:.2f} under {fig['gravity']}")
    if getattr(args, "json", False):
        summary = {**summary, "figures": fig}
    return summary
