"""Which strips hold: the stress term that governs, the thickest and the widest elastic strip,
the smallest model scale, and the stock sections of a material that stay elastic.

Every curvature a design imposes scales with ``1 / scale`` (:mod:`gridshell.structure.section`)
and the stresses are linear in them (:mod:`gridshell.structure.stresses`), so the design
curvatures (1/m of the design, scale-free) are computed once (a :class:`Demand`) and any
section of any material is judged on them without a new check:

- the deployed state per point of every lamella (exact: the same points as
  :func:`gridshell.structure.check.check_bundle`);
- each judged state of the alignment sequence by its largest weak-axis, strong-axis curvature
  and twist (an envelope: they need not occur at one point, so its utilisation bounds the
  state's from above and a section found to hold on it holds).

The utilisation of one section at another scale is exact: ``u(scale) = u(scale0) scale0 /
scale``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from gridshell.structure.materials import Material
from gridshell.structure.section import Section
from gridshell.structure.states import is_judged
from gridshell.structure.stresses import StripCurvatures, strip_stresses

#: the stress terms of the utilisation, by the key :func:`governing_term` returns
TERMS = {"weak": "weak-axis bending", "strong": "strong-axis bending", "twist": "torsion"}

#: what changes the governing term (the other remedy: a larger scale lowers every curvature)
HELPS = {"weak": "a thinner strip helps (weak-axis bending stress grows with the thickness)",
         "strong": "a narrower strip helps (strong-axis bending stress grows with the width; "
                   "the thickness does not change it)",
         "twist": "a thinner strip helps (torsional shear stress grows with the thickness)"}

#: strip widths tried by :func:`stock_sections`, mm of the model (the R10 preferred numbers)
WIDTHS_MM = (5.0, 6.3, 8.0, 10.0, 12.5, 16.0, 20.0, 25.0, 31.5, 40.0, 50.0, 63.0, 80.0, 100.0,
             125.0, 160.0, 200.0, 250.0, 315.0, 400.0)

#: a lamella is at least this many thicknesses wide (a strip with a weak axis)
MIN_EDGE_RATIO = 4.0


@dataclass
class Demand:
    """Design curvatures a design's strips must follow, per row (1/m and rad/m of the design).

    weak, strong, twist : (k,) the curvature changes of :class:`StripCurvatures` at scale 1;
    state : (k,) the state of each row (``"deployed"`` or a frame's name);
    lamella : (k,) the lamella id of each row (a state's worst lamella for its envelope row).
    """

    weak: np.ndarray
    strong: np.ndarray
    twist: np.ndarray
    state: np.ndarray
    lamella: np.ndarray

    def at(self, scale: float) -> StripCurvatures:
        """The curvatures of the model at ``scale`` (1/m of the real strip)."""
        return StripCurvatures(self.weak / scale, self.strong / scale, self.twist / scale)


def demand_from(ks: list[StripCurvatures], lamella_ids: list[int], scale: float,
                states: dict[str, Any] | None = None) -> Demand:
    """The :class:`Demand` of the deployed strip curvatures ``ks`` (one per lamella, on the
    model at ``scale``, as :func:`gridshell.structure.check.deployed_curvatures` gives them) and
    of the judged states of ``states`` (``check_bundle``'s ``"states"``: their largest
    curvatures on the model at ``scale``, the envelope rows)."""
    # lamella ids as Python ints (a bundle's ids are any integers, not only int64's)
    ids = [np.full(len(k.weak), int(i), dtype=object) for i, k in zip(lamella_ids, ks)]
    w = [k.weak * scale for k in ks]
    s = [k.strong * scale for k in ks]
    t = [k.twist * scale for k in ks]
    names = ["deployed"] * int(sum(len(k.weak) for k in ks))
    for f in (states or {}).get("frames", []):
        if f["t"] > 0 and is_judged(f):
            w.append(np.array([f["max_weak_curvature_per_m"] * scale]))
            s.append(np.array([f["max_strong_curvature_per_m"] * scale]))
            t.append(np.array([f["max_twist_rad_per_m"] * scale]))
            ids.append(np.array([int(f["worst_lamella"])], dtype=object))
            names.append(f["name"])
    cat = lambda a: np.concatenate(a) if a else np.zeros(0)  # noqa: E731
    return Demand(cat(w), cat(s), cat(t), np.asarray(names, dtype=object),
                  np.concatenate(ids) if ids else np.zeros(0, dtype=object))


def utilisation(demand: Demand, material: Material, section: Section) -> np.ndarray:
    """Utilisation ``(k,)`` of ``section`` of ``material`` on every row of ``demand``."""
    if not len(demand.weak):
        return np.zeros(0)
    return strip_stresses(demand.at(section.scale), section, material).utilisation


def max_utilisation(demand: Demand, material: Material, section: Section) -> float:
    u = utilisation(demand, material, section)
    return float(u.max()) if len(u) else 0.0


def governing_term(demand: Demand, material: Material, section: Section,
                   state: str | None = None) -> dict[str, Any]:
    """At the most utilised row (of ``state``'s rows if it has any): ``term`` (a key of
    :data:`TERMS`: the largest of the weak-axis, strong-axis bending stress and sqrt(3) times
    the torsional shear stress), the three stresses there (MPa: ``sigma_weak``,
    ``sigma_strong``, ``tau``), the allowable stress (MPa), the ``state``, the ``lamella`` and
    the utilisation ``u``."""
    st = strip_stresses(demand.at(section.scale), section, material)
    u = st.utilisation
    if state is not None and np.any(demand.state == state):
        u = np.where(demand.state == state, u, -np.inf)
    i = int(np.argmax(u))
    parts = {"weak": st.sigma_weak[i], "strong": st.sigma_strong[i],
             "twist": np.sqrt(3.0) * st.tau[i]}
    return {"term": max(parts, key=parts.get), "sigma_weak": st.sigma_weak[i] * 1e-6,
            "sigma_strong": st.sigma_strong[i] * 1e-6, "tau": st.tau[i] * 1e-6,
            "allowable": material.allowable * 1e-6, "state": str(demand.state[i]),
            "lamella": int(demand.lamella[i]), "u": float(st.utilisation[i])}


def _bisect(holds, lo: float, hi: float, steps: int = 40) -> float:
    """The largest x in [lo, hi] with ``holds(x)`` for a ``holds`` true below a threshold
    (``lo`` if none)."""
    if holds(hi):
        return hi
    if not holds(lo):
        return lo
    for _ in range(steps):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if holds(mid) else (lo, mid)
    return lo


def thickest_elastic_mm(demand: Demand, material: Material, section: Section) -> float:
    """The thickest strip (mm, capped at the width) of this width and scale that stays elastic
    on every row; 0 when none does (strong-axis bending alone exceeds the allowable)."""
    ok = lambda t: max_utilisation(demand, material, section.with_thickness(t)) <= 1.0  # noqa
    tiny = 1e-6 * section.width_mm
    return 0.0 if not ok(tiny) else _bisect(ok, tiny, section.width_mm)


def widest_elastic_mm(demand: Demand, material: Material, section: Section) -> float:
    """The widest strip (mm, at least the thickness, at most :data:`WIDTHS_MM`'s largest
    times 10) of this thickness and scale that stays elastic; 0 when not even a square
    section does."""
    ok = lambda w: max_utilisation(  # noqa: E731
        demand, material, Section(w, section.thickness_mm, section.scale)) <= 1.0
    t = section.thickness_mm
    return 0.0 if not ok(t) else _bisect(ok, t, max(10.0 * WIDTHS_MM[-1], t))


def smallest_scale(scale: float, max_utilisation: float) -> float:
    """The smallest model scale (model / design) at which a section checked at ``scale`` with
    ``max_utilisation`` (every judged state) holds: ``scale * max_utilisation`` (exact: the
    curvatures scale with 1 / scale)."""
    return float(scale) * float(max_utilisation)


def advice(demand: Demand, material: Material, section: Section,
           max_utilisation_all: float, state: str | None = None) -> dict[str, Any]:
    """What governs and what would hold (``structure.json["advice"]``): the governing term
    and its stresses in ``state`` (:func:`governing_term`), its remedy (:data:`HELPS`), the thickest and
    the widest elastic strip at this scale (mm; over the deployed points and the states'
    envelopes) and the smallest scale at which this section holds (from
    ``max_utilisation_all``, exact)."""
    g = governing_term(demand, material, section, state) if len(demand.weak) else None
    s_min = smallest_scale(section.scale, max_utilisation_all)
    return {"governing": g, "term": TERMS[g["term"]] if g else None,
            "helps": HELPS[g["term"]] if g else None,
            "thickest_elastic_mm": thickest_elastic_mm(demand, material, section),
            "widest_elastic_mm": widest_elastic_mm(demand, material, section),
            "smallest_scale": s_min,
            "smallest_scale_text": scale_text(s_min)}


def scale_text(scale: float) -> str:
    """``0.1 -> "1:10"``, ``0.137 -> "1:7.3"``, ``2 -> "2:1"``."""
    if scale <= 0:
        return "any scale"
    if scale >= 1:
        return f"{_up3(scale):g}:1"
    return f"1:{_down3(1.0 / scale):g}"


def _down3(x: float) -> float:
    """``x`` rounded down to 3 significant digits (a scale 1:N shown never smaller than it
    is: the section holds at the scale printed)."""
    q = 10.0 ** (math.floor(math.log10(x)) - 2)
    return math.floor(x / q + 1e-9) * q


def _up3(x: float) -> float:
    q = 10.0 ** (math.floor(math.log10(x)) - 2)
    return math.ceil(x / q - 1e-9) * q


def stock_sections(demand: Demand, material: Material, section: Section,
                   thicknesses_mm: tuple[float, ...] | None = None) -> list[dict[str, Any]]:
    """Per stock thickness of ``material`` (or ``thicknesses_mm``): the widest elastic strip
    at ``section``'s scale (:func:`widest_elastic_mm`) and the :data:`WIDTHS_MM` from
    :data:`MIN_EDGE_RATIO` thicknesses up to it, with the utilisation of the widest of them;
    ``[{"thickness_mm", "widest_mm", "widths_mm", "utilisation"}]``, thickest first."""
    out = []
    for t in sorted(thicknesses_mm or material.sheet_thicknesses_mm, reverse=True):
        wmax = widest_elastic_mm(demand, material, Section(section.width_mm, t, section.scale))
        widths = [w for w in WIDTHS_MM if MIN_EDGE_RATIO * t <= w <= wmax]
        u = (max_utilisation(demand, material, Section(widths[-1], t, section.scale))
             if widths else None)
        out.append({"thickness_mm": float(t), "widest_mm": float(wmax),
                    "widths_mm": widths, "utilisation": u})
    return out
