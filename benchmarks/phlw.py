"""Time the PHLW surface optimization (paper 4.2.1) at the paper's sizes and denser.

Saddle z = 0.3 (x^2 - y^2) over [-1, 1]^2 (a 30 x 30 quad grid), bi-degree 4, 9 x 9 control
points; samples 18 x 18 (paper) and 36 x 36 (4x the samples). Prints wall time per round and
per solver iteration, peak memory, and the acceptance figures.

    python benchmarks/phlw.py [--samples 18 36] [--outer 4] [--max-iter 40] [--mode phlw]
"""
import argparse
import time
import tracemalloc

import numpy as np

from gridshell.geometry.grid import grid_quads
from gridshell.ncp import phlw as P
from gridshell.ncp.reference import initial_surface


def saddle(n=30):
    x, y = np.meshgrid(np.linspace(-1, 1, n), np.linspace(-1, 1, n), indexing="ij")
    return np.stack([x, y, 0.3 * (x ** 2 - y ** 2)], -1).reshape(-1, 3), grid_quads(n, n)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", nargs="+", type=int, default=[18, 36])
    ap.add_argument("--outer", type=int, default=4)  # optimize_phlw's default
    ap.add_argument("--max-iter", type=int, default=40)
    ap.add_argument("--mode", default="phlw", choices=P.MODES)
    a = ap.parse_args()
    V, F = saddle()
    surf = initial_surface(V, F, n_ctrl=(9, 9), degree=(4, 4)).surface
    dense = np.linspace(0, 1, 60)
    for m in a.samples:
        tracemalloc.start()
        t0 = time.perf_counter()
        res = P.optimize_phlw(surf, (V, F), mode=a.mode, samples=(m, m), outer=a.outer,
                              max_iter=a.max_iter)
        dt = time.perf_counter() - t0
        peak = tracemalloc.get_traced_memory()[1] / 2 ** 20
        tracemalloc.stop()
        its = sum(h["iterations"] for h in res.history)
        b, f = res.report_before, res.report_after
        print(f"{a.mode} samples {m}x{m}: {dt:.1f} s, {its} iterations ({dt / max(its, 1):.3f} s/it), "
              f"peak {peak:.0f} MiB (Python allocations)")
        print(f"  E_PHLW {b['E_PHLW']['total']:.3g} -> {f['E_PHLW']['total']:.3g} "
              f"({b['E_PHLW']['total'] / f['E_PHLW']['total']:.3g}x), relation max rel "
              f"{f['relation_max_rel']:.2g} (60x60 refit "
              f"{np.max(P.row_relation_residual(res.surface, dense, dense)):.2g}), angle max "
              f"{f['angle_max_deg']:.3g} deg (60x60 "
              f"{np.max(P.principal_angle_error(res.surface, dense, dense)):.3g}), deviation "
              f"{res.deviation:.3f} % diag")


if __name__ == "__main__":
    main()
