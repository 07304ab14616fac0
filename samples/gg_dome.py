# Shows a geodesic (GG) alignable gridshell on a freeform dome, through the Python API:
# design_gg (the nearest surface isometric to a surface of revolution, and the geodesic net on
# it) -> write_gg (the design bundle) -> verify_bundle (the metrics recomputed from the files)
# -> fabricate (DXF/SVG cut files). The dome (samples/dome.obj) admits no exact geodesic
# alignable net; the designed surface deviates from it by a few % of its diagonal.
#
#     .venv/bin/python samples/gg_dome.py [OUT]        # default out/samples/gg_dome
import sys
from pathlib import Path

from fabrication import fabricate
from gridshell.verification import verify_bundle
from gridshell.gg.pipeline import design_gg, write_gg

HERE = Path(__file__).resolve().parent


def main(argv: list[str]) -> int:
    out = Path(argv[0]) if argv else Path("out/samples/gg_dome")
    bundle, report = design_gg(HERE / "dome.obj", grid=(16, 16), n_lamellae=8)
    write_gg(out, bundle)                       # the design bundle (replaced atomically)
    v = verify_bundle(out)                      # recomputed from net.obj, axes.obj, ...
    fab = fabricate(out, out / "fabrication",
                    {"width": 20, "thickness": 1, "hole": 3, "sheet": "600x400",
                     "scale": "1:10"})

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
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
