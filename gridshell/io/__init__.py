"""What users bring: mesh files and Rhino .3dm input, units, cleaning (pymeshlab).

- :mod:`.units`: ``--units`` (m, cm, mm, in, ft), conversion to metres, the plausibility check
- :mod:`.clean`: weld, de-duplicate, orient (pymeshlab), polygons kept
- :mod:`.rhino`: .3dm meshes, NURBS surfaces and single-face Breps, and one Rhino object (the
  Grasshopper server's) read the same way, through :mod:`gridshell.geometry.rhino_adapter`
- :mod:`.read`: :func:`read_input`, the one entry for a user's surface

Light at import: pymeshlab and rhino3dm load when a file needs them.

May import: :mod:`gridshell.core`, :mod:`gridshell.solver`, :mod:`gridshell.geometry`,
:mod:`gridshell.measure`.
"""
from __future__ import annotations

from gridshell.core.units import METRES, UNITS, Units, parse_units

__all__ = ["METRES", "UNITS", "Units", "parse_units", "read_input", "InputGeometry"]


def __getattr__(name: str):  # lazy: read pulls scipy, pymeshlab and rhino3dm on use
    if name in ("read_input", "InputGeometry"):
        from gridshell.io import read

        return getattr(read, name)
    raise AttributeError(name)
