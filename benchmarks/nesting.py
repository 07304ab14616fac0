"""Sheets, material used and nesting time: the drop nesting alone next to drop + raster passes.

For each bundle (default the demo's ``out/demo/gg`` and ``out/demo/ncp``: run ``make demo``
first) with the demo's cut-file parameters, and each gap (mm) and rotation rule, the parts are
nested twice in one run: with :data:`gridshell.fabrication.nesting.RASTER` emptied (the drop strategies
and rows only) and as shipped. Prints the sheet count, the floor (:func:`gap_bound`), the
15 % area bound (:func:`sheet_bound`), the material used per sheet and the CPU and wall
seconds of :func:`gridshell.fabrication.nesting.nest` (the machine may be loaded: compare CPU times).

    .venv/bin/python benchmarks/nesting.py [BUNDLE ...] [--gap 5 3 2] [--rotation free grain]
"""
from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from gridshell.fabrication import FabParams, nesting  # noqa: E402
from gridshell.fabrication.pipeline import plan_parts  # noqa: E402
from gridshell.design.bundle import read_bundle  # noqa: E402
from gridshell.cli.demo import FABRICATION  # noqa: E402


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("bundles", nargs="*", default=[str(ROOT / "out/demo/gg"),
                                                   str(ROOT / "out/demo/ncp")])
    ap.add_argument("--gap", type=float, nargs="+", default=[5.0, 3.0, 2.0])
    ap.add_argument("--rotation", nargs="+", default=["free", "grain"])
    a = ap.parse_args(argv)
    shipped = list(nesting.RASTER)
    print(f"{'bundle':<16}{'gap':>5} {'rotation':<9}{'nesting':<9}{'sheets':>7}{'floor':>6}"
          f"{'bound':>6}  {'CPU s':>6}{'wall s':>7}  used per sheet [%]")
    for b in a.bundles:
        bundle = read_bundle(b)
        for gap in a.gap:
            params = FabParams(**FABRICATION, gap=gap)
            parts, _, _ = plan_parts(bundle, params)
            floor = nesting.gap_bound(parts, params.sheet, gap)
            bound = nesting.sheet_bound(parts, params.sheet)
            for rot in a.rotation:
                p = dataclasses.replace(params, rotation=rot)
                for name, passes in (("drop", []), ("+raster", shipped)):
                    nesting.RASTER[:] = passes
                    c0, w0 = time.process_time(), time.perf_counter()
                    lay = nesting.nest(parts, p)
                    c, w = time.process_time() - c0, time.perf_counter() - w0
                    used = ", ".join(f"{100 * lay.used(k):.1f}" for k in range(lay.n_sheets))
                    print(f"{Path(b).name:<16}{gap:>5g} {rot:<9}{name:<9}{lay.n_sheets:>7}"
                          f"{floor:>6}{bound:>6}  {c:>6.2f}{w:>7.2f}  {used}", flush=True)
    nesting.RASTER[:] = shipped
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
