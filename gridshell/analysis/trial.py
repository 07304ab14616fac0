"""Quick coarse designs of the target that say how far the nearest surface of each kind lies
from it: GG (paper 4.1 at a 16 x 16 grid, a few rounds, no alignment sequence: a surface
isometric to one of revolution) and the NCP kinds (the PHLW step of paper 4.2.1 at 8 x 8
samples, one round: a PHLW, CNC or PK surface), the NCP distances also per region of the
curvature map. About a second each on the corpus' targets; the designs at the defaults are
finer and usually closer.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["GGTrial", "NCPTrial", "gg_trial", "ncp_trial"]

#: the GG trial's settings: grid, outer rounds, polish iterations
TRIAL_GRID, TRIAL_ROUNDS, TRIAL_POLISH = (16, 16), 4, 5
#: the NCP trial's settings (:func:`gridshell.ncp.phlw.optimize.optimize_phlw`): samples,
#: outer rounds, solver iterations, and the sampling of the trial surface the distances use
NCP_SAMPLES, NCP_OUTER, NCP_ITER, NCP_MESH = (8, 8), 1, 8, (32, 32)


def _r(x: Any, nd: int = 3) -> float | None:
    return None if x is None else round(float(x), nd)


@dataclass(frozen=True)
class GGTrial:
    """deviation_mean, deviation_max : the coarse GG surface's distance from the target, % of
    the diagonal; coverage : share of the target within reach of the net, %; seconds; error :
    why the trial could not run (None when it ran)."""

    deviation_mean: float | None
    deviation_max: float | None
    coverage: float | None
    seconds: float
    error: str | None = None

    def as_dict(self) -> dict[str, Any]:
        return {"deviation_mean_percent": _r(self.deviation_mean),
                "deviation_max_percent": _r(self.deviation_max),
                "coverage_percent": _r(self.coverage), "seconds": round(self.seconds, 2),
                "settings": {"grid": list(TRIAL_GRID), "rounds": TRIAL_ROUNDS,
                             "polish_iter": TRIAL_POLISH}, "error": self.error}


def gg_trial(target: Any) -> GGTrial:
    """Run the coarse GG design on ``target`` (an :class:`~gridshell.io.read.InputGeometry`,
    metres); a design error becomes :attr:`GGTrial.error`, not an exception."""
    import time

    from gridshell.core.errors import GridshellError
    from gridshell.gg.pipeline import design_gg

    t0 = time.perf_counter()
    try:
        d = design_gg(target, grid=TRIAL_GRID, frames=0, allow_unconverged=True,
                      rounds=TRIAL_ROUNDS, polish_iter=TRIAL_POLISH)
    except GridshellError as exc:
        return GGTrial(None, None, None, time.perf_counter() - t0, str(exc).splitlines()[0])
    m = d.bundle.metrics
    dev = m.get("deviation") or {}
    return GGTrial(dev.get("mean"), dev.get("max"), m.get("coverage"), time.perf_counter() - t0)


@dataclass(frozen=True)
class NCPTrial:
    """The coarse PHLW step of one NCP mode (``phlw``: a PHLW surface, ``cnc``: CNC, ``aa``:
    PK) started from the target's B-spline.

    deviation : ``{"mean", "p95", "max"}`` distance of the target (its curvature map's samples
    on it, area-weighted) from the trial surface, % of the diagonal; regions : the same per
    region of the map (``{"kind", "share_percent", "mean", "max"}``); relation : max relative
    residual of eq. 4.8; angle_deg : max angle of the parameter lines to the principal
    directions (eq. 4.7); no_net_percent : samples without a real net direction or umbilic;
    of_kind : the trial surface is of the mode's kind (relation, angle and net within the
    PHLW step's limits), so ``deviation`` is a distance to a surface of that kind; seconds;
    error : why there is none (no net can exist, the step failed), else None."""

    mode: str
    deviation: dict[str, float] | None
    regions: list[dict[str, Any]] = field(default_factory=list)
    relation: float | None = None
    angle_deg: float | None = None
    no_net_percent: float | None = None
    of_kind: bool = False
    seconds: float = 0.0
    error: str | None = None

    @property
    def surface(self) -> str:
        """The kind of surface the mode's net lives on: PHLW, CNC or PK."""
        return {"phlw": "PHLW", "cnc": "CNC", "aa": "PK"}[self.mode]

    def as_dict(self) -> dict[str, Any]:
        return {"mode": self.mode, "surface": self.surface,
                "deviation_percent": None if self.deviation is None else
                {k: _r(v, 4) for k, v in self.deviation.items()},
                "regions": self.regions, "relation_max_rel": _r(self.relation, 5),
                "angle_max_deg": _r(self.angle_deg), "no_net_percent": _r(self.no_net_percent, 1),
                "of_kind": self.of_kind, "seconds": round(self.seconds, 2),
                "settings": {"samples": list(NCP_SAMPLES), "outer": NCP_OUTER,
                             "max_iter": NCP_ITER}, "error": self.error}


def ncp_trial(surface: Any, V: np.ndarray, F: np.ndarray, mode: str, cmap: Any,
              regions: list[Any]) -> NCPTrial:
    """Run the coarse PHLW step of ``mode`` on ``surface`` (the target's B-spline) against the
    target ``(V, F)`` (metres) and measure the distance of the curvature map ``cmap``'s
    on-target samples from the result, over the target and per region of ``regions``
    (:class:`~gridshell.analysis.regions.Region` with their masks); a design error becomes
    :attr:`NCPTrial.error`, not an exception."""
    import time

    from gridshell.core.errors import GridshellError
    from gridshell.geometry.igl_adapter import closest_points
    from gridshell.ncp.phlw.optimize import optimize_phlw

    t0 = time.perf_counter()
    try:
        r = optimize_phlw(surface, (V, F), mode=mode, samples=NCP_SAMPLES, outer=NCP_OUTER,
                          max_iter=NCP_ITER, check_samples=NCP_MESH, early_stop=False)
    except GridshellError as exc:
        return NCPTrial(mode, None, seconds=time.perf_counter() - t0,
                        error=str(exc).splitlines()[0])
    mesh = r.surface.sample(*NCP_MESH)
    on = cmap.on_target
    d2, _, _ = closest_points(cmap.S[on], mesh.V, mesh.F)
    dist = np.full(on.shape, np.nan)
    dist[on] = 100.0 * np.sqrt(d2) / cmap.diagonal
    w = np.where(on, cmap.area, 0.0)
    fig = r.figures
    check = r.net_check
    bad = (None if check is None else
           100.0 * float(np.mean(check.umbilic | check.out_of_range)))
    per = [{"kind": g.kind, "share_percent": round(100 * g.share, 2),
            **_spread(dist, w, g.mask & on, ("mean", "max"))} for g in regions]
    return NCPTrial(mode, _spread(dist, w, on, ("mean", "p95", "max")), per,
                    fig["relation"]["value"], fig["angle"]["value"], bad,
                    all(fig[k]["ok"] for k in ("relation", "angle", "net")),
                    time.perf_counter() - t0)


def _spread(dist: np.ndarray, w: np.ndarray, sel: np.ndarray, keys: tuple[str, ...]
            ) -> dict[str, float]:
    """Area-weighted mean, 95th percentile and max of ``dist`` over ``sel`` (those asked)."""
    d, ww = dist[sel], w[sel]
    if not len(d):
        return {k: float("nan") for k in keys}
    order = np.argsort(d)
    cum = np.cumsum(ww[order]) / max(float(ww.sum()), 1e-300)
    out = {"mean": float((d * ww).sum() / max(float(ww.sum()), 1e-300)),
           "p95": float(d[order][min(np.searchsorted(cum, 0.95), len(d) - 1)]),
           "max": float(d.max())}
    return {k: round(out[k], 4) for k in keys}
