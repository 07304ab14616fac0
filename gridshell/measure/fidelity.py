"""How faithfully a net follows the user's target (issue 29, item 4): the same figures for GG
and NCP, from the net itself (its joints and net loops), never from an intermediate surface.

- ``deviation``: distance of the net's joints from the target, % of the target's
  bounding-box diagonal: mean, 95th percentile and max;
- ``coverage``: the share (%) of the target's area lying within ``COVER_TOL`` (2 %) of the
  diagonal from the net's surface (its loops, triangulated): a net that shrank from the
  target's boundary, or covers a patch of it, shows here;
- ``reach``: the largest distance of the target from the net's surface (% of the diagonal).

Units: metres in, percent out.
"""
from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["COVER_TOL", "fidelity_line", "fidelity_rows", "loop_triangles", "net_fidelity",
           "region_line", "require_fidelity"]

#: a target point is covered when it lies within this share of the diagonal of the net (%)
COVER_TOL = 2.0
#: target samples the coverage is measured on at most (a 200k-triangle target has 800k)
MAX_SAMPLES = 40000


def loop_triangles(loops: np.ndarray) -> np.ndarray:
    """Fan triangles ``(t, 3)`` of the net loops ``(m, k)`` (corner indices, ``-1`` padding)."""
    L = np.asarray(loops, np.int64)
    out = []
    for row in L:
        c = row[row >= 0]
        out += [(c[0], c[i], c[i + 1]) for i in range(1, len(c) - 1)]
    return np.asarray(out, np.int64).reshape(-1, 3)


def _target_samples(V: np.ndarray, T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Points and their areas (m2) sampling a triangle mesh: each triangle's centroid and
    the three points (2/3, 1/6, 1/6), a quarter of its area each."""
    A, B, C = V[T[:, 0]], V[T[:, 1]], V[T[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(B - A, C - A), axis=1)
    pts = [(A + B + C) / 3.0, (4 * A + B + C) / 6.0, (A + 4 * B + C) / 6.0,
           (A + B + 4 * C) / 6.0]
    return np.concatenate(pts), np.tile(area / 4.0, 4)


def net_fidelity(joints: np.ndarray, loops: np.ndarray, target_V: np.ndarray,
                 target_F: np.ndarray) -> dict[str, float]:
    """The net's fidelity to the target (module docstring): ``deviation_mean``,
    ``deviation_p95``, ``deviation_max``, ``reach_max`` and ``coverage`` in %, and the
    target's ``diagonal`` in metres."""
    from gridshell.geometry.igl_adapter import closest_points, triangulate

    tV, tT, _ = triangulate(np.asarray(target_V, float), target_F)
    used = tV[np.unique(tT)]
    diag = float(np.linalg.norm(used.max(0) - used.min(0)))
    J = np.asarray(joints, float)
    sq, _, _ = closest_points(J, tV, tT)
    d = 100.0 * np.sqrt(np.maximum(sq, 0.0)) / diag
    out = {"deviation_mean": float(d.mean()), "deviation_p95": float(np.percentile(d, 95)),
           "deviation_max": float(d.max()), "diagonal": diag}
    NT = loop_triangles(loops)
    if len(NT) == 0:
        return {**out, "coverage": 0.0, "reach_max": float("inf")}
    P, w = _target_samples(tV, tT)
    if len(P) > MAX_SAMPLES:                # a big target: an even subset of its samples
        keep = np.linspace(0, len(P) - 1, MAX_SAMPLES).astype(np.int64)
        P, w = P[keep], w[keep]
    sq, _, _ = closest_points(P, J, NT)
    r = 100.0 * np.sqrt(np.maximum(sq, 0.0)) / diag
    out["coverage"] = float(100.0 * w[r <= COVER_TOL].sum() / w.sum())
    out["reach_max"] = float(r.max())
    return out


def fidelity_line(f: dict | None) -> str:
    """The summary's line of a design's ``metrics["fidelity"]``."""
    if not f:
        return "-"
    return (f"joints from {f.get('target', 'the target')}: mean {f['deviation_mean']:.3g} %, "
            f"p95 {f['deviation_p95']:.3g} %, max {f['deviation_max']:.3g} % of the diagonal; "
            f"covers {f['coverage']:.0f} % of it (within {COVER_TOL:g} %)")


def region_line(rec: dict[str, Any] | None) -> str:
    """One line on the region a design was made on (design.json ``metrics["region"]``)."""
    if not rec:
        return "the whole surface"
    return (f"{rec['kind']}: radius {rec['inner_m']:.3g} to {rec['outer_m']:.3g} m "
            f"(loops {rec['aspect']:.2g} as wide across), the top inside and a "
            f"{rec['gap_deg']:.0f} deg gap left out; {rec['share_percent']:.0f} % of the target")


def fidelity_rows(metrics: dict) -> list[tuple[str, str]]:
    """The report's rows on a design's fidelity to its target and the region designed on
    (design.json ``metrics``; none where the design stored no fidelity)."""
    if not metrics.get("fidelity"):
        return []
    return [("fidelity to the target", fidelity_line(metrics["fidelity"])),
            ("designed region", region_line(metrics.get("region")))]


def require_fidelity(metrics: dict, max_deviation: float | None) -> None:
    """:class:`ConvergenceError` (exit 4) when the net's mean deviation from the target
    exceeds ``max_deviation`` (% of the diagonal; None: no gate)."""
    from gridshell.core.errors import ConvergenceError

    f = metrics.get("fidelity")
    if max_deviation is None or not f:
        return
    if f["deviation_mean"] > float(max_deviation):
        raise ConvergenceError(
            f"the net lies {f['deviation_mean']:.3g} % of the diagonal from the target on "
            f"average (p95 {f['deviation_p95']:.3g} %), more than --max-deviation "
            f"{float(max_deviation):g} %; nothing was written: a denser net or another "
            "pipeline may follow the shape closer ('gridshell analyze' compares them), or "
            "allow more")
