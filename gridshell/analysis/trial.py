"""A quick coarse GG design of the target (paper 4.1 at a 16 x 16 grid, a few rounds, no
alignment sequence): how far the nearest GG surface, isometric to one of revolution, lies
from the target, and how much of it the net covers. Under a second on the corpus' targets;
the design at the defaults is finer and usually closer.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

__all__ = ["GGTrial", "gg_trial"]

#: the trial's settings: grid, outer rounds, polish iterations
TRIAL_GRID, TRIAL_ROUNDS, TRIAL_POLISH = (16, 16), 4, 5


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
        r = (lambda x: None if x is None else round(float(x), 3))
        return {"deviation_mean_percent": r(self.deviation_mean),
                "deviation_max_percent": r(self.deviation_max),
                "coverage_percent": r(self.coverage), "seconds": round(self.seconds, 2),
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
