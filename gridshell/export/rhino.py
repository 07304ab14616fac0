"""Export a design bundle to a Rhino ``.3dm`` model through ``rhino3dm``.

Layers and objects (model units: metres)::

    surface     the designed surface as a mesh (user strings kind, bundle)
    family 1    one polyline curve per C^1 lamella axis
    family 3    one polyline curve per C^3 lamella axis
    joints      one point per joint (user string joint_id)
    aligned     one polyline per lamella through its joints in the aligned configuration
    revolution  GG only: the isometric surface of revolution as a mesh

Lamella curves carry the user strings ``lamella_id``, ``family``, ``length_m`` (axis length,
metres) and ``joints`` (joint ids along the lamella, space separated).
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import Callable

import numpy as np

from ..atomic import atomic_path
from ..errors import InputError, OutputError

__all__ = ["LAYERS", "export_3dm", "bundle_to_3dm"]

#: layer name -> RGBA colour (0-255)
LAYERS: dict[str, tuple[int, int, int, int]] = {
    "surface": (170, 175, 185, 255),
    "family 1": (33, 107, 179, 255),
    "family 3": (219, 89, 31, 255),
    "joints": (25, 25, 25, 255),
    "aligned": (90, 150, 60, 255),
    "revolution": (150, 120, 190, 255),
}
_FILE_VERSION = 8


def _mesh(V: np.ndarray, F: np.ndarray):
    import rhino3dm

    m = rhino3dm.Mesh()
    for x, y, z in np.asarray(V, float).reshape(-1, 3).tolist():
        m.Vertices.Add(x, y, z)
    F = np.asarray(F, np.int64)
    for f in F.tolist():
        f = [i for i in f if i >= 0]
        if len(f) == 4:
            m.Faces.AddFace(*f)
        elif len(f) == 3:
            m.Faces.AddFace(f[0], f[1], f[2])
        else:
            raise InputError(f"surface face {f} has {len(f)} corners; only triangles and quads "
                             "can go into a Rhino mesh")
    m.Normals.ComputeNormals()
    m.Compact()
    return m


def _polyline(P: np.ndarray):
    import rhino3dm

    pts = rhino3dm.Point3dList()
    for x, y, z in np.asarray(P, float).reshape(-1, 3).tolist():
        pts.Add(x, y, z)
    return pts


def bundle_to_3dm(bundle, name: str = ""):
    """A ``rhino3dm.File3dm`` of a :class:`~gridshell.bundle.DesignBundle` (see the module
    docstring for layers, objects and user strings)."""
    import rhino3dm

    model = rhino3dm.File3dm()
    model.Settings.ModelUnitSystem = rhino3dm.UnitSystem.Meters
    model.ApplicationName = "gridshell"
    layer_index: dict[str, int] = {}
    names = [n for n in LAYERS if n != "revolution" or bundle.revolution_V is not None]
    for n in names:
        layer = rhino3dm.Layer()
        layer.Name = n
        layer.Color = LAYERS[n]
        layer_index[n] = model.Layers.Add(layer)

    def attrs(layer: str, obj_name: str = "", **strings: object):
        a = rhino3dm.ObjectAttributes()
        a.LayerIndex = layer_index[layer]
        if obj_name:
            a.Name = obj_name
        for k, v in strings.items():
            a.SetUserString(k, str(v))
        return a

    model.Objects.AddMesh(_mesh(bundle.surface_V, bundle.surface_F),
                          attrs("surface", "surface", kind=bundle.kind, bundle=name))
    if bundle.revolution_V is not None:
        model.Objects.AddMesh(_mesh(bundle.revolution_V, bundle.revolution_F),
                              attrs("revolution", "surface of revolution", kind=bundle.kind))
    for lam in bundle.net.lamellae:
        strings = {"lamella_id": int(lam.id), "family": int(lam.family),
                   "length_m": f"{lam.length:.6f}",
                   "joints": " ".join(str(j) for j in lam.joints.tolist())}
        if len(lam.axis) >= 2:
            model.Objects.AddPolyline(_polyline(lam.axis),
                                      attrs(f"family {lam.family}", f"L{lam.id}", **strings))
        if len(lam.joints) >= 2:
            model.Objects.AddPolyline(_polyline(bundle.aligned[lam.joints]),
                                      attrs("aligned", f"L{lam.id} aligned", state="aligned",
                                            **strings))
    for j, (x, y, z) in enumerate(bundle.net.joints.tolist()):
        model.Objects.AddPoint(rhino3dm.Point3d(x, y, z), attrs("joints", f"J{j}", joint_id=j))
    return model


def _check_finite(bundle) -> None:
    """:class:`GridshellError` (a bug: bundles are validated when read) unless every coordinate
    that goes into the .3dm file is finite: nothing non-finite is ever written."""
    from ..errors import GridshellError

    arrays = {"net joints": bundle.net.joints, "aligned joints": bundle.aligned,
              "surface": bundle.surface_V}
    arrays.update({f"lamella {lam.id} axis": lam.axis for lam in bundle.net.lamellae})
    for what, a in arrays.items():
        if not np.all(np.isfinite(np.asarray(a, float))):
            raise GridshellError(f"refusing to write the .3dm file: the {what} are not finite; "
                                 "this is a bug, please report it")


def export_3dm(bundle_dir, path: str | os.PathLike, *,
               progress: Callable[[str], None] | None = None) -> Path:
    """Write the net, surface and lamellae of a design bundle to a Rhino ``.3dm`` file
    (Rhino 8 format, metres), atomically.

    Parameters
    ----------
    bundle_dir : path-like or DesignBundle
        The design bundle directory (or an in-memory bundle).
    path : path-like
        Output ``.3dm`` file.

    Returns
    -------
    Path
        ``path``.
    """
    from ..bundle import read_bundle

    path = Path(path)
    if path.suffix.lower() != ".3dm":
        raise InputError(f"{path.name}: a Rhino file needs the extension .3dm")
    if isinstance(bundle_dir, (str, os.PathLike)):
        bundle, name = read_bundle(bundle_dir), Path(bundle_dir).resolve().name
    else:
        bundle, name = bundle_dir, ""
    _check_finite(bundle)
    if progress is not None:
        progress(f"writing {path}")
    model = bundle_to_3dm(bundle, name)
    with atomic_path(path) as tmp:
        if not model.Write(str(tmp), _FILE_VERSION):
            raise OutputError(f"rhino3dm could not write {path}; check the location is "
                              "writable")
    return path
