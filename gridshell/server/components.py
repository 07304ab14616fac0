"""The Hops components of ``gridshell serve``, each a thin call of the Python API.

=============  ======================================================  ==================
route          inputs                                                   outputs
=============  ======================================================  ==================
``/gg``        Target (mesh, m), Lamellae, Grid, Options, Surface (m)   Net, Lamellae,
                                                                        Aligned, Metrics,
                                                                        Bundle
``/ncp``       Reference (mesh, m), Mode, Curves, Options, Surface      (as ``/gg``)
``/analyze``   Target (mesh, m), Samples, Surface (m)                   Recommended, Why,
                                                                        Summary, Report,
                                                                        Folder
``/verify``    Bundle                                                   OK, Checks, Report
``/fabricate`` Bundle, Scale, Sheet, Width, Options, Force              Cut, Score,
                                                                        Engrave, Sheets,
                                                                        Report, Folder
``/sweep``     Target (mesh), Vary (NAME=VALUES list), Workers,         Table, Best, Page,
               Surface, Units                                           Folder
``/build``     Target (mesh), Kind, Material, Lamellae, Scale,          Summary, Build,
               Surface, Units                                           Report, Pack
=============  ======================================================  ==================

A design component takes a mesh (Target / Reference) or a NURBS surface or single-face Brep
(Surface: a Grasshopper Mesh input would mesh it), read as ``gridshell gg|ncp model.3dm`` reads
the same object (:func:`gridshell.server.rhino.target_input`): double-precision vertices,
polygons kept, a NURBS surface the B-spline itself.

Designs are written as bundles into the server's work directory; ``Bundle`` is the path that
``/verify`` and ``/fabricate`` take, accepted inside that directory or a ``--allow`` folder
only (:mod:`gridshell.server.guard`). ``Options`` is a JSON object of further keywords of
:func:`gridshell.gg.pipeline.design_gg`, :func:`gridshell.ncp.pipeline.design_ncp` or
:class:`fabrication.FabParams` (``{}`` for none). Metrics and reports are JSON text.

``/sweep`` runs a small study (at most :data:`MAX_SWEEP` variants, ``Vary`` items as
``gridshell sweep --vary``) on the same engine as the CLI (a Dask LocalCluster of ``Workers``
processes, at most the cores): the target is stored as ``target.3dm`` (metres) in the
study's folder, read back as the CLI reads it; Table is the results as JSON rows.

A failure never leaves a dead component: the reply carries the tool's one-line message in
``errors`` (Hops shows it on the component, its outputs empty), and a design that misses the
paper's figures (``allow_unconverged`` in Options) comes back with a warning.
"""
from __future__ import annotations

import json
import uuid
from pathlib import Path
from typing import Any, Callable

import numpy as np

from gridshell.core.errors import InputError
from gridshell.server import rhino

#: the keywords ``Options`` may give, per component (the others are inputs of their own)
GG_OPTIONS = ("units", "meridians", "direction", "spacing", "crossing_angle", "at_parallel", "offsets",
              "weights", "angle", "rounds", "polish_iter", "allow_unconverged", "frames")
NCP_OPTIONS = ("units", "spacing", "n", "samples", "levelset_ctrl", "levelset_degree", "omega_f",
               "trace_grid", "collapse_samples", "postopt_weights", "postopt_rounds",
               "frames", "sim_weights", "surface_samples", "phlw_options",
               "allow_unconverged")
#: keys of the sub-dictionaries and pairs given as JSON lists
_PAIRS = ("samples", "levelset_ctrl", "levelset_degree", "trace_grid", "collapse_samples",
          "surface_samples")
SHEET_SPACING = 50.0   # mm between the sheets laid out along x in the Fabricate outputs
#: the largest study ``/sweep`` runs (a bigger one belongs to ``gridshell sweep``)
MAX_SWEEP = 24


class Reply:
    """What a component handler returns: output values in order, and warnings."""

    def __init__(self, *values: Any, warnings: list[str] | None = None):
        self.values = values
        self.warnings = list(warnings or [])


def options(text: str, allowed: tuple[str, ...], what: str) -> dict[str, Any]:
    """The JSON object ``text`` as keyword arguments; InputError naming an unknown key."""
    text = (text or "").strip() or "{}"
    try:
        d = json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError(f"Options is not JSON ({exc.msg} at character {exc.pos}); give an "
                         'object such as {"frames": 0}') from None
    if not isinstance(d, dict):
        raise InputError('Options must be a JSON object such as {"frames": 0}')
    bad = sorted(set(d) - set(allowed))
    if bad:
        raise InputError(f"Options of {what} has unknown keys {', '.join(bad)}; allowed: "
                         f"{', '.join(allowed)}")
    for k in _PAIRS:
        if k in d and isinstance(d[k], list):
            d[k] = tuple(d[k])
    return d


def _net_outputs(bundle, out: Path, warnings: list[str]) -> Reply:
    """Net (mesh of the joints and loops), lamella axes and aligned polylines (m), metrics
    (JSON) and the bundle's path."""
    from gridshell.design.bundle import finite_json

    net = bundle.net
    mesh = rhino.to_mesh(net.joints, net.loops, compact=False)   # every joint, in order
    axes = [rhino.to_polyline(lam.axis) for lam in net.lamellae]
    aligned = [rhino.to_polyline(bundle.aligned[np.asarray(lam.joints)])
               for lam in net.lamellae]
    metrics = json.dumps(finite_json(bundle.metrics), default=_plain, allow_nan=False)
    return Reply(mesh, axes, aligned, metrics, str(out), warnings=warnings)


def _quality_warning(bundle) -> list[str]:
    q = bundle.metrics.get("quality") or bundle.params.get("quality") or {}
    if q and not q.get("ok", True):
        return [f"the design misses the paper's figures ({q.get('summary', '')}); written "
                "because of allow_unconverged, marked as failing"]
    return []


def _plain(o: Any) -> Any:
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    return str(o)


def design_gg_component(new_dir: Callable[[str], Path], target: Any = None, lamellae: int = 6,
                        grid: int = 12, opts: str = "{}", surface: Any = None) -> Reply:
    """The ``/gg`` component: a GG design of ``target`` (a Rhino mesh) or ``surface`` (a NURBS
    surface or single-face Brep), both in metres, read as the CLI reads the same object from a
    .3dm (:func:`gridshell.server.rhino.target_input`), written as a bundle into
    ``new_dir("gg")``."""
    from gridshell.api import design_gg, write

    kw = options(opts, GG_OPTIONS, "GG design")
    kw.setdefault("frames", 0)
    units = rhino.parse_units_input(kw.pop("units", None))
    geo = rhino.target_input(_one_target(target, surface, "Target"), units=units)
    if int(grid) < 4 or int(lamellae) < 2:
        raise InputError(f"Grid {grid} and Lamellae {lamellae}: give Grid >= 4 and "
                         "Lamellae >= 2")
    design = design_gg(geo, grid=(int(grid), int(grid)), n_lamellae=int(lamellae), **kw)
    out = write(new_dir("gg"), design, render=False, frames=0)
    return _net_outputs(design.bundle, out, _quality_warning(design.bundle))


def design_ncp_component(new_dir: Callable[[str], Path], reference: Any = None,
                         mode: str = "cnc", curves: int = 8, opts: str = "{}",
                         surface: Any = None) -> Reply:
    """The ``/ncp`` component: an NCP / CNC / AA design of ``reference`` (a Rhino mesh) or
    ``surface`` (a NURBS surface or single-face Brep, used as the B-spline it is), metres,
    written as a bundle into ``new_dir(kind)``."""
    from gridshell.api import design_ncp, write

    kw = options(opts, NCP_OPTIONS, "NCP design")
    units = rhino.parse_units_input(kw.pop("units", None))
    geo = rhino.target_input(_one_target(reference, surface, "Reference"), what="the reference",
                             units=units)
    design = design_ncp(geo, mode=str(mode).strip().lower(), curves=int(curves), **kw)
    bundle = design.bundle
    out = write(new_dir(bundle.kind.lower()), design, render=False)
    return _net_outputs(bundle, out, _quality_warning(bundle))


def _one_target(mesh: Any, surface: Any, name: str) -> Any:
    """The one target given: the mesh input ``name`` or the Surface input; InputError for
    neither or both."""
    if mesh is None and surface is None:
        raise InputError(f"input {name} is missing; connect a mesh to {name} or a NURBS "
                         "surface to Surface")
    if mesh is not None and surface is not None:
        raise InputError(f"both {name} and Surface are connected; connect one of them")
    return mesh if surface is None else surface


def analyze_component(new_dir: Callable[[str], Path], target: Any = None, samples: int = 64,
                      surface: Any = None) -> Reply:
    """The ``/analyze`` component: where each kind of net can exist on ``target`` (a Rhino
    mesh) or ``surface`` (NURBS), metres, and the pipeline to run
    (:func:`gridshell.api.analyze`); analysis.json and analysis.png in ``new_dir("analysis")``."""
    from gridshell.api import analyze
    from gridshell.analysis.analyze import summary_of
    from gridshell.design.bundle import finite_json

    if not 8 <= int(samples) <= 400:
        raise InputError(f"Samples {samples}: give 8 to 400 samples per direction")
    geo = rhino.target_input(_one_target(target, surface, "Target"))
    out = new_dir("analysis")
    a = analyze(geo, samples=int(samples), output=out)
    lines = [f"{k}: {v}" for k, v in summary_of(a).items()]
    rec = a.recommendation
    return Reply(rec.command, rec.why, lines,
                 json.dumps(finite_json(a.as_dict()), default=_plain, allow_nan=False), str(out))


def verify_component(resolve: Callable[[Any], Path], bundle_dir: str) -> Reply:
    """The ``/verify`` component: OK, the pass / FAIL lines and the recomputed figures (JSON)
    of the bundle at ``bundle_dir`` (:func:`gridshell.design.verification.design_verdict`),
    a folder ``resolve`` accepts (:meth:`gridshell.server.guard.Guard.bundle_dir`)."""
    from gridshell.design.bundle import finite_json
    from gridshell.design.verification import design_verdict

    verdict = design_verdict(resolve(bundle_dir))
    res = verdict.report
    warnings = [] if verdict.ok else ["the design fails its checks: " + "; ".join(
        [g.line() for g in verdict.gates if not g.ok] + list(verdict.problems))]
    return Reply(bool(res["ok"]), list(res["checks"]) + list(res["problems"]),
                 json.dumps(finite_json(res), default=_plain, allow_nan=False),
                 warnings=warnings)


def fabricate_component(resolve: Callable[[Any], Path], bundle_dir: str,
                        scale: str | None = None, sheet: str = "600x400",
                        width: float | None = None, opts: str = "{}",
                        force: bool = False) -> Reply:
    """The ``/fabricate`` component: the cut files (as ``gridshell fabricate``) of the bundle
    at ``bundle_dir``, a folder ``resolve`` accepts, and its nested parts as curves, mm, the
    sheets laid out along x (:func:`_sheet_curves`)."""
    from dataclasses import fields

    from gridshell.design.section import resolve_section
    from gridshell.design.verification import require_design
    from gridshell.fabrication import FabParams, fabricate

    names = tuple(f.name for f in fields(FabParams) if f.name not in ("scale", "sheet", "width"))
    kw = options(opts, names, "Fabricate")
    path = resolve(bundle_dir)
    verdict = require_design(str(path), bool(force), "set Force to cut it anyway")
    strip = resolve_section(path, width=width, thickness=kw.pop("thickness", None),
                            scale=scale, stored=False)   # as 'gridshell fabricate'
    params = FabParams(scale=strip.scale, sheet=sheet, width=strip.width_mm,
                       thickness=strip.thickness_mm, **kw)
    out = path / "fabrication"
    rep = fabricate(path, out, params, plan=False, keep_layout=True)
    cut, score, engrave, sheets = _sheet_curves(rep.pop("layout"), params.tolerance)
    warnings = [] if verdict.ok else ["the design fails its checks; cut anyway (Force)"]
    if rep.get("joints_fallback"):
        warnings.append(rep["joints_fallback"])
    summary = {k: rep[k] for k in ("kind", "shape", "n_strips", "n_pieces", "n_sheets",
                                   "utilisation", "utilisation_per_sheet",
                                   "material_used", "labels_dropped") if k in rep}
    return Reply(cut, score, engrave, sheets,
                 json.dumps(summary, default=_plain), str(out), warnings=warnings)


def sweep_component(new_dir: Callable[[str], Path], target: Any = None, vary: Any = None,
                    workers: int = 2, surface: Any = None, units: str = "") -> Reply:
    """The ``/sweep`` component: every variant of ``vary`` (``NAME=V1,V2`` items, as
    ``gridshell sweep --vary``) on ``target`` (a Rhino mesh) or ``surface`` (NURBS), metres,
    run by :func:`gridshell.workflow.sweep.sweep` into ``new_dir("sweep")``; the table as
    JSON rows, the best variant (elastic, cut, least utilisation), sweep.html and the folder."""
    import os

    from gridshell.api import sweep
    from gridshell.design.bundle import finite_json
    from gridshell.workflow.study import Study, parse_vary

    items = [vary] if isinstance(vary, str) else list(vary or [])
    values, ranges = parse_vary([str(v) for v in items if str(v).strip()])
    if not values or ranges:
        raise InputError("Vary: give NAME=V1,V2 items (e.g. lamellae=6,8 and kind=gg,cnc); "
                         "ranges are for 'gridshell sweep --samples'")
    study_size = len(Study("target.3dm", values))
    if study_size > MAX_SWEEP:
        raise InputError(f"Vary gives {study_size} variants, more than the server's "
                         f"{MAX_SWEEP}; give fewer values or run 'gridshell sweep'")
    cores = os.cpu_count() or 1
    if not 1 <= int(workers) <= cores:
        raise InputError(f"Workers {workers}: give 1 to {cores} (the server's cores)")
    u = rhino.parse_units_input(units)
    out = new_dir("sweep")
    target_3dm = _stored_target(target, surface, u, out)
    res = sweep(Study(str(target_3dm), values), out / "study", workers=int(workers))
    rows = finite_json(res.table.to_dict(orient="records"))
    ok = [r for r in rows if r.get("code") == 0 and r.get("max_utilisation") is not None]
    best = min(ok, key=lambda r: r["max_utilisation"]) if ok else None
    best_text = (", ".join(f"{k}={best[k]}" for k in values) + f" (key {best['key']})"
                 if best else "")
    warnings = [] if ok else ["no variant was cut: see the Table's code and message"]
    return Reply(json.dumps(rows, default=_plain, allow_nan=False), best_text,
                 str(res.page or ""), str(out / "study"), warnings=warnings)


def _stored_target(target: Any, surface: Any, units: str | None, out: Path) -> Path:
    """The target (checked first: a bad one gives its message before anything is written)
    stored as ``out/target.3dm`` in the unit it is drawn in, which the CLI reads as it is."""
    from gridshell.geometry import rhino_adapter as rh

    obj = _one_target(target, surface, "Target")
    rhino.target_input(obj, units=units)
    out.mkdir(parents=True)
    model = rh.Model3dm(rhino.RHINO_UNITS[units or "m"], 1e-6).model
    model.Objects.Add(obj)
    if not rh.write_file(model, out / "target.3dm"):
        raise InputError("could not store the target as a .3dm; connect a mesh or a surface")
    return out / "target.3dm"


def build_component(new_dir: Callable[[str], Path], target: Any = None, kind: str = "auto",
                    material: str = "", lamellae: int = 0, scale: str = "",
                    surface: Any = None, units: str = "") -> Reply:
    """The ``/build`` component: ``gridshell build`` of ``target`` (a Rhino mesh) or
    ``surface`` (NURBS) drawn in ``units`` (default metres), into ``new_dir("build")``: the
    summary lines, build.json (JSON), report.html and the pack's folder."""
    from gridshell.design.bundle import finite_json
    from gridshell.design.section import parse_scale
    from gridshell.structure.materials import get_material
    from gridshell.workflow.build import BUILD_JSON, KINDS, build

    kind = str(kind or "auto").strip().lower()
    if kind not in KINDS:
        raise InputError(f"Kind {kind!r}: give one of {', '.join(KINDS)}")
    mat = str(material or "").strip() or None
    if mat is not None:
        get_material(mat)                                    # an unknown one: its message
    if scale:
        parse_scale(scale)
    n = int(lamellae or 0)
    if n == 1 or n < 0:
        raise InputError(f"Lamellae {lamellae}: give 2 or more (0: the default)")
    u = rhino.parse_units_input(units)
    out = new_dir("build")
    model = _stored_target(target, surface, u, out)
    res = build(model, out / "pack", kind=kind, material=mat, lamellae=n or None,
                scale=scale or None)
    rec = json.loads((out / "pack" / BUILD_JSON).read_text(encoding="utf-8"))
    sec, st = res.section, res.stages
    lines = [f"kind: {res.kind} ({res.why})",
             f"section: {sec['width_mm']:g} x {sec['thickness_mm']:g} mm {sec['material']} at "
             f"{sec['scale']}",
             f"structure: {st['check']['verdict']}, max utilisation "
             f"{st['check']['max_utilisation']:.2f}",
             f"sheets: {st['fabricate']['sheets']}, {st['fabricate']['strip_length_m']:.2f} m "
             f"of strip, {st['fabricate']['mass_kg']:.3g} kg",
             f"time: {res.seconds:.1f} s"]
    return Reply(lines, json.dumps(finite_json(rec), default=_plain, allow_nan=False),
                 str(out / "pack" / "report.html"), str(out / "pack"))


def _sheet_curves(layout: Any, tolerance: float) -> tuple[list, list, list, list]:
    """``(cut, score, engrave, sheets)`` curves (mm) of a nesting layout: each sheet shifted
    along x by its width and :data:`SHEET_SPACING`; outlines flattened to ``tolerance`` mm."""
    W, H = layout.sheet
    cut, score, engrave, sheets = [], [], [], []
    for p, k in zip(layout.parts, layout.sheet_of):
        dx = np.array([k * (W + SHEET_SPACING), 0.0])
        cut.append(rhino.to_polyline(np.vstack([p.outline.flatten(tolerance),
                                                p.outline.V[:1]]) + dx))
        cut += [rhino.to_circle(c + dx, r) for c, r in zip(p.holes, p.radii)]
        score += [rhino.to_polyline(s + dx) for s in p.scores]
        engrave += [rhino.to_polyline(L + dx) for L in p.engrave]
    for k in range(layout.n_sheets):
        x0 = k * (W + SHEET_SPACING)
        sheets.append(rhino.to_polyline(np.array([[x0, 0], [x0 + W, 0], [x0 + W, H],
                                                  [x0, H], [x0, 0]], float)))
    return cut, score, engrave, sheets


def _net_params(hs) -> list:
    """The outputs of a design component (GG and NCP alike: :func:`_net_outputs`)."""
    return [hs.HopsMesh("Net", "N", "joints and net loops, metres"),
            hs.HopsCurve("Lamellae", "L", "lamella axes, metres",
                         access=hs.HopsParamAccess.LIST),
            hs.HopsCurve("Aligned", "A", "lamellae through their joints when aligned",
                         access=hs.HopsParamAccess.LIST),
            hs.HopsString("Metrics", "M", "figures of the design (JSON)"),
            hs.HopsString("Bundle", "B", "design bundle folder (for Verify, Fabricate)")]


def _surface_param(hs) -> Any:
    """The optional Surface input of the design components (a Grasshopper Mesh input would
    mesh a surface: this one keeps it a NURBS surface, used as the B-spline it is)."""
    return hs.HopsSurface("Surface", "S", "or a NURBS surface / single-face Brep, metres "
                          "(used as the B-spline it is)", optional=True)


def _gg_spec(hs) -> dict[str, Any]:
    """The Hops declaration of ``/gg``."""
    return dict(
        rule="/gg", name="GG design", nickname="GG",
        description="Design a geodesic alignable lamella gridshell (GG) on a target surface",
        category="Gridshell", subcategory="Design",
        inputs=[hs.HopsMesh("Target", "T", "target mesh, metres", optional=True),
                hs.HopsInteger("Lamellae", "N", "lamellae per family", optional=True),
                hs.HopsInteger("Grid", "G", "GG mesh resolution (G x G)", optional=True),
                hs.HopsString("Options", "O", "JSON object of further design_gg keywords",
                              optional=True),
                _surface_param(hs)],
        outputs=_net_params(hs))


def _ncp_spec(hs) -> dict[str, Any]:
    """The Hops declaration of ``/ncp``."""
    return dict(
        rule="/ncp", name="NCP design", nickname="NCP",
        description="Design a normal-curvature-preserving alignable gridshell (NCP, CNC, AA)",
        category="Gridshell", subcategory="Design",
        inputs=[hs.HopsMesh("Reference", "R", "reference mesh, metres", optional=True),
                hs.HopsString("Mode", "M", "phlw, cnc or aa", optional=True),
                hs.HopsInteger("Curves", "C", "curves per family", optional=True),
                hs.HopsString("Options", "O", "JSON object of further design_ncp keywords",
                              optional=True),
                _surface_param(hs)],
        outputs=_net_params(hs))


def _analyze_spec(hs) -> dict[str, Any]:
    """The Hops declaration of ``/analyze``."""
    return dict(
        rule="/analyze", name="Analyze target", nickname="Analyze",
        description="Before any design: where GG and each NCP mode can exist on a target, and "
                    "the pipeline to run",
        category="Gridshell", subcategory="Check",
        inputs=[hs.HopsMesh("Target", "T", "target mesh, metres", optional=True),
                hs.HopsInteger("Samples", "N", "curvature samples per direction (8..400)",
                               optional=True),
                _surface_param(hs)],
        outputs=[hs.HopsString("Recommended", "R", "the command to run"),
                 hs.HopsString("Why", "W", "why that pipeline and mode"),
                 hs.HopsString("Summary", "S", "the analysis, one line per item",
                               access=hs.HopsParamAccess.LIST),
                 hs.HopsString("Report", "J", "analysis.json (JSON)"),
                 hs.HopsString("Folder", "D", "folder of analysis.json and analysis.png")])


def _verify_spec(hs) -> dict[str, Any]:
    """The Hops declaration of ``/verify``."""
    return dict(
        rule="/verify", name="Verify design", nickname="Verify",
        description="Recompute every figure of a design bundle from its files",
        category="Gridshell", subcategory="Check",
        inputs=[hs.HopsString("Bundle", "B", "design bundle folder")],
        outputs=[hs.HopsBoolean("OK", "OK", "all figures within the paper's thresholds"),
                 hs.HopsString("Checks", "C", "pass / FAIL per figure",
                               access=hs.HopsParamAccess.LIST),
                 hs.HopsString("Report", "R", "the recomputed figures (JSON)")])


def _fabricate_spec(hs) -> dict[str, Any]:
    """The Hops declaration of ``/fabricate``."""
    return dict(
        rule="/fabricate", name="Fabricate", nickname="Fab",
        description="Cut curves of a design bundle nested on sheets (mm), with DXF/SVG files",
        category="Gridshell", subcategory="Fabricate",
        inputs=[hs.HopsString("Bundle", "B", "design bundle folder"),
                hs.HopsString("Scale", "S", "model scale, e.g. 1:10", optional=True),
                hs.HopsString("Sheet", "Sh", "sheet WIDTHxHEIGHT in mm", optional=True),
                hs.HopsNumber("Width", "W", "strip width, mm", optional=True),
                hs.HopsString("Options", "O", "JSON object of further FabParams fields",
                              optional=True),
                hs.HopsBoolean("Force", "F", "cut a design that fails its checks",
                               optional=True)],
        outputs=[hs.HopsCurve("Cut", "C", "outlines and holes, mm, sheet by sheet along x",
                              access=hs.HopsParamAccess.LIST),
                 hs.HopsCurve("Score", "Sc", "score lines, mm", access=hs.HopsParamAccess.LIST),
                 hs.HopsCurve("Engrave", "E", "label strokes, mm",
                              access=hs.HopsParamAccess.LIST),
                 hs.HopsCurve("Sheets", "Sh", "sheet outlines, mm",
                              access=hs.HopsParamAccess.LIST),
                 hs.HopsString("Report", "R", "sheets, material used, pieces (JSON)"),
                 hs.HopsString("Folder", "D", "folder of the DXF / SVG files")])


def _units_param(hs) -> Any:
    """The optional Units input: the unit the Rhino document is drawn in."""
    return hs.HopsString("Units", "U", "the unit the model is drawn in: m, cm, mm, in or ft "
                         "(the Rhino document's; default m)", optional=True)


def _build_spec(hs) -> dict[str, Any]:
    """The Hops declaration of ``/build``."""
    return dict(
        rule="/build", name="Build pack", nickname="Build",
        description="The whole chain in one component: analyse, design, verify, section, check, "
                    "simulate, fabricate, .3dm and report (gridshell build)",
        category="Gridshell", subcategory="Design",
        inputs=[hs.HopsMesh("Target", "T", "target mesh", optional=True),
                hs.HopsString("Kind", "K", "auto (default), gg, phlw, cnc or aa", optional=True),
                hs.HopsString("Material", "Mat", "strip material preset (default pp)",
                              optional=True),
                hs.HopsInteger("Lamellae", "N", "lamellae per family (0: the default)",
                               optional=True),
                hs.HopsString("Scale", "S", "model scale, e.g. 1:10", optional=True),
                _surface_param(hs), _units_param(hs)],
        outputs=[hs.HopsString("Summary", "S", "what was chosen and the verdicts",
                               access=hs.HopsParamAccess.LIST),
                 hs.HopsString("Build", "B", "build.json (JSON)"),
                 hs.HopsString("Report", "R", "report.html"),
                 hs.HopsString("Pack", "P", "the pack's folder (cut files in fabrication/)")])


def _sweep_spec(hs) -> dict[str, Any]:
    """The Hops declaration of ``/sweep``."""
    return dict(
        rule="/sweep", name="Design study", nickname="Sweep",
        description=f"A small design study (at most {MAX_SWEEP} variants): every combination "
                    "of the Vary values designed, verified, checked and cut",
        category="Gridshell", subcategory="Explore",
        inputs=[hs.HopsMesh("Target", "T", "target mesh, metres", optional=True),
                hs.HopsString("Vary", "V", "NAME=V1,V2 per item, e.g. lamellae=6,8 and "
                              "kind=gg,cnc", access=hs.HopsParamAccess.LIST),
                hs.HopsInteger("Workers", "W", "processes (default 2)", optional=True),
                _surface_param(hs), _units_param(hs)],
        outputs=[hs.HopsString("Table", "T", "one row per variant (JSON)"),
                 hs.HopsString("Best", "B", "the elastic cut variant of least utilisation"),
                 hs.HopsString("Page", "P", "sweep.html"),
                 hs.HopsString("Folder", "D", "the study's folder (variants/, results)")])


def register(hops, workdir: Path, resolve: Callable[[Any], Path]) -> None:
    """Register the seven components on ``hops`` (a ghhops_server Hops middleware); designs
    go into new folders of ``workdir``, bundles are taken where ``resolve`` accepts them.
    Each handler's parameters are its inputs in order (Hops passes them so, a missing
    optional input as its default)."""
    import ghhops_server as hs

    def new_dir(kind: str) -> Path:
        return workdir / f"{kind}-{uuid.uuid4().hex[:10]}"

    @hops.component(**_gg_spec(hs))
    def gg(target=None, lamellae=6, grid=12, opts="{}", surface=None):
        return design_gg_component(new_dir, target, lamellae, grid, opts, surface)

    @hops.component(**_ncp_spec(hs))
    def ncp(reference=None, mode="cnc", curves=8, opts="{}", surface=None):
        return design_ncp_component(new_dir, reference, mode, curves, opts, surface)

    @hops.component(**_analyze_spec(hs))
    def analyze(target=None, samples=64, surface=None):
        return analyze_component(new_dir, target, samples, surface)

    @hops.component(**_verify_spec(hs))
    def verify(bundle_dir):
        return verify_component(resolve, bundle_dir)

    @hops.component(**_fabricate_spec(hs))
    def fab(bundle_dir, scale=None, sheet="600x400", width=None, opts="{}", force=False):
        return fabricate_component(resolve, bundle_dir, scale, sheet, width, opts, force)

    @hops.component(**_sweep_spec(hs))
    def study(target=None, vary=None, workers=2, surface=None, units=""):
        return sweep_component(new_dir, target, vary, workers, surface, units)

    @hops.component(**_build_spec(hs))
    def pack(target=None, kind="auto", material="", lamellae=0, scale="", surface=None,
             units=""):
        return build_component(new_dir, target, kind, material, lamellae, scale, surface, units)


def make_app(workdir: str | Path | None = None, *, allow: tuple = (), host: str = "127.0.0.1",
             port: int | None = None, max_body: int | None = None):
    """The Flask app of the Hops server; designs go into ``workdir`` (default: a new
    temporary folder); bundles are read and written there and in the folders ``allow`` only,
    requests answered when addressed to ``host`` (and ``port``, when given) and no larger than
    ``max_body`` bytes (:mod:`gridshell.server.guard`)."""
    import tempfile

    from flask import Flask

    from gridshell.server.guard import Guard, GuardMiddleware
    from gridshell.server.hops import GridshellHops

    wd = Path(workdir) if workdir else Path(tempfile.mkdtemp(prefix="gridshell-hops-"))
    wd.mkdir(parents=True, exist_ok=True)
    guard = Guard.make(wd, allow, host=host, port=port, max_body=max_body)
    app = Flask("gridshell")
    hops = GridshellHops(app, guard=guard)
    register(hops, guard.roots[0], guard.bundle_dir)
    app.wsgi_app = GuardMiddleware(app.wsgi_app, guard)
    app.config.update(GRIDSHELL_WORKDIR=str(guard.roots[0]), GRIDSHELL_GUARD=guard)
    return app
