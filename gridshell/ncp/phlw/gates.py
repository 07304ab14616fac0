"""Quality gates of the PHLW step (``gridshell phlw``): the step's own figures as
:class:`gridshell.measure.quality.Gate` objects (judged by their own rule, not a % limit).

A PHLW / CNC / PK surface counts as designed when the optimization

- converged (its last round met a solver tolerance),
- ended with E_PHLW (paper 4.2.1, dimensionless) not higher than it started,
- ended with the relation error of eq. 4.8 (``relation_max_rel``) not higher than at the start,
- ended with the principal angle (parameter lines vs. principal directions, eq. 4.7,
  ``angle_max_deg``) not higher than at the start.

"Not higher" allows the floors below: a reference that already is a PHLW surface starts at
rounding level, and an end at 1e-7 from a start at 1e-8 is not a blow-up. The figures come
from ``PHLWResult.report_before`` / ``report_after`` (plain dicts, see
:func:`gridshell.ncp.phlw.optimize_phlw`).
"""
from __future__ import annotations

import math
import warnings
from typing import Any, Mapping

from gridshell.measure.quality import Gate

__all__ = ["ANGLE_FLOOR_DEG", "ENERGY_FLOOR", "RELATION_FLOOR", "phlw_gates"]

#: E_PHLW below this per sample (dimensionless; an RMS residual of 1e-3) counts as zero
ENERGY_FLOOR = 1e-6
#: a relative residual of eq. 4.8 below this counts as holding (1 %)
RELATION_FLOOR = 1e-2
#: a principal angle below this counts as principal, degrees
ANGLE_FLOOR_DEG = 0.5


def __getattr__(name: str) -> Any:
    if name == "Check":
        warnings.warn("gridshell.ncp.phlw.gates.Check is gridshell.measure.quality.Gate now: "
                      "Gate(name, label, held=ok, detail=detail); Check goes in the next "
                      "release", DeprecationWarning, stacklevel=2)
        return _check
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _check(name: str, label: str, ok: bool, detail: str) -> Gate:
    """The :class:`~gridshell.measure.quality.Gate` the former ``Check(name, label, ok,
    detail)`` made."""
    return Gate(name, label, held=bool(ok), detail=detail)


def _num(m: Mapping[str, Any], *keys: str) -> float:
    v: Any = m
    for k in keys:
        v = v.get(k) if isinstance(v, Mapping) else None
    try:
        return float(v)
    except (TypeError, ValueError):
        return float("nan")


def _not_higher(name: str, label: str, a: float, b: float, floor: float, unit: str = ""
                ) -> Gate:
    ok = math.isfinite(b) and (b <= max(a, floor) if math.isfinite(a) else b <= floor)
    rel = "<=" if ok else ">"
    ref = f"start {a:.3g}{unit}" + (f", floor {floor:g}{unit}" if not (a >= floor) else "")
    return _check(name, label, ok, f"{a:.3g}{unit} -> {b:.3g}{unit} ({rel} {ref})")


def phlw_gates(before: Mapping[str, Any], after: Mapping[str, Any], converged: bool,
               samples: int = 1) -> list[Gate]:
    """The gates of a PHLW step from its figures before and after the optimization
    (``{"E_PHLW": {"total"}, "relation_max_rel", "angle_max_deg"}``) on ``samples``
    optimization samples. A figure that is missing or not finite fails."""
    return [
        _check("converged", "optimizer converged", bool(converged),
              "yes" if converged else "no (its iteration limits ran out first)"),
        _not_higher("energy", "E_PHLW not higher than at the start",
                    _num(before, "E_PHLW", "total"), _num(after, "E_PHLW", "total"),
                    ENERGY_FLOOR * max(int(samples), 1)),
        _not_higher("relation", "relation error (eq. 4.8) not higher than at the start",
                    _num(before, "relation_max_rel"), _num(after, "relation_max_rel"),
                    RELATION_FLOOR),
        _not_higher("angle", "principal angle (eq. 4.7) not higher than at the start",
                    _num(before, "angle_max_deg"), _num(after, "angle_max_deg"),
                    ANGLE_FLOOR_DEG, " deg"),
    ]
