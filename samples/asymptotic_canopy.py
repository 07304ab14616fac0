# Shows an asymptotic (AA) gridshell for a canopy, through the Python API: design_ncp in mode
# "aa" from a reference mesh (samples/pseudosphere.obj, a patch of constant negative Gaussian
# curvature: the PHLW step keeps it a PK surface) -> the asymptotic net (normal curvature 0),
# which collapses into a straight line -> post-optimization, alignment simulation -> write
# -> verify. Asymptotic lamellae stand orthogonal to the surface and are cut straight.
#
#     .venv/bin/python samples/asymptotic_canopy.py [OUT] [--quick]
#                                                   # default out/samples/asymptotic_canopy
import sys
from pathlib import Path

import gridshell as gs

HERE = Path(__file__).resolve().parent


def main(argv: list[str]) -> int:
    quick = "--quick" in argv
    args = [a for a in argv if a != "--quick"]
    out = Path(args[0]) if args else Path("out/samples/asymptotic_canopy")
    phlw = {"samples": (12, 12), "outer": 2, "max_iter": 10 if quick else 15}
    design = gs.design_ncp(HERE / "pseudosphere.obj", mode="aa", curves=10,
                           phlw_options=phlw, frames=6 if quick else 12,
                           collapse_samples=(600, 600) if quick else (1200, 1200))
    gs.write(out, design)
    v = gs.verify(out)
    bundle = design.bundle

    m = bundle.metrics
    print(f"AA canopy: {out}")
    print(f"  lamellae: {m['n_lamellae']['C1']} + {m['n_lamellae']['C3']}, "
          f"joints: {m['n_joints']}, net-loops: {m['n_loops']}")
    print(f"  collapses into a line {m['collapse_length']:.4g} m long (aligned joints off it "
          f"by {m['aligned_line_error']:.2g} % of the span)")
    for tag, key in (("traced", "delta_a_before"), ("post-optimized", "delta_a_after")):
        print(f"  Delta_a {tag}: mean {m[key]['mean']:.3g} %, max {m[key]['max']:.3g} %")
    print(f"  Delta_a (verified): mean {v['alignability']['mean']:.3g} %, "
          f"max {v['alignability']['max']:.3g} %")
    print(f"  Delta_l max {v['delta_l']['max']:.3g} %, Delta_n max {v['delta_n']['max']:.3g} %")
    print(f"  PK surface off the reference: max {bundle.params['phlw_deviation']:.3g} % of its "
          "diagonal")
    print(f"  alignment: {out / 'alignment.gif'} ({len(list((out / 'sequence').glob('*.obj')))} "
          "frames)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
