"""Quality gates: the paper's figures (5.1, Table 1) that a design must meet to count as one.

A design is accepted when its figures hold on the traced net, not when a solver residual
crossed a number. The thresholds are the paper's floor:

- ``Delta_a`` (alignability error of the net-loops, Definition 4 / eq. 5.1): mean < 1 %,
  max < 3 %; for GG both with the straight joint-to-joint edges and with the lamella arc
  lengths (the exact quantity the collapse uses);
- NCP / CNC / AA: ``Delta_l`` (edge lengths kept between the deployed and the aligned state)
  and ``Delta_n`` (the lamellae stay orthogonal to the surface) max < 1 %, and the collapse:
  the aligned joints on the collapse circle (CNC, radius error) or line (AA, distance from
  the line, % of its span) within 1 %.

A figure that is missing or not finite fails: a check that measured nothing is not a pass.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping

__all__ = ["THRESHOLDS", "Gate", "design_gates", "failing", "gate_lines", "gate_summary",
           "passed"]

#: figure -> (label, limit in %); a figure passes when it is finite and strictly below its limit
THRESHOLDS: dict[str, tuple[str, float]] = {
    "delta_a_mean": ("Delta_a mean", 1.0),
    "delta_a_max": ("Delta_a max", 3.0),
    "delta_a_arc_mean": ("Delta_a (arc) mean", 1.0),
    "delta_a_arc_max": ("Delta_a (arc) max", 3.0),
    "delta_l_max": ("Delta_l max", 1.0),
    "delta_n_max": ("Delta_n max", 1.0),
    "collapse_error": ("collapse error", 1.0),
}


@dataclass(frozen=True)
class Gate:
    """One figure of a design (or of a step such as PHLW) and whether it holds.

    A threshold gate has ``value`` and ``limit`` (both in %) and holds when the value is finite
    and strictly below the limit. A gate judged by its own rule (the PHLW step's "not higher
    than at the start", :mod:`gridshell.ncp.phlw.gates`) has no limit: ``held`` is its verdict
    and ``detail`` says what was compared.
    """

    name: str
    label: str
    value: float | None = None
    limit: float | None = None
    held: bool | None = None
    detail: str | None = None

    @property
    def ok(self) -> bool:
        if self.held is not None:
            return bool(self.held)
        return (self.value is not None and self.limit is not None
                and math.isfinite(self.value) and self.value < self.limit)

    def statement(self) -> str:
        """``"Delta_a max 0.41 % < 3 %"`` / ``"Delta_a max 7.05 % >= 3 %"`` (no verdict word);
        ``"label: detail"`` for a gate with its own rule."""
        if self.detail is not None or self.limit is None:
            return f"{self.label}: {self.detail or ('yes' if self.ok else 'no')}"
        if self.value is None or not math.isfinite(self.value):
            return f"{self.label}: not measured (limit {self.limit:g} %)"
        rel = "<" if self.ok else ">="
        return f"{self.label} {self.value:.3g} % {rel} {self.limit:g} %"

    def line(self) -> str:
        """``"pass  Delta_a max 0.41 % < 3 %"`` / ``"FAIL  Delta_a max 7.05 % >= 3 %"``."""
        return f"{'pass' if self.ok else 'FAIL'}  {self.statement()}"

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> "Gate":
        """The gate of :meth:`as_dict`'s record."""
        if d.get("limit") is None:
            return cls(str(d["name"]), str(d["label"]), held=bool(d["ok"]),
                       detail=d.get("detail"))
        return cls(str(d["name"]), str(d["label"]), d.get("value"), float(d["limit"]))

    def as_dict(self) -> dict[str, Any]:
        """``{name, label, value, limit, ok}``; ``{name, label, ok, detail, line}`` for a gate
        with its own rule."""
        if self.limit is None:
            return {"name": self.name, "label": self.label, "ok": self.ok,
                    "detail": self.detail, "line": self.line()}
        return {"name": self.name, "label": self.label, "value": self.value,
                "limit": self.limit, "ok": self.ok}


def _get(m: Mapping[str, Any], key: str, sub: str | None = None) -> float | None:
    v = m.get(key)
    if sub is not None:
        v = v.get(sub) if isinstance(v, Mapping) else None
    try:
        return None if v is None else float(v)
    except (TypeError, ValueError):
        return None


def design_gates(kind: str, metrics: Mapping[str, Any]) -> list[Gate]:
    """The gates of a design of ``kind`` ("GG", "NCP", "CNC", "AA") from its metrics
    (``design.json["metrics"]`` or the recomputed figures of ``verify``; percentages).

    GG metrics: ``alignability`` and ``alignability_arc`` (``{"mean", "max"}``). NCP metrics:
    ``delta_a_after`` (or ``alignability``), ``delta_l``, ``delta_n`` (``{"mean", "max"}``),
    and ``aligned_radius_error`` (CNC) or ``aligned_line_error`` (AA).
    """
    def gate(name: str, value: float | None) -> Gate:
        label, limit = THRESHOLDS[name]
        return Gate(name, label, value, limit)

    kind = str(kind).upper()
    if kind == "GG":
        return [gate("delta_a_mean", _get(metrics, "alignability", "mean")),
                gate("delta_a_max", _get(metrics, "alignability", "max")),
                gate("delta_a_arc_mean", _get(metrics, "alignability_arc", "mean")),
                gate("delta_a_arc_max", _get(metrics, "alignability_arc", "max"))]
    if kind not in ("NCP", "CNC", "AA"):
        raise ValueError(f"unknown design kind {kind!r}; expected GG, NCP, CNC or AA")
    da = "delta_a_after" if "delta_a_after" in metrics else "alignability"
    gates = [gate("delta_a_mean", _get(metrics, da, "mean")),
             gate("delta_a_max", _get(metrics, da, "max")),
             gate("delta_l_max", _get(metrics, "delta_l", "max")),
             gate("delta_n_max", _get(metrics, "delta_n", "max"))]
    if kind == "CNC":
        gates.append(gate("collapse_error", _get(metrics, "aligned_radius_error")))
    elif kind == "AA":
        gates.append(gate("collapse_error", _get(metrics, "aligned_line_error")))
    return gates


def passed(gates: list[Gate]) -> bool:
    """Every gate holds."""
    return all(g.ok for g in gates)


def failing(gates: list[Gate]) -> list[Gate]:
    """The gates that do not hold."""
    return [g for g in gates if not g.ok]


def gate_lines(gates: list[Gate]) -> list[str]:
    """One line per gate (see :meth:`Gate.line`)."""
    return [g.line() for g in gates]


def gate_summary(gates: list[Gate]) -> str:
    """``"all 4 figures within the paper's thresholds"`` or ``"2 of 4 figures fail: Delta_a max
    7.05 % >= 3 %, ..."``, for messages and summaries."""
    bad = failing(gates)
    if not bad:
        return f"all {len(gates)} figures within the paper's thresholds"
    return f"{len(bad)} of {len(gates)} figures fail: " + ", ".join(
        g.line().split("  ", 1)[1] for g in bad)
