"""Export a design bundle to a Rhino ``.3dm`` model an architect can use, through ``rhino3dm``.

**Units and frame.** The model is in the user's unit and frame: ``ModelUnitSystem`` is the
bundle's input unit (``design.json`` ``"units"``, metres when absent; ``units=`` overrides it)
and every coordinate is the bundle's metres divided by the unit's size in metres. Nothing is
moved but the collapsed state and the surface of revolution, which live in frames of their own
and are placed onto the design by the best rigid fit (``collapsed``, ``revolution`` below). Lengths in user strings are in the same unit (``units`` names it) and in metres
(``*_m``).

**Layers and objects**::

    surface           the designed surface as a mesh
    B-spline surface  NCP kinds: the PHLW B-spline of surface.json as a NURBS surface
    family 1          one closed mesh per C^1 lamella (each side its own vertices, shaded
                      flat; see unwelded_sides; only the axis samples it needs, its
                      corner edges within gridshell.geometry.strips3d.ring_tolerance of the
                      full-resolution ones: solid_rings): the strip as built, real width x
                      thickness (gridshell.geometry.strips3d), tangent to the surface for GG (stacked:
                      family 1 on the side the surface.obj normals point to, family 3 on the
                      other, so that crossing strips touch on the surface), standing on
                      it for NCP / CNC / AA (on the centre line, or on its edge with axis "edge")
    family 3          the same for C^3
    axes              one polyline per lamella axis (the design's centre line)
    joints            one point per joint (user strings joint_id, lamellae)
    holes             joint style "hole": one capped cylinder (an Extrusion, as Rhino makes
                      cylinders) per lamella and joint, the hole through the strip (real
                      diameter = hole / scale)
    collapsed         the collapsed (aligned) state: one polyline per lamella through its
                      aligned joints (aligned.obj), moved rigidly onto the deployed joints
                      (best fit): in the input's frame, through the middle of the net
    revolution        GG: the isometric surface of revolution as a mesh, moved rigidly onto
                      the designed surface (best fit of its grid to surface.obj's) when the
                      two grids match, else as stored
    sheet 01, ...     the cut sheets, one layer each, as curves in the XY plane beside the
                      model: the sheet's border, each part's outline (arcs exact), holes,
                      score marks and engraved labels, at the physical size of the cut files
                      (mm of the model, converted to the user's unit)

**User strings.** Strips and axes: ``lamella_id``, ``family``, ``length`` (axis length, user
unit), ``length_m``, ``joints`` (joint ids along the lamella, space separated; also as
``joint_ids``), ``joint_s`` (their arc lengths, user unit), ``width``, ``thickness`` (user unit)
and ``width_m``, ``thickness_m``, ``units``, ``kind``. Sheet curves: ``sheet``, ``role``
(``border``, ``outline``, ``hole``, ``score``, ``engrave``) and for parts ``lamella_id``,
``family``, ``piece``, ``n_pieces``. The model's own strings (``model.Strings``): kind, units,
fabrication parameters and where they came from.

The strip section comes from the fabrication parameters (:mod:`.fabparams`): cut width and
thickness divided by the scale (20 x 1 mm at 1:10 -> 200 x 10 mm). Cut sheets are left out of
a design that fails its figures (as ``gridshell fabricate`` refuses it) unless ``force``.
"""
from __future__ import annotations

import os
from contextlib import nullcontext
from pathlib import Path
from typing import Any, Callable

import numpy as np

from gridshell.core.atomic import atomic_path
from gridshell.core.errors import GridshellError, InputError, OutputError
from gridshell.export import rhino_geometry as geo
from gridshell.geometry import rhino_adapter as rh
from gridshell.core.units import METRES, Units, bundle_units, parse_units

__all__ = ["LAYERS", "RHINO_UNITS", "bundle_to_3dm", "export_3dm"]

#: fixed layer name -> RGBA colour (0-255); sheet layers ("sheet 01", ...) follow them
LAYERS: dict[str, tuple[int, int, int, int]] = {
    "surface": (170, 175, 185, 255),
    "B-spline surface": (150, 160, 175, 255),
    "family 1": (33, 107, 179, 255),
    "family 3": (219, 89, 31, 255),
    "axes": (60, 60, 60, 255),
    "joints": (25, 25, 25, 255),
    "holes": (200, 30, 30, 255),
    "collapsed": (90, 150, 60, 255),
    "revolution": (150, 120, 190, 255),
}
SHEET_COLOUR = (200, 0, 0, 255)
_FILE_VERSION = 8

#: unit name -> rhino3dm.UnitSystem member name
RHINO_UNITS = {"m": "Meters", "mm": "Millimeters", "cm": "Centimeters", "in": "Inches",
               "ft": "Feet"}


def _say(progress: Callable[[str], None] | None, msg: str) -> None:
    if progress is not None:
        progress(msg)


def sheet_layer(k: int) -> str:
    """Layer name of the 0-based sheet ``k``: ``"sheet 01"``, ``"sheet 02"`` ..."""
    return f"sheet {k + 1:02d}"


class _Model(rh.Model3dm):
    """A File3dm (:class:`gridshell.geometry.rhino_adapter.Model3dm`: named layers, object
    attributes) in the user's unit, with the conversion of metres to it."""

    def __init__(self, units: Units) -> None:
        super().__init__(RHINO_UNITS[units.name], 1e-5 / units.metres_per_unit)
        self.units = units

    def u(self, X):
        """Metres -> the user's unit."""
        return np.asarray(X, float) / self.units.metres_per_unit

    def fmt(self, metres: float) -> str:
        return f"{metres / self.units.metres_per_unit:.9g}"


def _clean_polyline(P: np.ndarray) -> np.ndarray:
    """``P (k,3)`` without consecutive repeated points."""
    P = np.asarray(P, float).reshape(-1, 3)
    return P[_distinct(P)]


def _distinct(P: np.ndarray) -> np.ndarray:
    """The rows of ``P (k,3)`` that :func:`_clean_polyline` keeps (each that differs from the
    one before), a boolean mask."""
    if len(P) < 2:
        return np.ones(len(P), bool)
    return np.concatenate([[True], np.linalg.norm(np.diff(P, axis=0), axis=1) > 0])


def _axes_points(bundle) -> np.ndarray:
    """Every lamella axis's points one after the other ``(sum k_i, 3)``, metres: the points
    whose closest surface points the strips' frames and the design check
    (:func:`gridshell.measure.metrics.crossing_normal_curvature_on_mesh`) both ask."""
    return np.concatenate([np.asarray(lam.axis, float).reshape(-1, 3)
                           for lam in bundle.net.lamellae])


def _ask_ahead(bundle) -> None:
    """The closest surface points (and normals) of the axes and the closest points of the
    joints asked now, in one igl query, and kept for reuse (:mod:`gridshell.geometry.igl_adapter`):
    the strips ask the first, and the design check of an NCP kind asks both, in a process
    forked after this (:mod:`gridshell.core.aside`) where it finds them."""
    from gridshell.geometry.igl_adapter import ask_closest_points, closest_points_with_normals

    P, V, F = _axes_points(bundle), bundle.surface_V, bundle.surface_F
    ask_closest_points([P, bundle.net.joints], V, F)
    closest_points_with_normals(P, V, F, reuse=True)


def unwelded_sides(V: np.ndarray, F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The closed strip mesh of :func:`gridshell.geometry.strips3d.strip_solid` (``V (4k,3)``,
    ``F (8(k-1)+4, 3)``: the four long sides, two triangles per segment each, then the two end
    caps) with its own vertices for each of its six sides, so that a renderer shades the
    sides flat instead of smoothing the normals round the strip's edges. The shape is the
    same, the mesh still closed (Rhino joins coincident vertices for its topology)."""
    F = np.asarray(F, np.int64)
    n_side = (len(F) - 4) // 4
    side = np.concatenate([np.repeat(np.arange(4), n_side), [4, 4, 5, 5]])
    # the pairs (side, vertex) as one integer each, in the same (lexicographic) order as
    # np.unique(pairs, axis=0) gives, at a fraction of its time (no row-wise sort)
    M = int(F.max()) + 1 if F.size else 1
    uniq, inverse = np.unique(np.repeat(side, 3) * M + F.reshape(-1), return_inverse=True)
    return np.asarray(V, float)[uniq % M], inverse.reshape(-1, 3)


def _split_frames(PNTWH: tuple[np.ndarray, ...], ends: np.ndarray) -> list[tuple]:
    """The ``(T, W, H)`` of each lamella from :func:`gridshell.geometry.strips3d.strip_frames`' output
    ``(P, N, T, W, H)`` of all lamellae, split at the row offsets ``ends``."""
    _, _, T, W, H = PNTWH
    return list(zip(np.split(T, ends), np.split(W, ends), np.split(H, ends)))


def _strips(m: _Model, bundle, params, with_holes: bool) -> dict[str, Any]:
    """Strip solids on the family layers, axes, and the holes; returns figures."""
    from gridshell.geometry.igl_adapter import closest_points_with_normals
    from gridshell.geometry.net import polyline_arclength
    from gridshell.geometry.strips3d import (is_tangent, real_section_m, solid_rings_many, strip_frames,
                            strip_solid)

    tangent = is_tangent(bundle.kind)
    w, t = real_section_m(params.width, params.thickness, params.scale)
    radius = 0.5 * 1e-3 * params.hole / params.scale
    axes = [np.asarray(lam.axis, float).reshape(-1, 3) for lam in bundle.net.lamellae]
    keeps = [_distinct(P) for P in axes]
    used = [k.sum() >= 2 for k in keeps]
    lams = [(lam, P[k]) for lam, P, k, u in zip(bundle.net.lamellae, axes, keeps, used) if u]
    if not lams:
        return {"strips": 0, "holes": 0, "width_m": w, "thickness_m": t}
    # the surface normal interpolated at the closest point (smooth along the axis; the nearest
    # vertex's normal jumps from vertex to vertex and crinkles the strip: +1.7 % of area on
    # the demo dome, 0.2 % with these), asked for every axis point (reuse: the query the
    # verification of the design asks, gridshell.design.verification; igl answers each point alone)
    normals = closest_points_with_normals(np.concatenate(axes), bundle.surface_V,
                                          bundle.surface_F, reuse=True)[1]   # _axes_points
    normals = normals[np.concatenate([k & u for k, u in zip(keeps, used)])]
    # the frames of all lamellae in one pass each (strip_frames: the numbers of one
    # strip_frame per lamella)
    ends = np.cumsum([len(P) for _, P in lams])[:-1]
    Ns = np.split(normals, ends)
    frames = _split_frames(strip_frames([P for _, P in lams], Ns, tangent), ends)
    if tangent:      # stacked: family 1 on the normals' side of the surface, 3 below
        Cs = [P + (0.5 * t if lam.family == 1 else -0.5 * t) * H
              for (lam, P), (_, _, H) in zip(lams, frames)]
    elif params.axis == "edge":    # the axis on the edge the strip stands on
        Cs = [P + 0.5 * w * W for (_, P), (_, W, _) in zip(lams, frames)]
    else:
        Cs = [P for _, P in lams]
    # the solids' frames along C: the ones above when C is the axis itself
    solid = frames if Cs[0] is lams[0][1] else \
        _split_frames(strip_frames(Cs, Ns, tangent), ends)
    # only the rings the solid needs: its corner edges within ring_tolerance(t) (1 % of
    # the thickness or 0.05 mm, real size) of the full-resolution ones; the axis
    # polyline, the holes and the user strings keep every sample (solid_rings_many: the
    # indices of one solid_rings per lamella)
    rings = solid_rings_many(Cs, [f[1] for f in solid], [f[2] for f in solid], w, t)
    n_holes = 0
    for (lam, P), N, (_, _, H), C, (Tc, Wc, Hc), r in zip(lams, Ns, frames, Cs, solid, rings):
        V, F = strip_solid(C[r], N[r], w, t, tangent, frame=(Tc[r], Wc[r], Hc[r]))
        s = polyline_arclength(P)
        strings = {"lamella_id": int(lam.id), "family": int(lam.family), "kind": bundle.kind,
                   "length": m.fmt(lam.length), "length_m": f"{lam.length:.9g}",
                   "units": m.units.name,
                   "joints": " ".join(str(j) for j in lam.joints.tolist()),
                   "joint_ids": " ".join(str(j) for j in lam.joints.tolist()),
                   "joint_s": " ".join(m.fmt(x) for x in lam.joint_s.tolist()),
                   "width": m.fmt(w), "thickness": m.fmt(t),
                   "width_m": f"{w:.9g}", "thickness_m": f"{t:.9g}"}
        layer = f"family {lam.family}"
        V, F = unwelded_sides(V, F)
        a = m.attrs(layer, f"L{lam.id}", **strings)
        m.model.Objects.AddMesh(geo.mesh(m.u(V), F, what=f"lamella {lam.id} strip"), a)
        m.model.Objects.AddPolyline(geo.point_list(m.u(P)),
                                    m.again(a, "axes", f"L{lam.id} axis"))
        if not with_holes or not len(lam.joints):
            continue
        js = np.clip(lam.joint_s, 0.0, s[-1])
        centres = np.stack([np.interp(js, s, C[:, c]) for c in range(3)], axis=1)
        axes = np.stack([np.interp(js, s, H[:, c]) for c in range(3)], axis=1)
        # one set of attributes for the lamella's holes, the name and joint set for each
        # (joint_id holds its place in the strings: "-" until then; "" would remove it)
        a = m.shared(0, "holes", "", lamella_id=int(lam.id), joint_id="-",
                     diameter=m.fmt(2 * radius))
        for j, c, ax in zip(lam.joints.tolist(), centres, axes):
            hole = geo.cylinder(m.u(c), ax, radius / m.units.metres_per_unit,
                                t / m.units.metres_per_unit)
            m.model.Objects.AddExtrusion(hole, m.again(a, "holes", f"L{lam.id} J{j} hole",
                                                       joint_id=j))
            n_holes += 1
    return {"strips": len(lams), "holes": n_holes, "width_m": w, "thickness_m": t}


def _bbox(bundle) -> tuple[np.ndarray, np.ndarray]:
    X = np.concatenate([np.asarray(bundle.surface_V, float).reshape(-1, 3), bundle.net.joints]
                       + [lam.axis for lam in bundle.net.lamellae])
    return X.min(axis=0), X.max(axis=0)


def _sheets(m: _Model, bundle, layout, params) -> list[dict[str, Any]]:
    """The cut sheets as curves on one layer each, in a row in the XY plane beside the model
    (right of its bounding box, from its lowest corner), at their physical size."""
    lo, hi = _bbox(bundle)
    W, H = layout.sheet
    to_unit = 1e-3 / m.units.metres_per_unit      # mm -> user unit
    x = m.u(hi[0] + 0.1 * max(float(np.linalg.norm(hi - lo)), 1e-3))
    y0, z = m.u(lo[1]), float(m.u(lo[2]))
    out = []
    for k in range(layout.n_sheets):
        layer = sheet_layer(k)
        m.layer(layer, SHEET_COLOUR)
        origin = np.array([float(x), float(y0)])

        def place(P):
            return origin + np.asarray(P, float).reshape(-1, 2) * to_unit

        border = place([[0, 0], [W, 0], [W, H], [0, H], [0, 0]])
        m.model.Objects.AddCurve(geo.bulge_curve(border, None, False, z),
                                 m.attrs(layer, layer, sheet=k + 1, role="border",
                                         width_mm=f"{W:g}", height_mm=f"{H:g}",
                                         scale=f"{params.scale:g}"))
        parts = layout.on_sheet(k)
        for p in parts:
            st = p.strip
            ids = {"sheet": k + 1, "lamella_id": int(st.lamella), "family": int(st.family),
                   "piece": int(st.piece), "n_pieces": int(st.n_pieces)}
            name = f"L{st.lamella}" + (f"-{st.piece}/{st.n_pieces}" if st.n_pieces > 1 else "")
            m.model.Objects.AddCurve(geo.bulge_curve(place(p.outline.V), p.outline.B,
                                                     p.outline.closed, z),
                                     m.attrs(layer, name, role="outline", **ids))
            # one set of attributes for a part's holes, one for its scores, one for its
            # labels (copied into each object: the same attributes as one set each)
            if len(p.holes):
                a = m.shared(len(p.holes), layer, f"{name} hole", role="hole", **ids)
                for c, r in zip(place(p.holes), p.radii.tolist()):
                    m.model.Objects.AddCircle(geo.circle(c, r * to_unit, z), a)
            if len(p.scores):
                a = m.shared(len(p.scores), layer, f"{name} score", role="score", **ids)
                for ab in p.scores:
                    m.model.Objects.AddCurve(geo.bulge_curve(place(ab), None, False, z), a)
            if len(p.engrave):
                a = m.shared(len(p.engrave), layer, f"{name} label", role="engrave", **ids)
                for L in p.engrave:
                    m.model.Objects.AddCurve(geo.bulge_curve(place(L), None, False, z), a)
        out.append({"layer": layer, "parts": len(parts),
                    "origin": [float(origin[0]), float(origin[1]), z]})
        x = x + (W + 0.05 * W) * to_unit
    return out


def bundle_to_3dm(bundle, *, name: str = "", units: Any = None, params: Any = None,
                  layout: Any = None, bspline: Any = None, params_source: str = ""
                  ) -> tuple[Any, dict[str, Any]]:
    """``(model, info)``: a ``rhino3dm.File3dm`` of a :class:`~gridshell.design.bundle.DesignBundle`
    (layers, objects and user strings: the module docstring) and what went into it.

    Parameters
    ----------
    units : unit name, ``{"name", "metres_per_unit"}`` or Units, optional
        The model's unit; default the bundle's input unit (metres when it records none).
    params : FabParams, optional
        Strip section, holes and sheets (mm of the model); default
        :class:`~gridshell.fabrication.params.FabParams` ().
    layout : gridshell.fabrication.nesting.Layout, optional
        Cut sheets to draw (:func:`gridshell.export.fabparams.plan_sheets`); None: none.
    bspline : BSplineSurface, optional
        The NURBS surface of the "B-spline surface" layer.
    """
    return _finish(_body(bundle, name=name, units=units, params=params, bspline=bspline),
                   layout=layout, params_source=params_source)


def _body(bundle, *, name: str, units: Any, params: Any, bspline: Any) -> dict[str, Any]:
    """The model of :func:`bundle_to_3dm` but its cut sheets and strings, and what
    :func:`_finish` needs to add them."""
    from gridshell.fabrication.params import FabParams

    units = parse_units(units) if units is not None else bundle_units(bundle)
    note = ""
    if units.name not in RHINO_UNITS:
        note = f"unit {units.name} has no Rhino unit system: the model is in metres"
        units = METRES
    params = params or FabParams()
    m = _Model(units)
    with_holes = params.joints == "hole"
    for n, colour in LAYERS.items():
        if n == "revolution" and bundle.revolution_V is None:
            continue
        if n == "B-spline surface" and bspline is None:
            continue
        if n == "holes" and not with_holes:
            continue
        m.layer(n, colour)

    m.model.Objects.AddMesh(geo.mesh(m.u(bundle.surface_V), bundle.surface_F),
                            m.attrs("surface", "surface", kind=bundle.kind, bundle=name,
                                    units=units.name))
    if bspline is not None:
        m.model.Objects.AddSurface(
            geo.nurbs_surface(bspline.degree_u, bspline.degree_v, bspline.knots_u,
                              bspline.knots_v, m.u(bspline.ctrl)),
            m.attrs("B-spline surface", "B-spline surface", kind=bundle.kind))
    if bundle.revolution_V is not None:
        m.model.Objects.AddMesh(geo.mesh(m.u(_placed_revolution(bundle)), bundle.revolution_F),
                                m.attrs("revolution", "surface of revolution", kind=bundle.kind))
    strips = _strips(m, bundle, params, with_holes)

    through: dict[int, list[int]] = {}
    collapsed = _placed_collapsed(bundle)
    for lam in bundle.net.lamellae:
        for j in lam.joints.tolist():
            through.setdefault(j, []).append(int(lam.id))
        if len(lam.joints) >= 2:
            m.model.Objects.AddPolyline(
                geo.point_list(m.u(collapsed[lam.joints])),
                m.attrs("collapsed", f"L{lam.id} collapsed", state="collapsed",
                        lamella_id=int(lam.id), family=int(lam.family),
                        joints=" ".join(str(j) for j in lam.joints.tolist())))
    a = m.shared(0, "joints", "", joint_id="-", lamellae="-")     # one set, values per joint
    for j, p in enumerate(m.u(bundle.net.joints).tolist()):
        m.model.Objects.AddPoint(rh.point(p), m.again(
            a, "joints", f"J{j}", joint_id=j, lamellae=" ".join(map(str, through.get(j, [])))))

    return {"m": m, "bundle": bundle, "name": name, "params": params, "units": units,
            "strips": strips, "note": note}


def _finish(body: dict[str, Any], *, layout: Any, params_source: str
            ) -> tuple[Any, dict[str, Any]]:
    """The cut sheets of ``layout`` and the model's strings added to the model of
    :func:`_body`: ``(model, info)`` of :func:`bundle_to_3dm`."""
    m, bundle, name, params = body["m"], body["bundle"], body["name"], body["params"]
    units, strips, note = body["units"], body["strips"], body["note"]
    sheets = _sheets(m, bundle, layout, params) if layout is not None else []
    strings = {"gridshell.kind": bundle.kind, "gridshell.units": units.name,
               "gridshell.metres_per_unit": f"{units.metres_per_unit:.12g}",
               "gridshell.bundle": name,
               "gridshell.strip_width_mm": f"{params.width:g}",
               "gridshell.strip_thickness_mm": f"{params.thickness:g}",
               "gridshell.hole_mm": f"{params.hole:g}",
               "gridshell.scale": f"{params.scale:g}",
               "gridshell.fabrication_parameters": params_source or "given"}
    m.strings(strings)
    info = {"units": units.name, "metres_per_unit": units.metres_per_unit,
            "layers": dict(m.counts), "strips": strips["strips"], "holes": strips["holes"],
            "strip_width_m": strips["width_m"], "strip_thickness_m": strips["thickness_m"],
            "sheets": sheets, "note": note}
    return m.model, info


def _check_finite(bundle) -> None:
    """:class:`GridshellError` (a bug: bundles are validated when read) unless every coordinate
    that goes into the .3dm file is finite: nothing non-finite is ever written."""
    arrays = {"net joints": bundle.net.joints, "aligned joints": bundle.aligned,
              "surface": bundle.surface_V}
    arrays.update({f"lamella {lam.id} axis": lam.axis for lam in bundle.net.lamellae})
    for what, a in arrays.items():
        if not np.all(np.isfinite(np.asarray(a, float))):
            raise GridshellError(f"refusing to write the .3dm file: the {what} are not finite; "
                                 "this is a bug, please report it")


def export_3dm(bundle, path: str | os.PathLike, *, width: float | None = None,
               thickness: float | None = None, hole: float | None = None,
               scale: Any = None, sheet: Any = None, params: Any = None, units: Any = None,
               sheets: bool = True, force: bool = False, verified: bool = False,
               progress: Callable[[str], None] | None = None) -> dict[str, Any]:
    """Write a design to a Rhino ``.3dm`` file (Rhino 8 format), atomically; returns what was
    written (``path``, ``units``, object counts per layer, ``sheets``, the fabrication
    parameters and their source, and ``notes``). ``gridshell.export_3dm`` is this function.

    Parameters
    ----------
    bundle : path-like, Design or DesignBundle
        The design bundle directory, or a design in memory (the result of ``design_gg`` /
        ``design_ncp``, or its bundle).
    path : path-like
        Output ``.3dm`` file.
    width, thickness, hole, scale, sheet : optional
        Cut strip width, thickness and hole diameter (mm of the model), the model scale
        (``"1:10"`` or 0.1) and the sheet size (``"600x400"`` mm); the strips' real section
        is width / scale x thickness / scale. Default: the bundle's
        ``fabrication/fabrication.json``, else FabParams defaults.
    params : FabParams or dict, optional
        All fabrication parameters at once (the values above still override them).
    units : optional
        The model's unit (``"mm"``, ``"m"`` ...); default the bundle's input unit.
    sheets : bool
        Draw the cut sheets (planned in memory as ``gridshell fabricate`` would).
    force : bool
        Draw the cut sheets of a design that fails its figures too.
    verified : bool
        The caller has just verified these very files (``gridshell build``'s verify stage):
        the design's figures are not computed again before the sheets are drawn.

    The design check and the cut-sheet plan run in a second process (:mod:`gridshell.core.aside`,
    forked on Linux) while this one builds the rest of the model; the file is the same.
    """
    bundle = _design_bundle(bundle)
    path = check_3dm_path(path)
    info = write_model(bundle, path, width=width, thickness=thickness, hole=hole, scale=scale,
                       sheet=sheet, params=params, units=units, sheets=sheets, force=force,
                       verified=verified, progress=progress, publish=True)
    info["path"] = str(path)
    return info


def _design_bundle(design: Any) -> Any:
    """A bundle directory or DesignBundle as it is; the bundle of a Design; else InputError."""
    from gridshell.design.bundle import Design, DesignBundle

    if isinstance(design, (str, os.PathLike, DesignBundle)):
        return design
    if isinstance(design, Design):
        return design.bundle
    raise InputError(f"expected a design (the result of design_gg / design_ncp), a "
                     f"DesignBundle or a bundle directory, got {type(design).__name__}")


def __getattr__(name: str) -> Any:
    if name == "write_3dm":
        import warnings

        warnings.warn("gridshell.export.rhino.write_3dm is export_3dm now (the same function "
                      "and result); write_3dm goes in the next release", DeprecationWarning,
                      stacklevel=2)
        return export_3dm
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def check_3dm_path(path: str | os.PathLike) -> Path:
    """``path`` as a Path; :class:`InputError` unless it ends in ``.3dm``."""
    path = Path(path)
    if path.suffix.lower() != ".3dm":
        raise InputError(f"{path.name}: a Rhino file needs the extension .3dm")
    return path


def write_model(bundle, path: str | os.PathLike, *, width: float | None = None,
                thickness: float | None = None, hole: float | None = None,
                scale: Any = None, sheet: Any = None, params: Any = None, units: Any = None,
                sheets: bool = True, force: bool = False, verified: bool = False,
                progress: Callable[[str], None] | None = None, publish: bool = False,
                shown: str | os.PathLike | None = None) -> dict[str, Any]:
    """The body of :func:`export_3dm` (same parameters): build the model, then write it to
    ``path`` - atomically with ``publish`` (:func:`gridshell.core.atomic.atomic_path`: temporary
    file, rename, manifest entry), else as it is, into a temporary file the caller publishes
    (:mod:`gridshell.workflow.outputs` runs this in a second process). ``shown`` is the path progress and
    errors name (default ``path``). Returns what :func:`export_3dm` returns but ``path``."""
    from gridshell.core.aside import Aside
    from gridshell.design.bundle import read_bundle, read_design_json
    from gridshell.export.fabparams import export_params

    shown = path if shown is None else shown
    bundle_dir = None
    if isinstance(bundle, (str, os.PathLike)):
        bundle_dir = Path(bundle)
        design = read_design_json(bundle_dir)
        bundle, name = read_bundle(bundle_dir), bundle_dir.resolve().name
        if units is None:
            units = bundle_units(design)
    else:
        name = ""
    _check_finite(bundle)
    fab, source = export_params(bundle_dir, params, width=width, thickness=thickness,
                                hole=hole, scale=scale, sheet=sheet)
    notes: list[str] = []
    bspline = None
    if bundle_dir is not None and (bundle_dir / "surface.json").is_file():
        from gridshell.geometry.bspline import BSplineSurface

        bspline = BSplineSurface.load(bundle_dir / "surface.json")
    judged = None if verified else bundle_dir if bundle_dir is not None else bundle
    if sheets:
        _say(progress, "checking the design's figures and planning the cut sheets")
    # the cut sheets (design check, then plan) computed aside, in a second process, while this
    # one builds the rest of the model: the same objects in the same order as one after the
    # other (gridshell.core.aside; one process where a fork is not safe)
    if sheets:
        _ask_ahead(bundle)
    with Aside(_cut_sheets, judged, bundle, fab, force) if sheets else nullcontext() as aside:
        _say(progress, f"writing {shown}")
        body = _body(bundle, name=name, units=units, params=fab, bspline=bspline)
        layout = None
        if aside is not None:
            ok, why, layout, planned, fallback = aside.result()
            if layout is not None and planned != fab:   # holes became marks: other strips
                body = _body(bundle, name=name, units=units, params=planned, bspline=bspline)
            fab = planned
            if not ok:
                notes.append(f"cut sheets of a design that fails its figures ({why}), drawn "
                             "because of force" if layout is not None else
                             f"no cut sheets: the design fails its figures ({why}); force draws "
                             "them anyway")
            if fallback:
                notes.append(fallback)
    model, info = _finish(body, layout=layout, params_source=source)
    if info["note"]:
        notes.append(info["note"])
    with atomic_path(path) if publish else nullcontext(path) as tmp:
        if not rh.write_file(model, tmp, _FILE_VERSION):
            raise OutputError(f"rhino3dm could not write {shown}; check the location is "
                              "writable")
    info.update(params=fab.to_json(), params_source=source, notes=notes)
    return info


def _cut_sheets(judged, bundle, fab, force: bool) -> tuple[bool, str, Any, Any, str | None]:
    """``(ok, why, layout, params, fallback)``: the verdict on the design
    (:func:`gridshell.design.verification.design_verdict` of ``judged``, its directory or itself;
    ``judged`` None: verified by the caller, it holds) and,
    if it holds or ``force``, its cut sheets planned (:func:`.fabparams.plan_sheets`; ``layout``
    None otherwise) with the parameters the plan used and why joints too close for holes
    became marks (``fallback``, None when they did not)."""
    from gridshell.design.verification import design_verdict
    from gridshell.export.fabparams import plan_sheets

    if judged is None:
        return (True, "", *plan_sheets(bundle, fab))
    verdict = design_verdict(judged)
    ok, why = verdict.ok, verdict.why()
    if not (ok or force):
        return ok, why, None, fab, None
    return (ok, why, *plan_sheets(bundle, fab))


def _placed_collapsed(bundle) -> np.ndarray:
    """The aligned joints ``(n, 3)`` moved by the rigid motion that best fits them to the
    deployed joints (metres of the design)."""
    from gridshell.geometry.vectors import rigid_fit

    A = np.asarray(bundle.aligned, float)
    if len(A) < 3:
        return A
    R, b = rigid_fit(A, bundle.net.joints)
    return A @ R.T + b


def _placed_revolution(bundle) -> np.ndarray:
    """The surface of revolution's vertices moved by the rigid motion that best fits them to
    the designed surface's, vertex for vertex (the two grids match), else as stored."""
    from gridshell.geometry.vectors import rigid_fit

    V = np.asarray(bundle.revolution_V, float)
    if V.shape != np.asarray(bundle.surface_V).shape or len(V) < 3:
        return V
    R, b = rigid_fit(V, bundle.surface_V)
    return V @ R.T + b
