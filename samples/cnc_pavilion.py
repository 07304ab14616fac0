# Shows a CNC gridshell (constant normal curvature, lamellae standing on the surface) for a
# pavilion vault, through the Python API: design_ncp in mode "cnc" from a reference mesh
# (samples/torus_patch.obj: the PHLW step fits and optimizes a B-spline first) -> the net, the
# collapse curve (a circle of radius 1/n), post-optimization and the alignment simulation ->
# write (bundle with sequence/frame_*.obj, alignment.gif, colour maps) -> verify.
# Every lamella collapses onto one circle: all strips are arcs of that circle, cut flat.
#
#     .venv/bin/python samples/cnc_pavilion.py [OUT] [--quick]   # default out/samples/cnc_pavilion
import sys
from pathlib import Path

import gridshell as gs

HERE = Path(__file__).resolve().parent


def main(argv: list[str]) -> int:
    quick = "--quick" in argv
    args = [a for a in argv if a != "--quick"]
    out = Path(args[0]) if args else Path("out/samples/cnc_pavilion")
    # the reference is already a CNC surface (a torus zone): a light PHLW step suffices
    phlw = {"samples": (12, 12), "outer": 2, "max_iter": 10 if quick else 20}
    design = gs.design_ncp(HERE / "torus_patch.obj", mode="cnc", curves=12,
                           phlw_options=phlw, frames=6 if quick else 12,
                           collapse_samples=(600, 600) if quick else (1200, 1200))
    gs.write(out, design)                       # bundle + sequence/, alignment.gif, maps
    v = gs.verify(out)
    bundle = design.bundle

    m = bundle.metrics
    print(f"CNC pavilion: {out}")
    print(f"  lamellae: {m['n_lamellae']['C1']} + {m['n_lamellae']['C3']}, "
          f"joints: {m['n_joints']}, net-loops: {m['n_loops']}")
    print(f"  normal curvature n = {m['n']:.4g} 1/m: collapses into a circle of radius "
          f"{m['collapse_radius']:.4g} m (aligned joints off it by "
          f"{m['aligned_radius_error']:.2g} %)")
    for tag, key in (("traced", "delta_a_before"), ("post-optimized", "delta_a_after")):
        print(f"  Delta_a {tag}: mean {m[key]['mean']:.3g} %, max {m[key]['max']:.3g} %")
    print(f"  Delta_a (verified): mean {v['alignability']['mean']:.3g} %, "
          f"max {v['alignability']['max']:.3g} %")
    print(f"  Delta_l max {v['delta_l']['max']:.3g} %, Delta_n max {v['delta_n']['max']:.3g} %")
    print(f"  PHLW surface off the reference: max {bundle.params['phlw_deviation']:.3g} % of its "
          "diagonal")
    print(f"  alignment: {out / 'alignment.gif'} ({len(list((out / 'sequence').glob('*.obj')))} "
          "frames)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
