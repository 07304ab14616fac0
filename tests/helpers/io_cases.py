"""Inputs as users bring them, built in the tests: a hill mesh (metres or scaled to another
unit), triangle soups, and Rhino .3dm files written with rhino3dm itself."""
from __future__ import annotations

from pathlib import Path

import numpy as np


def hill(n: int = 16, m: int = 12, scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """The issue's 12 x 8 m hill (2.5 m high, tilted), triangulated on an ``n x m`` grid; the
    coordinates times ``scale`` (1000: drawn in millimetres)."""
    x, y = np.linspace(-6, 6, n), np.linspace(-4, 4, m)
    X, Y = np.meshgrid(x, y, indexing="ij")
    Z = 2.5 * np.exp(-(X ** 2 / 30 + Y ** 2 / 14)) + 0.1 * X
    V = np.stack([X, Y, Z], -1).reshape(-1, 3) * scale
    idx = np.arange(n * m).reshape(n, m)
    a, b, c, d = idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]
    T = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3),
                        np.stack([a, c, d], -1).reshape(-1, 3)])
    return V, T


def soup(V: np.ndarray, F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Every face with its own copies of its vertices (Rhino's unwelded render-mesh export)."""
    S = np.asarray(V)[np.asarray(F)].reshape(-1, 3)
    return S, np.arange(len(S)).reshape(F.shape)


def write_obj_text(path: Path, V: np.ndarray, F: np.ndarray, fmt: str = "%.17g") -> Path:
    """A plain OBJ (any vertex format: ``%.6f`` as a modeller writes)."""
    lines = ["v " + " ".join(fmt % x for x in row) for row in np.asarray(V)]
    lines += ["f " + " ".join(str(i + 1) for i in row) for row in np.asarray(F)]
    path.write_text("\n".join(lines) + "\n")
    return path


def write_ply_soup(path: Path, V: np.ndarray, F: np.ndarray) -> Path:
    """A binary PLY triangle soup, as STL converters write it (float32 coordinates)."""
    S, T = soup(V, F)
    head = (f"ply\nformat binary_little_endian 1.0\nelement vertex {len(S)}\n"
            "property float x\nproperty float y\nproperty float z\n"
            f"element face {len(T)}\nproperty list uchar int vertex_indices\nend_header\n")
    faces = np.zeros(len(T), dtype=[("n", "u1"), ("i", "<i4", (3,))])
    faces["n"], faces["i"] = 3, T
    path.write_bytes(head.encode() + S.astype("<f4").tobytes() + faces.tobytes())
    return path


def rhino_units(name: str):
    import rhino3dm

    return {"m": rhino3dm.UnitSystem.Meters, "mm": rhino3dm.UnitSystem.Millimeters,
            "cm": rhino3dm.UnitSystem.Centimeters, "ft": rhino3dm.UnitSystem.Feet,
            "none": rhino3dm.UnitSystem.None_ if hasattr(rhino3dm.UnitSystem, "None_")
            else getattr(rhino3dm.UnitSystem, "None")}[name]


def rhino_mesh(V: np.ndarray, F: np.ndarray):
    import rhino3dm

    m = rhino3dm.Mesh()
    for x, y, z in np.asarray(V, float):
        m.Vertices.Add(float(x), float(y), float(z))
    for f in np.asarray(F):
        m.Faces.AddFace(*[int(i) for i in f])
    return m


def rhino_nurbs(ctrl: np.ndarray, degree: tuple[int, int] = (3, 3), weights=None):
    """A rhino3dm NurbsSurface with clamped uniform knots in Rhino's convention (count + order -
    2 knots per direction), control points ``ctrl (nu, nv, 3)``; rational with ``weights``."""
    import rhino3dm

    nu, nv, _ = ctrl.shape
    du, dv = degree
    ns = rhino3dm.NurbsSurface.Create(3, weights is not None, du + 1, dv + 1, nu, nv)
    for knots, n, d in ((ns.KnotsU, nu, du), (ns.KnotsV, nv, dv)):
        inner = np.linspace(0.0, 10.0, n - d + 1)  # a domain other than [0, 1]
        full = np.concatenate([[0.0] * (d - 1), inner, [10.0] * (d - 1)])
        assert len(full) == n + d - 1 == len(knots)
        for i, k in enumerate(full):
            knots[i] = float(k)
    for i in range(nu):
        for j in range(nv):
            w = 1.0 if weights is None else float(weights[i, j])
            x, y, z = ctrl[i, j]
            ns.Points[i, j] = rhino3dm.Point4d(x * w, y * w, z * w, w)
    return ns


def hill_ctrl(nu: int = 6, nv: int = 5, scale: float = 1.0) -> np.ndarray:
    """Control points of a hill-like surface (12 x 8 m), times ``scale``."""
    x, y = np.linspace(-6, 6, nu), np.linspace(-4, 4, nv)
    X, Y = np.meshgrid(x, y, indexing="ij")
    Z = 2.5 * np.exp(-(X ** 2 / 30 + Y ** 2 / 14)) + 0.1 * X
    return np.stack([X, Y, Z], -1) * scale


def write_3dm(path: Path, objects: list, units: str = "m") -> Path:
    """A .3dm (version 7) holding ``objects``: ``(geometry, name, layer)`` triples."""
    import rhino3dm

    model = rhino3dm.File3dm()
    model.Settings.ModelUnitSystem = rhino_units(units)
    layers: dict[str, int] = {}
    for geom, name, layer in objects:
        if layer not in layers:
            lay = rhino3dm.Layer()
            lay.Name = layer
            layers[layer] = model.Layers.Add(lay)
        attr = rhino3dm.ObjectAttributes()
        attr.Name = name
        attr.LayerIndex = layers[layer]
        if isinstance(geom, rhino3dm.Mesh):
            model.Objects.AddMesh(geom, attr)
        elif isinstance(geom, rhino3dm.Brep):
            model.Objects.AddBrep(geom, attr)
        elif isinstance(geom, rhino3dm.Surface):
            model.Objects.AddSurface(geom, attr)
        else:
            model.Objects.AddCurve(geom, attr)
    assert model.Write(str(path), 7)
    return path


def rhino_objects(path) -> list:
    """Every object of a .3dm file: layer name, object name, user strings, the geometry's
    archive (base64 of its opennurbs record)."""
    import rhino3dm

    model = rhino3dm.File3dm.Read(str(path))
    layers = [layer.Name for layer in model.Layers]
    return [(layers[o.Attributes.LayerIndex], o.Attributes.Name,
             sorted(o.Attributes.GetUserStrings()), o.Geometry.Encode()["data"])
            for o in model.Objects], layers, dict(model.Strings)
