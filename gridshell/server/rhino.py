"""Rhino geometry <-> arrays for the Hops components (model units at the edges: metres in,
metres out for designs, millimetres for cut curves), through
:mod:`gridshell.geometry.rhino_adapter` as every other door.

A target comes in as a mesh (triangles and quads kept as the .3dm reader keeps them), a NURBS
surface or a single-face Brep (the B-spline it is, as ``gridshell gg|ncp model.3dm`` reads
it): :func:`target_input` reads it exactly as :func:`gridshell.io.read.read_input` reads the
same object from a .3dm file, so Grasshopper and the CLI design the same surface.
"""
from __future__ import annotations

import json
from typing import Any

import numpy as np

from gridshell.core.errors import InputError
from gridshell.geometry import rhino_adapter as rh


def decode(item: dict) -> Any:
    """The Rhino object of one Hops input item ``{"type": ..., "data": "<json>"}``."""
    data = item["data"]
    obj = rh.decode(json.loads(data) if isinstance(data, str) else data)
    if obj is None:
        raise InputError(f"could not read the {item.get('type', 'geometry')} input; connect a "
                         "mesh or a surface")
    return obj


#: Rhino's unit system of each unit a Units input may give
RHINO_UNITS = {"m": "Meters", "cm": "Centimeters", "mm": "Millimeters", "in": "Inches",
               "ft": "Feet"}


def parse_units_input(text: Any) -> str | None:
    """The unit of a Hops Units input (``m``, ``cm``, ``mm``, ``in``, ``ft``; empty: metres or
    the size's own, as the CLI reads a file that does not say); InputError otherwise."""
    t = str(text or "").strip().lower()
    if not t:
        return None
    if t not in RHINO_UNITS:
        raise InputError(f"Units {text!r}: give one of {', '.join(RHINO_UNITS)} (the Rhino "
                         "document's unit, e.g. mm)")
    return t


def target_input(obj: Any, what: str = "the target", units: str | None = None) -> Any:
    """The :class:`~gridshell.io.read.InputGeometry` (metres) of a target or reference: a mesh
    (welded, checked: :func:`gridshell.io.read.read_input`), or a NURBS surface or single-face
    Brep as its B-spline (``surface``; ``V, F`` its sampling) - what the CLI reads from a .3dm
    holding the same object. :class:`InputError` for anything else."""
    from gridshell.io.read import read_input
    from gridshell.io.rhino import object_input

    return read_input(object_input(obj, what), what=what, units=units)


def mesh_arrays(m: Any) -> tuple[np.ndarray, np.ndarray]:
    """``(V (n,3) float64, P (m,4) int64)`` of a Rhino mesh, a ``(V, F)`` pair
    :func:`gridshell.io.read.read_input` takes (:func:`gridshell.geometry.rhino_adapter.
    mesh_arrays`: double precision, ``-1`` pads a triangle)."""
    return rh.mesh_arrays(m)[:2]


def to_mesh(V: np.ndarray, F: np.ndarray, compact: bool = True) -> Any:
    """A Rhino mesh of ``V (n,3)`` and faces ``F (m,3|4)`` (double-precision vertices;
    ``compact=False`` keeps the vertices no face uses)."""
    return rh.mesh(V, F, compact=compact)


def to_polyline(P: np.ndarray) -> Any:
    """A PolylineCurve through ``P (k,2|3)`` (z = 0 for 2D points)."""
    return rh.polyline_curve(P)


def to_circle(c: np.ndarray, r: float) -> Any:
    """A NurbsCurve of the circle of centre ``c (2,)`` and radius ``r`` (z = 0)."""
    return rh.circle_curve(c, r)
