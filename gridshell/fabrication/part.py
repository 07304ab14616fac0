"""A Part: the cut geometry of one strip in the plane, by layer, in mm.

``outline`` (CUT, closed, bulges for arcs), ``holes`` (CUT circles), ``scores`` (SCORE line
segments), ``engrave`` (ENGRAVE stroke polylines). :func:`build_part` makes it from a
:class:`~gridshell.fabrication.strip.Strip` (:func:`build_parts` the parts of many strips at once);
``Part.moved`` places it on a sheet.
"""
from __future__ import annotations

import math

from dataclasses import dataclass, field

import numpy as np
import shapely
from shapely.geometry import Polygon

from gridshell.core.errors import InputError

from gridshell.fabrication.joints import hole_centres, joint_points, outline_corners, score_marks
from gridshell.fabrication.kerf import hole_radius, offset_corners
from gridshell.fabrication.labels import labelled, safe_regions, strip_labels
from gridshell.fabrication.params import FabParams
from gridshell.fabrication.path import Motion, Path
from gridshell.fabrication.strip import Strip


@dataclass
class Part:
    """Cut geometry of one strip.

    Attributes
    ----------
    strip : Strip
    outline : Path
        Closed cut path (kerf-compensated when asked).
    holes : (k,2) float, radii : (k,) float
        Hole centres and cut-path radii.
    scores : (m,2,2) float
        Score line segments.
    engrave : list of (p,2) float
        Label strokes.
    joints : (j,2) float
        The joints on the axis (not written; for checks and the cut list).
    nominal : Path
        The outline without kerf compensation.
    labels_dropped : int
    area : float
        Material area of the nominal part (outline minus holes), mm^2.
    motion : Motion
        The placement applied so far (identity for a fresh part).
    """

    strip: Strip
    outline: Path
    holes: np.ndarray
    radii: np.ndarray
    scores: np.ndarray
    engrave: list[np.ndarray]
    joints: np.ndarray
    nominal: Path
    labels_dropped: int = 0
    area: float = 0.0
    motion: Motion = field(default_factory=Motion)

    def moved(self, m: Motion) -> "Part":
        """The part moved by ``m`` (every layer; the points as :meth:`Motion.apply` and
        :meth:`Path.moved` move them, the rotation made once)."""
        o, n = self.outline, self.nominal
        V, W, holes, scores, joints, *engrave = m.apply_each(
            [o.V, n.V, self.holes, self.scores.reshape(-1, 2), self.joints, *self.engrave])
        return Part(self.strip, Path(V, o.B.copy(), o.closed), holes.reshape(-1, 2),
                    self.radii, scores.reshape(-1, 2, 2), engrave, joints.reshape(-1, 2),
                    Path(W, n.B.copy(), n.closed), self.labels_dropped, self.area,
                    self.motion.then(m))

    def polygon(self, tol: float = 0.05) -> Polygon:
        """The outline as a shapely polygon (no holes): the sheet area the part takes."""
        return Polygon(self.outline.flatten(tol))



def _corners_to_path(axis, C: np.ndarray, tol: float) -> Path:
    Vs, Bs = [], []
    n = len(C)
    for i in range(n):
        a, b = C[i], C[(i + 1) % n]
        if i % 2 == 0:
            V, B = axis.edge(a[0], b[0], a[1], tol)
        else:
            V, B = axis.point(a[0], a[1])[None], np.zeros(1)
        Vs.append(V)
        Bs.append(B)
    return Path(np.concatenate(Vs), np.concatenate(Bs), closed=True)


def joint_clearance(strip: Strip, params: FabParams) -> tuple[float, float]:
    """``(gap, need)``: the smallest distance between neighbouring joints (and splice
    fasteners) of ``strip`` and the distance its joint features (hole, slot, mark) need so as
    not to merge, mm (``gap`` is inf with fewer than two)."""
    s = np.sort(np.concatenate([strip.joint_s, strip.splice_s]))
    gap = float(np.min(np.diff(s))) if len(s) >= 2 else math.inf
    need = {"hole": params.hole, "slots": params.slot_width, "marks": 0.0}[params.joints] + 0.5
    return gap, need


def check_spacing(strip: Strip, params: FabParams) -> None:
    """Raise InputError if neighbouring joint (or splice fastener) features would merge."""
    gap, need = joint_clearance(strip, params)
    if gap < need:
        raise InputError(f"lamella {strip.lamella}: two joints are only {gap:.3g} mm apart at "
                         f"this scale, too close for {params.joints} of {need - 0.5:g} mm; use a "
                         "larger --scale or smaller --hole/--thickness")


def build_part(strip: Strip, params: FabParams) -> Part:
    """Outline (with slots), holes, score marks and labels of ``strip``."""
    return build_parts([strip], params)[0]


def build_parts(strips: list[Strip], params: FabParams) -> list[Part]:
    """:func:`build_part` of each of ``strips``. The parts' material polygons (outline less
    the hole circles), their areas (mm^2) and the labels' safe regions are made for all
    parts at once with shapely's vectorized functions: the same GEOS operations, one
    geometry at a time, as part by part (the same polygons; test)."""
    parts = [_cut(strip, params) for strip in strips]
    tol = params.tolerance
    mats = np.empty(len(parts), dtype=object)
    mats[:] = [Polygon(p.nominal.flatten(tol)) for p in parts]
    drilled = [i for i, p in enumerate(parts) if len(p.holes)]
    if drilled:
        # the hole circles (32 segments a quarter) buffered at once: the same polygons as
        # Point(c).buffer(r, 32) one by one; each part's united, then cut from its outline
        counts = [len(parts[i].holes) for i in drilled]
        centres = np.concatenate([np.asarray(parts[i].holes, float) for i in drilled])
        circles = shapely.buffer(shapely.points(centres), params.hole / 2, quad_segs=32)
        rows = np.full((len(drilled), max(counts)), None, dtype=object)
        start = 0
        for r, k in enumerate(counts):
            rows[r, :k] = circles[start:start + k]
            start += k
        mats[drilled] = shapely.difference(mats[drilled], shapely.union_all(rows, axis=1))
    for p, area in zip(parts, shapely.area(mats).tolist()):
        p.area = area
    if params.labels:
        wide = [i for i, s in enumerate(strips) if labelled(s, params)]
        safe = dict(zip(wide, safe_regions(mats[wide]))) if wide else {}
        for i, (p, s) in enumerate(zip(parts, strips)):
            p.engrave, p.labels_dropped = strip_labels(s, params, mats[i], safe.get(i))
    return parts


def _cut(strip: Strip, params: FabParams) -> Part:
    """The part of ``strip`` without its labels and area: outline (with slots), holes and
    score marks (raises InputError where joint features would merge)."""
    check_spacing(strip, params)
    tol = params.tolerance
    C = outline_corners(strip, params)
    nominal = _corners_to_path(strip.axis, C, tol)
    d = params.kerf / 2
    outline = _corners_to_path(strip.axis, offset_corners(strip.axis, C, d), tol) if d else nominal
    k = len(strip.joint_s)
    if params.joints == "hole":
        holes, radii = hole_centres(strip), np.full(k, hole_radius(params.hole, params.kerf))
    else:
        holes, radii = np.zeros((0, 2)), np.zeros(0)
    scores = score_marks(strip) if params.joints == "marks" else np.zeros((0, 2, 2))
    if len(strip.splice_s):      # span-splice fasteners: holes, else score marks
        f = len(strip.splice_s)
        if params.joints == "hole":
            holes = np.concatenate([holes, hole_centres(strip, strip.splice_s)])
            radii = np.concatenate([radii, np.full(f, hole_radius(params.hole, params.kerf))])
        else:
            scores = np.concatenate([scores, score_marks(strip, strip.splice_s)])
    return Part(strip, outline, holes, radii, scores, [], joint_points(strip), nominal)
