"""Regions of a curvature map: connected areas of one class (K > 0, K < 0, near umbilic)
and the largest parameter rectangle a mode admits.

A rectangle of the fitted surface's parameter plane is a patch with four boundary curves
and no hole; the NCP modes design on such a patch (paper 4.2: a regular patch of curvature
lines, devoid of singularities), so the largest admissible one is the largest rectangle of
samples that are on the target and admitted by the mode (no near-umbilic sample for PHLW
and CNC, K < 0 everywhere for AA). Its sides are the fit's parameter lines, which the PHLW
step turns onto the principal lines: the rectangle is an estimate of the region, not its
exact boundary.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gridshell.analysis.maps import CurvatureMap

__all__ = ["Rectangle", "Region", "largest_rectangle", "regions"]


@dataclass(frozen=True)
class Region:
    """A connected region of one class: ``kind``, its share of the target's area (0..1),
    its centre (the area-weighted mean of its samples, metres), its sample count and its
    samples (``mask``, the map's shape)."""

    kind: str
    share: float
    centre: tuple[float, float, float]
    samples: int
    mask: np.ndarray | None = field(default=None, repr=False, compare=False)

    def as_dict(self) -> dict:
        return {"kind": self.kind, "share_percent": round(100 * self.share, 2),
                "centre_m": [round(c, 4) for c in self.centre], "samples": self.samples}


@dataclass(frozen=True)
class Rectangle:
    """The largest admissible parameter rectangle: sample index ranges ``rows = (i0, i1)``,
    ``cols = (j0, j1)`` (inclusive), its parameters ``u = (u0, u1)``, ``v = (v0, v1)`` and
    its share of the target's area (0..1)."""

    rows: tuple[int, int]
    cols: tuple[int, int]
    u: tuple[float, float]
    v: tuple[float, float]
    share: float

    def as_dict(self) -> dict:
        return {"u": [round(x, 4) for x in self.u], "v": [round(x, 4) for x in self.v],
                "share_percent": round(100 * self.share, 2)}


def regions(m: CurvatureMap, mask: np.ndarray, kind: str, min_share: float = 0.005
            ) -> list[Region]:
    """The connected regions (4-neighbours on the sample grid) of the on-target samples of
    ``mask``, largest first, those below ``min_share`` of the area left out."""
    from scipy import ndimage

    labels, n = ndimage.label(mask & m.on_target)
    out = []
    for k in range(1, n + 1):
        sel = labels == k
        share = m.share(sel)
        if share < min_share:
            continue
        w = m.area[sel]
        c = (m.S[sel] * w[:, None]).sum(0) / max(w.sum(), 1e-300)
        out.append(Region(kind, share, tuple(float(x) for x in c), int(sel.sum()), sel))
    return sorted(out, key=lambda r: -r.share)


def largest_rectangle(m: CurvatureMap, admitted: np.ndarray) -> Rectangle | None:
    """The rectangle of samples, all on the target and ``admitted``, of the largest area
    (the maximal-rectangle search over column histograms, O(n^2)); None if there is none."""
    ok = admitted & m.on_target
    R, C = ok.shape
    heights = np.zeros(C, int)
    best, box = 0.0, None
    A = np.where(m.on_target, m.area, 0.0)
    cum = np.zeros((R + 1, C + 1))                       # prefix sums of the cell areas
    cum[1:, 1:] = A.cumsum(0).cumsum(1)

    def area(i0, i1, j0, j1):
        return cum[i1 + 1, j1 + 1] - cum[i0, j1 + 1] - cum[i1 + 1, j0] + cum[i0, j0]
    for i in range(R):
        heights = np.where(ok[i], heights + 1, 0)
        stack: list[int] = []
        for j in range(C + 1):
            h = heights[j] if j < C else 0
            while stack and heights[stack[-1]] >= h:
                top = stack.pop()
                left = stack[-1] + 1 if stack else 0
                if heights[top] > 0:
                    a = area(i - heights[top] + 1, i, left, j - 1)
                    if a > best:
                        best, box = a, (i - heights[top] + 1, i, left, j - 1)
            stack.append(j)
    if box is None:
        return None
    i0, i1, j0, j1 = box
    return Rectangle((i0, i1), (j0, j1), (float(m.u[i0]), float(m.u[i1])),
                     (float(m.v[j0]), float(m.v[j1])), m.share(_box(ok.shape, box)))


def _box(shape: tuple[int, int], box: tuple[int, int, int, int]) -> np.ndarray:
    mask = np.zeros(shape, bool)
    mask[box[0]:box[1] + 1, box[2]:box[3] + 1] = True
    return mask
