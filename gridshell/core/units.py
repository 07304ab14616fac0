"""Length units at the edges of the tool: parse ``--units``, convert to metres, and refuse a
mesh whose size reads as another unit.

Everything inside the tool is in metres; a user's geometry is converted once when it is read
(:func:`to_metres`) and the unit is recorded in the bundle (``design.json``: ``"units":
{"name": "mm", "metres_per_unit": 0.001}``; absent means metres), so that exports can go back
(:func:`bundle_units`: the unit of a bundle; :func:`parse_units`: a unit from a name, a record,
a :class:`Units` or None).

The plausibility rule (:func:`check_plausible`): a gridshell spans between a 0.1 m model and a
~200 m hall, so a bounding-box diagonal in :data:`PLAUSIBLE_DIAGONAL` (0.1 .. 300 m) read as
metres is accepted. A larger one that some other unit of :data:`UNITS` brings into that range is
refused (a building drawn in millimetres reads as kilometres), naming both readings, unless the
unit was given. A smaller one is accepted: no unit of the list makes it larger, and the extent
guard of :func:`gridshell.geometry.meshfile.read_mesh` still catches the absurd. The factor between the
two ends (3000) is larger than 1000, so a model drawn in millimetres whose diagonal is below
300 mm (a 0.3 m model) reads as a plausible 300 m hall: such a model needs ``--units mm``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from gridshell.core.errors import InputError

#: ``--units`` choices -> metres per unit
UNITS: dict[str, float] = {"m": 1.0, "cm": 0.01, "mm": 0.001, "in": 0.0254, "ft": 0.3048}

#: every unit name understood (Rhino's unit systems included) -> (metres per unit, long name)
_KNOWN: dict[str, tuple[float, str]] = {
    "m": (1.0, "metres"), "cm": (0.01, "centimetres"), "mm": (0.001, "millimetres"),
    "in": (0.0254, "inches"), "ft": (0.3048, "feet"), "dm": (0.1, "decimetres"),
    "km": (1000.0, "kilometres"), "um": (1e-6, "microns"), "yd": (0.9144, "yards"),
    "mi": (1609.344, "miles"), "dam": (10.0, "dekametres"), "hm": (100.0, "hectometres"),
}
_ALIASES = {"metre": "m", "metres": "m", "meter": "m", "meters": "m",
            "centimetre": "cm", "centimetres": "cm", "centimeter": "cm", "centimeters": "cm",
            "millimetre": "mm", "millimetres": "mm", "millimeter": "mm", "millimeters": "mm",
            "inch": "in", "inches": "in", '"': "in", "foot": "ft", "feet": "ft", "'": "ft",
            "decimetre": "dm", "decimeter": "dm", "decimetres": "dm", "decimeters": "dm",
            "kilometre": "km", "kilometer": "km", "kilometres": "km", "kilometers": "km",
            "micron": "um", "microns": "um", "micrometre": "um", "micrometer": "um",
            "yard": "yd", "yards": "yd", "mile": "mi", "miles": "mi"}

#: bounding-box diagonals (metres) a gridshell can plausibly have: a 0.1 m model to a ~200 m hall
PLAUSIBLE_DIAGONAL = (0.1, 300.0)
#: the size a reading is compared with when several units are plausible (metres, log scale)
_TYPICAL = 20.0


@dataclass(frozen=True)
class Units:
    """A length unit: its short name (``"mm"``) and metres per unit (``0.001``)."""

    name: str = "m"
    metres_per_unit: float = 1.0

    @property
    def long_name(self) -> str:
        """``"millimetres"`` for ``"mm"``; the short name for a unit without one."""
        return _KNOWN.get(self.name, (None, self.name))[1]

    def to_json(self) -> dict[str, Any]:
        """``{"name", "metres_per_unit"}`` as recorded in design.json and report.json."""
        return {"name": self.name, "metres_per_unit": float(self.metres_per_unit)}

    @classmethod
    def from_json(cls, d: Any) -> "Units":
        """The units of a design.json field: absent (None) is metres; a legacy string ``"m"``
        or a record ``{"name", "metres_per_unit"}``. :class:`InputError` otherwise."""
        if d is None:
            return METRES
        if isinstance(d, str):
            return parse_units(d)
        if isinstance(d, dict):
            f = d.get("metres_per_unit")
            if isinstance(f, (int, float)) and not isinstance(f, bool) and math.isfinite(f) \
                    and f > 0:
                return cls(str(d.get("name", "?")), float(f))
        raise InputError(f"'units' must be a record {{\"name\": \"mm\", \"metres_per_unit\": "
                         f"0.001}}, got {d!r}; re-run the design command")

    def __str__(self) -> str:
        return self.name


METRES = Units("m", 1.0)


def unit_from_name(text: str) -> Units:
    """The :class:`Units` of a unit name (``"mm"``, ``"millimetres"``, ``"ft"``, ...,
    case-insensitive); :class:`InputError` naming the choices otherwise."""
    key = str(text).strip().lower()
    key = _ALIASES.get(key, key)
    if key not in _KNOWN:
        raise InputError(f"unknown unit {text!r}; use one of {', '.join(UNITS)}")
    return Units(key, _KNOWN[key][0])


def to_metres(V: np.ndarray, units: Units) -> np.ndarray:
    """Coordinates ``V (n,3)`` in ``units`` as metres (a new float64 array).

    For a unit a whole number of which makes a metre (cm, mm: ``k`` = 100, 1000) each value
    ``p`` becomes the float ``x`` nearest ``p / k`` for which ``x * k`` is ``p`` again, where
    such a float is one of the two neighbours of ``p / k``: a model drawn in metres and exported
    in millimetres (``x * 1000``) comes back as the very same numbers (a plain ``p * 0.001``
    missed 12 % of them by an ulp, and the optimizers carry an ulp into ~1e-6 of the
    diagonal). Other values are ``p / k`` (correctly rounded)."""
    V = np.asarray(V, dtype=np.float64)
    f = float(units.metres_per_unit)
    if f == 1.0:
        return V.copy()
    k = 1.0 / f
    if k != round(k) or k < 1:
        return V * f
    k = float(round(k))
    p = V.ravel()
    x = p / k
    for direction in (np.inf, -np.inf):
        miss = np.flatnonzero(x * k != p)
        if not len(miss):
            break
        y = np.nextafter(x[miss], direction)
        hit = y * k == p[miss]
        x[miss[hit]] = y[hit]
    return x.reshape(V.shape)


def from_metres(V: np.ndarray, units: Units) -> np.ndarray:
    """Coordinates ``V`` in metres as ``units`` (the inverse of :func:`to_metres`)."""
    V = np.asarray(V, dtype=np.float64)
    return V / float(units.metres_per_unit) if units.metres_per_unit != 1.0 else V.copy()


def describe_length(metres: float) -> str:
    """``"14.6 km"``, ``"14.6 m"``, ``"0.146 m"``: a length for messages (3 digits)."""
    if metres >= 1000.0:
        return f"{metres / 1000.0:.3g} km"
    return f"{metres:.3g} m"


def plausible_readings(diagonal: float) -> list[Units]:
    """The units of :data:`UNITS` under which numbers spanning ``diagonal`` (bounding-box
    diagonal in file units) give a plausible gridshell (:data:`PLAUSIBLE_DIAGONAL`), the most
    typical size first."""
    lo, hi = PLAUSIBLE_DIAGONAL
    out = [parse_units(n) for n, f in UNITS.items() if lo <= diagonal * f <= hi]
    return sorted(out, key=lambda u: abs(math.log(diagonal * u.metres_per_unit / _TYPICAL)))


def check_plausible(diagonal: float, name: str) -> None:
    """:class:`InputError` if numbers spanning ``diagonal`` (bounding-box diagonal in file
    units) are implausibly large as metres while another unit reads as a gridshell: the
    message names both readings ("14.6 km as metres, 14.6 m as millimetres: pass --units").
    A size plausible as metres, or one that no unit makes plausible, passes (the extent guard
    decides about the latter)."""
    if not math.isfinite(diagonal) or diagonal <= PLAUSIBLE_DIAGONAL[1]:
        return
    others = [u for u in plausible_readings(diagonal) if u.name != "m"]
    if not others:
        return
    first, rest = others[0], others[1:]
    also = ""
    if rest:
        also = " (" + ", ".join(f"{describe_length(diagonal * u.metres_per_unit)} as "
                                f"{u.long_name}" for u in rest) + ")"
    raise InputError(
        f"{name}: the model spans {describe_length(diagonal)} as metres, "
        f"{describe_length(diagonal * first.metres_per_unit)} as {first.long_name}{also}: pass "
        f"--units (e.g. --units {first.name}; --units m keeps metres) - a gridshell spans "
        f"{PLAUSIBLE_DIAGONAL[0]:g} .. {PLAUSIBLE_DIAGONAL[1]:g} m")


def parse_units(value: Any) -> Units:
    """:class:`Units` from a name (``"mm"``, ``"m"``, ``"in"`` ...), a ``{"name",
    "metres_per_unit"}`` record (the name may be left out for a known size), an object with
    those attributes, a :class:`Units`, or None (metres). Raises :class:`InputError` naming
    the value otherwise."""
    if value is None:
        return METRES
    if isinstance(value, Units):
        return value
    if isinstance(value, str):
        return unit_from_name(value)
    if isinstance(value, dict):
        name, mpu = value.get("name"), value.get("metres_per_unit")
    else:
        name, mpu = getattr(value, "name", None), getattr(value, "metres_per_unit", None)
    if mpu is None:
        return parse_units(name)
    if name is None:  # the size alone: name it when it is a known unit
        try:
            name = next((k for k, v in UNITS.items() if math.isclose(v, float(mpu),
                                                                   rel_tol=1e-9)), None)
        except (TypeError, ValueError):
            name = None
        name = name if name is not None else f"{mpu} m"
    try:
        return Units.from_json({"name": str(name), "metres_per_unit": mpu})
    except InputError:
        raise InputError(f"units {value!r}: metres_per_unit must be a positive number; "
                         "re-run the design command") from None


def bundle_units(bundle_or_design: Any) -> Units:
    """The input unit of a :class:`~gridshell.design.bundle.DesignBundle` (its ``units`` field) or of
    a design.json record (its ``"units"`` entry); metres when absent."""
    if isinstance(bundle_or_design, dict):
        return parse_units(bundle_or_design.get("units"))
    return parse_units(getattr(bundle_or_design, "units", None))
