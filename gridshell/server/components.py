"""The Hops components of ``gridshell serve``, each a thin call of the Python API.

=============  ======================================================  ==================
route          inputs                                                   outputs
=============  ======================================================  ==================
``/gg``        Target (mesh or surface, m), Lamellae, Grid, Options     Net, Lamellae,
                                                                        Aligned, Metrics,
                                                                        Bundle
``/ncp``       Reference (mesh or surface, m), Mode, Curves, Options    (as ``/gg``)
``/verify``    Bundle                                                   OK, Checks, Report
``/fabricate`` Bundle, Scale, Sheet, Width, Options, Force              Cut, Score,
                                                                        Engrave, Sheets,
                                                                        Report, Folder
=============  ======================================================  ==================

Designs are written as bundles into the server's work directory; ``Bundle`` is the path that
``/verify`` and ``/fabricate`` take. ``Options`` is a JSON object of further keywords of
:func:`gridshell.gg.pipeline.design_gg`, :func:`gridshell.ncp.pipeline.design_ncp` or
:class:`fabrication.FabParams` (``{}`` for none). Metrics and reports are JSON text.

A failure never leaves a dead component: the reply carries the tool's one-line message in
``errors`` (Hops shows it on the component, its outputs empty), and a design that misses the
paper's figures (``allow_unconverged`` in Options) comes back with a warning.
"""
from __future__ import annotations

import json
import uuid
from pathlib import Path
from typing import Any

import numpy as np

from gridshell.core.errors import GridshellError, InputError
from gridshell.server import rhino

#: the keywords ``Options`` may give, per component (the others are inputs of their own)
GG_OPTIONS = ("meridians", "direction", "spacing", "crossing_angle", "at_parallel", "offsets",
              "weights", "angle", "rounds", "polish_iter", "allow_unconverged", "frames")
NCP_OPTIONS = ("spacing", "n", "samples", "levelset_ctrl", "levelset_degree", "omega_f",
               "trace_grid", "collapse_samples", "postopt_weights", "postopt_rounds",
               "frames", "sim_weights", "surface_samples", "phlw_options",
               "allow_unconverged")
#: keys of the sub-dictionaries and pairs given as JSON lists
_PAIRS = ("samples", "levelset_ctrl", "levelset_degree", "trace_grid", "collapse_samples",
          "surface_samples")
SHEET_SPACING = 50.0   # mm between the sheets laid out along x in the Fabricate outputs


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
    mesh = rhino.to_mesh(net.joints, net.loops)
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


def register(hops, workdir: Path) -> None:
    """Register the four components on ``hops`` (a ghhops_server Hops middleware)."""
    import ghhops_server as hs

    def new_dir(kind: str) -> Path:
        return workdir / f"{kind}-{uuid.uuid4().hex[:10]}"

    def net_outputs() -> list:
        """The outputs of a design component (GG and NCP alike: :func:`_net_outputs`)."""
        return [hs.HopsMesh("Net", "N", "joints and net loops, metres"),
                hs.HopsCurve("Lamellae", "L", "lamella axes, metres",
                             access=hs.HopsParamAccess.LIST),
                hs.HopsCurve("Aligned", "A", "lamellae through their joints when aligned",
                             access=hs.HopsParamAccess.LIST),
                hs.HopsString("Metrics", "M", "figures of the design (JSON)"),
                hs.HopsString("Bundle", "B", "design bundle folder (for Verify, Fabricate)")]

    @hops.component(
        rule="/gg", name="GG design", nickname="GG",
        description="Design a geodesic alignable lamella gridshell (GG) on a target surface",
        category="Gridshell", subcategory="Design",
        inputs=[hs.HopsMesh("Target", "T", "target surface, metres (mesh or surface)"),
                hs.HopsInteger("Lamellae", "N", "lamellae per family", optional=True),
                hs.HopsInteger("Grid", "G", "GG mesh resolution (G x G)", optional=True),
                hs.HopsString("Options", "O", "JSON object of further design_gg keywords",
                              optional=True)],
        outputs=net_outputs())
    def gg(target, lamellae=6, grid=12, opts="{}"):
        from gridshell.api import design_gg, write

        kw = options(opts, GG_OPTIONS, "GG design")
        kw.setdefault("frames", 0)
        V, F = rhino.target_arrays(target)
        if int(grid) < 4 or int(lamellae) < 2:
            raise InputError(f"Grid {grid} and Lamellae {lamellae}: give Grid >= 4 and "
                             "Lamellae >= 2")
        design = design_gg((V, F), grid=(int(grid), int(grid)), n_lamellae=int(lamellae), **kw)
        bundle = design.bundle
        out = write(new_dir("gg"), design, render=False, frames=0)
        return _net_outputs(bundle, out, _quality_warning(bundle))

    @hops.component(
        rule="/ncp", name="NCP design", nickname="NCP",
        description="Design a normal-curvature-preserving alignable gridshell (NCP, CNC, AA)",
        category="Gridshell", subcategory="Design",
        inputs=[hs.HopsMesh("Reference", "R", "reference surface, metres (mesh or surface)"),
                hs.HopsString("Mode", "M", "phlw, cnc or aa", optional=True),
                hs.HopsInteger("Curves", "C", "curves per family", optional=True),
                hs.HopsString("Options", "O", "JSON object of further design_ncp keywords",
                              optional=True)],
        outputs=net_outputs())
    def ncp(reference, mode="cnc", curves=8, opts="{}"):
        from gridshell.api import design_ncp, write

        kw = options(opts, NCP_OPTIONS, "NCP design")
        V, F = rhino.target_arrays(reference)
        design = design_ncp((V, F), mode=str(mode).strip().lower(), curves=int(curves), **kw)
        bundle = design.bundle
        out = write(new_dir(bundle.kind.lower()), design, render=False)
        return _net_outputs(bundle, out, _quality_warning(bundle))

    @hops.component(
        rule="/verify", name="Verify design", nickname="Verify",
        description="Recompute every figure of a design bundle from its files",
        category="Gridshell", subcategory="Check",
        inputs=[hs.HopsString("Bundle", "B", "design bundle folder")],
        outputs=[hs.HopsBoolean("OK", "OK", "all figures within the paper's thresholds"),
                 hs.HopsString("Checks", "C", "pass / FAIL per figure",
                               access=hs.HopsParamAccess.LIST),
                 hs.HopsString("Report", "R", "the recomputed figures (JSON)")])
    def verify(bundle_dir):
        from gridshell.design.bundle import finite_json
        from gridshell.design.verification import design_verdict

        verdict = design_verdict(_bundle_path(bundle_dir))
        res = verdict.report
        warnings = [] if verdict.ok else ["the design fails its checks: " + "; ".join(
            [g.line() for g in verdict.gates if not g.ok] + list(verdict.problems))]
        return Reply(bool(res["ok"]), list(res["checks"]) + list(res["problems"]),
                     json.dumps(finite_json(res), default=_plain, allow_nan=False),
                     warnings=warnings)

    @hops.component(
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
    def fab(bundle_dir, scale=None, sheet="600x400", width=None, opts="{}", force=False):
        from dataclasses import fields

        from gridshell.fabrication import FabParams, fabricate

        from gridshell.design.section import resolve_section
        from gridshell.design.verification import require_design

        names = tuple(f.name for f in fields(FabParams) if f.name not in
                      ("scale", "sheet", "width"))
        kw = options(opts, names, "Fabricate")
        path = _bundle_path(bundle_dir)
        verdict = require_design(str(path), bool(force), "set Force to cut it anyway")
        strip = resolve_section(path, width=width, thickness=kw.pop("thickness", None),
                                scale=scale, stored=False)   # as 'gridshell fabricate'
        params = FabParams(scale=strip.scale, sheet=sheet, width=strip.width_mm,
                           thickness=strip.thickness_mm, **kw)
        out = path / "fabrication"
        rep = fabricate(path, out, params, plan=False, keep_layout=True)
        layout = rep.pop("layout")
        W, H = layout.sheet
        cut, score, engrave, sheets = [], [], [], []
        for p, k in zip(layout.parts, layout.sheet_of):
            dx = np.array([k * (W + SHEET_SPACING), 0.0])
            cut.append(rhino.to_polyline(np.vstack([p.outline.flatten(params.tolerance),
                                                    p.outline.V[:1]]) + dx))
            cut += [rhino.to_circle(c + dx, r) for c, r in zip(p.holes, p.radii)]
            score += [rhino.to_polyline(s + dx) for s in p.scores]
            engrave += [rhino.to_polyline(L + dx) for L in p.engrave]
        for k in range(layout.n_sheets):
            x0 = k * (W + SHEET_SPACING)
            sheets.append(rhino.to_polyline(np.array([[x0, 0], [x0 + W, 0], [x0 + W, H],
                                                      [x0, H], [x0, 0]], float)))
        warnings = [] if verdict.ok else ["the design fails its checks; cut anyway (Force)"]
        if rep.get("joints_fallback"):
            warnings.append(rep["joints_fallback"])
        summary = {k: rep[k] for k in ("kind", "shape", "n_strips", "n_pieces", "n_sheets",
                                       "utilisation", "utilisation_per_sheet",
                                       "material_used", "labels_dropped") if k in rep}
        return Reply(cut, score, engrave, sheets,
                     json.dumps(summary, default=_plain), str(out), warnings=warnings)


def _bundle_path(text: str) -> Path:
    path = Path(str(text or "").strip())
    if not str(path) or not (path / "design.json").is_file():
        raise InputError(f"{str(text)!r} is not a design bundle folder (no design.json); connect "
                         "the Bundle output of a GG or NCP component")
    return path


def make_app(workdir: str | Path | None = None):
    """The Flask app of the Hops server; designs go into ``workdir`` (default: a new
    temporary folder)."""
    import tempfile

    from flask import Flask

    from gridshell.server.hops import GridshellHops

    wd = Path(workdir) if workdir else Path(tempfile.mkdtemp(prefix="gridshell-hops-"))
    wd.mkdir(parents=True, exist_ok=True)
    app = Flask("gridshell")
    hops = GridshellHops(app)
    register(hops, wd)
    app.config["GRIDSHELL_WORKDIR"] = str(wd)
    return app
