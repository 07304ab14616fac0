"""Time the GG pipeline (paper 4.1) on 30 x 30 and 100 x 100 meshes and print the figures.

Targets: helicoid grids (isometric to a catenoid, so the discrete GG model is met up to the
grid's own discretization). For each size it times the post-design stages on the grid itself
(rebuild, trace, map back, collapse, metrics) and then the whole pipeline `design_gg`
(initial grid + surface optimization + the same stages).

    .venv/bin/python benchmarks/gg_pipeline.py [--sizes 30 100]
"""
from __future__ import annotations

import argparse
import resource
import time

import numpy as np

from gridshell.gg.pipeline import collapse_gg, design_gg, gg_metrics, gg_net_from_mesh
from gridshell.geometry.grid import grid_quads


def helicoid(n: int, c: float = 0.5) -> np.ndarray:
    u, v = np.meshgrid(np.linspace(-1.0, 1.0, n), np.linspace(0.0, 2.0, n), indexing="ij")
    return np.stack([u * np.cos(v), u * np.sin(v), c * v], axis=-1)


def stages(P: np.ndarray, n_lamellae: int) -> None:
    R, C = P.shape[:2]
    V, F = P.reshape(-1, 3), grid_quads(R, C)
    t0 = time.perf_counter()
    st = gg_net_from_mesh(P, n_lamellae=n_lamellae, crossing_angle=80.0)
    t1 = time.perf_counter()
    _, info = collapse_gg(st["net"])
    t2 = time.perf_counter()
    m = gg_metrics(st["net"], V, F, net_rev=st["net_rev"], target=(V, F))
    t3 = time.perf_counter()
    print(f"  net stages on the {R} x {C} grid: rebuild+trace+map {t1 - t0:.2f} s, "
          f"collapse {t2 - t1:.3f} s, metrics {t3 - t2:.2f} s")
    print(f"    {m['n_joints']} joints, {m['n_loops']} loops; Delta_a mean/max "
          f"{m['alignability']['mean']:.2e} / {m['alignability']['max']:.2e} %, arc "
          f"{m['alignability_arc']['mean']:.2e} / {m['alignability_arc']['max']:.2e} %, "
          f"turning {m['geodesic_turning']:.3f} %, collapse mismatch {info['mismatch_max']:.1e} m")


def full(P: np.ndarray, n_lamellae: int) -> None:
    R, C = P.shape[:2]
    V, F = P.reshape(-1, 3), grid_quads(R, C)
    marks: list[tuple[float, str]] = []
    t0 = time.perf_counter()
    bundle, _ = design_gg((V, F), grid=(R, C), n_lamellae=n_lamellae, crossing_angle=80.0,
                          progress=lambda msg: marks.append((time.perf_counter() - t0, msg)))
    total = time.perf_counter() - t0
    m = bundle.metrics
    print(f"  design_gg {R} x {C}: {total:.2f} s total")
    for t, msg in marks:
        print(f"    [{t:7.2f} s] {msg}")
    print(f"    Delta_a mean/max {m['alignability']['mean']:.3f} / {m['alignability']['max']:.3f} %,"
          f" turning {m['geodesic_turning']:.3f} %, deviation mean/max "
          f"{m['deviation']['mean']:.3f} / {m['deviation']['max']:.3f} % of the diagonal")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[30, 100])
    ap.add_argument("--lamellae", type=int, default=12)
    args = ap.parse_args()
    for n in args.sizes:
        print(f"{n} x {n}")
        P = helicoid(n)
        stages(P, args.lamellae)
        full(P, args.lamellae)
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"peak memory {rss:.0f} MB")


if __name__ == "__main__":
    main()
