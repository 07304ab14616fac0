"""Raster nesting of curved parts: free rotation, bottom-left placement by FFT correlation (mm).

Each part, grown by half the gap, is rasterized at :data:`RES` mm per pixel (pixel centres
inside the grown outline plus :data:`MARGIN`) at every ``step`` degrees of rotation; the
sheet is a pixel grid whose placed parts mark their pixels. The free places of a part at one
rotation are the pixel offsets where the correlation of the sheet's occupancy with the part's
mask is zero: one FFT product per rotation (all rotations at once), found with
:func:`scipy.fft.irfft2`. A part goes to the first open sheet with a free place, at the
place whose ranking point (the part's bottom, top or centroid: :func:`_lift`) is lowest, then
leftmost. The offsets are chosen so that the part's box keeps the gap from
the sheet edges exactly; the raster only proposes: each place is checked with the exact
outlines (shapely distance at least the gap to every placed part) and the next best is taken
when the check fails.

Rotation is free for isotropic sheet materials (polypropylene, acrylic, MDF, sheet metal);
``turns="grain"`` keeps parts at 0 or 180 degrees from their chord along the sheet's long side,
for plywood whose grain should run along the strips.

A sheet is tried only with the rotations whose mask can fit its free pixels at all: a mask
that fits, translated, inside the free pixels has its deepest pixel (Euclidean distance to the
nearest pixel outside the mask) on a free pixel at least as deep (:func:`depth`). On a nearly
full sheet most rotations, often all, fail that test and skip the FFT product (on a 150-piece
CNC layout 97 % of the failing tries; the layouts are the same).
"""
from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass

import numpy as np
import scipy.fft
import shapely
import shapely.affinity
from shapely.geometry import Polygon

from gridshell.fabrication.path import Motion

RES = 1.0          # mm per pixel of the raster
MARGIN = 0.3       # mm, extra growth of the rasterized outlines (pays for pixel sampling)
STEP = 10.0        # degrees between the rotations tried
FREE = 0.5         # a correlation under this is a free place (it counts pixels)
CHECKS = 40        # most raster places checked with shapely per part, rotation and sheet
#: outlines whose poses are kept (each: one FFT per rotation, ~1 MB per 600 x 400 mm sheet at
#: 1 mm pixels); parts go largest first, so congruent parts come one after another
POSES = 8


def fill(ring: np.ndarray, nx: int, ny: int, res: float = RES) -> np.ndarray:
    """Boolean ``(ny, nx)`` image: pixels ``[j res, (j+1) res] x [i res, (i+1) res]`` whose
    centre is inside the closed ring ``(k,2)`` (even-odd rule: each edge toggles the pixels
    right of where it crosses a row of centres)."""
    a, b = ring[:-1] / res - 0.5, ring[1:] / res - 0.5       # pixel-centre units
    lo, hi = np.minimum(a[:, 1], b[:, 1]), np.maximum(a[:, 1], b[:, 1])
    r0 = np.floor(lo).astype(int) + 1                          # rows with lo < i <= hi
    r1 = np.floor(hi).astype(int)
    cnt = np.maximum(r1 - r0 + 1, 0)
    e = np.repeat(np.arange(len(a)), cnt)
    i = r0[e] + np.arange(cnt.sum()) - np.repeat(np.cumsum(cnt) - cnt, cnt)
    t = (i - a[e, 1]) / (b[e, 1] - a[e, 1])
    x = a[e, 0] + t * (b[e, 0] - a[e, 0])
    j = np.clip(np.floor(x).astype(int) + 1, 0, nx)
    ok = (i >= 0) & (i < ny)
    out = np.zeros((ny, nx), bool)
    if not ok.any():
        return out
    i, j = i[ok], j[ok]
    i0, i1, j0, j1 = i.min(), i.max() + 1, j.min(), j.max() + 1   # the ring's box
    tog = np.zeros((i1 - i0, j1 - j0 + 1), np.int32)
    np.add.at(tog, (i - i0, j - j0), 1)
    out[i0:i1, j0:min(j1, nx)] = (np.cumsum(tog, axis=1)[:, :min(j1, nx) - j0] % 2) == 1
    return out


def depth(mask: np.ndarray) -> float:
    """The largest Euclidean distance (pixels) of a pixel of the boolean ``mask`` to the
    nearest pixel outside it (outside the image counts as outside); 0 for an empty mask. A
    mask that fits inside another by a translation is at most as deep as it."""
    import scipy.ndimage      # here: ~0.1 s to import, and only raster passes need it

    rows, cols = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
    if not len(rows):
        return 0.0
    box = mask[rows[0]:rows[-1] + 1, cols[0]:cols[-1] + 1]
    return float(scipy.ndimage.distance_transform_edt(np.pad(box, 1)).max())


@dataclass
class _Pose:
    """One rotation of a shape: the polygon placed at the sheet's lower-left free corner
    (offset 0, 0), its mask there, the FFT of the mask, the number of offsets ``(ni, nj)``,
    the mask's :func:`depth` (pixels)."""

    angle: float
    poly: Polygon
    motion: Motion
    n: tuple[int, int]
    fft: np.ndarray
    depth: float


def _poses(poly: Polygon, Lx: float, Ly: float, gap: float, angles: np.ndarray,
           shape: tuple[int, int], res: float) -> list[_Pose]:
    """The shape ``poly`` at each angle (radians), lower-left at ``gap`` from the sheet edges."""
    ny, nx = shape
    out = []
    for t in angles:
        m0 = Motion(float(t), 0.0, 0.0)
        p = shapely.affinity.rotate(poly, float(t), origin=(0, 0), use_radians=True)
        x0, y0, x1, y1 = p.bounds
        nj = int(np.floor((Lx - 2 * gap - (x1 - x0)) / res + 1e-9)) + 1
        ni = int(np.floor((Ly - 2 * gap - (y1 - y0)) / res + 1e-9)) + 1
        if ni < 1 or nj < 1:
            continue
        m = m0.then(Motion(0.0, gap - x0, gap - y0))
        p = shapely.affinity.translate(p, gap - x0, gap - y0)
        g = p.buffer(gap / 2 + MARGIN, quad_segs=8)
        ring = np.asarray(g.exterior.coords)
        mask = fill(ring, nx, ny, res)
        out.append(_Pose(float(t), p, m, (ni, nj),
                         np.conj(scipy.fft.rfft2(mask.astype(np.float32))), depth(mask)))
    return out


def _lift(p: _Pose, key: str) -> float:
    """The height (mm) of the point of pose ``p`` whose height ranks the places: its
    bottom (``"bottom"``), top or centroid above the pose's bottom."""
    b = p.poly.bounds
    return {"bottom": 0.0, "top": b[3] - b[1], "centre": p.poly.centroid.y - b[1]}[key]


class _Sheet:
    """A raster sheet: occupancy image, its FFT, the exact placed polygons, the
    :func:`depth` of its free pixels within ``extent`` (pixel rows and columns of the sheet)
    and the number of correlations (one per rotation) computed on it."""

    def __init__(self, shape: tuple[int, int], extent: tuple[int, int]):
        self.occ = np.zeros(shape, np.float32)
        self.fft = scipy.fft.rfft2(self.occ)
        self.polys: list[Polygon] = []
        self.extent = extent
        self.depth = self._free_depth()
        self.correlations = 0

    def _free_depth(self) -> float:
        a, b = self.extent
        return depth(self.occ[:a, :b] < FREE)

    def place(self, poses: tuple[list[_Pose], np.ndarray | None], gap: float, res: float,
              shape: tuple[int, int], key: str = "bottom") -> tuple[_Pose, float, float] | None:
        """The free place over the poses (and their masks' FFTs stacked) whose ranking height
        (``key``) is lowest, then leftmost, checked exactly; None if there is none."""
        poses, stack = poses
        fits = [k for k, p in enumerate(poses) if p.depth <= self.depth]
        if len(fits) < len(poses):          # rotations too deep for the free pixels
            poses, stack = [poses[k] for k in fits], stack[fits]
        if not poses:
            return None
        if self.polys:
            self.correlations += len(poses)
            F = stack * self.fft[None]
            corr = scipy.fft.irfft2(F, s=shape, axes=(1, 2))
        lifts = [_lift(p, key) / res for p in poses]
        best = None
        for k in np.argsort(lifts, kind="stable"):
            p, lift = poses[k], lifts[k]
            if best is not None and lift >= best[0][0]:
                break                       # no place of this pose or the next ranks better
            ni, nj = p.n
            free = corr[k, :ni, :nj] < FREE if self.polys else np.ones((ni, nj), bool)
            tried = 0
            for i in np.flatnonzero(free.any(axis=1)):
                if (best is not None and (i + lift, 0) >= best[0]) or tried >= CHECKS:
                    break
                for j in np.flatnonzero(free[i])[:CHECKS - tried]:
                    tried += 1
                    if self._clear(p.poly, j * res, i * res, gap):
                        if best is None or (i + lift, j) < best[0]:
                            best = ((i + lift, j), p, i, j)
                        break
                else:
                    continue
                break
        if best is None:
            return None
        _, p, i, j = best
        return p, float(j * res), float(i * res)

    def _clear(self, poly: Polygon, x: float, y: float, gap: float) -> bool:
        cand = shapely.affinity.translate(poly, x, y)
        b = cand.bounds
        for q in self.polys:
            c = q.bounds
            if (c[0] - gap < b[2] and c[2] + gap > b[0] and c[1] - gap < b[3]
                    and c[3] + gap > b[1] and cand.distance(q) < gap - 1e-6):
                return False
        return True

    def add(self, pose: _Pose, x: float, y: float, gap: float, res: float) -> Polygon:
        poly = shapely.affinity.translate(pose.poly, x, y)
        ny, nx = self.occ.shape
        ring = np.asarray(poly.buffer(gap / 2 + MARGIN, quad_segs=8).exterior.coords)
        self.occ = np.maximum(self.occ, fill(ring, nx, ny, res).astype(np.float32))
        self.fft = scipy.fft.rfft2(self.occ)
        self.polys.append(poly)
        self.depth = self._free_depth()
        return poly


def raster_nest(polys: list[Polygon], Lx: float, Ly: float, gap: float,
                order: list[int], step: float = STEP, turns: str = "free",
                res: float = RES, key: str = "bottom", budget: int | None = None
                ) -> tuple[list[int], list[Motion], int] | None:
    """Place ``polys`` (part outlines, mm) in ``order`` on sheets ``Lx x Ly`` (``Lx >= Ly``),
    ``gap`` mm apart and from the edges, turned every ``step`` degrees (``turns="free"``) or by
    0 and 180 degrees (``"grain"``); ``key``: the height that ranks places (:func:`_lift`).

    Returns per polygon its sheet (0-based) and the motion that places it, and the number of
    sheets; None if a polygon fits no empty sheet or the pass needs more than ``budget``
    correlations (one per rotation and sheet tried; ~3 ms each on a 600 x 400 mm sheet at
    1 mm pixels, 2 cores): a big layout then keeps the drop nesting's."""
    extent = (int(np.ceil(Ly / res)), int(np.ceil(Lx / res)))      # the sheet's pixels
    shape = tuple(scipy.fft.next_fast_len(n, real=True) for n in extent)
    if turns == "grain":
        angles = np.array([0.0, np.pi])
    else:
        angles = np.radians(np.arange(0.0, 360.0, step))
    cache: OrderedDict = OrderedDict()      # the poses of the last POSES outlines

    def poses_of(P: Polygon) -> tuple[Motion, tuple[list[_Pose], np.ndarray | None]]:
        """The move of ``P`` to the origin and its poses (with their FFTs stacked)."""
        x0, y0, _, _ = P.bounds                   # parts of one outline share their poses
        pre = Motion(0.0, -x0, -y0)
        same = np.round(np.asarray(P.exterior.coords) - (x0, y0), 3).tobytes()
        if same in cache:
            cache.move_to_end(same)
            return pre, cache[same]
        ps = _poses(shapely.affinity.translate(P, -x0, -y0), Lx, Ly, gap, angles, shape, res)
        stack = np.stack([p.fft for p in ps]) if ps else None
        for k, p in enumerate(ps):
            p.fft = stack[k]                      # a view: one copy of the FFTs
        cache[same] = (ps, stack)
        if len(cache) > POSES:
            cache.popitem(last=False)
        return pre, cache[same]

    sheets: list[_Sheet] = []
    sheet_of = [0] * len(polys)
    motion = [Motion()] * len(polys)
    for i in order:
        pre, ps = poses_of(polys[i])
        for k in range(len(sheets) + 1):
            if k == len(sheets):
                sheets.append(_Sheet(shape, extent))
            got = sheets[k].place(ps, gap, res, shape, key)
            if budget is not None and sum(s.correlations for s in sheets) > budget:
                return None
            if got is not None:
                break
            if not sheets[k].polys:
                return None
        pose, x, y = got
        sheets[k].add(pose, x, y, gap, res)
        sheet_of[i] = k
        motion[i] = pre.then(pose.motion).then(Motion(0.0, x, y))
    return sheet_of, motion, len(sheets)
