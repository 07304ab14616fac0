"""``gridshell check``: will the strips bend into the design without breaking?

Stresses along every lamella of a design bundle for a strip section and material
(:func:`gridshell.structure.check.check_bundle`), written to ``DIR/structure.json`` (listed in
the bundle's manifest) and ``DIR/structure.png`` (the strips coloured by utilisation). Prints a
table (the ``--top`` most utilised lamellae) and a verdict.
Exit code: 0 every state stays elastic (utilisation <= 1); 4 overstressed (like a figure
that fails in ``verify``; ``structure.json`` is written all the same); 2 bad input.
"""
from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from gridshell.cli.values import checked, count, number, positive

HELP = ("stresses the design imposes on its strips (bending about both axes, twist) for a "
        "material and section; writes DIR/structure.json (exit 0 elastic, 4 overstressed)")

#: exit code of an overstressed design (gridshell.core.errors.EXIT_CODES: a figure fails)
OVERSTRESSED = 4


def add_args(p: argparse.ArgumentParser) -> None:
    from gridshell.structure.materials import get_material
    from gridshell.design.section import parse_scale
    from gridshell.structure import MATERIALS
    from gridshell.cli.common import add_bundle_arg

    add_bundle_arg(p, "; structure.json goes into it")
    g = p.add_argument_group("material")
    g.add_argument("--material",
                   type=checked(get_material, "material"), default=None, metavar="NAME",
                   help="preset: " + "; ".join(f"{k}: {m.label}" for k, m in MATERIALS.items())
                        + " (default pp unless --E and --allowable give your own)")
    g.add_argument("--E", dest="E", type=positive, metavar="GPA", help="Young's modulus, GPa")
    g.add_argument("--G", dest="G", type=positive, metavar="GPA",
                   help="shear modulus, GPa (default: from E and the Poisson ratio for an "
                        "isotropic material, the preset's for timber and GFRP)")
    g.add_argument("--nu", type=number(-1.0, strict=True, maximum=0.5), help="Poisson ratio")
    g.add_argument("--allowable", type=positive, metavar="MPA",
                   help="allowable (elastic limit) stress, MPa")
    g.add_argument("--allowable-strain", type=number(0.0, strict=True, maximum=100.0),
                   metavar="PERCENT",
                   help="allowable strain, %% (the smaller of stress and E x strain governs)")
    g.add_argument("--density", type=positive, metavar="KG_M3", help="density, kg/m^3")
    g = p.add_argument_group("strip (mm of the model; default: DIR/fabrication's, else 20 x 1 "
                             "at 1:10)")
    g.add_argument("--width", type=positive, help="strip width, mm")
    g.add_argument("--thickness", type=positive, help="strip thickness, mm")
    g.add_argument("--scale",
                   type=checked(parse_scale, "scale"), help="model scale, e.g. 1:10, 1:1 or 0.1")
    p.add_argument("--no-states", action="store_true",
                   help="deployed state only (not the collapsed state nor the alignment "
                        "sequence)")
    p.add_argument("--no-picture", action="store_true",
                   help="do not draw DIR/structure.png (the strips coloured by utilisation)")
    p.add_argument("--suggest", action="store_true",
                   help="also print the sections of the material that hold (its stock "
                        "thicknesses, the widths that stay elastic at the scale) and the "
                        "smallest model scale at which this strip holds")
    p.add_argument("--top", type=count(0, "0: none listed"), default=12, metavar="N",
                   help="lamellae listed in the table, most utilised first (default 12; 0: all)")


def material_of(args: Any):
    """The material the options describe: a preset name (None: the default) or, with values of
    its own (``--E``, ``--allowable`` ...), a :class:`~gridshell.structure.materials.Material`."""
    from gridshell.core.errors import InputError
    from gridshell.design.section import DEFAULTS
    from gridshell.structure import get_material, user_material

    for name, v in (("E", args.E), ("G", args.G), ("allowable", args.allowable),
                    ("allowable-strain", args.allowable_strain), ("density", args.density)):
        if v is not None and not v > 0:
            raise InputError(f"--{name} must be positive, got {v}")
    own = args.material is None and args.E is not None
    changes = (args.E, args.G, args.nu, args.density, args.allowable, args.allowable_strain)
    if not own and all(v is None for v in changes):
        get_material(args.material or DEFAULTS["material"])  # an unknown name, before any work
        return args.material
    base = None if own else get_material(args.material or DEFAULTS["material"])
    return user_material(
        base, E=None if args.E is None else args.E * 1e9,
        G=None if args.G is None else args.G * 1e9, nu=args.nu, density=args.density,
        allowable_stress=None if args.allowable is None else args.allowable * 1e6,
        allowable_strain=None if args.allowable_strain is None else args.allowable_strain / 100)


def table(result: dict[str, Any], top: int = 12) -> list[str]:
    """The lamella table's lines, most utilised first (``top`` rows; 0: all)."""
    rows = sorted(result["lamellae"], key=lambda r: -r["max_utilisation"])
    if top > 0:
        rows = rows[:top]
    lines = [f"  {'lamella':>7} {'fam':>3} {'util':>6} {'at s [m]':>9} {'joint':>6} "
             f"{'sig_w':>6} {'sig_s':>6} {'tau':>6} {'R_min [mm]':>10} {'t_max [mm]':>10}",
             f"  {'':>7} {'':>3} {'':>6} {'':>9} {'':>6} {'[MPa]':>6} {'[MPa]':>6} "
             f"{'[MPa]':>6}"]
    for r in rows:
        R = r["min_radius_m"]
        Rt = f"{R * 1e3:10.1f}" if R is not None and R < float("inf") else f"{'straight':>10}"
        lines.append(f"  {r['id']:>7} {'C' + str(r['family']):>3} {r['max_utilisation']:6.2f} "
                     f"{r['worst_s_m']:9.3f} {r['worst_joint']:>6} "
                     f"{r['max_sigma_weak_MPa']:6.2f} {r['max_sigma_strong_MPa']:6.2f} "
                     f"{r['max_tau_MPa']:6.2f} {Rt} {r['max_elastic_thickness_mm']:10.2f}")
    return lines


def verdict_line(result: dict[str, Any]) -> str:
    """One line: the verdict, the governing utilisation and where, what governs and what
    would hold (:func:`gridshell.structure.verdict.verdict_line`)."""
    from gridshell.structure.verdict import verdict_line as line

    return line(result)


def suggest_rows(bundle, result: dict[str, Any], material, section) -> list[dict[str, Any]]:
    """Per stock thickness of the material the widths that hold at this scale
    (:func:`gridshell.structure.sizing.stock_sections` on the check's curvatures)."""
    from gridshell.structure.check import deployed_curvatures
    from gridshell.structure.sizing import demand_from, stock_sections

    _, ks, _ = deployed_curvatures(bundle, section)
    demand = demand_from(ks, [lam.id for lam in bundle.net.lamellae], section.scale,
                         result["states"])
    return stock_sections(demand, material, section)


def suggest_lines(rows: list[dict[str, Any]], result: dict[str, Any], material,
                  section) -> list[str]:
    """``--suggest``'s lines: the rows of :func:`suggest_rows` and the smallest scale at which
    this strip holds."""
    from gridshell.structure.sizing import MIN_EDGE_RATIO

    sc = result["section"]["scale_text"]
    lines = [f"  suggest   {material.name} sections that hold at {sc} (stock thicknesses; "
             f"widths of the R10 series from {MIN_EDGE_RATIO:g} thicknesses; every state "
             "checked on its largest curvatures):"]
    for row in rows:
        t, ws = row["thickness_mm"], row["widths_mm"]
        if ws:
            lines.append(f"    {t:g} mm thick: {ws[0]:g} to {ws[-1]:g} mm wide (widest "
                         f"{row['widest_mm']:.1f} mm; utilisation {row['utilisation']:.2f} at "
                         f"{t:g} x {ws[-1]:g} mm)")
        else:
            lines.append(f"    {t:g} mm thick: none" + (
                f" (widest elastic strip {row['widest_mm']:.1f} mm, narrower than "
                f"{MIN_EDGE_RATIO:g} thicknesses)" if row["widest_mm"] > 0 else ""))
    adv = result["advice"]
    lines.append(f"  scale     this {section.width_mm:g} x {section.thickness_mm:g} mm strip "
                 f"holds at {adv['smallest_scale_text']} or a larger model (the smallest "
                 "model that stays elastic)")
    return lines


def run(args: Any) -> int:
    from gridshell.api import check_structure
    from gridshell.core.errors import InputError
    from gridshell.design.bundle import finite_json, read_design_json
    from gridshell.cli.common import Progress

    progress = Progress(args)
    if args.top < 0:
        raise InputError(f"--top must be >= 0, got {args.top}")
    read_design_json(args.bundle)
    chk = check_structure(args.bundle, material=material_of(args), width=args.width,
                          thickness=args.thickness, scale=args.scale,
                          states=not args.no_states, picture=not args.no_picture,
                          progress=progress.callback)
    from gridshell.design.bundle import read_bundle
    from gridshell.structure.section import Section

    res, material, out, picture = chk.result, chk.material, chk.file, chk.picture
    code = 0 if res["verdict"] == "ok" else OVERSTRESSED
    section = Section(chk.section.width_mm, chk.section.thickness_mm, chk.section.scale)
    rows = (suggest_rows(read_bundle(args.bundle), res, material, section) if args.suggest
            else None)
    if getattr(args, "json", False):
        summary = {k: v for k, v in res.items() if k not in ("lamellae", "states")}
        summary["states"] = {k: v for k, v in res["states"].items() if k != "frames"}
        summary["file"] = str(out)
        summary["picture"] = str(picture) if picture else None
        if rows is not None:
            summary["suggest"] = rows
        print(json.dumps(finite_json({"ok": code == 0, **summary}), indent=1, allow_nan=False))
        return code
    print(f"Structure of {args.bundle} ({res['kind']}, {res['orientation']} strips cut "
          f"{res['cut_shape']})")
    print(f"  material  {material.label}: E {material.E / 1e9:.3g} GPa, G {material.G / 1e9:.3g} "
          f"GPa, allowable {material.allowable / 1e6:.3g} MPa")
    sec = res["section"]
    print(f"  section   {sec['width_mm']:g} x {sec['thickness_mm']:g} mm at "
          f"{sec['scale_text']} (edge ratio {sec['edge_ratio']:.3g}:1)")
    print("\n".join(table(res, args.top)))
    st = res["states"]
    if st:
        col = st["collapsed"]
        print(f"  states    alignment sequence max utilisation "
              f"{st['sequence_max_utilisation']:.2f}; collapsed {col['max_utilisation']:.2f}")
        if st["unresolved"]:
            print(f"  warning   {len(st['unresolved'])} states of the alignment sequence fold "
                  f"(a lamella turns by more than {st['fold_deg']:g} deg between joints): "
                  f"{', '.join(st['unresolved'])}: not judged (the sequence is kinematic; "
                  "where it folds its stresses mean nothing)")
        over = [f["name"] for f in st["frames"] if f.get("approximate") and f["resolved"]
                and f["max_utilisation"] > 1.0]
        if over:
            print(f"  note      utilisation above 1 in {', '.join(over)}: "
                  f"{st['approximate_path']}")
    if rows is not None:
        print("\n".join(suggest_lines(rows, res, material, section)))
    print(f"  files     {out}" + (f", {picture}" if picture else ""))
    print(verdict_line(res))
    if code and not getattr(args, "quiet", False):
        print("gridshell check: overstressed (exit 4); " + (res["advice"]["helps"] or "")
              + ", as does a larger scale or a stronger material ('--suggest' lists the "
              "sections that hold)", file=sys.stderr)
    return code
