"""Analytic kerf compensation: cut paths move by half the kerf so parts come out to size.

Outlines move outwards by ``d = kerf / 2`` (the part grows), holes inwards (radius ``- d``).
The outline is offset in strip coordinates (see :func:`gridshell.fabrication.joints.outline_corners`):
an edge along the axis moves from ``t`` to ``t -+ d``, which is its exact offset (a concentric
arc, an offset line or offset curve); an edge across the axis (the normal line at ``s``) moves
to the parallel line at distance ``d``, whose corners :meth:`axis.shift` finds on the offset
curves (exact for lines and arcs).
"""
from __future__ import annotations

import numpy as np


def offset_corners(axis, C: np.ndarray, d: float) -> np.ndarray:
    """Corners of the rectilinear ``(s, t)`` polygon ``C (n,2)`` (counter-clockwise, edges
    alternating along/across the axis, corner 0 starting an along-edge) offset outwards by
    ``d`` mm in the plane. Returns ``(n,2)`` ``(s, t)``; the across-edges stay straight."""
    if d == 0:
        return C.copy()
    n = len(C)
    out = np.empty_like(C)
    for i in range(n):
        prev, nxt = C[i - 1], C[(i + 1) % n]
        if i % 2 == 0:      # outgoing edge along the axis, incoming across
            along, across = nxt - C[i], C[i] - prev
        else:               # incoming edge along the axis, outgoing across
            along, across = C[i] - prev, nxt - C[i]
        # outward normal of a CCW edge (ds, dt) is (dt, -ds)
        t_new = C[i, 1] - d * np.sign(along[0])
        s_dir = np.sign(across[1])
        out[i, 1] = t_new
        out[i, 0] = axis.shift(C[i, 0], d * s_dir, t_new)
    return out


def hole_radius(diameter: float, kerf: float) -> float:
    """Radius of the cut path of a hole of nominal ``diameter``."""
    return diameter / 2 - kerf / 2
