"""Utilisation of the demo's strips against their thickness, and the time of the check.

For each bundle (default the demo's ``out/demo/gg`` and ``out/demo/ncp``: run ``make demo``
first) and each thickness, :func:`gridshell.structure.check.check_bundle` with 20 mm wide
polypropylene strips at 1:10: the utilisation in the deployed state, the governing one over the
alignment sequence and the collapsed state, and the thickest strip that stays elastic in the
deployed state. Then the CPU and wall time of one check at 1 mm (the machine may be loaded:
compare CPU times).

    .venv/bin/python benchmarks/structure_check.py [BUNDLE ...] [--thickness 0.5 1 2 3]
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from gridshell.design.bundle import read_bundle  # noqa: E402
from gridshell.structure import Section, get_material  # noqa: E402
from gridshell.structure.check import check_bundle  # noqa: E402


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("bundles", nargs="*", default=[str(ROOT / "out/demo/gg"),
                                                   str(ROOT / "out/demo/ncp")])
    ap.add_argument("--thickness", nargs="+", type=float, default=[0.5, 1.0, 2.0, 3.0, 5.0])
    ap.add_argument("--width", type=float, default=20.0)
    ap.add_argument("--scale", type=float, default=0.1)
    ap.add_argument("--material", default="pp")
    a = ap.parse_args(argv)
    mat = get_material(a.material)
    print("| bundle | thickness [mm] | deployed | governing (state) | collapsed | "
          "thickest elastic [mm] | smallest radius [mm] |")
    print("|---|---|---|---|---|---|---|")
    for path in a.bundles:
        b = read_bundle(path)
        for t in a.thickness:
            r = check_bundle(b, mat, Section(a.width, t, a.scale), bundle_dir=path)
            print(f"| {Path(path).name} ({r['kind']}) | {t:g} | "
                  f"{r['max_utilisation_deployed']:.2f} | {r['max_utilisation']:.2f} "
                  f"({r['governing_state']}) | {r['states']['collapsed']['max_utilisation']:.2f}"
                  f" | {r['max_elastic_thickness_mm']:.2f} | {1e3 * r['min_radius_m']:.0f} |")
    for path in a.bundles:
        c, w = time.process_time(), time.perf_counter()
        check_bundle(path, mat, Section(a.width, 1.0, a.scale))
        print(f"{path}: check at 1 mm (read, deployed, states) {time.process_time() - c:.2f} s "
              f"CPU, {time.perf_counter() - w:.2f} s wall")
    return 0


if __name__ == "__main__":
    sys.exit(main())
