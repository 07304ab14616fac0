"""Engraved labels in a single-line (Hershey) font: lamella id and neighbour ids (issue item 3).

Text is written as stroke polylines on the ENGRAVE layer, never as DXF TEXT. Each label
lies along the axis tangent at its centre; a label that would leave the material (outline
shrunk by 0.5 mm, clear of holes) is shrunk, then dropped (counted in the report).
"""
from __future__ import annotations

from functools import lru_cache
from itertools import accumulate

import numpy as np
import shapely
from shapely.geometry import MultiLineString, Polygon

from gridshell.fabrication.joints import feature_halfwidth, slot_edge
from gridshell.fabrication.params import FabParams
from gridshell.fabrication.strip import Strip

MIN_HEIGHT = 1.5  # mm; smaller single-line text does not engrave legibly
SAFE_INSET = 0.5  # mm; labels keep this far inside the material (from edges and holes)


@lru_cache(maxsize=1)
def _font():
    from HersheyFonts import HersheyFonts

    f = HersheyFonts()
    f.load_default_font("futural")
    f.normalize_rendering(1.0)
    segs = np.array(list(f.lines_for_text("0123456789L")), float).reshape(-1, 2, 2)
    y0, y1 = segs[..., 1].min(), segs[..., 1].max()
    return f, y0, y1 - y0


@lru_cache(maxsize=None)
def _glyph(char: str) -> tuple[np.ndarray, np.ndarray, list[int], float] | None:
    """The glyph of ``char`` as ``lines_for_text`` renders it (``normalize_rendering``'s
    scale), its strokes of two or more points (a shorter one gives no line) one after the
    other: the x offsets of their points from the pen position, ``(x - left) * scalex``; the
    y of their points with the labels' baseline and cap height applied, ``(yofs + y * scaley
    - y0) / cap``; the number of points of each stroke; and the pen advance ``spacing +
    scalex * width``. None for a character the font lacks (``lines_for_text`` skips it)."""
    f, y0, cap = _font()
    glyphs = list(f.glyphs_for_text(char))
    if not glyphs:
        return None
    g, o = glyphs[0], f.render_options
    sx, sy, yofs = o["scalex"], o["scaley"], o["yofs"]
    pts = [p for s in g.strokes if len(s) >= 2 for p in s]
    x = np.array([(px - g.left_offset) * sx for px, _ in pts], float)
    y = (np.array([yofs + py * sy for _, py in pts], float) - y0) / cap
    return x, y, [len(s) for s in g.strokes if len(s) >= 2], o["spacing"] + sx * g.char_width


@lru_cache(maxsize=4096)
def _unit_strokes(text: str) -> tuple[tuple[np.ndarray, ...], float]:
    """Stroke polylines ``[(k,2)]`` of ``text`` with cap height 1, baseline at y = 0,
    starting at x = 0, and its length: ``lines_for_text``'s segments, consecutive ones
    joined where they meet (``np.allclose``), composed from the glyphs of :func:`_glyph`
    with the same floating-point operations (the same numbers; test)."""
    f, _, cap = _font()
    xofs = f.render_options["xofs"]
    xs, ys, counts = [], [], []
    for char in text:
        g = _glyph(char)
        if g is None:
            continue
        if g[2]:
            xs.append(xofs + g[0])         # as the library: xofs + (x - left) * scalex
            ys.append(g[1])
            counts += g[2]
        xofs += g[3]
    if not counts:
        return (), 0.0
    P = np.empty((sum(counts), 2))
    P[:, 0] = np.concatenate(xs) if len(xs) > 1 else xs[0]
    P[:, 0] /= cap
    P[:, 1] = np.concatenate(ys) if len(ys) > 1 else ys[0]
    x0, x1 = P[:, 0].min(), P[:, 0].max()
    P[:, 0] -= x0
    # a stroke continues the line before it where its first point meets that line's last
    # (consecutive segments of one stroke always do): np.allclose, without its overhead
    ends = list(accumulate(counts))
    first = np.array(ends[:-1], dtype=np.intp)
    a, b0 = P[first], P[first - 1]
    join = np.all(np.abs(a - b0) <= 1e-8 + 1e-5 * np.abs(b0), axis=1).tolist()
    lines, line = [], [P[:ends[0]]]
    for k, joined in enumerate(join):
        if joined:
            line.append(P[ends[k] + 1:ends[k + 1]])
        else:
            lines.append(np.concatenate(line) if len(line) > 1 else line[0])
            line = [P[ends[k]:ends[k + 1]]]
    lines.append(np.concatenate(line) if len(line) > 1 else line[0])
    return tuple(lines), float(x1 - x0)


def text_strokes(text: str, height: float) -> tuple[list[np.ndarray], float]:
    """Stroke polylines ``[(k,2)]`` of ``text`` with cap height ``height`` mm, baseline at
    y = 0, starting at x = 0; and the text's length in mm."""
    lines, length = _unit_strokes(text)
    return [L * height for L in lines], length * height


def place_text(strip: Strip, text: str, height: float, s: float, t: float) -> list[np.ndarray]:
    """Strokes of ``text`` centred at strip coordinates ``(s, t)``, reading along +s."""
    lines, length = text_strokes(text, height)
    if not lines:
        return []
    c = strip.axis.point(s, t)
    T = strip.axis.tangent(s)
    R = np.array([T, [-T[1], T[0]]])
    shift = np.array([length / 2, height / 2])
    return [(L - shift) @ R + c for L in lines]


def text_length(text: str, height: float) -> float:
    return _unit_strokes(text)[1] * height


def _band(strip: Strip, params: FabParams) -> tuple[float, float]:
    """``(h0, t)``: the largest label height of the strip and the strip coordinate ``t`` of
    the labels' centre line, mm."""
    w = strip.width
    band_t, band_h = strip.t_mid, w
    if params.joints == "slots":   # keep to the half the notches leave whole
        band_h = w / 2
        band_t = strip.t_mid + (-w / 4 if slot_edge(strip.family) == "hi" else w / 4)
    return min(0.3 * w, band_h - 2.0, 8.0), band_t


def labelled(strip: Strip, params: FabParams) -> bool:
    """Whether the strip is wide enough for labels (of at least MIN_HEIGHT)."""
    return _band(strip, params)[0] >= MIN_HEIGHT


def safe_regions(materials: np.ndarray) -> np.ndarray:
    """Where labels may go on each of the parts' ``materials`` (shapely polygons, holes as
    interiors): the material shrunk by SAFE_INSET mm, made at once (``material.buffer(
    -SAFE_INSET)`` of each: the method's defaults, the same polygons)."""
    return shapely.buffer(materials, -SAFE_INSET, quad_segs=16)


def _free_stretches(occupied: list[tuple[float, float]], strip: Strip
                    ) -> list[tuple[float, float]]:
    """The stretches ``(a, b)`` (mm along the strip) between the ``occupied`` ones and the
    strip's ends (1 mm kept clear), longest first."""
    occ = sorted(occupied + [(strip.s0 - 1, strip.s0 + 1.0), (strip.s1 - 1.0, strip.s1 + 1)])
    free, end = [], occ[0][1]
    for a, b in occ[1:]:
        if a > end:
            free.append((end, a))
        end = max(end, b)
    return sorted(free, key=lambda ab: ab[0] - ab[1])


def strip_labels(strip: Strip, params: FabParams, material: Polygon,
                 safe: Polygon | None = None) -> tuple[list[np.ndarray], int]:
    """Engraving strokes of the strip: its name (``L12``, ``L12-1/2``) in the widest free
    stretch, the neighbour ids right after each joint and the label of each span splice
    (``L12-S1``) between its fasteners. ``material``: the part's shapely
    polygon (holes as interiors); ``safe``: its :func:`safe_regions` if made already.
    Returns the strokes and the number of labels dropped."""
    h0, band_t = _band(strip, params)
    if h0 < MIN_HEIGHT:
        return [], len(strip.joint_s) + 1
    if safe is None:
        safe = safe_regions(np.array([material], dtype=object))[0]
    shapely.prepare(safe)        # many containment tests against one polygon; same answers
    pad = feature_halfwidth(params) + 1.0
    strokes: list[np.ndarray] = []
    dropped = 0
    occupied: list[tuple[float, float]] = [(s - pad, s + pad)
                                           for s in np.concatenate([strip.joint_s,
                                                                    strip.splice_s])]

    def fits(lines):
        return bool(lines) and safe.contains(MultiLineString([L for L in lines]))

    heights = []                 # the label heights tried: h0, 0.75 h0, ... to MIN_HEIGHT
    h = h0
    while h >= MIN_HEIGHT:
        heights.append(h)
        h *= 0.75

    for s_j, nb in zip(strip.joint_s, strip.neighbours):
        if not nb:
            continue
        text = ",".join(str(i) for i in nb)
        # the next occupied stretch after the joint (occupied grows only when placed)
        limit = min([a for a, _ in occupied if a > s_j + 1e-9] + [strip.s1 - 1.0])
        for h in heights:
            L = text_length(text, h)
            s_c = s_j + pad + L / 2
            if s_c + L / 2 <= limit and fits(lines := place_text(strip, text, h, s_c, band_t)):
                strokes += lines
                occupied.append((s_j + pad, s_c + L / 2 + 1.0))
                break
        else:
            dropped += 1
    # span splices: their label on both pieces, inside the overlap, clear of the fasteners
    for note in strip.splices:
        if note.get("kind") != "span":
            continue
        f = note["fasteners"]
        a, b = (f[0] + pad + 1.0, f[-1] - pad - 1.0) if len(f) > 1 else \
            (f[0] + pad + 1.0, note["to"] - 1.0)
        a, b = max(a, strip.s0 + 1.0), min(b, strip.s1 - 1.0)
        for h in heights:
            L = text_length(note["label"], h)
            if L <= b - a:
                lines = place_text(strip, note["label"], h, 0.5 * (a + b), band_t)
                if fits(lines):
                    strokes += lines
                    occupied.append((0.5 * (a + b - L), 0.5 * (a + b + L)))
                    break
        else:
            dropped += 1
    # the strip's name in the longest free stretch
    text = strip.name
    placed = False
    for a, b in _free_stretches(occupied, strip):
        if text_length(text, heights[-1]) > b - a:
            break                # too short at the smallest height, and so are the rest
        for h in heights:
            if text_length(text, h) <= b - a:
                lines = place_text(strip, text, h, 0.5 * (a + b), band_t)
                if fits(lines):
                    strokes += lines
                    placed = True
                    break
        if placed:
            break
    dropped += 0 if placed else 1
    return strokes, dropped

