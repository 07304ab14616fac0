"""Nesting parts on sheets (issue item 4): never overlapping, never outside a sheet.

* straight strips: rows along the sheet's long side, filled first-fit decreasing (the
  longest strip goes into the first row, on any sheet, with room for it);
* curved strips (arcs, collapse-curve pieces): turned so that their chord lies along the long
  side (``+s`` along ``+x``, so labels read upright), then stacked across it - along the
  symmetry direction of an arc: each part drops
  onto the ones below it in its stack until it comes ``gap`` from them (the congruent pieces of
  one curve nest into each other). Each part goes into the first stack with room for it, else
  into a new stack right of the others on the first sheet with room, else on a new sheet.

All parts keep ``gap`` mm from each other and from the sheet edges. Sheets are filled in a
frame whose x axis is the sheet's long side, then turned to the sheet as given.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely
import shapely.affinity
from shapely.geometry import Polygon

from .params import FabParams
from .part import Part
from .path import Motion
from .splice import chord_frame


DROP_TOL = 0.02    # mm, ring simplification for the drop search
CHECK_TOL = 0.001  # mm, for the distance check that follows it
FLAT_TOL = 0.01    # mm, chord tolerance of the part polygons (arcs bulge out by up to this)


@dataclass
class Layout:
    """Parts placed on ``n_sheets`` sheets: ``parts[i]`` lies on sheet ``sheet_of[i]`` (0-based)."""

    parts: list[Part]
    sheet_of: list[int]
    n_sheets: int
    sheet: tuple[float, float]

    def on_sheet(self, k: int) -> list[Part]:
        return [p for p, s in zip(self.parts, self.sheet_of) if s == k]


def _canonical(part: Part, curved: bool) -> Part:
    """The part turned into the nesting orientation with its bounding box at the origin."""
    if curved:
        _, u = chord_frame(part.strip)
        ang = -np.arctan2(u[1], u[0])
        p = part.moved(Motion(ang, 0.0, 0.0))     # +s along +x: labels read upright
    else:
        p = part
    x0, y0, _, _ = p.polygon(FLAT_TOL).bounds
    return p.moved(Motion(0.0, -x0, -y0))


def _drop(A: np.ndarray, B: np.ndarray) -> float:
    """How far polygon ``B`` (closed ring ``(m,2)``) can fall in -y before touching polygon
    ``A`` (ring ``(n,2)``); +inf if it passes by. Vertical rays from B's vertices down to A's
    edges and from A's vertices up to B's edges."""
    def rays(P, Q, sign):
        q0, q1 = Q[:-1], Q[1:]
        xa, xb = np.minimum(q0[:, 0], q1[:, 0]), np.maximum(q0[:, 0], q1[:, 0])
        x = P[:, 0][:, None]
        inside = (x >= xa) & (x <= xb) & (xb > xa)
        f = np.where(inside, (x - q0[:, 0]) / np.where(xb > xa, q1[:, 0] - q0[:, 0], 1.0), 0.0)
        y = q0[:, 1] + f * (q1[:, 1] - q0[:, 1])
        d = sign * (P[:, 1][:, None] - y)
        d = np.where(inside & (d >= -1e-9), d, np.inf)
        return d.min(initial=np.inf)
    return min(rays(B, A, 1.0), rays(A, B, -1.0))


def _ring(poly: Polygon) -> np.ndarray:
    return np.asarray(poly.exterior.coords)


def _frame_to_sheet(W: float, H: float) -> Motion:
    """From the nesting frame (long side along x) to the sheet as given."""
    return Motion() if W >= H else Motion(np.pi / 2, W, 0.0)


def nest(parts: list[Part], params: FabParams) -> Layout:
    """Place ``parts`` on as many sheets as needed; see the module docstring."""
    W, H = params.sheet
    Lx, Ly, g = max(W, H), min(W, H), params.gap
    to_sheet = _frame_to_sheet(W, H)
    placed: list[tuple[int, Part]] = []
    n_sheets = 0
    straight = [p for p in parts if p.strip.axis.kind == "line"]
    curved = [p for p in parts if p.strip.axis.kind != "line"]

    # rows, first-fit decreasing
    if straight:
        canon = [_canonical(p, False) for p in straight]
        order = sorted(range(len(canon)), key=lambda i: -canon[i].polygon().bounds[2])
        rows: list[list[float]] = []      # [sheet, y, x_end, height]
        for i in order:
            p = canon[i]
            _, _, w, h = p.polygon(FLAT_TOL).bounds
            row = next((r for r in rows if r[2] + g + w <= Lx - g + 1e-9 and h <= r[3] + 1e-9),
                       None)
            if row is None:
                last = [r for r in rows if r[0] == n_sheets - 1]
                y = (last[-1][1] + last[-1][3] + g) if last else g
                if not last or y + h > Ly - g + 1e-9:
                    n_sheets += 1
                    y = g
                row = [n_sheets - 1, y, 0.0, h]
                rows.append(row)
            placed.append((row[0], p.moved(Motion(0.0, row[2] + g, row[1]))))
            row[2] += g + w

    # stacks of curved parts
    if curved:
        canon = [_canonical(p, True) for p in curved]
        order = sorted(range(len(canon)), key=lambda i: -canon[i].polygon().bounds[2])

        # a stack: sheet, x, width, parts [(ring, grown ring, top)]
        def try_stack(st: dict, poly: Polygon, w: float, h: float):
            x = st["x"] + 0.5 * (st["width"] - w)
            if not st["parts"]:
                return x, g
            coarse = poly.simplify(DROP_TOL)
            B = _ring(coarse) + [x, 0.0]
            y0 = max(t for _, _, t in st["parts"]) + g       # B entirely above the stack
            d = min(_drop(A, B + [0.0, y0]) for _, A, _ in st["parts"])
            y = max(g, y0 - d) if np.isfinite(d) else g
            fine = poly.simplify(CHECK_TOL)
            while True:       # the drop used coarse rings: make sure, nudge up
                cand = shapely.affinity.translate(fine, x, y)
                need = g + 2 * CHECK_TOL + 2 * FLAT_TOL
                short = max(need - cand.distance(A) for A, _, _ in st["parts"])
                if short <= 0:
                    break
                y += short + 0.01
            return (x, y) if y + h <= Ly - g + 1e-9 else None

        stacks: list[dict] = []
        right: dict[int, float] = {}    # per sheet of stacks: x where the next stack may start

        for i in order:
            p = canon[i]
            poly = p.polygon(FLAT_TOL)
            _, _, w, h = poly.bounds
            stack, pos = None, None
            for st in stacks:           # first fit: the first stack with room for it
                if w <= st["width"] + 1e-9:
                    pos = try_stack(st, poly, w, h)
                    if pos is not None:
                        stack = st
                        break
            if stack is None:           # a new stack right of the others, on any sheet
                k = next((k for k, x in right.items() if x + w <= Lx - g + 1e-9), None)
                if k is None:
                    n_sheets += 1
                    k = n_sheets - 1
                    right[k] = g
                stack = {"sheet": k, "x": right[k], "width": w, "parts": []}
                stacks.append(stack)
                right[k] += w + g
                pos = try_stack(stack, poly, w, h)
            q = p.moved(Motion(0.0, *pos))
            qp = q.polygon(FLAT_TOL)
            stack["parts"].append((qp.simplify(CHECK_TOL),
                                   _ring(qp.simplify(DROP_TOL).buffer(g + 2 * FLAT_TOL,
                                                                      quad_segs=8)),
                                   pos[1] + h))
            placed.append((stack["sheet"], q))

    out_parts = [p.moved(to_sheet) for _, p in placed]
    return Layout(out_parts, [s for s, _ in placed], n_sheets, (W, H))


def check_layout(layout: Layout, gap: float, tol: float = 1e-6) -> None:
    """Assert that parts keep ``gap`` from each other and lie inside their sheets."""
    W, H = layout.sheet
    sheet = shapely.box(0, 0, W, H)
    for k in range(layout.n_sheets):
        polys = [p.polygon(FLAT_TOL) for p in layout.on_sheet(k)]
        for P in polys:
            if not sheet.contains(P):
                raise AssertionError(f"a part leaves sheet {k + 1}")
        tree = shapely.STRtree(polys)
        for i, P in enumerate(polys):
            for j in tree.query(P.buffer(gap - tol)):
                if j > i and polys[j].distance(P) < gap - 1e-3:
                    raise AssertionError(f"parts {i} and {j} on sheet {k + 1} are closer than "
                                         f"{gap} mm")
