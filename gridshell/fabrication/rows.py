"""Straight strips in rows and columns: the sheet as one-dimensional bins (pure arithmetic, mm).

Straight strips are rectangles of one width ``h`` and lengths ``w``. On a sheet ``Lx x Ly``
(``Lx >= Ly``) with ``gap`` g between parts and from the edges, a row along the long side
holds strips whose ``sum(w + g)`` is at most ``Lx - g``; rows stack ``max h + g`` apart. Rows
alone leave a band under ``h + g`` at the top and cap the use of thin strips; ``columns`` of
strips turned by 90 degrees at the sheet's right end (each ``max h + g`` wide, holding
``sum(w + g) <= Ly - g``) trade ``rows x (h + g)`` of row length for ``Ly - g`` of column
length, which packs tighter when ``Ly`` is not a multiple of ``h + g`` - and holds the long
strips that leave awkward remainders in a row. Each bin is filled as full as it can be with
the longest strip left that fits it and the subset of the others that fills the rest best.
"""
from __future__ import annotations

import numpy as np

ROW_UNIT = 0.1     # mm, the length unit of the row filling
SLACK = 0.05       # mm: a piece cut to fit the sheet (to 0.01 mm, arcs sampled) fits it


def fullest(lengths: np.ndarray, cap: float) -> list[int]:
    """Indices of a subset of ``lengths`` that contains the first and whose sum is largest
    but at most ``cap`` (subset sum over ROW_UNIT steps, lengths rounded up)."""
    units = np.ceil(lengths / ROW_UNIT - 1e-9).astype(int).tolist()
    c = int(np.floor(cap / ROW_UNIT + 1e-9)) - units[0]
    if c < 0:
        return []
    # the sums reachable with the items so far: bit i of an int for a sum of i units
    full = (1 << (c + 1)) - 1
    reach = 1
    history = []
    for u in units[1:]:
        history.append(reach)
        if u <= c:
            reach = (reach | reach << u) & full
    total = reach.bit_length() - 1
    chosen = [0]
    for k in range(len(units) - 1, 0, -1):      # walk back through the items
        if not history[k - 1] >> total & 1:
            chosen.append(k)
            total -= units[k]
    return sorted(chosen)


def _pick(left: list[int], L: np.ndarray, cap: float) -> list[int]:
    """The fullest bin of capacity ``cap`` from ``left`` (sorted longest first; ``L``: the
    lengths plus the gap): the longest that fits and the best subset of the others."""
    fit = [i for i in left if L[i] <= cap]
    return [fit[k] for k in fullest(L[fit], cap)] if fit else []


def plan_rows(w: np.ndarray, h: np.ndarray, Lx: float, Ly: float, gap: float,
              columns: int = 0, columns_first: bool = False
              ) -> list[tuple[int, float, float, bool]] | None:
    """Place strips ``w x h`` (mm, length along x) in rows and ``columns`` columns per sheet.

    Returns, per strip, ``(sheet, x, y, turned)``: the 0-based sheet and the lower-left corner
    of its box there, ``turned`` if it stands in a column (turned by 90 degrees, box
    ``h x w``); None when a strip fits no bin. Sheets are filled one after the other, the
    columns before the rows when ``columns_first``."""
    g = gap
    cw = float(np.max(h)) + g if len(h) else g
    xc = Lx - columns * cw                   # the columns start here
    if xc - g <= 0:
        return None
    L = np.asarray(w, float) + g
    row_cap, col_cap = xc - g + SLACK, Ly - g + SLACK
    left = sorted(range(len(w)), key=lambda i: (-w[i], i))
    out: dict[int, tuple[int, float, float, bool]] = {}
    sheet = -1

    def fill_columns() -> None:
        nonlocal left
        for j in range(columns):
            chosen = _pick(left, L, col_cap)
            y = g
            for i in chosen:
                out[i] = (sheet, xc + j * cw, y, True)
                y += L[i]
            left = [i for i in left if i not in set(chosen)]

    def fill_rows() -> None:
        nonlocal left
        y = g
        while left:
            chosen = _pick(left, L, row_cap)
            if not chosen:
                return
            top = max(h[i] for i in chosen)
            if y + top > Ly - g + SLACK:
                return
            x = g
            for i in chosen:
                out[i] = (sheet, x, y, False)
                x += L[i]
            y += top + g
            left = [i for i in left if i not in set(chosen)]

    while left:
        sheet += 1
        before = len(left)
        for fill in ((fill_columns, fill_rows) if columns_first else (fill_rows, fill_columns)):
            fill()
        if len(left) == before:
            return None
    return [out[i] for i in range(len(w))]
