"""Time the GG surface design stage (paper 4.1.1) alone, at the default settings.

Targets: a slightly elliptic dome z = -(x^2/2 + y^2/2.2) sampled as a structured R x C grid
(used directly as the initial grid) - no exact rotationally isometric mesh fits it, so every
round does real work. Prints time, convergence, residuals and deviation per size. The design
is judged as ``gridshell gg`` judges it: by its figures on the traced net (``gg_score``, the
largest figure / threshold; below 1 every gate passes), which also ends the polish.

    .venv/bin/python benchmarks/gg_design.py [R C ...]
"""
from __future__ import annotations

import sys
import time

import numpy as np

from gridshell.gg.design import design_gg_surface
from gridshell.gg.pipeline import gg_score
from gridshell.geometry.grid import grid_quads
from gridshell.solver.linear import default_backend


def dome_grid(R: int, C: int) -> np.ndarray:
    x, y = np.meshgrid(np.linspace(-1, 1, R), np.linspace(-0.8, 0.8, C), indexing="ij")
    return np.stack([x, y, -(x ** 2 / 2.0 + y ** 2 / 2.2)], axis=-1)


def bench(R: int, C: int) -> None:
    P0 = dome_grid(R, C)
    V, F = P0.reshape(-1, 3), grid_quads(R, C)
    t, c = time.perf_counter(), time.process_time()
    d = design_gg_surface(V, F, P0, evaluate=gg_score)
    dt, cpu = time.perf_counter() - t, time.process_time() - c
    rounds = ", ".join(f"{h['time']:.2f}" for h in d.history)
    print(f"{R} x {C}: {dt:.2f} s ({cpu:.2f} s CPU; linear solver {default_backend()}; cumulative per round: {rounds}); figures {'hold' if d.score < 1 else 'MISSED'} (score {d.score:.3g}, polish stopped: {d.stop}, {d.checkpoint}), geodesic {d.geodesic_residual_max:.1e}"
          f" rad, length spread {d.length_residual_rel_max:.1e}, deviation max "
          f"{d.deviation['max']:.2f} % mean {d.deviation['mean']:.2f} %")


if __name__ == "__main__":
    args = [int(a) for a in sys.argv[1:]] or [30, 30, 60, 60, 120, 120]
    for R, C in zip(args[::2], args[1::2]):
        bench(R, C)
