# Shows a geodesic (GG) alignable gridshell on a freeform dome, through the Python API:
# design_gg (the nearest surface isometric to a surface of revolution, and the geodesic net on
# it) -> write (the design bundle) -> verify (the metrics recomputed from the files)
# -> fabricate (DXF/SVG cut files) -> export_3dm (Rhino: strips, holes, surface, cut sheets). The dome (samples/dome.obj) admits no exact geodesic
# alignable net; the designed surface deviates from it by a few % of its diagonal.
#
#     .venv/bin/python samples/gg_dome.py [OUT]        # default out/samples/gg_dome
import sys
from pathlib import Path

import gridshell as gs

HERE = Path(__file__).resolve().parent


def main(argv: list[str]) -> int:
    out = Path(argv[0]) if argv else Path("out/samples/gg_dome")
    design = gs.design_gg(HERE / "dome.obj", grid=(16, 16), n_lamellae=8)
    gs.write(out, design)                       # the design bundle (replaced atomically)
    v = gs.verify(out)                          # recomputed from net.obj, axes.obj, ...
    fab = gs.fabricate(out, out / "fabrication",
                       {"width": 20, "thickness": 1, "hole": 3, "sheet": "600x400",
                        "scale": "1:10"})
    rhino = gs.export_3dm(out, out / "gg.3dm")  # with the cut sheets just written
    bundle, report = design

    m = bundle.metrics
    print(f"GG gridshell on the dome: {out}")
    print(f"  lamellae: {m['n_lamellae']['C1']} + {m['n_lamellae']['C3']}, "
          f"joints: {v['n_joints']}, net-loops: {v['n_loops']}")
    print(f"  Delta_a (verified): mean {v['alignability']['mean']:.4g} %, "
          f"max {v['alignability']['max']:.4g} %")
    print(f"  Delta_a arc length (verified): mean {v['alignability_arc']['mean']:.4g} %, "
          f"max {v['alignability_arc']['max']:.4g} %")
    print(f"  geodesic turning of the axes: {v['geodesic_turning']:.3g} %")
    print(f"  deviation from the dome: mean {v['deviation']['mean']:.3g} %, "
          f"max {v['deviation']['max']:.3g} % of its diagonal")
    print(f"  surface of revolution: {report['revolution']['method']}")
    print(f"  cut files: {fab['n_pieces']} strips on {fab['n_sheets']} sheet(s) in "
          f"{out / 'fabrication'}")
    print(f"  Rhino model: {rhino['path']} ({rhino['strips']} strips "
          f"{1000 * rhino['strip_width_m']:.0f} x {1000 * rhino['strip_thickness_m']:.0f} mm, "
          f"{len(rhino['sheets'])} sheet layer(s), unit {rhino['units']})")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
