"""Splitting lamellae longer than the sheet into spliced pieces.

A lamella that does not fit the sheet is cut into overlapping pieces, each as long as the
sheet allows, by two kinds of lap splice:

Every splice holds its two pieces by at least two fasteners (:data:`MIN_SHARED`): shared
joints of a joint splice, the two fasteners of a span splice; a splice of one would be a
hinge and is never made. So no piece is shorter than its overlaps.

* a **joint splice** at joint ``k``: the next piece starts one end margin before
  joint ``k`` (like any strip before its first joint) and the previous piece ends ``overlap``
  mm after that start. Default overlap: the spacing from joint ``k`` to joint ``k+1`` plus two
  end margins, so that the two pieces share two joints - their joint holes line up and two
  fasteners make a lap splice that carries bending (one shared joint would act as a hinge);
* a **span splice** between two joints, where no joint splice fits (joints further apart
  than the sheet allows): the pieces overlap by ``overlap`` mm (default ``2 * width`` plus two
  end margins) lying between two consecutive joints, at least one end margin clear of both,
  with two fasteners (holes, or score marks with ``--joints marks/slots``) one end margin
  inside each end of the overlap - the same layout as the two shared joints of a joint
  splice. It is labelled ``L<lamella>-S<n>`` on both pieces.

A lamella that joint splices alone can cut is split as before (the farthest joint splice for
each piece); any other by span splices alone (:func:`_span_plan`, exact: it finds a split
whenever one exists), which lose the least material to overlaps; failing that (stretches of
joints too close for a span overlap), by both, depth first (:func:`_plan`). What none can
cut (a strip whose shortest piece is wider than the sheet) is an :class:`InputError` naming
the fix.
"""
from __future__ import annotations

import dataclasses
import functools

import numpy as np

from gridshell.core.errors import InputError

from gridshell.fabrication.joints import feature_halfwidth
from gridshell.fabrication.params import FabParams
from gridshell.fabrication.strip import Strip

#: joints (or fasteners) every splice's two pieces share: one would be a hinge
MIN_SHARED = 2


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


def _joint_splices(strip: Strip, params: FabParams, start: float, first: int,
                   floor: float | None) -> list[dict]:
    """The joint splices for the piece from ``start`` that fit the sheet, farthest first.

    ``first``: index of the first joint a splice may use; ``floor``: after a span splice,
    the end of its overlap, before which the next piece may not start (None: any)."""
    js, m = strip.joint_s, params.margin
    found = []
    for k in range(first + (1 if floor is None else 0), len(js)):
        ov = params.overlap if params.overlap is not None else (
            (js[k + 1] - js[k] if k + 1 < len(js) else 0.0) + 2 * m)
        end = js[k] - m + ov
        if end >= strip.s1:
            break
        if floor is not None and js[k] - m < floor - 1e-9:
            continue
        if not fits_sheet(strip.sub(start, end), params):
            break
        nxt = js[k] - m
        shared = [int(i) for i in np.flatnonzero((js >= nxt - 1e-9) & (js <= end + 1e-9))]
        if len(shared) < MIN_SHARED:
            continue                    # one shared joint would be a hinge
        found.append({"kind": "joint", "overlap": float(ov), "from": float(nxt),
                      "to": float(end), "splice_joint": int(k), "splice_name": joint_name(strip, k),
                      "shared_joints": shared,
                      "shared_names": [joint_name(strip, i) for i in shared]})
    return found[::-1]


def joint_name(strip: Strip, k: int) -> str:
    """The name engraved beside joint ``k`` of ``strip``: the ids of the lamellae crossing it
    (``11``, ``11,12``); for a joint no other lamella crosses, its position along the strip
    from the strip's start (``at 123.4 mm``)."""
    nb = strip.neighbours[k] if k < len(strip.neighbours) else []
    return ",".join(str(i) for i in nb) if nb else f"at {strip.joint_s[k] - strip.s0:.1f} mm"


def span_overlap(params: FabParams) -> float:
    """Overlap of a span splice, mm: ``--overlap``, else two widths plus two end margins."""
    return params.overlap if params.overlap is not None else 2 * params.width + 2 * params.margin


def span_fasteners(c: float, ov: float, params: FabParams) -> list[float]:
    """Fastener positions of the span splice overlapping ``[c, c + ov]``: one end margin
    inside each end (:func:`span_overlap_holds` tells whether the two stay apart)."""
    m = params.margin
    return [c + m, c + ov - m]


def span_overlap_holds(params: FabParams) -> bool:
    """Whether a span overlap has room for its two fasteners, one end margin inside each
    end and not merging (else a span splice would be a hinge and is not made)."""
    need = 2 * feature_halfwidth(params) + 0.5
    return span_overlap(params) - 2 * params.margin >= need


def _span_splice(strip: Strip, params: FabParams, start: float,
                 floor: float) -> dict | None:
    """The farthest span splice for the piece from ``start`` that fits the sheet, or None.

    The overlap ``[c, c + ov]`` lies between two consecutive stations of ``s0, joints, s1``,
    one end margin clear of both and of ``floor`` (the end of the previous overlap)."""
    m, ov = params.margin, span_overlap(params)
    if not span_overlap_holds(params):
        return None
    B = np.concatenate([[strip.s0], strip.joint_s, [strip.s1]])
    fits = lambda c: fits_sheet(strip.sub(start, c + ov), params)  # noqa: E731
    best = None
    for i in range(len(B) - 1):
        lo, hi = max(B[i] + m, floor + m, start + 1e-6), B[i + 1] - m - ov
        if hi < lo:
            continue
        if not fits(lo):
            break                       # farther windows give longer pieces still
        if fits(hi):
            best = (i, hi)
            continue
        a, b = lo, hi                   # fits(a), not fits(b): bisect to 0.01 mm
        while b - a > 0.01:
            mid = 0.5 * (a + b)
            a, b = (mid, b) if fits(mid) else (a, mid)
        best = (i, a)
        break
    if best is None:
        return None
    return _span_note(strip, params, best[1], best[0])


def _span_note(strip: Strip, params: FabParams, c: float, i: int) -> dict:
    """The note of the span splice overlapping ``[c, c + overlap]`` in window ``i`` (between
    stations ``i`` and ``i + 1`` of ``s0, joints, s1``)."""
    ov = span_overlap(params)
    n = len(strip.joint_s)      # stations i, i+1 are joints i-1, i (0, n+1: the strip ends)
    where = (f"before the first joint ({joint_name(strip, 0)})" if i == 0 else
             f"after the last joint ({joint_name(strip, n - 1)})" if i == n
             else f"between joints {joint_name(strip, i - 1)} and {joint_name(strip, i)}")
    return {"kind": "span", "overlap": float(ov), "from": float(c), "to": float(c + ov),
            "at": float(c + ov / 2), "where": where,
            "fasteners": span_fasteners(float(c), float(ov), params),
            "lamella": int(strip.lamella)}


def _plan(strip: Strip, params: FabParams, span: bool, budget: list[int]) -> list[dict] | None:
    """The splices of the lamella, in order, or None if it cannot be cut from the sheet.

    ``span=False``: the farthest joint splice for each piece, nothing else. ``span=True``:
    depth first over the splices of each piece, the farthest span splice (the least
    material lost to overlaps) then the joint splices, farthest first; a choice that leaves
    the rest uncuttable is revisited (``budget``: how many more pieces may be tried)."""
    js = strip.joint_s

    def go(start, first, floor, prev_end):
        if fits_sheet(strip.sub(start, strip.s1), params):
            return []
        def options():
            if span:
                sp = _span_splice(strip, params, start, prev_end)
                if sp is not None:
                    yield sp
            joint = _joint_splices(strip, params, start, first, floor)
            yield from joint if span else joint[:1]

        for sp in options():
            budget[0] -= 1
            if budget[0] < 0:
                return None
            if sp["kind"] == "joint":
                rest = go(sp["from"], sp["splice_joint"], None, sp["to"])
            else:
                rest = go(sp["from"], int(np.searchsorted(js, sp["from"])), sp["to"], sp["to"])
            if rest is not None:
                return [sp] + rest
        return None

    return go(strip.s0, 0, None, strip.s0)


def _windows(strip: Strip, params: FabParams) -> list[tuple[int, float, float]]:
    """``(i, lo, hi)``: where a span overlap may start, one end margin clear of the
    stations ``i`` and ``i + 1`` of ``s0, joints, s1``; non-empty ones, in order."""
    m, ov = params.margin, span_overlap(params)
    if not span_overlap_holds(params):
        return []
    B = np.concatenate([[strip.s0], strip.joint_s, [strip.s1]])
    return [(i, B[i] + m, B[i + 1] - m - ov) for i in range(len(B) - 1)
            if B[i + 1] - m - ov >= B[i] + m]


def _reach(strip: Strip, params: FabParams, x: float) -> float:
    """The farthest end (mm along the axis) of a piece from ``x`` that fits the sheet."""
    fits = lambda e: fits_sheet(strip.sub(x, e), params)  # noqa: E731
    a, b = x, strip.s1
    if fits(b):
        return b
    two = x + 2 * max(params.sheet)     # usually too long already: a shorter bracket
    if two < b and not fits(two):
        b = two
    while b - a > 0.01:
        mid = 0.5 * (a + b)
        a, b = (mid, b) if fits(mid) else (a, mid)
    return a


def _span_plan(strip: Strip, params: FabParams) -> list[dict] | None:
    """Span splices only, placed exactly: the set of overlap starts reachable with ``j``
    pieces is propagated window by window (a union of intervals: a piece from ``c`` reaches
    overlap starts ``[c + overlap + margin, reach(c) - overlap]``, monotone in ``c``) until
    the rest of the strip fits one piece; then walked back, each overlap as far along as
    the next allows. Finds a split whenever one by span splices exists (to 0.01 mm), where
    the greedy choice of :func:`_plan` can strand the rest (short sheets)."""
    m, ov = params.margin, span_overlap(params)
    W = _windows(strip, params)
    if not W:
        return None
    # the windows' ends repeat from level to level: each reach is a bisection of ~20 fit
    # tests, so they are computed once (a 3 m arc at 1:10: 602 calls, 32 distinct)
    reach = functools.lru_cache(maxsize=None)(lambda x: _reach(strip, params, x))

    def clip(intervals):
        out = []
        for a, b in intervals:
            for i, lo, hi in W:
                lo2, hi2 = max(a, lo), min(b, hi)
                if hi2 >= lo2:
                    out.append((i, lo2, hi2))
        return out

    levels = [clip([(strip.s0 + m, reach(strip.s0) - ov)])]
    limit = int(strip.length / (ov + m)) + 2
    while levels[-1] and len(levels) <= limit:
        top = max(hi for _, _, hi in levels[-1])
        if fits_sheet(strip.sub(top, strip.s1), params):
            break
        levels.append(clip([(lo + ov + m, reach(hi) - ov)
                            for _, lo, hi in levels[-1]]))
    else:
        return None
    # walk back: the last overlap as far along as possible, then each one before it
    c = max(hi for _, _, hi in levels[-1])
    i = next(i for i, _, hi in levels[-1] if hi == c)
    chosen = [(i, c)]
    for level in levels[-2::-1]:
        cand = [(i, min(hi, c - ov - m)) for i, lo, hi in level if lo <= c - ov - m]
        if not cand:
            return None
        i, x = max(cand, key=lambda t: t[1])
        if reach(x) < c + ov - 1e-6:
            return None
        chosen.append((i, x))
        c = x
    return [_span_note(strip, params, c, i) for i, c in chosen[::-1]]


def _why_unsplit(strip: Strip, params: FabParams) -> str:
    """Why no splice plan exists (the reason of the refusal), one clause."""
    if not span_overlap_holds(params):
        return (f"a {span_overlap(params):g} mm overlap between joints leaves no room for "
                f"two fasteners {params.margin:g} mm inside its ends, and no piece reaches "
                "two shared joints (a splice of one shared joint would be a hinge; raise "
                "--overlap)")
    return ("no piece that fits reaches far enough to share two joints (or two fasteners "
            "between joints) with the next one (a splice of one would be a hinge)")


def split_strip(strip: Strip, params: FabParams) -> list[Strip]:
    """``[strip]`` if it fits the sheet, else its spliced pieces (numbered, with splice notes
    and, for span splices, the fasteners in ``splice_s``)."""
    if fits_sheet(strip, params):
        return [strip]
    n_min = int(np.ceil(strip.length / (max(params.sheet) - 2 * params.gap)))
    # joint splices alone, as long as they do; else splices between joints; else both
    splices = _plan(strip, params, False, [100 + 10 * n_min])
    if splices is None:
        splices = _span_plan(strip, params)
    if splices is None:
        splices = _plan(strip, params, True, [100 + 10 * n_min])
    if splices is None:
        raise InputError(
            f"lamella {strip.lamella} does not fit the {params.sheet[0]:g} x "
            f"{params.sheet[1]:g} mm sheet even in spliced pieces ({strip.length:.1f} mm long, "
            f"{strip.width:g} mm wide at this scale): {_why_unsplit(strip, params)}; use a "
            "larger --sheet or a smaller --scale")
    starts = [strip.s0] + [sp["from"] for sp in splices]
    ends = [sp["to"] for sp in splices] + [strip.s1]
    pieces = list(zip(starts, ends, splices + [None]))
    n_span = 0
    for _, _, sp in pieces:
        if sp is not None and sp["kind"] == "span":
            n_span += 1
            sp["label"] = f"L{strip.lamella}-S{n_span}"
    fasteners = [f for _, _, sp in pieces if sp is not None for f in sp.get("fasteners", [])]
    whole = dataclasses.replace(strip, splice_s=np.array(fasteners, float))
    n = len(pieces)
    out = []
    for i, (a, b, sp) in enumerate(pieces):
        notes = []
        if i > 0:
            prev = dict(pieces[i - 1][2]); prev["with"] = i
            notes.append(prev)
        if sp is not None:
            notes.append({**sp, "with": i + 2})
        out.append(whole.sub(a, b, piece=i + 1, n_pieces=n, splices=notes))
    return out
