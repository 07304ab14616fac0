"""Strip thickness sweep: how far the built gridshell settles from its design, and how hard
its strips work, as the strip's edge ratio (width / thickness) falls.

For each design bundle (default: the demo's GG dome and CNC pavilion, ``make demo``) at 1:10
in 20 mm wide polypropylene, boundary joints held, with and without self-weight, for thicknesses 0.5 to
3 mm (edge ratio 40:1 to 6.7:1), :func:`gridshell.structure.equilibrium.simulate` gives the
equilibrium's largest and mean joint deviation (% of the bounding-box diagonal) and the peak
utilisation of the strips (equivalent stress / allowable) in the design shape and at
equilibrium. Prints a table, writes a JSON of every figure and a plot (deviation and
utilisation against the edge ratio, the paper's 10:1 remark marked).

    .venv/bin/python benchmarks/structure_sweep.py [GG_DIR NCP_DIR] [--png PNG] [--json OUT]
    .venv/bin/python benchmarks/structure_sweep.py --from-json gg.json ncp.json   # plot only

Times are wall and CPU seconds (the machine may be shared: CPU is the steadier figure).
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
THICKNESSES = (0.5, 0.75, 1.0, 1.5, 2.0, 2.5, 3.0)


def sweep(bundle_dir: Path, thicknesses=THICKNESSES, width: float = 20.0, scale: float = 0.1,
          material: str = "pp", every: int = 1, loads=(True, False)) -> list[dict]:
    """Rows of figures per thickness and load case; supports: every ``every``-th boundary
    joint (1: all of them)."""
    from gridshell.design.bundle import read_bundle
    from gridshell.structure import Section, get_material
    from gridshell.structure.deployed import boundary_joints
    from gridshell.structure.equilibrium import simulate

    b = read_bundle(bundle_dir)
    supports = boundary_joints(b.net)[::every] if every > 1 else "boundary"
    mat = get_material(material)
    rows = []
    for t in thicknesses:
        for gravity in loads:
            eq = simulate(b, mat, Section(width, t, scale), gravity=gravity, require=False,
                          supports=supports)
            f = eq.figures
            r = {"kind": b.kind, "gravity": gravity, "supports_every": every, "thickness_mm": t, "edge_ratio": width / t,
                 "deviation_max_pct": f["deviation_max_pct"],
                 "deviation_mean_pct": f["deviation_mean_pct"],
                 "utilisation_design": f["utilisation_design"],
                 "utilisation_peak": f["utilisation_peak"],
                 "energy_J": f["energy_J"], "reaction_max_N": f["reaction_max_N"],
                 "weight_N": f["weight_N"], "converged": f["converged"],
                 "newton": f["newton"], "wall_s": f["wall_s"], "cpu_s": f["cpu_s"]}
            rows.append(r)
            print(f"{b.kind:4s} supports 1/{every} t={t:4.2f} mm ratio {r['edge_ratio']:5.1f}:1 "
                  f"{'self-weight' if gravity else 'no load   '}  deviation max "
                  f"{r['deviation_max_pct']:8.4f} % mean {r['deviation_mean_pct']:8.4f} %  "
                  f"utilisation design {r['utilisation_design']:6.3f} equilibrium "
                  f"{r['utilisation_peak']:6.3f}  reaction max {r['reaction_max_N']:8.3g} N  "
                  f"{r['newton']}  {r['wall_s']:5.1f} s wall {r['cpu_s']:5.1f} s CPU",
                  flush=True)
    return rows


def plot(rows: list[dict], path: Path) -> None:
    from matplotlib.figure import Figure

    fig = Figure(figsize=(10, 4.2), dpi=110)
    ax1, ax2 = fig.add_subplot(1, 2, 1), fig.add_subplot(1, 2, 2)
    for kind, colour in (("GG", (0.13, 0.42, 0.70)), ("CNC", (0.86, 0.35, 0.12)),
                         ("NCP", (0.86, 0.35, 0.12)), ("AA", (0.4, 0.6, 0.2))):
        cases = sorted({(r.get("supports_every", 1), r.get("gravity", True)) for r in rows
                        if r["kind"] == kind})
        for every, gravity in cases:
            rs = [r for r in rows if r["kind"] == kind and r.get("gravity", True) == gravity
                  and r.get("supports_every", 1) == every]
            style = ("o-" if gravity else "s--") if every == 1 else ("^-." if gravity else "v:")
            x = [r["edge_ratio"] for r in rs]
            what = ("self-weight" if gravity else "no load") + \
                ("" if every == 1 else f", 1/{every} of the boundary held")
            ax1.plot(x, [r["deviation_max_pct"] for r in rs], style, color=colour, ms=4,
                     label=f"{kind}, {what}")
            if gravity and every == 1:
                ax2.plot(x, [r["utilisation_peak"] for r in rs], "o-", color=colour, ms=4,
                         label=f"{kind} at equilibrium (self-weight)")
                ax2.plot(x, [r["utilisation_design"] for r in rs], "s:", color=colour, ms=3,
                         label=f"{kind} in the design shape")
    for ax in (ax1, ax2):
        ax.axvline(10.0, color="0.5", lw=0.8, ls=":")
        ax.set_xscale("log")
        ax.set_xlabel("edge ratio width / thickness (20 mm wide)")
        ax.invert_xaxis()
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    ax1.set_yscale("log")
    ax1.set_ylabel("largest joint deviation from the design, % of diagonal")
    ax1.set_title("how far the built shell settles from the design", fontsize=9)
    ax2.axhline(1.0, color="r", lw=0.8)
    ax2.set_ylabel("peak utilisation (equivalent stress / allowable)")
    ax2.set_title("how hard the strips work (1 = elastic limit)", fontsize=9)
    fig.suptitle("Demo gridshells at 1:10 in polypropylene, thickness 0.5 to 3 mm "
                 "(dotted: the paper's 10:1)", fontsize=10)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("bundles", nargs="*", type=Path,
                   default=[ROOT / "out/demo/gg", ROOT / "out/demo/ncp"])
    p.add_argument("--png", type=Path, default=ROOT / "docs/images/structure_sweep.png")
    p.add_argument("--json", type=Path, default=None, help="write every figure here")
    p.add_argument("--every", type=int, default=1,
                   help="hold every N-th boundary joint only (default 1: all)")
    p.add_argument("--thickness", type=float, nargs="+", default=list(THICKNESSES), metavar="MM")
    p.add_argument("--loaded-only", action="store_true", help="self-weight case only")
    p.add_argument("--from-json", type=Path, nargs="+", default=None,
                   help="plot the rows of earlier --json runs instead of simulating")
    args = p.parse_args(argv)
    rows = []
    if args.from_json:
        for f in args.from_json:
            rows += json.loads(f.read_text())
    else:
        for d in args.bundles:
            if not (d / "design.json").is_file():
                print(f"{d}: not a design bundle; run 'make demo' first", file=sys.stderr)
                return 2
            rows += sweep(d, args.thickness, every=args.every,
                          loads=(True,) if args.loaded_only else (True, False))
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1))
    plot(rows, args.png)
    print(f"plot: {args.png}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
