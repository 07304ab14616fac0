"""The pipeline and mode to use on a target, from its map and the GG trial.

Each kind of net has a condition on the surface (paper 3-4): GG, any surface near one
isometric to a surface of revolution (the trial measures how near); NCP AA, K < 0 (real
asymptotic directions); NCP CNC and PHLW, a regular patch of curvature lines (no umbilic).
A mode is *admissible* when its largest rectangle covers at least ``min_coverage`` of the
target; the recommendation is GG when its trial is within :data:`GG_GOOD` of the diagonal
(it follows the drawn shape), else the admissible NCP mode of the largest coverage, else GG
with its deviation said.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

__all__ = ["GG_GOOD", "MIN_COVERAGE", "RING_COVERAGE", "Recommendation", "recommend"]

#: mean deviation (% of the diagonal) under which a GG design follows the shape
GG_GOOD = 2.0
#: share of the target (%) an NCP mode's largest admissible patch must cover
MIN_COVERAGE = 50.0
#: the share of the target (%) a ring's net must cover: the ring is the fallback where no
#: regular patch exists, its design kept only where it covers most of the target
RING_COVERAGE = 60.0
#: the order NCP modes are preferred in at equal coverage (PHLW is the general one)
_NCP_ORDER = ("phlw", "cnc", "aa")


@dataclass(frozen=True)
class Recommendation:
    """pipeline ("gg" or "ncp"), mode (None for gg), the command to run, why, and the
    expected deviation (% of the diagonal, mean) and coverage (%) where known."""

    pipeline: str
    mode: str | None
    command: str
    why: str
    deviation_percent: float | None
    coverage_percent: float | None

    def as_dict(self) -> dict[str, Any]:
        return dict(self.__dict__)


def recommend(coverage: dict[str, float], gg: Any, min_coverage: float = MIN_COVERAGE,
              ring: dict[str, Any] | None = None, trials: dict[str, Any] | None = None
              ) -> Recommendation:
    """``coverage``: NCP mode -> % of the target its largest admissible patch covers;
    ``gg``: the :class:`~gridshell.analysis.trial.GGTrial`; ``ring``: the ring around the
    umbilic where no regular patch exists (its ``share_percent``; an NCP PHLW net on it is
    recommended where it covers :data:`RING_COVERAGE` % and GG does not follow the shape);
    ``trials``: NCP mode -> :class:`~gridshell.analysis.trial.NCPTrial` (an NCP mode's
    expected deviation is its trial's mean where the trial surface is of its kind)."""
    gg_dev = gg.deviation_mean if gg is not None else None
    if gg_dev is not None and gg_dev <= GG_GOOD:
        return Recommendation("gg", None, "gridshell gg TARGET -o DIR",
                              f"a GG surface lies {gg_dev:.2f} % of the diagonal from the target "
                              f"(coarse trial; <= {GG_GOOD:g} %)", gg_dev, gg.coverage)
    ok = [m for m in _NCP_ORDER if coverage.get(m, 0.0) >= min_coverage]
    if ok:
        best = max(ok, key=lambda m: (coverage[m], -_NCP_ORDER.index(m)))
        why = (f"its largest admissible patch covers {coverage[best]:.0f} % of the target"
               + ("" if gg_dev is None else f"; the nearest GG surface lies {gg_dev:.2f} % away"))
        t = (trials or {}).get(best)
        dev = t.deviation["mean"] if t is not None and t.of_kind and t.deviation else None
        if dev is not None:
            why += f"; a {t.surface} surface lies {dev:.2f} % away (coarse trial)"
        return Recommendation("ncp", best, f"gridshell ncp TARGET -o DIR --mode {best}", why,
                              dev, coverage[best])
    share = (ring or {}).get("share_percent", 0.0)
    if share >= RING_COVERAGE and gg is not None:     # the GG trial ran and misses the shape
        why = (f"no regular patch of curvature lines covers {min_coverage:g} % of the target; "
               f"the {ring['kind']} covers {share:.0f} % of it"
               + ("" if gg_dev is None else f"; the nearest GG surface lies {gg_dev:.2f} % away"))
        return Recommendation("ncp", "phlw", "gridshell ncp TARGET -o DIR --mode phlw", why,
                              None, share)
    best_ncp = max(_NCP_ORDER, key=lambda m: coverage.get(m, 0.0))
    why = (f"no NCP mode has a regular patch over {min_coverage:g} % of the target (best: "
           f"{best_ncp} {coverage.get(best_ncp, 0.0):.0f} %)")
    if share:
        why += (f"; the {ring['kind']} covers {share:.0f} % of it " +
                ("('gridshell ncp' designs there)" if share >= RING_COVERAGE else
                 f"(an NCP design there needs {RING_COVERAGE:g} %)"))
    if gg_dev is None:
        return Recommendation("gg", None, "gridshell gg TARGET -o DIR",
                              why + f"; the GG trial failed: {gg.error if gg else 'not run'}",
                              None, None)
    return Recommendation("gg", None, "gridshell gg TARGET -o DIR",
                          why + f"; GG follows it within {gg_dev:.2f} % of the diagonal "
                          "(coarse trial)", gg_dev, gg.coverage)
