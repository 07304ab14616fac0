"""A reference's target file as a user brings it: OBJ, PLY, OFF or a Rhino .3dm mesh, in
metres, centimetres or millimetres (:attr:`Reference.file_format`, :attr:`Reference.units`).

Coordinates are the reference's metres divided by the unit's length; a .3dm records its unit
in the model settings (the tool reads it), the mesh formats do not (a run passes
``--units``). Written atomically, like every file the tool writes.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from gridshell.core.atomic import atomic_path
from gridshell.core.units import parse_units

__all__ = ["target_name", "write_target"]

#: rhino3dm's UnitSystem member of each unit the corpus writes
_RHINO_UNITS = {"m": "Meters", "cm": "Centimeters", "mm": "Millimeters"}


def target_name(ref: Any) -> str:
    """``target.<ext>`` of a :class:`~gridshell.corpus.registry.Reference`'s file format."""
    return f"target.{ref.file_format}"


def write_target(ref: Any, folder: Path) -> Path:
    """Write ``ref``'s mesh into ``folder`` in its format and units; returns the path."""
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / target_name(ref)
    V, F = ref.mesh_arrays()
    V = V / parse_units(ref.units).metres_per_unit
    if ref.file_format == "3dm":
        _write_3dm_mesh(path, V, F, ref.units, ref.name)
    else:
        from gridshell.geometry.meshfile import write_mesh

        write_mesh(path, V, F)
    return path


def _write_3dm_mesh(path: Path, V: np.ndarray, F: np.ndarray, units: str, name: str) -> None:
    """A version-7 .3dm holding one mesh object named ``name`` (layer ``target``) in model
    units ``units``, its vertices in double precision
    (:mod:`gridshell.geometry.rhino_adapter`)."""
    from gridshell.geometry import rhino_adapter as rh

    m = rh.Model3dm(_RHINO_UNITS[units], 1e-5 / parse_units(units).metres_per_unit)
    m.layer("target", (150, 160, 175, 255))
    m.model.Objects.AddMesh(rh.mesh(V, F, what=name), m.attrs("target", name))
    with atomic_path(path) as tmp:
        if not rh.write_file(m.model, tmp, 7):
            raise OSError(f"rhino3dm could not write {path}")
