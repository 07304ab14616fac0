"""Splitting lamellae longer than the sheet into spliced pieces (issue item 4).

A lamella that does not fit the sheet is cut at a joint ``k`` (the splice joint) into two
overlapping pieces: the next piece starts one end margin before joint ``k`` (like any strip
before its first joint) and the previous piece ends ``overlap`` mm after that start. Default
overlap: the spacing from joint ``k`` to joint ``k+1`` plus two end margins, so that the two
pieces share two joints - their joint holes line up and two fasteners make a lap splice that
carries bending (one shared joint would act as a hinge). Pieces are made as long as the
sheet allows.
"""
from __future__ import annotations

import numpy as np

from gridshell.errors import InputError

from .params import FabParams
from .strip import Strip


def chord_frame(strip: Strip) -> tuple[np.ndarray, np.ndarray]:
    """Origin ``(2,)`` and unit direction ``(2,)`` of the chord of the centre line."""
    a, b = strip.axis.point([strip.s0, strip.s1], [strip.t_mid, strip.t_mid])
    u = b - a
    return a, u / np.linalg.norm(u)


def extent(strip: Strip, kerf: float = 0.0) -> tuple[float, float]:
    """Size ``(along, across)`` of the strip's bounding box aligned with its chord, mm."""
    if strip.axis.kind == "line":
        return strip.length + kerf, strip.width + kerf
    s = np.linspace(strip.s0, strip.s1, 257)
    P = np.concatenate([strip.axis.point(s, strip.t_lo), strip.axis.point(s, strip.t_hi)])
    o, u = chord_frame(strip)
    x = (P - o) @ u
    y = (P - o) @ np.array([-u[1], u[0]])
    return float(np.ptp(x)) + kerf, float(np.ptp(y)) + kerf


def fits_sheet(strip: Strip, params: FabParams) -> bool:
    """Whether the strip fits the sheet inside the gap border (long side along the long side)."""
    a, b = extent(strip, params.kerf)
    L, S = max(params.sheet) - 2 * params.gap, min(params.sheet) - 2 * params.gap
    return a <= L + 1e-9 and b <= S + 1e-9


def split_strip(strip: Strip, params: FabParams) -> list[Strip]:
    """``[strip]`` if it fits the sheet, else its spliced pieces (numbered, with splice notes)."""
    if fits_sheet(strip, params):
        return [strip]
    js, m = strip.joint_s, params.margin
    pieces: list[tuple[float, float, dict | None]] = []
    start, first = strip.s0, 0
    while True:
        if fits_sheet(strip.sub(start, strip.s1), params):
            pieces.append((start, strip.s1, None))
            break
        best = None
        for k in range(first + 1, len(js)):
            ov = params.overlap if params.overlap is not None else (
                (js[k + 1] - js[k] if k + 1 < len(js) else 0.0) + 2 * m)
            end = js[k] - m + ov
            if end >= strip.s1:
                break
            if not fits_sheet(strip.sub(start, end), params):
                break
            best = (k, end, ov)
        if best is None:
            raise InputError(
                f"lamella {strip.lamella} does not fit the {params.sheet[0]:g} x "
                f"{params.sheet[1]:g} mm sheet even between two joints "
                f"({strip.length:.1f} mm long at this scale); use a larger --sheet or a "
                "smaller --scale")
        k, end, ov = best
        nxt = js[k] - m
        shared = [int(i) for i in np.flatnonzero((js >= nxt - 1e-9) & (js <= end + 1e-9))]
        pieces.append((start, end, {"overlap": float(ov), "from": float(nxt), "to": float(end),
                                    "splice_joint": int(k), "shared_joints": shared}))
        start, first = nxt, k
    n = len(pieces)
    out = []
    for i, (a, b, sp) in enumerate(pieces):
        notes = []
        if i > 0:
            prev = dict(pieces[i - 1][2]); prev["with"] = i
            notes.append(prev)
        if sp is not None:
            notes.append({**sp, "with": i + 2})
        out.append(strip.sub(a, b, piece=i + 1, n_pieces=n, splices=notes))
    return out
