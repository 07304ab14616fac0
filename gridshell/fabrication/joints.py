"""Joint features of a strip (issue item 2), in strip coordinates ``(s, t)`` and in the plane.

* ``hole``: a circle of the given diameter on the centre line at each joint's ``s``;
* ``slots``: cross-halving notches, half the width deep, ``thickness + clearance`` wide,
  family 1 from the ``t_hi`` edge and family 3 from the ``t_lo`` edge, so that two crossing
  lamellae slide into each other; the notches are part of the outline;
* ``marks``: score lines across the strip at each joint.

The outline is a polygon in ``(s, t)`` whose edges alternate between constant ``t`` (along
the axis: lines, arcs or offset curves in the plane) and constant ``s`` (straight, normal
to the axis); :func:`outline_corners` returns its corners counter-clockwise.
"""
from __future__ import annotations

import numpy as np

from gridshell.fabrication.params import FabParams
from gridshell.fabrication.strip import Strip


def slot_edge(family: int) -> str:
    """``"hi"`` for family 1 (notched from the ``t_hi`` edge), ``"lo"`` for family 3."""
    return "hi" if family == 1 else "lo"


def outline_corners(strip: Strip, params: FabParams) -> np.ndarray:
    """Corners ``(n,2)`` of the strip outline in ``(s, t)``, counter-clockwise, starting at
    ``(s0, t_lo)``; consecutive corners share ``t`` (along the axis) or ``s`` (across)."""
    s0, s1, lo, hi = strip.s0, strip.s1, strip.t_lo, strip.t_hi
    notches = strip.joint_s if params.joints == "slots" else np.zeros(0)
    half = params.slot_width / 2
    depth = strip.width / 2
    edge = slot_edge(strip.family)
    C = [(s0, lo)]
    if edge == "lo":
        for s in notches:
            a, b = s - half, s + half
            C += [(a, lo), (a, lo + depth), (b, lo + depth), (b, lo)]
    C += [(s1, lo), (s1, hi)]
    if edge == "hi":
        for s in notches[::-1]:
            a, b = s - half, s + half
            C += [(b, hi), (b, hi - depth), (a, hi - depth), (a, hi)]
    C += [(s0, hi)]
    return np.array(C, float)


def hole_centres(strip: Strip, at: np.ndarray | None = None) -> np.ndarray:
    """Hole centres ``(k,2)`` in the plane: the centre line at each joint (or at ``at``)."""
    s = strip.joint_s if at is None else np.asarray(at, float)
    return strip.axis.point(s, np.full(len(s), strip.t_mid))


def joint_points(strip: Strip) -> np.ndarray:
    """The joints on the axis ``(k,2)`` (``t = 0``), in the plane."""
    return strip.axis.point(strip.joint_s, np.zeros(len(strip.joint_s)))


def score_marks(strip: Strip, at: np.ndarray | None = None) -> np.ndarray:
    """Score lines ``(k,2,2)`` across the strip at each joint (or at ``at``)."""
    s = strip.joint_s if at is None else np.asarray(at, float)
    return np.stack([strip.axis.point(s, np.full(len(s), strip.t_lo)),
                     strip.axis.point(s, np.full(len(s), strip.t_hi))], axis=1)


def feature_halfwidth(params: FabParams) -> float:
    """Half the extent along the axis that a joint feature occupies (labels keep clear)."""
    return {"hole": params.hole / 2, "slots": params.slot_width / 2, "marks": 0.25}[params.joints]
