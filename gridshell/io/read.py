"""What users bring, read once: a mesh file (OBJ, PLY, OFF) or a Rhino .3dm, in the user's
units, cleaned, checked, as metres (:func:`read_input`).

Order: parse (:func:`gridshell.geometry.meshfile.read_polygons` / :func:`gridshell.io.rhino.read_3dm`),
units (the .3dm's own, ``units``, or metres after the plausibility check of
:func:`gridshell.core.units.check_plausible`), conversion to metres, cleaning
(:func:`gridshell.io.clean.clean_mesh`), the mesh checks (:func:`gridshell.geometry.quadmesh.
validate_mesh`), the extent and, with ``require_disk``, one disk-like patch (the message says
whether the mesh looked unwelded).
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from gridshell.core.errors import InputError, MeshError
from gridshell.core.units import METRES, Units, check_plausible, parse_units, to_metres

#: a NURBS surface is sampled for mesh uses (gg's target, deviations) with this many vertices
#: along its longer side (gg's default grid, so its design grid is the sampling itself)
SURFACE_SAMPLES = 64


@dataclass
class InputGeometry:
    """A user's geometry in metres: ``V (n,3)``, ``F (m,3|4)`` (quads when every face is a
    quad), and for a NURBS input its :class:`~gridshell.geometry.bspline.BSplineSurface` (``F`` then a
    sampling of it). ``units`` is the unit the user drew in; ``info()`` goes into bundles."""

    V: np.ndarray
    F: np.ndarray
    units: Units = METRES
    name: str = "(V, F)"
    path: str | None = None
    surface: Any = None
    object: str | None = None
    object_query: str | None = None  # --object as given
    clean: Any = None  # CleanReport, or None when not cleaned
    notes: list[str] = field(default_factory=list)
    units_source: str = "default"  # "file", "option", "default"

    def info(self) -> dict[str, Any]:
        """The record of the input kept in a bundle's params (``params["input"]``)."""
        d: dict[str, Any] = {"file": self.path, "units": self.units.to_json(),
                             "units_source": self.units_source,
                             "vertices": int(len(self.V)), "faces": int(len(self.F))}
        if self.object is not None:
            d["object"] = self.object
            d["object_query"] = self.object_query
        if self.surface is not None:
            d["surface"] = "NURBS"
        d["clean"] = self.clean.to_json() if self.clean is not None else None
        if self.notes:
            d["notes"] = list(self.notes)
        return d

    def summary(self) -> str:
        """One line for the CLI summary: units, what cleaning did, notes."""
        parts = [f"{self.name}" + (f" ({self.object})" if self.object else ""),
                 f"units {self.units.name}" + (" (from the file)" if self.units_source == "file"
                                               else "")]
        if self.surface is not None:
            parts.append("NURBS surface")
        elif self.clean is not None:
            parts.append(self.clean.summary())
        else:
            parts.append("not cleaned (--no-clean)")
        return "; ".join(parts + self.notes)


def resolve_units(units: Units | str | None) -> Units | None:
    """``--units`` as :class:`Units` (None stays None: not given)."""
    if units is None or isinstance(units, Units):
        return units
    return parse_units(units)


def read_input(source: Any, *, units: Units | str | None = None, clean: bool = True,
               obj: str | None = None, require_disk: bool = True,
               what: str = "the target") -> InputGeometry:
    """Read a user's surface as metres.

    Parameters
    ----------
    source : path of an OBJ / PLY / OFF / 3DM file, an :class:`InputGeometry` (returned as it
        is), a QuadMesh / TriMesh or a ``(V, F)`` pair (in ``units``), or one Rhino object as
        :func:`gridshell.io.rhino.object_input` reads it (a .3dm's object, read the same way)
    units : the unit the geometry is drawn in (``"m"``, ``"cm"``, ``"mm"``, ``"in"``, ``"ft"``);
        None: a .3dm's own unit system, else metres after :func:`check_plausible`
    clean : weld, de-duplicate and orient first (:func:`gridshell.io.clean.clean_mesh`)
    obj : a .3dm's object to read (name, id or layer) when it holds several
    require_disk : refuse anything but one disk-like patch
    what : the name of the surface in messages

    Raises
    ------
    InputError / MeshError : unreadable files, unit conflicts or implausible sizes, meshes that
        fail the checks.
    """
    if isinstance(source, InputGeometry):
        return source
    raw = _parse(source, obj)
    u, src = _pick_units(raw.name, raw.units, resolve_units(units))
    made = dict(units=u, name=raw.name, path=raw.path, object=raw.object, object_query=obj,
                notes=raw.notes, units_source=src)
    if raw.surface is not None:
        surface = _scaled_surface(raw.surface, u.metres_per_unit)
        if src == "default":
            from gridshell.geometry.quadmesh import bbox_diagonal

            check_plausible(bbox_diagonal(surface.ctrl.reshape(-1, 3)), raw.name)
        mesh = _sample_surface(surface)
        return InputGeometry(V=mesh.V, F=mesh.F, surface=surface, clean=None, **made)
    if src == "default":
        from gridshell.geometry.quadmesh import bbox_diagonal

        check_plausible(bbox_diagonal(raw.V), raw.name)
    V, F, report = _checked_mesh(to_metres(raw.V, u), raw.P, raw.sizes, raw.name, clean)
    if require_disk:
        check_disk(V, F, raw.name, report, what=what)
    return InputGeometry(V=V, F=F, clean=report, **made)


@dataclass
class _Parsed:
    """What a source holds before units and checks: a polygon mesh (``V``, ``P``, ``sizes``)
    or a B-spline ``surface``, in the source's units (``units``: a .3dm's own, else None)."""

    name: str
    path: str | None = None
    units: Units | None = None
    notes: list[str] = field(default_factory=list)
    object: str | None = None
    surface: Any = None
    V: Any = None
    P: Any = None
    sizes: Any = None


def _parse(source: Any, obj: str | None) -> _Parsed:
    """The :class:`_Parsed` of a path (a .3dm through :func:`gridshell.io.rhino.read_3dm`,
    OBJ / PLY / OFF through :func:`gridshell.geometry.meshfile.read_polygons`), of one Rhino
    object already read (the Grasshopper server's) or of a mesh / ``(V, F)`` pair."""
    if isinstance(source, (str, os.PathLike)):
        path = Path(source)
        out = _Parsed(name=path.name, path=str(path.resolve()))
        if path.suffix.lower() == ".3dm":
            from gridshell.io.rhino import read_3dm

            r = read_3dm(path, obj)
            _take_rhino(out, r)
            out.object = r.object.label()
            return out
        if obj is not None:
            raise InputError(f"{path.name}: --object picks an object of a .3dm file; a mesh "
                             "file holds one mesh - drop --object")
        from gridshell.geometry.meshfile import read_polygons

        out.V, out.P, out.sizes = read_polygons(path)
        return out
    if _is_rhino_input(source):
        out = _Parsed(name=source.name or "(Rhino object)")
        _take_rhino(out, source)
        return out
    out = _Parsed(name="(V, F)")
    out.V, out.P, out.sizes = _arrays(source)
    return out


def _take_rhino(out: _Parsed, r: Any) -> None:
    """Copy a :class:`gridshell.io.rhino.RhinoInput`'s units, notes and geometry into ``out``."""
    out.units, out.notes = r.units, list(r.notes)
    out.surface, out.V, out.P, out.sizes = r.surface, r.V, r.P, r.sizes


def _pick_units(name: str, file_u: Units | None, given: Units | None) -> tuple[Units, str]:
    """``(unit, source)``: the file's own (``"file"``; :class:`InputError` when ``--units``
    says another), the option's (``"option"``) or metres (``"default"``)."""
    if file_u is not None:
        if given is not None and given != file_u:
            raise InputError(f"{name}: the model is drawn in {file_u.long_name} (its unit "
                             f"system) but --units {given.name} was given; drop --units or set "
                             "the model's units in Rhino")
        return file_u, "file"
    if given is not None:
        return given, "option"
    return METRES, "default"


def _checked_mesh(V: np.ndarray, P: np.ndarray, sizes: np.ndarray, name: str,
                  clean: bool) -> tuple[np.ndarray, np.ndarray, Any]:
    """``(V, F, report)`` of a polygon mesh in metres: coordinates checked, cleaned
    (:func:`gridshell.io.clean.clean_mesh`; ``report`` None when not), validated, its extent
    checked, and its faces as :func:`_faces` gives them."""
    from gridshell.geometry.meshfile import _check_extent, check_coordinates
    from gridshell.geometry.quadmesh import check_face_areas, validate_mesh

    bad = ~np.isfinite(V).all(axis=1)
    if bad.any():   # a Rhino object's arrays come unchecked (a mesh file's were checked)
        raise MeshError(f"{name}: {int(bad.sum())} vertices have NaN or infinite coordinates "
                        f"(the first is vertex {int(np.flatnonzero(bad)[0])}); repair the mesh")
    if len(P) == 0 or P.shape[1] == 0:
        raise MeshError(f"{name}: the mesh is empty, {len(V)} vertices but no faces; give a "
                        "mesh with its faces")
    check_coordinates(V, name)
    report = None
    if clean:
        from gridshell.io.clean import clean_mesh

        if len(P):  # a weld must not hide a degenerate face of the file (welding its corners
            check_face_areas(V, P, name)  # would drop it; a mesh at one point would vanish)
        V, P, sizes, report = clean_mesh(V, P, sizes, name=name)
    validate_mesh(V, P, name=name)
    _check_extent(V, name)
    return V, _faces(V, P, sizes), report


def _is_rhino_input(source: Any) -> bool:
    from gridshell.io.rhino import RhinoInput

    return isinstance(source, RhinoInput)


def _arrays(source: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    from gridshell.geometry.quadmesh import _as_padded

    if hasattr(source, "V") and hasattr(source, "F"):
        V, F = source.V, source.F
    elif isinstance(source, tuple) and len(source) == 2:
        V, F = source
    else:
        raise InputError("the surface must be a mesh file path (OBJ, PLY, OFF, 3DM), a "
                         "QuadMesh / TriMesh or a (V, F) pair")
    V = np.asarray(V, dtype=np.float64)
    if V.ndim != 2 or V.shape[1] != 3:
        raise MeshError(f"vertices must have shape (n, 3), got {V.shape}")
    if not np.all(np.isfinite(V)):
        raise MeshError("the vertices hold NaN or infinite coordinates; repair the mesh")
    P, sizes = _as_padded(F)
    if len(P) and (P.max() >= len(V) or P[P >= 0].min() < 0):
        raise MeshError(f"faces refer to vertices outside 0 .. {len(V) - 1}")
    return V, P, sizes


def _faces(V: np.ndarray, P: np.ndarray, sizes: np.ndarray) -> np.ndarray:
    """Quads when every face is a quad, triangles when every face is one, else triangulated."""
    from gridshell.geometry.quadmesh import _triangulate_padded

    if np.all(sizes == 4):
        return P[:, :4].copy()
    if np.all(sizes == 3):
        return P[:, :3].copy()
    return _triangulate_padded(V, P, sizes)


def _scaled_surface(surface: Any, factor: float) -> Any:
    from gridshell.geometry.bspline import BSplineSurface

    if factor == 1.0:
        return surface
    return BSplineSurface(surface.degree_u, surface.degree_v, surface.knots_u, surface.knots_v,
                          surface.ctrl * float(factor))


def swap_uv(surface: Any) -> Any:
    """The same B-spline surface with ``u`` and ``v`` exchanged (``--transpose`` of a NURBS
    input: the PHLW rows follow the other family)."""
    from gridshell.geometry.bspline import BSplineSurface

    return BSplineSurface(surface.degree_v, surface.degree_u, surface.knots_v, surface.knots_u,
                          surface.ctrl.transpose(1, 0, 2).copy())


def surface_grid(surface: Any, longest: int = SURFACE_SAMPLES) -> tuple[int, int]:
    """Rows x columns of a sampling of ``surface`` with ``longest`` samples along its longer
    side (mean iso-curve lengths through the control net), at least 8 along the other."""
    C = surface.ctrl
    lu = float(np.linalg.norm(np.diff(C, axis=0), axis=-1).sum(axis=0).mean())
    lv = float(np.linalg.norm(np.diff(C, axis=1), axis=-1).sum(axis=1).mean())
    if lu >= lv:
        return longest, max(8, int(round(longest * lv / max(lu, 1e-300))))
    return max(8, int(round(longest * lu / max(lv, 1e-300)))), longest


def _sample_surface(surface: Any) -> Any:
    return surface.sample(*surface_grid(surface))


def check_disk(V: np.ndarray, F: np.ndarray, name: str, report: Any = None, *,
               what: str = "the target", tolerance: float | None = None,
               weld_hint: bool = True) -> None:
    """:class:`MeshError` unless ``(V, F)`` (checked manifold and oriented) is one disk: one
    connected piece, Euler characteristic 1, one boundary loop. The message says whether the
    mesh looked unwelded: with ``report`` (the cleaning done) what the weld did; without it
    (``--no-clean``) how many vertices coincide."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    from gridshell.geometry.quadmesh import unique_ints

    F = np.asarray(F, dtype=np.int64)
    n = len(V)
    k = F.shape[1]
    src = F.ravel()
    dst = np.roll(F, -1, axis=1).ravel()
    a, b = np.minimum(src, dst), np.maximum(src, dst)
    key = a * n + b
    uk, cnt = np.unique(key, return_counts=True)
    used = unique_ints(F)
    chi = len(used) - len(uk) + len(F)
    g = coo_matrix((np.ones(len(src)), (src, dst)), shape=(n, n))
    n_comp = connected_components(g, directed=False)[0] - (n - len(used))
    bk = uk[cnt == 1]
    loops = 0
    if len(bk):
        ba, bb = bk // n, bk % n
        gb = coo_matrix((np.ones(len(bk)), (ba, bb)), shape=(n, n))
        on = unique_ints(np.concatenate([ba, bb]))
        loops = connected_components(gb, directed=False)[0] - (n - len(on))
    if n_comp == 1 and chi == 1 and loops == 1:
        return
    del k
    if n_comp > 1:
        fix = "keep the one patch to design on (or weld the pieces)"
    elif loops == 0:
        fix = "the surface is closed (no boundary): cut it open"
    else:
        fix = "cut the surface open (e.g. a cylinder along a generator) or fill its holes"
    if not weld_hint:
        weld = "a working copy of the target"
    elif report is not None:
        weld = (f"it was welded ({report.summary()}) and is still not one disk" if report.welded
                else "it is not an unwelded mesh (no coincident vertices to weld)")
    else:
        from gridshell.io.clean import WELD_TOLERANCE, coincident_vertices, mean_edge_length
        from gridshell.geometry.quadmesh import _as_padded

        P, sizes = _as_padded(F)
        tol = tolerance if tolerance is not None else \
            WELD_TOLERANCE * mean_edge_length(np.asarray(V, float), P, sizes)
        c = coincident_vertices(np.asarray(V, float), tol, P)
        weld = (f"it looks unwelded: {c} of its {n} vertices coincide with others - weld it "
                "(drop --no-clean)" if c else
                "it is not an unwelded mesh (no coincident vertices)")
    raise MeshError(f"{name}: {what} is not a disk ({n_comp} connected component"
                    f"{'s' if n_comp != 1 else ''}, Euler characteristic {chi}, {loops} "
                    f"boundary loop(s)); a design needs one disk-like patch: {fix}; {weld}")
