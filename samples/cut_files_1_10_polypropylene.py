# Shows the cut files of a 1:10 model in 1 mm polypropylene (as the paper's prototypes, Fig. 21:
# 20 mm wide lamellae cut from 1 mm polypropylene sheet), through the Python API: a GG
# gridshell on the helicoid (samples/helicoid.obj, an exact GG target: isometric to a catenoid)
# is designed and written, then `fabricate` unrolls every lamella into a flat strip, marks the
# joints at their arc lengths, nests the strips on 600 x 400 mm sheets and writes one DXF and one
# SVG per sheet (millimetres), a cut list and an assembly plan. The sheet count and every strip's
# length are printed. With --bundle DIR it cuts an existing design bundle instead (for example
# out/samples/cnc_pavilion: arcs of one circle).
#
#     .venv/bin/python samples/cut_files_1_10_polypropylene.py [OUT] [--bundle DIR]
#                                       # default out/samples/cut_files_1_10_polypropylene
import sys
from pathlib import Path

import gridshell as gs
from gridshell.fabrication import FabParams

HERE = Path(__file__).resolve().parent

#: 1 mm polypropylene at 1:10 (lengths in mm of the model)
POLYPROPYLENE_1_10 = FabParams(
    width=20.0,         # strip width: 20 mm, as the paper's prototypes
    thickness=1.0,      # 1 mm polypropylene sheet
    hole=3.0,           # 3 mm holes at the joints, for M3 bolts or 3 mm rivets
    margin=12.0,        # strip beyond the end joints
    scale="1:10",       # design metres -> model millimetres: mm = m * 1000 / 10
    sheet="600x400",    # sheet (and laser bed) size, mm
    gap=4.0,            # between parts and to the sheet edges
    kerf=0.0,           # set your cutter's kerf (e.g. 0.15) to compensate it
)


def main(argv: list[str]) -> int:
    bundle_dir = None
    if "--bundle" in argv:
        k = argv.index("--bundle")
        bundle_dir = Path(argv[k + 1])
        argv = argv[:k] + argv[k + 2:]
    out = Path(argv[0]) if argv else Path("out/samples/cut_files_1_10_polypropylene")
    if bundle_dir is None:
        design = gs.design_gg(HERE / "helicoid.obj", n_lamellae=8, crossing_angle=70.0,
                                  at_parallel=0.3)
        bundle_dir = out / "design"
        gs.write(bundle_dir, design, render=False)
    v = gs.verify(bundle_dir)
    rep = gs.fabricate(bundle_dir, out / "fabrication", POLYPROPYLENE_1_10)

    p = POLYPROPYLENE_1_10
    print(f"cut files, 1:10 model in {p.thickness:g} mm polypropylene: {out / 'fabrication'}")
    print(f"  design: {rep['kind']} gridshell {bundle_dir}, Delta_a (verified): mean "
          f"{v['alignability']['mean']:.3g} %, max {v['alignability']['max']:.3g} %")
    print(f"  strips: {rep['n_strips']} ({rep['shape']}, {p.width:g} mm wide, "
          f"{p.hole:g} mm holes), pieces: {rep['n_pieces']}, joint holes: {rep['n_joint_marks']}")
    print(f"  sheets: {rep['n_sheets']} x {p.sheet[0]:g} x {p.sheet[1]:g} mm, utilisation "
          f"{100 * rep['utilisation']:.0f} %")
    lengths = sorted((d["flat_length_mm"], d["lamella"], d["piece"], d["n_pieces"])
                     for d in rep["pieces"])
    print(f"  strip lengths: {lengths[0][0]:.0f} to {lengths[-1][0]:.0f} mm, total "
          f"{sum(x[0] for x in lengths) / 1000:.2f} m")
    for length, lam, piece, n in sorted(lengths, key=lambda x: (x[1], x[2])):
        name = f"L{lam}" + (f"-{piece}/{n}" if n > 1 else "")
        print(f"    {name:<8} {length:7.1f} mm")
    print(f"  files: {', '.join(rep['files'])}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
