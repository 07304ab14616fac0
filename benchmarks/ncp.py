"""Time the NCP pipeline stages (paper 4.2.2-4.2.4) at the paper's sizes.

Surfaces: a pseudosphere patch (AA, PK surface), a torus zone (CNC) and optionally a PHLW
B-spline written by ``gridshell phlw`` (``--surface surface.json``). Stages: net directions +
level-set fit + tracing (48 x 48 samples, 12 x 12 control points, bi-degree 3), collapse curve
at 1200 x 1200, post-optimization (3 rounds + polish), alignment simulation (12 frames),
writing the bundle with pictures and the GIF, and the whole ``design_ncp``. Prints wall times,
peak Python memory of the collapse stage, and the acceptance figures.

    python benchmarks/ncp.py [--curves 10] [--collapse 1200] [--surface surface.json --mode phlw]
"""
import argparse
import tempfile
import time
import tracemalloc

import numpy as np

from gridshell.geometry.bspline import BSplineSurface, fit_grid
from gridshell.measure.metrics import alignability_error, delta_l, delta_n
from gridshell.ncp.collapse import collapse_curve
from gridshell.geometry.bspline import uniform_params
from gridshell.ncp.directions import net_directions
from gridshell.ncp.levelset import trace
from gridshell.api import write
from gridshell.ncp.pipeline import design_ncp
from gridshell.ncp.postopt import post_optimize
from gridshell.ncp.alignment import collapse_direction, simulate_alignment


def pseudosphere():
    s, p = np.meshgrid(np.linspace(0.5, 1.5, 40), np.linspace(0, 1.5, 40), indexing="ij")
    P = np.stack([np.cos(p) / np.cosh(s), np.sin(p) / np.cosh(s), s - np.tanh(s)], -1)
    return fit_grid(P, 12, 12, 4, 4)[0]


def torus():
    th, ph = np.meshgrid(np.linspace(-0.6, 0.6, 40), np.linspace(0, 1.0, 40), indexing="ij")
    rho = 3.0 + np.cos(th)
    P = np.stack([rho * np.cos(ph), rho * np.sin(ph), np.sin(th)], -1)
    return fit_grid(P, 12, 12, 4, 4)[0]


def timed(fn, *a, **k):
    t0 = time.perf_counter()
    out = fn(*a, **k)
    return out, time.perf_counter() - t0


def stages(name, surf, mode, curves, m):
    print(f"{name} ({mode}), {curves} curves per family")
    u, v = uniform_params(surf, (48, 48))
    tn, t_tr = timed(lambda: trace(surf, net_directions(surf, u, v, mode=mode), curves=curves))
    net = tn.net
    tracemalloc.start()
    col, t_col = timed(collapse_curve, surf, mode=mode, samples=(m, m))
    peak = tracemalloc.get_traced_memory()[1] / 2 ** 20
    tracemalloc.stop()
    post, t_po = timed(post_optimize, surf, net, tn.joint_uv, col)
    E = net.edges()
    seq, t_sim = timed(simulate_alignment, post.V, post.r, E, collapse_direction(surf),
                       aligned=(post.Vt, post.rt), frames=12)
    da0 = 100 * alignability_error(post.V0, net.loops)
    da1 = 100 * alignability_error(post.V, net.loops)
    dl = 100 * delta_l(post.V, seq.aligned, E)
    dn = 100 * delta_n(post.V, post.r, seq.aligned, seq.aligned_r, E)
    print(f"  tracing (directions + 2 level fits + trace): {t_tr:6.2f} s  "
          f"({len(net.joints)} joints, {len(net.loops)} loops)")
    print(f"  collapse {m} x {m}:                      {t_col:6.2f} s  (peak {peak:.0f} MiB)")
    print(f"  post-optimization:                        {t_po:6.2f} s  "
          f"(Delta_a mean {da0.mean():.3f} % -> {da1.mean():.4f} %, max {da0.max():.3f} % -> "
          f"{da1.max():.4f} %)")
    print(f"  simulation (12 frames):                   {t_sim:6.2f} s  "
          f"(Delta_l max {np.nanmax(dl):.4f} %, Delta_n max {np.nanmax(dn):.4f} %)")
    (bundle, report), t_all = timed(design_ncp, surf, mode=mode, curves=curves,
                                    collapse_samples=(m, m))
    with tempfile.TemporaryDirectory() as tmp:
        _, t_w = timed(write, f"{tmp}/b", (bundle, report))
    print(f"  design_ncp total:                         {t_all:6.2f} s  "
          f"(stages {', '.join(f'{k} {v:.2f}' for k, v in bundle.metrics['timings'].items())})")
    print(f"  write with pictures + GIF:                {t_w:6.2f} s")
    mm = bundle.metrics
    extra = {k: mm[k] for k in ("aligned_radius_error", "aligned_line_error") if k in mm}
    print(f"  deviation max {mm['deviation']['max']:.4f} % diag, crossing kn max "
          f"{mm['crossing_kn']['max']:.3f} %, {extra}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--curves", type=int, default=10)
    ap.add_argument("--collapse", type=int, default=1200)
    ap.add_argument("--surface", help="a surface.json written by gridshell phlw")
    ap.add_argument("--mode", default="phlw", choices=("phlw", "cnc", "aa"))
    a = ap.parse_args()
    if a.surface:
        stages(a.surface, BSplineSurface.load(a.surface), a.mode, a.curves, a.collapse)
        return
    stages("pseudosphere", pseudosphere(), "aa", a.curves, a.collapse)
    stages("torus zone", torus(), "cnc", a.curves, a.collapse)


if __name__ == "__main__":
    main()
