"""Lamella fairness and net sanity: the figures Delta_a, Delta_l and Delta_n do not see.

A net can meet the paper's figures and still not be buildable: a lamella that loops on
itself, turns in a hairpin or has a corner, strips that leave the surface, net-loops that
fold over during the alignment. Measured per lamella at the design's resolution (the dense
axis polyline), with the surface normal at each sample (closest point on the design's
surface):

- the smallest **in-plane radius**: the radius the flat strip is bent to about its strong
  axis, which a strip of width ``w`` cannot take below about ``10 w`` (strain ``w / 2R`` of
  5 %). A tangent (GG) strip is cut straight: its in-plane bending is the axis' geodesic
  curvature ``kg``. An orthogonal (NCP) strip is cut to the collapse curve and keeps its
  normal curvature ``kn`` (``normal_geodesic_curvature``): its in-plane bending is how far
  ``kn`` leaves the cut shape's curvature, taken as the running median of ``kn`` over
  ``10 w`` (a kink shows, the slow change of a congruent strip's curvature does not);
- the smallest **radius** of the axis in space (``1 / |kappa|``; below :data:`BEND_WIDTHS`
  strip widths a kink) and the largest **curvature jump** between neighbouring samples
  (``|kappa_{i+1} - kappa_i|`` times the strip width, reported);
- **corners**: a turn of the axis by more than :data:`CORNER_DEG` at one sample;
- **hairpins**: the tangent turned by more than :data:`HAIRPIN_DEG` within
  :data:`HAIRPIN_WIDTHS` strip widths of arc length;
- **loops**: the axis passes within half a strip width of itself at two samples more than
  ``pi`` strip widths apart along it (self-intersection of the strip);
- the largest **distance from the surface** of the axis samples, % of the diagonal;

and per alignment state, the net-loops that **fold** (a loop's vector area points more than
150 degrees away from a neighbour's in the same state, both keeping a quarter of their area).

:func:`gridshell.measure.quality.fairness_gates` turns the record into gates that name the
lamella and the position (arc length along it, metres).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Iterable, Mapping, Sequence

import numpy as np

from gridshell.geometry.diffgeo import normal_geodesic_curvature, polyline_curvature

__all__ = ["BEND_WIDTHS", "CORNER_DEG", "FAIR_RADIUS_WIDTHS", "HAIRPIN_DEG", "HAIRPIN_WIDTHS", "OFF_SURFACE",
           "LamellaFairness", "fairness_metrics", "net_fairness", "folded_loops",
           "lamella_fairness"]

#: smallest in-plane radius of a strip, in strip widths at the built scale
FAIR_RADIUS_WIDTHS = 10.0
#: a turn of the axis at one sample larger than this (degrees) is a corner
CORNER_DEG = 30.0
#: the tangent turned by more than this (degrees) ...
HAIRPIN_DEG = 150.0
#: ... within this many strip widths of arc length is a hairpin
HAIRPIN_WIDTHS = 3.0
#: smallest radius of the axis in space, in strip widths: a strip bent tighter than its own
#: width about any axis has a kink
BEND_WIDTHS = 1.0
#: axis samples farther than this from the design's surface (% of the diagonal) are off it
OFF_SURFACE = 2.0
#: an axis that turns less than this in all (degrees) cannot come back within w/2 of itself
#: after pi w of arc: its tangents stay within 80.9 degrees of the middle one, so the chord of
#: any stretch of length L is at least L cos(80.9) = L / (2 pi) > w / 2 (the search is skipped)
LOOP_TURNING_DEG = 160.0
#: a net-loop folds when its vector area points more than this (degrees) away from a neighbour's ...
FOLD_DEG = 150.0
#: ... while its area is at least this share of its deployed area
FOLD_MIN_AREA = 0.25
#: the net folds when more than this share of its loops fold in one state (a single loop
#: that inverts and comes back, as on the paper's AA pseudosphere, is reported, not refused)
FOLD_SHARE = 0.05


@dataclass(frozen=True)
class LamellaFairness:
    """The fairness figures of one lamella (lengths in metres, angles in degrees).

    radius_in_plane : smallest in-plane (strong-axis) radius and ``s_in_plane`` where;
    radius : smallest radius of the axis in space and ``s_radius`` where;
    jump : largest curvature jump times the strip width (dimensionless);
    corner_deg / s_corner : largest turn at one sample and where;
    hairpin_deg / s_hairpin : largest tangent turn within the hairpin window and where;
    loop_s : arc lengths ``(s1, s2)`` of the closest self-approach if it is a loop, else None;
    off_surface : largest distance of the axis from the surface, % of the diagonal, and
    ``s_off`` where.
    """

    id: int
    radius_in_plane: float
    s_in_plane: float
    radius: float
    s_radius: float
    jump: float
    corner_deg: float
    s_corner: float
    hairpin_deg: float
    s_hairpin: float
    loop_s: tuple[float, float] | None
    off_surface: float
    s_off: float

    def as_dict(self) -> dict:
        r = (lambda x: None if x is None or not math.isfinite(x) else round(float(x), 6))
        return {"id": self.id, "radius_in_plane_m": r(self.radius_in_plane),
                "s_in_plane_m": r(self.s_in_plane), "radius_m": r(self.radius),
                "s_radius_m": r(self.s_radius), "curvature_jump": r(self.jump),
                "corner_deg": r(self.corner_deg), "s_corner_m": r(self.s_corner),
                "hairpin_deg": r(self.hairpin_deg), "s_hairpin_m": r(self.s_hairpin),
                "loop_s_m": None if self.loop_s is None else [r(x) for x in self.loop_s],
                "off_surface_percent": r(self.off_surface), "s_off_m": r(self.s_off)}


def _arc(P: np.ndarray) -> np.ndarray:
    """Arc length at each vertex of ``P``, metres."""
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(P, axis=0), axis=1))])


def _clean(P: np.ndarray, N: np.ndarray | None) -> tuple[np.ndarray, np.ndarray | None]:
    """``P`` (and its normals) without repeated consecutive points."""
    keep = np.concatenate([[True], np.linalg.norm(np.diff(P, axis=0), axis=1) > 1e-12])
    return P[keep], None if N is None else N[keep]


def _argmin_finite(x: np.ndarray) -> int:
    return int(np.nanargmin(np.where(np.isfinite(x), x, np.inf))) if len(x) else 0


def _turns(P: np.ndarray) -> np.ndarray:
    """The turning angle at each inner vertex, degrees (``k - 2``)."""
    d = np.diff(P, axis=0)
    t = d / np.linalg.norm(d, axis=1)[:, None]
    return np.degrees(np.arccos(np.clip((t[:-1] * t[1:]).sum(1), -1.0, 1.0)))


def _running_median(x: np.ndarray, s: np.ndarray, window: float) -> np.ndarray:
    """The median of ``x`` over ``window`` of arc length around each sample (NaN ends filled
    from their neighbours)."""
    x = np.asarray(x, float).copy()
    ok = np.isfinite(x)
    if not ok.any():
        return np.zeros_like(x)
    x[~ok] = np.interp(np.flatnonzero(~ok), np.flatnonzero(ok), x[ok])
    h = float(np.median(np.diff(s))) if len(s) > 1 else 1.0
    n = int(min(len(x), max(3, round(window / max(h, 1e-12))))) | 1
    if n > len(x):
        n -= 2
    if n < 3:
        return x
    padded = np.pad(x, n // 2, mode="edge")
    return np.median(np.lib.stride_tricks.sliding_window_view(padded, n), axis=1)


def _hairpin(P: np.ndarray, s: np.ndarray, window: float) -> tuple[float, float]:
    """The largest angle between the segment tangents at most ``window`` apart along the
    axis (degrees) and the arc length midway between them."""
    d = np.diff(P, axis=0)
    t = d / np.linalg.norm(d, axis=1)[:, None]
    sm = 0.5 * (s[:-1] + s[1:])
    best, where = 1.0, 0.0                   # the smallest cosine and where
    for k in range(1, len(t)):               # segment pairs k apart, all at once
        near = sm[k:] - sm[:-k] <= window
        if not near.any():
            break
        c = np.where(near, (t[k:] * t[:-k]).sum(1), 1.0)
        i = int(np.argmin(c))
        if c[i] < best:
            best, where = float(c[i]), 0.5 * (sm[i] + sm[i + k])
    return math.degrees(math.acos(max(-1.0, min(1.0, best)))), where


def _loop(P: np.ndarray, s: np.ndarray, width: float) -> tuple[float, float] | None:
    """Arc lengths of two samples closer than ``width / 2`` and farther than ``pi width``
    apart along the axis (the strip crosses itself), or None."""
    from scipy.spatial import cKDTree

    pairs = cKDTree(P).query_pairs(0.5 * width, output_type="ndarray")
    if len(pairs) == 0:
        return None
    gap = np.abs(s[pairs[:, 0]] - s[pairs[:, 1]])
    far = gap > math.pi * width
    if not far.any():
        return None
    i, j = pairs[far][int(np.argmax(gap[far]))]
    return float(s[i]), float(s[j])


def lamella_fairness(lamella_id: int, axis: np.ndarray, normals: np.ndarray, *,
                     tangent: bool, width: float, diagonal: float,
                     surface_points: np.ndarray | None = None) -> LamellaFairness:
    """The figures of one lamella. ``axis (k, 3)`` and unit surface ``normals (k, 3)`` at its
    samples, metres; ``tangent``: a GG strip (in-plane curvature ``kg``) or an orthogonal one
    (``kn``); ``width``: the strip width at the built scale, metres; ``diagonal``: the
    design's bounding-box diagonal, metres; ``surface_points (k, 3)``: the closest surface
    points of the samples (for the distance from the surface)."""
    P, N = _clean(np.asarray(axis, float), np.asarray(normals, float))
    s = _arc(P)
    nan = float("nan")
    if len(P) < 3:
        return LamellaFairness(int(lamella_id), math.inf, 0.0, math.inf, 0.0, 0.0, 0.0, 0.0,
                               0.0, 0.0, None, 0.0, 0.0)
    kn, kg = normal_geodesic_curvature(P, N)
    k_in = np.abs(kg) if tangent else np.abs(kn - _running_median(kn, s, FAIR_RADIUS_WIDTHS
                                                                  * width))
    _, kappa = polyline_curvature(P)
    with np.errstate(divide="ignore"):
        r_in, r = 1.0 / k_in, 1.0 / kappa
    i_in, i_r = _argmin_finite(r_in), _argmin_finite(r)
    jump = np.abs(np.diff(kappa[1:-1])) * width if len(P) > 3 else np.zeros(0)
    turns = _turns(P)
    i_c = int(np.argmax(turns))
    hp, s_hp = _hairpin(P, s, HAIRPIN_WIDTHS * width)
    off, s_off = 0.0, 0.0
    if surface_points is not None:
        _, C = _clean(np.asarray(axis, float), np.asarray(surface_points, float))
        dist = 100.0 * np.linalg.norm(P - C, axis=1) / diagonal
        i_o = int(np.argmax(dist))
        off, s_off = float(dist[i_o]), float(s[i_o])
    return LamellaFairness(
        int(lamella_id), float(r_in[i_in]) if np.isfinite(r_in[i_in]) else math.inf,
        float(s[i_in]), float(r[i_r]) if np.isfinite(r[i_r]) else math.inf, float(s[i_r]),
        float(np.nanmax(jump)) if jump.size and np.isfinite(jump).any() else nan,
        float(turns[i_c]), float(s[i_c + 1]), hp, s_hp,
        _loop(P, s, width) if turns.sum() >= LOOP_TURNING_DEG else None, off, s_off)


def _loop_pairs(Q: np.ndarray) -> np.ndarray:
    """``(p, 2)`` pairs of net-loops that share an edge."""
    E = np.sort(np.stack([Q, np.roll(Q, -1, axis=1)], -1).reshape(-1, 2), axis=1)
    owner = np.repeat(np.arange(len(Q)), Q.shape[1])
    order = np.lexsort((E[:, 1], E[:, 0]))
    E, owner = E[order], owner[order]
    same = np.all(E[1:] == E[:-1], axis=1)
    return np.stack([owner[:-1][same], owner[1:][same]], -1)


def folded_loops(states: Sequence[np.ndarray], loops: np.ndarray) -> list[tuple[int, int]]:
    """``(state, loop)`` pairs where the net folds: a net-loop whose vector area points more
    than :data:`FOLD_DEG` away from that of a neighbour (a loop sharing an edge) in the same
    state, both keeping at least :data:`FOLD_MIN_AREA` of their area in the first state (a
    crease, judged within each state, whatever the step between states). ``states``: joint
    positions ``(n, 3)`` per state, the deployed one first and the aligned (collapsed) one
    last, where every loop is degenerate by design and is not judged; ``loops (m, 4)``."""
    Q = np.asarray(loops, dtype=np.int64)
    if len(states) < 3 or len(Q) == 0:
        return []
    pairs = _loop_pairs(Q)
    if len(pairs) == 0:
        return []

    def vector_area(V: np.ndarray) -> np.ndarray:
        V = np.asarray(V, float)
        return 0.5 * np.cross(V[Q[:, 2]] - V[Q[:, 0]], V[Q[:, 3]] - V[Q[:, 1]])

    a0 = np.linalg.norm(vector_area(states[0]), axis=1)
    cos_fold = math.cos(math.radians(FOLD_DEG))
    out: list[tuple[int, int]] = []
    for k in range(1, len(states) - 1):       # the last state is the collapse: no area
        A = vector_area(states[k])
        a = np.linalg.norm(A, axis=1)
        live = (a >= FOLD_MIN_AREA * a0) & (a0 > 0)
        i, j = pairs[:, 0], pairs[:, 1]
        with np.errstate(invalid="ignore", divide="ignore"):
            c = (A[i] * A[j]).sum(1) / (a[i] * a[j])
        bad = live[i] & live[j] & (c < cos_fold)
        smaller = np.where(a[i] <= a[j], i, j)[bad]
        out += [(k, int(m)) for m in np.unique(smaller)]
    return out


def fairness_metrics(lamellae: Iterable[tuple[int, np.ndarray]], V: np.ndarray, F: np.ndarray,
                     *, tangent: bool, width: float,
                     states: Sequence[np.ndarray] | None = None,
                     loops: np.ndarray | None = None, gate_folds: bool = True) -> dict:
    """``metrics["fairness"]`` of a design: every lamella's figures
    (:func:`lamella_fairness`) against its surface ``V, F`` (metres), the folds of the
    alignment ``states`` (:func:`folded_loops`), and the thresholds used. ``lamellae``:
    ``(id, axis)`` pairs; ``width``: the strip width at the built scale, metres;
    ``gate_folds``: the states are the physical path (GG: the isometric family), so a fold
    fails the design; False where they are an approximate simulation (NCP: folds reported)."""
    from gridshell.geometry.igl_adapter import closest_points_with_normals

    lams = [(int(i), np.asarray(a, float)) for i, a in lamellae]
    V = np.asarray(V, float)
    diagonal = float(np.linalg.norm(V.max(0) - V.min(0))) if len(V) else 1.0
    per = []
    if lams:
        P = np.concatenate([a for _, a in lams])
        C, N = closest_points_with_normals(P, V, F)
        cuts = np.cumsum([len(a) for _, a in lams])[:-1]
        for (i, a), c, n in zip(lams, np.split(C, cuts), np.split(N, cuts)):
            per.append(lamella_fairness(i, a, n, tangent=tangent, width=width,
                                        diagonal=diagonal, surface_points=c))
    folds = folded_loops(states, loops) if states is not None and loops is not None else []
    return {"width_m": float(width), "strip": "tangent" if tangent else "orthogonal",
            "limits": {"radius_in_plane_m": FAIR_RADIUS_WIDTHS * float(width),
                       "radius_m": BEND_WIDTHS * float(width),
                       "corner_deg": CORNER_DEG, "hairpin_deg": HAIRPIN_DEG,
                       "hairpin_window_m": HAIRPIN_WIDTHS * float(width),
                       "off_surface_percent": OFF_SURFACE},
            "lamellae": [f.as_dict() for f in per],
            "folds": [{"state": k, "loop": j} for k, j in folds],
            "n_loops": 0 if loops is None else int(len(loops)), "fold_share": FOLD_SHARE,
            "gate_folds": bool(gate_folds),
            "n_states": 0 if states is None else len(states)}


def net_fairness(net, V: np.ndarray, F: np.ndarray, *, tangent: bool, width: float,
                 states: Sequence[np.ndarray] | None = None, gate_folds: bool = True) -> dict:
    """:func:`fairness_metrics` of a :class:`~gridshell.geometry.net.Net` (its lamella axes
    and net-loops) on its surface ``V, F`` with the alignment ``states`` (joint positions,
    metres, the deployed state first)."""
    return fairness_metrics([(lam.id, lam.axis) for lam in net.lamellae], V, F,
                            tangent=tangent, width=width, states=states, loops=net.loops,
                            gate_folds=gate_folds)
