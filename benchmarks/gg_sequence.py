"""GG alignment sequence, side by side in one run: the physical path (gridshell.gg.path, one
closed-form evaluation per state) against the optimized joint sequence it replaces
(gridshell.gg.alignment), 12 steps, on the sample dome and a vase. Prints seconds.

    python benchmarks/gg_sequence.py
"""
from __future__ import annotations

import time

import numpy as np

from gridshell.gg.alignment import gg_alignment_sequence
from gridshell.gg.path import gg_path
from gridshell.gg.pipeline import collapse_gg, gg_net_from_mesh


def _vase(R=31, C=25):
    z, ph = np.linspace(0, 1.5, R), np.linspace(-1.0, 1.0, C)
    r = 1 + 0.2 * np.sin(2.5 * z + 0.5)
    return np.stack([r[:, None] * np.cos(ph)[None, :], r[:, None] * np.sin(ph)[None, :],
                     np.broadcast_to(z[:, None], (R, C))], -1)


def _dome():
    from gridshell.api import design_gg
    b = design_gg("samples/dome.obj", frames=0).bundle
    R, C = b.params["grid"]
    return b.surface_V.reshape(R, C, 3)


def main() -> None:
    print(f"{'case':8s} {'joints':>7s} {'path [s]':>9s} {'optimized [s]':>14s}")
    for name, P in (("vase", _vase()), ("dome", _dome())):
        g = gg_net_from_mesh(P)
        net = g["net"]
        aligned, _ = collapse_gg(net)
        t0 = time.perf_counter()
        path = gg_path(g["inet"], g["rev"], net, aligned, P, frames=12)
        t1 = time.perf_counter()
        gg_alignment_sequence(net.joints, aligned, net.edges(), frames=12)
        t2 = time.perf_counter()
        print(f"{name:8s} {len(net.joints):7d} {t1 - t0:9.2f} {t2 - t1:14.2f}"
              + ("" if path is not None else "  (no closed-form path)"))


if __name__ == "__main__":
    main()
