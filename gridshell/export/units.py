"""The user's length unit of a design bundle, as exports need it.

Bundles hold geometry in metres and record the unit of the input in ``design.json``::

    "units": {"name": "mm", "metres_per_unit": 0.001}

(older bundles: ``"units": "m"`` or no entry, both metres). Exports convert back:
a coordinate in the user's unit is ``metres / metres_per_unit``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from ..errors import InputError

__all__ = ["KNOWN", "Units", "METRES", "bundle_units", "parse_units"]

#: unit name -> metres per unit (the names ``--units`` accepts)
KNOWN: dict[str, float] = {"m": 1.0, "cm": 0.01, "mm": 0.001, "in": 0.0254, "ft": 0.3048}
_ALIASES = {"meters": "m", "metres": "m", "meter": "m", "metre": "m", "millimeters": "mm",
            "millimetres": "mm", "centimeters": "cm", "centimetres": "cm", "inches": "in",
            "inch": "in", "feet": "ft", "foot": "ft"}


@dataclass(frozen=True)
class Units:
    """A length unit: its name and its size in metres."""

    name: str
    metres_per_unit: float

    def from_metres(self, x):
        """``x`` (metres; a number or an array) in this unit."""
        return x / self.metres_per_unit

    def from_mm(self, x):
        """``x`` (millimetres) in this unit."""
        return x * 1e-3 / self.metres_per_unit


METRES = Units("m", 1.0)


def parse_units(value: Any) -> Units:
    """:class:`Units` from a name (``"mm"``, ``"m"``, ``"in"`` ...), a ``{"name",
    "metres_per_unit"}`` record, an object with those attributes, a :class:`Units`, or None
    (metres). Raises :class:`InputError` naming the value otherwise."""
    if value is None:
        return METRES
    if isinstance(value, Units):
        return value
    if isinstance(value, str):
        key = _ALIASES.get(value.strip().lower(), value.strip().lower())
        if key not in KNOWN:
            raise InputError(f"unknown unit {value!r}; use one of {', '.join(KNOWN)}")
        return Units(key, KNOWN[key])
    if isinstance(value, dict):
        name, mpu = value.get("name"), value.get("metres_per_unit")
    else:
        name, mpu = getattr(value, "name", None), getattr(value, "metres_per_unit", None)
    if mpu is None:
        return parse_units(name)
    try:
        mpu = float(mpu)
    except (TypeError, ValueError):
        mpu = math.nan
    if not (math.isfinite(mpu) and mpu > 0):
        raise InputError(f"units {value!r}: metres_per_unit must be a positive number; "
                         "re-run the design command")
    if name is None:  # the size alone: name it when it is a known unit
        name = next((k for k, v in KNOWN.items() if math.isclose(v, mpu, rel_tol=1e-9)),
                    f"{mpu:g} m")
    return Units(str(name), mpu)


def bundle_units(bundle_or_design: Any) -> Units:
    """The input unit of a :class:`~gridshell.bundle.DesignBundle` (its ``units`` field) or of
    a design.json record (its ``"units"`` entry); metres when absent."""
    if isinstance(bundle_or_design, dict):
        return parse_units(bundle_or_design.get("units"))
    return parse_units(getattr(bundle_or_design, "units", None))
