"""The user's length unit of a design bundle, as exports need it (over :mod:`gridshell.io.units`).

Bundles hold geometry in metres and record the unit of the input in ``design.json``::

    "units": {"name": "mm", "metres_per_unit": 0.001}

(older bundles: ``"units": "m"`` or no entry, both metres). Exports convert back:
a coordinate in the user's unit is ``metres / metres_per_unit``.
"""
from __future__ import annotations

import math
from typing import Any

from ..errors import InputError
from ..io.units import METRES, UNITS, Units
from ..io.units import parse_units as parse_unit_name

__all__ = ["Units", "METRES", "bundle_units", "parse_units"]


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
        return parse_unit_name(value)
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
    """The input unit of a :class:`~gridshell.bundle.DesignBundle` (its ``units`` field) or of
    a design.json record (its ``"units"`` entry); metres when absent."""
    if isinstance(bundle_or_design, dict):
        return parse_units(bundle_or_design.get("units"))
    return parse_units(getattr(bundle_or_design, "units", None))
