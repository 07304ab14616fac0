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
    """A version-7 .3dm holding one mesh object named ``name`` in model units ``units``
    (double-precision vertices kept where rhino3dm stores them)."""
    import rhino3dm

    mesh = rhino3dm.Mesh()
    for x, y, z in V:
        mesh.Vertices.Add(float(x), float(y), float(z))
    for f in F:
        mesh.Faces.AddFace(*(int(i) for i in f))
    model = rhino3dm.File3dm()
    model.Settings.ModelUnitSystem = getattr(rhino3dm.UnitSystem, _RHINO_UNITS[units])
    attr = rhino3dm.ObjectAttributes()
    attr.Name = name
    model.Objects.AddMesh(mesh, attr)
    with atomic_path(path) as tmp:
        if not model.Write(str(tmp), 7):
            raise OSError(f"rhino3dm could not write {path}")
