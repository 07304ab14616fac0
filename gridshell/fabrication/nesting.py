"""Nesting parts on sheets: first fit decreasing, bottom-left by dropping, polygons not boxes.

Every part is turned so that its chord lies along the sheet's long side (``+s`` along ``+x``,
labels read upright; curved parts may also be turned by 180 degrees) and the parts are taken
longest first. Each goes onto the first sheet with room for it, at the lowest, then leftmost,
of its candidate places: at the sheet's left and right edges, right and left of every part
already there, and aligned with its left end, right end and middle. At each candidate ``x``
the part drops from above the sheet until it comes ``gap`` from a part below it (or the
bottom margin) - the true outlines, not their bounding boxes: arcs of one radius fall into
each other, a short strip goes into the room a row leaves. Sheets are opened as needed.

Straight strips are also laid out in rows and in columns of strips turned by 90 degrees
(:mod:`gridshell.fabrication.rows`); curved parts also go through raster passes that turn them freely
(:mod:`gridshell.fabrication.raster`; 0 or 180 degrees only under ``FabParams.rotation == "grain"``);
the best layout of all strategies is kept, and the search stops at :func:`gap_bound`, the
fewest sheets any layout needs.

All parts keep ``gap`` mm from each other and from the sheet edges. The drop uses outer
approximations of the outlines (grown by ``DROP_TOL``, simplified by as much), so a dropped
part never comes closer than ``gap``; :func:`check_layout` checks the result with the fine
outlines. Sheets are filled in a frame whose x axis is the sheet's long side, then turned to
the sheet as given.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import shapely
import shapely.affinity
from shapely.geometry import Polygon

from gridshell.core.errors import InputError

from gridshell.fabrication.params import FabParams
from gridshell.fabrication.part import Part
from gridshell.fabrication.path import Motion
from gridshell.fabrication.raster import raster_nest
from gridshell.fabrication.rows import SLACK, fullest as _fullest, plan_rows  # noqa: F401 (_fullest: tests)
from gridshell.fabrication.splice import chord_frame


DROP_TOL = 0.1     # mm, growth and simplification of the rings the drop search uses
FLAT_TOL = 0.01    # mm, chord tolerance of the part polygons (arcs bulge out by up to this)
COLUMN = 2.0       # mm, width of the columns of the part profiles (the step of the places)


@dataclass
class Layout:
    """Parts placed on ``n_sheets`` sheets: ``parts[i]`` lies on sheet ``sheet_of[i]`` (0-based)."""

    parts: list[Part]
    sheet_of: list[int]
    n_sheets: int
    sheet: tuple[float, float]

    def on_sheet(self, k: int) -> list[Part]:
        return [p for p, s in zip(self.parts, self.sheet_of) if s == k]

    def used(self, k: int | None = None) -> float:
        """Material used: the area of the part outlines (holes not subtracted) over the area
        of sheet ``k`` (None: of all sheets), 0..1."""
        W, H = self.sheet
        parts = self.parts if k is None else self.on_sheet(k)
        n = self.n_sheets if k is None else 1
        return sum(p.polygon(FLAT_TOL).area for p in parts) / (n * W * H) if n else 0.0


def sheet_bound(parts: list[Part], sheet: tuple[float, float], slack: float = 1.15) -> int:
    """``ceil(slack * total part area / sheet area)``: the sheet count a nesting that
    wastes at most ``slack - 1`` of the sheets would need (outline areas, mm^2)."""
    area = sum(p.polygon(FLAT_TOL).area for p in parts)
    return int(np.ceil(slack * area / (sheet[0] * sheet[1]) - 1e-9))


@dataclass
class _Shape:
    """One orientation of a part in the nesting frame: fine polygon with its bounding box at
    the origin, size ``w x h``; the outer approximation's x range ``ox`` and its lowest y per
    column from ``ox[0]`` on (``low``; ``up``: the highest), which the drop placement uses
    (made on first use: a rows-and-columns layout, see :func:`_rows_best`, needs only the
    sizes)."""

    part: Part
    poly: Polygon
    w: float
    h: float

    @cached_property
    def _profile(self) -> tuple:
        """``(ox, low, up, runs_low, runs_up)``; see :func:`_profile`."""
        return _profile(self.poly)

    @property
    def ox(self) -> tuple[float, float]:
        return self._profile[0]

    @property
    def low(self) -> np.ndarray:
        return self._profile[1]

    @property
    def up(self) -> np.ndarray:
        return self._profile[2]

    @property
    def runs_low(self) -> list:            # _runs of low and up (Sheet._profiles)
        return self._profile[3]

    @property
    def runs_up(self) -> list:
        return self._profile[4]


@dataclass
class _Placed:
    poly: Polygon              # fine polygon, placed
    grown: np.ndarray          # closed ring containing poly grown by the gap
    box: tuple[float, float, float, float] = field(init=False)   # of poly

    def __post_init__(self) -> None:
        self.box = self.poly.bounds


def _outer_ring(poly: Polygon, grow: float) -> np.ndarray:
    """A closed ring ``(k,2)`` of a polygon containing ``poly`` grown by ``grow`` mm (mitred
    corners contain the rounded ones; the simplification cuts in by at most DROP_TOL, which
    the extra growth pays for)."""
    g = poly.buffer(grow + DROP_TOL, join_style="mitre", mitre_limit=3.0)
    g = g.simplify(DROP_TOL, preserve_topology=True)
    if g.geom_type != "Polygon":    # pragma: no cover - a strip outline stays one polygon
        g = g.convex_hull
    return np.asarray(g.exterior.coords)


def _shapes(part: Part, curved: bool) -> list[_Shape]:
    """The part in its nesting orientations (and turned by 180 degrees when curved)."""
    if curved:
        _, u = chord_frame(part.strip)
        base = part.moved(Motion(-np.arctan2(u[1], u[0]), 0.0, 0.0))  # +s along +x
    else:
        base = part
    return [_shape(base, turn, curved) for turn in ((0.0, np.pi) if curved else (0.0,))]


def _shape(base: Part, turn: float, curved: bool) -> _Shape:
    """``base`` turned by ``turn`` (radians), its box at the origin (its profiles made when
    first used)."""
    p = base.moved(Motion(turn, 0.0, 0.0)) if turn else base
    pad = FLAT_TOL if curved else 0.0               # arcs bulge out by up to FLAT_TOL
    x0, y0, _, _ = p.polygon(FLAT_TOL).bounds
    p = p.moved(Motion(0.0, pad - x0, pad - y0))
    poly = p.polygon(FLAT_TOL)
    _, _, w, h = poly.bounds
    return _Shape(p, poly, w + pad, h + pad)


def _profile(poly: Polygon) -> tuple:
    """The profiles of a shape's polygon ``poly`` (mm): the x range ``ox`` of its outer
    approximation, its lowest / highest y per column from ``ox[0]`` on (``low``, ``up``) and
    their :func:`_runs`."""
    ring = _outer_ring(poly, 0.0)
    ox = (float(ring[:, 0].min()), float(ring[:, 0].max()))
    n = int(np.ceil((ox[1] - ox[0]) / COLUMN)) + 1
    low, up = _columns(ring, ox[0], n, False), _columns(ring, ox[0], n, True)
    # one column wider, each column also covering its left neighbour: the profile of the
    # shape anywhere between two column offsets (so it may also touch the margins)
    low = np.minimum(np.append(low, np.inf), np.insert(low, 0, np.inf))
    up = np.maximum(np.append(up, -np.inf), np.insert(up, 0, -np.inf))
    return ox, low, up, _runs(low, np.inf), _runs(up, -np.inf)


def _columns(ring: np.ndarray, x0: float, n: int, top: bool) -> np.ndarray:
    """The highest (``top``) or lowest y of the closed ring ``(k,2)`` over each column
    ``[x0 + j COLUMN, x0 + (j + 1) COLUMN]``, ``j < n``; -inf / +inf where it has no point.

    Exact for the polyline: the extreme over a column is at a vertex inside it or where an
    edge crosses one of its two bounds."""
    out = np.full(n, -np.inf if top else np.inf)
    at = np.maximum.at if top else np.minimum.at
    j = np.floor((ring[:, 0] - x0) / COLUMN).astype(int)
    keep = (j >= 0) & (j < n)
    at(out, j[keep], ring[keep, 1])
    a, b = ring[:-1], ring[1:]
    lo, hi = np.minimum(a[:, 0], b[:, 0]), np.maximum(a[:, 0], b[:, 0])
    m0 = np.ceil((lo - x0) / COLUMN).astype(int)
    m1 = np.floor((hi - x0) / COLUMN).astype(int)
    cnt = np.maximum(m1 - m0 + 1, 0) * (hi > lo)
    if cnt.sum():
        e = np.repeat(np.arange(len(a)), cnt)
        m = m0[e] + np.arange(cnt.sum()) - np.repeat(np.cumsum(cnt) - cnt, cnt)
        xb = x0 + m * COLUMN
        t = (xb - a[e, 0]) / (b[e, 0] - a[e, 0])
        y = a[e, 1] + t * (b[e, 1] - a[e, 1])
        for col in (m - 1, m):
            ok = (col >= 0) & (col < n)
            at(out, col[ok], y[ok])
    return out


class _Sheet:
    """One sheet being filled, in the nesting frame ``Lx x Ly`` (Lx >= Ly): the placed
    polygons and, per column, the top and bottom of each placed part grown by the gap."""

    def __init__(self, Lx: float, Ly: float, gap: float):
        self.Lx, self.Ly, self.g = Lx, Ly, gap
        self.placed: list[_Placed] = []
        n = int(np.ceil(Lx / COLUMN)) + 1
        self.top = np.zeros((0, n))
        self.bot = np.zeros((0, n))
        self._tmax: list[np.ndarray] = []    # sparse tables of top / bot (_window_extreme)
        self._bmin: list[np.ndarray] = []

    def places(self, s: _Shape) -> tuple[np.ndarray, np.ndarray]:
        """Free places ``(x, y)`` (arrays) of the shape inside the sheet's margins: at every
        column, on the bottom margin or resting on a placed part (its lowest point on the top
        of that part), where it is clear of every placed part. Per column offset, a placed
        part (grown by the gap) blocks the heights from where the shape would touch it from
        below to where it rests on it (conservative: each column spans from its lowest to
        its highest point, and a shape is either above or below a part in all columns they
        share)."""
        nb, n = len(s.low), self.top.shape[1]
        if nb > n:
            return np.zeros(0), np.zeros(0)
        off = np.arange(n - nb + 1)
        x0 = off * COLUMN - s.ox[0]
        x = np.clip(x0, self.g, max(self.g, self.Lx - self.g - s.w))  # dilated profile covers
        inside = (x >= x0 - 1e-9) & (x <= x0 + COLUMN + 1e-9) & \
            (x + s.w <= self.Lx - self.g + SLACK)          # [x0, x0 + COLUMN], in the sheet
        x, off = x[inside], off[inside]
        y = np.full((1, len(off)), self.g)
        if len(self.placed):       # (no inf - inf: tops and lows are never +inf, -inf)
            hi, lo = self._profiles(s, off)
            y = np.vstack([y, hi])                                  # (parts + 1, offsets)
            blocked = ((y[:, None, :] > lo[None] + 1e-9) &
                       (y[:, None, :] < hi[None] - 1e-9)).any(axis=1)
            y = np.where(blocked, np.inf, y)
        X = np.broadcast_to(x, y.shape).ravel()
        Y = y.ravel()
        ok = (Y >= self.g - 1e-9) & (Y <= self.Ly - self.g - s.h + SLACK)
        return X[ok], Y[ok]

    def clear(self, poly: Polygon, x: float, y: float) -> bool:
        """Whether ``poly`` moved by ``(x, y)`` keeps the gap from every placed part (the check
        with the fine outlines after the drop on their approximations)."""
        cand = shapely.affinity.translate(poly, x, y)
        b = cand.bounds
        for q in self.placed:
            if (q.box[0] - self.g < b[2] and q.box[2] + self.g > b[0]
                    and q.box[1] - self.g < b[3] and q.box[3] + self.g > b[1]):
                if cand.distance(q.poly) < self.g - 1e-6:
                    return False
        return True

    def add(self, s: _Shape, x: float, y: float) -> tuple[Part, Motion]:
        """Place ``s`` at ``(x, y)``; the part and its move (made by :func:`_moved` for
        the winning layout only: moving every label stroke of every pass costs)."""
        q = (s.part, Motion(0.0, x, y))
        poly = shapely.affinity.translate(s.poly, x, y)
        grown = _outer_ring(poly, self.g)
        self.placed.append(_Placed(poly, grown))
        n = self.top.shape[1]
        self.top = np.vstack([self.top, _columns(grown, 0.0, n, True)])
        self.bot = np.vstack([self.bot, _columns(grown, 0.0, n, False)])
        self._tmax = _sparse_table(self.top[-1:], True, self._tmax)
        self._bmin = _sparse_table(self.bot[-1:], False, self._bmin)
        return q

    def _profiles(self, s: _Shape, off: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Per placed part and column offset ``off``: the height ``hi`` at which the shape
        rests on the part (``max_j top[off + j] - low[j]``) and the height ``lo`` at which it
        touches it from below (``min_j bot[off + j] - up[j]``), ``(parts, offsets)``.

        Runs of equal ``low`` / ``up`` (a straight strip's profile is a few runs) take the
        extreme of the sheet's profile over the run from sparse tables (two look-ups per run
        instead of one per column); rounding is monotone, so ``max(top) - v`` equals
        ``max(top - v)`` bit for bit. Profiles of many runs use the sliding windows."""
        nb = len(s.low)
        if len(s.runs_low) + len(s.runs_up) > nb // 4:
            view = np.lib.stride_tricks.sliding_window_view
            hi = (view(self.top, nb, axis=1)[:, off] - s.low).max(axis=2)
            lo = (view(self.bot, nb, axis=1)[:, off] - s.up).min(axis=2)
            return hi, lo
        hi = np.full((len(self.top), len(off)), -np.inf)
        for a, L, v in s.runs_low:
            hi = np.maximum(hi, _window_extreme(self._tmax, off + a, L, True) - v)
        lo = np.full((len(self.bot), len(off)), np.inf)
        for a, L, v in s.runs_up:
            lo = np.minimum(lo, _window_extreme(self._bmin, off + a, L, False) - v)
        return hi, lo


def _sparse_table(a: np.ndarray, top: bool, below: list | None = None) -> list[np.ndarray]:
    """Level ``k``: the max (``top``) or min of ``a`` ``(p, n)`` over the columns
    ``[i, i + 2^k)``, ``(p, n - 2^k + 1)``; under the rows of the table ``below`` if given."""
    f = np.maximum if top else np.minimum
    out = [a]
    k = 1
    while 2 * k <= a.shape[1]:
        prev = out[-1]
        out.append(f(prev[:, :-k], prev[:, k:]))
        k *= 2
    return [np.vstack([b, t]) for b, t in zip(below, out)] if below else out


def _window_extreme(table: list[np.ndarray], start: np.ndarray, L: int, top: bool) -> np.ndarray:
    """Max (``top``) or min over the columns ``[start, start + L)`` of the array whose
    :func:`_sparse_table` is ``table``, ``(p, len(start))``."""
    k = L.bit_length() - 1
    T = table[k]
    f = np.maximum if top else np.minimum
    return f(T[:, start], T[:, start + L - (1 << k)])


def _runs(prof: np.ndarray, skip: float) -> list[tuple[int, int, float]]:
    """Runs ``(start, length, value)`` of equal values of ``prof``, except ``skip`` (the
    columns without points, which block nothing)."""
    cut = np.flatnonzero(prof[1:] != prof[:-1]) + 1
    starts = np.concatenate([[0], cut])
    ends = np.concatenate([cut, [len(prof)]])
    return [(int(a), int(b - a), float(prof[a])) for a, b in zip(starts, ends)
            if prof[a] != skip]


def _frame_to_sheet(W: float, H: float) -> Motion:
    """From the nesting frame (long side along x) to the sheet as given."""
    return Motion() if W >= H else Motion(np.pi / 2, W, 0.0)


#: the strategies tried: which place wins (lowest then leftmost, or leftmost then lowest),
#: whether curved parts may turn by 180 degrees, and the order of the parts
STRATEGIES = [("bottom-left", True, "length"), ("bottom-left", False, "length"),
              ("left-bottom", False, "length")]
RETRIES = 2        # passes more per strategy, with the last sheet's parts placed first
COLUMNS = 8        # most columns of turned straight strips tried per sheet (rows.plan_rows)
#: raster passes for curved parts (:mod:`gridshell.fabrication.raster`), cheapest first: pixel size
#: (mm), rotation step (degrees; free rotation), the height that ranks places
RASTER = [(1.5, 15.0, "centre"), (1.0, 10.0, "top"), (1.0, 10.0, "centre")]
#: most correlations (one per rotation and sheet tried) a raster pass may compute (about a
#: minute at 1 mm pixels on a 600 x 400 mm sheet); a bigger layout keeps the drop layout
RASTER_WORK = 20000


def _key(key: str, x: np.ndarray, y: np.ndarray, h: float) -> np.ndarray:
    """Indices of the places ``(x, y)`` from best to worst under ``key``."""
    if key == "bottom-left":
        return np.lexsort((x, np.round(y, 6)))
    if key == "left-bottom":
        return np.lexsort((y, np.round(x, 6)))
    return np.lexsort((x, np.round(y + h, 6)))


def _order(shapes: list[list[_Shape]], order: str, first: list[int]) -> list[int]:
    """The parts' order: ``first``, then the others by decreasing length (or area)."""
    if order == "length":
        key = lambda i: (-round(shapes[i][0].w, 6), -shapes[i][0].poly.area, i)  # noqa: E731
    else:
        key = lambda i: (-shapes[i][0].poly.area, i)  # noqa: E731
    rest = sorted((i for i in range(len(shapes)) if i not in set(first)), key=key)
    return sorted(first, key=key) + rest


def _nest_once(shapes: list[list[_Shape]], Lx: float, Ly: float, g: float, key: str,
               turn: bool, seq: list[int], beat: tuple | None = None
               ) -> tuple[list[_Sheet], dict[int, tuple[int, Part]]] | None:
    """One first-fit pass under one strategy, parts in the order ``seq``. None as soon as
    the pass cannot end with a score ``(sheets, area on the last sheet)`` below ``beat``
    (the score only grows as parts are added: more sheets, or more area on the last)."""
    sheets: list[_Sheet] = []
    placed: dict[int, tuple[int, Part]] = {}
    for i in seq:
        if beat is not None and sheets and len(sheets) >= beat[0] and not \
                (len(sheets), sum(q.poly.area for q in sheets[-1].placed)) < beat:
            return None
        options = shapes[i] if turn else shapes[i][:1]
        for k in range(len(sheets) + 1):
            if k == len(sheets):
                sheets.append(_Sheet(Lx, Ly, g))
            best = None
            for s in options:
                x, y = sheets[k].places(s)
                tried = 0
                for j in _key(key, x, y, s.h):
                    cand = (y[j], x[j]) if key != "left-bottom" else (x[j], y[j])
                    if key == "low-top":
                        cand = (y[j] + s.h, x[j])
                    if (best is not None and cand >= best[0]) or tried > 20:
                        break
                    if sheets[k].clear(s.poly, x[j], y[j]):
                        best = (cand, s, x[j], y[j])
                        break
                    tried += 1
            if best is not None:
                _, s, x, y = best
                placed[i] = (k, sheets[k].add(s, float(x), float(y)))
                break
            if not sheets[k].placed:
                raise InputError(f"lamella {s.part.strip.lamella}: a piece does not fit an "
                                 f"empty {Lx:g} x {Ly:g} mm sheet; use a larger --sheet or "
                                 "a smaller --gap")
    return sheets, placed


def gap_bound(parts: list[Part], sheet: tuple[float, float], gap: float) -> int:
    """The fewest sheets any layout needs: parts grown by ``gap / 2`` are disjoint and lie
    in the sheet shrunk by ``gap / 2``, so their areas (mm^2) sum to at most
    ``(W - gap) (H - gap)`` per sheet (a lower bound; rounded up)."""
    area = sum(p.polygon(FLAT_TOL).buffer(gap / 2, quad_segs=16).area for p in parts)
    return int(np.ceil(area / ((sheet[0] - gap) * (sheet[1] - gap)) - 1e-9))


def _rows_best(parts: list[Part], shapes: list[list[_Shape]], Lx: float, Ly: float,
               g: float, columns: int = COLUMNS) -> tuple | None:
    """The best plan of :func:`gridshell.fabrication.rows.plan_rows` over 0 .. ``columns`` columns of
    turned strips (first or last): fewest sheets, then the emptiest last sheet, then the
    fewest columns. ``(score, None, plan)``; None if no plan holds the parts."""
    w = np.array([s[0].w for s in shapes])
    h = np.array([s[0].h for s in shapes])
    area = np.array([s[0].poly.area for s in shapes])
    best = None
    for k in range(columns + 1):
        if k and w.min() + 2 * g > Ly + SLACK:
            break                          # no strip fits a column
        for first in ((False, True) if k else (False,)):
            plan = plan_rows(w, h, Lx, Ly, g, columns=k, columns_first=first)
            if plan is None:
                continue
            n = max(s for s, *_ in plan) + 1
            score = (n, float(area[[s == n - 1 for s, *_ in plan]].sum()), k)
            if best is None or score < best[0]:
                best = (score, None, plan)
    return best


def _place_plan(shapes: list[list[_Shape]], plan: list
                ) -> tuple[int, dict[int, tuple[int, tuple[Part, Motion]]]]:
    """Sheet count and placed parts of a :func:`gridshell.fabrication.rows.plan_rows` plan: each part
    (turned by 90 degrees where the plan says so, its box at the origin) and its move to
    ``(x, y)``, as :meth:`_Sheet.add` would leave them (no sheet profiles: nothing is placed
    after them)."""
    placed = {}
    for i, (k, x, y, turned) in enumerate(plan):
        s = _shape(shapes[i][0].part, np.pi / 2, False) if turned else shapes[i][0]
        placed[i] = (k, (s.part, Motion(0.0, float(x), float(y))))
    return max(s for s, *_ in plan) + 1, placed


def _drop_best(shapes: list[list[_Shape]], Lx: float, Ly: float, g: float, strategies: list,
               curved: bool, best: tuple | None, floor: int) -> tuple | None:
    """``best`` or a better layout of the drop ``strategies`` (of :data:`STRATEGIES`), each
    again with the last sheet's parts first (:data:`RETRIES`); stops at ``floor`` sheets."""
    for key, turn, order in strategies:
        if best is not None and best[0][0] <= floor:
            break                         # no layout has fewer sheets
        if turn and not curved:
            continue
        first: list[int] = []
        for r in range(RETRIES + 1):      # the parts left on the last sheet go first next time
            got = _nest_once(shapes, Lx, Ly, g, key, turn, _order(shapes, order, first),
                             best[0] if best is not None and r == RETRIES else None)
            if got is None:               # the last pass of the strategy cannot win
                break
            sheets, placed = got
            last = sum(q.poly.area for q in sheets[-1].placed) if sheets else 0.0
            score = (len(sheets), last)
            if best is None or score < best[0]:
                best = (score, sheets, placed)
            if len(sheets) < 2:
                break
            first = first + [i for i, (k, _) in placed.items()
                             if k == len(sheets) - 1 and i not in first]
    return best


def _raster_best(parts: list[Part], shapes: list[list[_Shape]], Lx: float, Ly: float,
                 g: float, rotation: str, best: tuple | None, floor: int, passes: list
                 ) -> tuple | None:
    """``best`` or a better layout of the raster ``passes`` (of :data:`RASTER`), parts largest
    first; stops at ``floor`` sheets; a pass over :data:`RASTER_WORK` correlations is dropped.
    Under ``rotation="grain"`` parts turn by 0 or 180 degrees only (from their nesting
    orientation, chord along the long side)."""
    polys = [s[0].poly for s in shapes]
    order = sorted(range(len(parts)), key=lambda i: (-polys[i].area, i))
    for res, step, key in passes:
        if best is not None and best[0][0] <= floor:
            break
        got = raster_nest(polys, Lx, Ly, g, order, step=step, turns=rotation, res=res,
                          key=key, budget=RASTER_WORK)
        if got is None:
            continue
        sheet_of, motion, n = got
        last = sum(polys[i].area for i in range(len(parts)) if sheet_of[i] == n - 1)
        if best is None or (n, last) < best[0]:
            best = ((n, last), n, {i: (sheet_of[i], shapes[i][0].part.moved(motion[i]))
                                   for i in range(len(parts))})
    return best


def nest(parts: list[Part], params: FabParams) -> Layout:
    """Place ``parts`` on as many sheets as needed; see the module docstring.

    Straight strips first go in rows and columns (:func:`_rows_best`). Each strategy of
    :data:`STRATEGIES` nests all parts, first fit decreasing: each part
    goes onto the first sheet with room for it, at the best of its drop places there; then
    again (:data:`RETRIES` times) with the parts the last sheet got placed first. Curved parts
    then go through the raster passes (:data:`RASTER`, rotation free unless
    ``params.rotation == "grain"``). The layout with the fewest sheets wins, then the one whose
    last sheet is emptiest; the search stops at :func:`gap_bound`. Raises
    :class:`InputError` for a part that no empty sheet holds
    (:func:`gridshell.fabrication.splice.split_strip` cuts such lamellae into pieces first)."""
    W, H = params.sheet
    Lx, Ly, g = max(W, H), min(W, H), params.gap
    to_sheet = _frame_to_sheet(W, H)
    shapes = [_shapes(p, p.strip.axis.kind != "line") for p in parts]
    curved = any(len(s) > 1 for s in shapes)
    best = None
    floor = gap_bound(parts, params.sheet, g)
    if not curved:
        best = _rows_best(parts, shapes, Lx, Ly, g,
                          0 if params.rotation == "grain" else COLUMNS)
    best = _drop_best(shapes, Lx, Ly, g, STRATEGIES, curved, best, floor)
    if curved:
        best = _raster_best(parts, shapes, Lx, Ly, g, params.rotation, best, floor, RASTER)
    _, sheets, placed = best
    if isinstance(placed, list):           # a rows-and-columns plan: place it now
        sheets, placed = _place_plan(shapes, placed)
    n = sheets if isinstance(sheets, int) else len(sheets)
    idx = sorted(placed)
    return Layout([_moved(placed[i][1]).moved(to_sheet) for i in idx], [placed[i][0] for i in idx],
                  n, (W, H))


def _moved(q: Part | tuple[Part, Motion]) -> Part:
    """A placed part: the part, or the part moved as :meth:`_Sheet.add` left it."""
    return q[0].moved(q[1]) if isinstance(q, tuple) else q


def check_layout(layout: Layout, gap: float, tol: float = 1e-3) -> None:
    """Assert that parts keep ``gap`` mm from each other and from the sheet edges (to SLACK:
    a piece cut to fit the sheet fits it to 0.01 mm)."""
    W, H = layout.sheet
    m = gap - tol - SLACK
    inner = shapely.box(m, m, W - m, H - m)
    for k in range(layout.n_sheets):
        polys = [p.polygon(FLAT_TOL) for p in layout.on_sheet(k)]
        for P in polys:
            if not inner.contains(P):
                raise AssertionError(f"a part leaves sheet {k + 1} or its {gap} mm margin")
        tree = shapely.STRtree(polys)
        for i, P in enumerate(polys):
            for j in tree.query(P.buffer(gap - tol)):
                if j > i and polys[j].distance(P) < gap - tol:
                    raise AssertionError(f"parts {i} and {j} on sheet {k + 1} are closer than "
                                         f"{gap} mm")
