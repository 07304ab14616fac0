"""``fabricate``: from a design bundle to laser-ready sheets, a cut list and an assembly plan.

Everything that can go wrong with the parameters or the design is checked before the first
file is written; the output directory then appears at once (``gridshell.core.atomic.atomic_dir``)::

    sheet_01.dxf, sheet_01.svg, ...   one DXF and one SVG per sheet
    sheet_01.png, ...                  a preview of each sheet (headless matplotlib)
    cutlist.csv                        one row per piece
    plan.png, plan.svg                 the net with every lamella's id at its place
    fabrication.json                   this report
    manifest.json                      the files written (gridshell.core.manifest)
"""
from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path
from typing import Any, Callable

import numpy as np

from gridshell.core.atomic import atomic_dir
from gridshell.design.bundle import DesignBundle, finite_json, read_bundle
from gridshell.core.errors import InputError, OutputError
from gridshell.core.manifest import MANIFEST, refusal

from gridshell.fabrication.nesting import Layout, check_layout, nest
from gridshell.fabrication.params import FabParams, scale_text
from gridshell.fabrication.part import Part, build_parts, joint_clearance
from gridshell.fabrication.splice import split_strip
from gridshell.fabrication.strips import strips_from_bundle

REPORT = "fabrication.json"
#: the command whose outputs :func:`fabricate` writes and may replace (gridshell.core.manifest)
OWNER = "fabricate"


def _check_out(out: Path, bundle_dir: Path | None) -> None:
    out_r = out.resolve()
    if bundle_dir is not None:
        b = bundle_dir.resolve()
        if out_r == b or out_r in b.parents:
            raise OutputError(f"output directory {out} would replace the design bundle "
                              f"{bundle_dir}; choose another -o (default: DIR/fabrication)")
    why = refusal(out, OWNER)
    if why:
        raise OutputError(why)


def plan_parts(bundle: DesignBundle, params: FabParams,
               progress: Callable[[str], None] | None = None) -> tuple[list[Part], Layout, dict]:
    """Strips, pieces, parts and their layout, without writing anything."""
    say = progress or (lambda msg: None)
    strips = strips_from_bundle(bundle, params)
    say(f"{len(strips)} {strips[0].axis.kind} strips")
    pieces = [p for s in strips for p in split_strip(s, params)]
    by_lamella: dict[int, list] = {}
    for p in pieces:
        by_lamella.setdefault(p.lamella, []).append(p)
    split = []
    for lam, ps in by_lamella.items():
        if len(ps) > 1:
            notes = [n for p in ps for n in p.splices if n["with"] > p.piece]
            split.append({"lamella": lam, "pieces": len(ps),
                          "overlaps_mm": [round(n["overlap"], 3) for n in notes],
                          "splice_joints": [n["splice_joint"] for n in notes
                                            if n["kind"] == "joint"],
                          "splice_joint_names": [n["splice_name"] for n in notes
                                                 if n["kind"] == "joint"],
                          "span_splices_mm": [round(n["at"], 3) for n in notes
                                              if n["kind"] == "span"]})
    if split:
        n_span = sum(len(d["span_splices_mm"]) for d in split)
        say(f"{len(split)} lamellae longer than the sheet split"
            + (f" ({n_span} splices between joints)" if n_span else " at joints"))
    fallback = None
    if params.joints != "marks" and params.fallback_marks:
        tight = [(p.lamella, *joint_clearance(p, params)) for p in pieces]
        tight = [t for t in tight if t[1] < t[2]]
        if tight:
            lam, gap, need = min(tight, key=lambda t: t[1])
            fallback = (f"joints only {gap:.3g} mm apart at {scale_text(params.scale)} (lamella "
                        f"{lam}; {params.joints} need {need - 0.5:g} mm): engraved as marks "
                        "instead; use a larger --scale for " + params.joints)
            say("warning: " + fallback)
            params = replace(params, joints="marks")
    parts = build_parts(pieces, params)
    layout = nest(parts, params)
    check_layout(layout, params.gap)
    say(f"nested {len(parts)} pieces on {layout.n_sheets} sheet(s)")
    return parts, layout, {"strips": strips, "split": split, "params": params,
                           "joints_fallback": fallback}


def fabricate(bundle: str | Path | DesignBundle, out_dir: str | Path,
              params: FabParams | dict[str, Any] | None = None,
              progress: Callable[[str], None] | None = None,
              plan: bool = True, keep_layout: bool = False,
              structure: dict[str, Any] | None = None) -> dict[str, Any]:
    """Write cut files, cut list and plan of a design bundle to ``out_dir``.

    Parameters
    ----------
    bundle : path or DesignBundle
        A design bundle directory (read with :func:`gridshell.design.bundle.read_bundle`) or the
        bundle itself.
    out_dir : path
        Output directory; replaced atomically. It must not be (or contain) the bundle, and an
        existing non-empty directory must be an earlier fabrication output.
    params : FabParams or dict of its fields
    progress : callable, optional
    plan : bool
        Draw plan.png / plan.svg (the slowest step; off for quick checks).
    keep_layout : bool
        Also return the :class:`~gridshell.fabrication.nesting.Layout` under ``"layout"`` (not written).
    structure : dict, optional
        The structural verdict of these strips, computed by the caller (the API and the CLI:
        ``verdict``, ``line``, ``max_utilisation``, ...); recorded as ``"structure"``.

    Returns
    -------
    dict
        The report also written to ``fabrication.json``: parameters, counts, utilisation,
        split lamellae, files (``previews``: the sheet PNGs), the structural verdict, and each
        piece's sheet and placement (the rigid motion from strip coordinates, see
        :mod:`gridshell.fabrication.axis`, to the sheet; mm and degrees).
    """
    say = progress or (lambda msg: None)
    if params is None:
        params = FabParams()
    elif isinstance(params, dict):
        params = FabParams(**params)
    bundle_dir = None
    if not isinstance(bundle, DesignBundle):
        bundle_dir = Path(bundle)
        say(f"reading {bundle_dir}")
        bundle = read_bundle(bundle_dir)
    out = Path(out_dir)
    _check_out(out, bundle_dir)
    parts, layout, info = plan_parts(bundle, params, say)
    params = info["params"]  # joints engraved as marks where holes would merge
    report = fabrication_report(bundle, parts, layout, info, plan)
    report["structure"] = structure
    say(f"writing {out}")
    write_fabrication(out, bundle, layout, params, report, plan, say)
    report["out"] = str(out)
    if keep_layout:
        report["layout"] = layout
    return report


def sheet_names(n_sheets: int) -> list[str]:
    """``sheet_01``, ``sheet_02``, ...: the stems of the sheets' files."""
    return [f"sheet_{k + 1:02d}" for k in range(n_sheets)]


def fabrication_report(bundle: DesignBundle, parts: list[Part], layout: Layout, info: dict,
                       plan: bool) -> dict[str, Any]:
    """The content of ``fabrication.json`` (:func:`fabricate`'s return) for the parts and
    layout of :func:`plan_parts`; lengths in mm of the model."""
    params = info["params"]
    W, H = params.sheet
    area = sum(p.area for p in parts)
    names = sheet_names(layout.n_sheets)
    files = [f"{n}{ext}" for n in names for ext in (".dxf", ".svg", ".png")]
    files += ["cutlist.csv"] + (["plan.png", "plan.svg"] if plan else []) + [REPORT, MANIFEST]
    return {
        "kind": bundle.kind,
        "shape": info["strips"][0].axis.kind,
        "params": params.to_json(),
        "n_strips": len(info["strips"]),
        "n_pieces": len(parts),
        "n_sheets": layout.n_sheets,
        "n_joint_marks": int(sum(len(p.strip.joint_s) for p in parts)),
        "n_design_joints": int(sum(len(lam.joints) for lam in bundle.net.lamellae)),
        "utilisation": area / (layout.n_sheets * W * H),
        "utilisation_per_sheet": [sum(p.area for p in layout.on_sheet(k)) / (W * H)
                                  for k in range(layout.n_sheets)],
        "material_used": layout.used(),
        "material_used_per_sheet": [layout.used(k) for k in range(layout.n_sheets)],
        "pieces_split": info["split"],
        "labels_dropped": int(sum(p.labels_dropped for p in parts)),
        "joints_fallback": info["joints_fallback"],
        "radius_mm": info["strips"][0].axis.radius,
        "sheet_files": "one DXF and one SVG per sheet, and a PNG preview of each",
        "files": files,
        "previews": [f"{n}.png" for n in names],
        "pieces": [{"lamella": p.strip.lamella, "piece": p.strip.piece,
                    "n_pieces": p.strip.n_pieces, "sheet": s + 1,
                    "flat_length_mm": p.strip.length, "s0": p.strip.s0,
                    "motion": p.motion.to_json()}
                   for p, s in zip(layout.parts, layout.sheet_of)],
    }


def write_fabrication(out: Path, bundle: DesignBundle, layout: Layout, params: FabParams,
                      report: dict[str, Any], plan: bool,
                      say: Callable[[str], None]) -> None:
    """Write the sheets (DXF, SVG, PNG), the cut list, the plan and ``report`` into ``out``
    at once (:func:`gridshell.core.atomic.atomic_dir`)."""
    # the writers (ezdxf, the previews, the cut list): only for writing, plan_parts does
    # without them
    from gridshell.fabrication.cutlist import cutlist_rows, write_cutlist
    from gridshell.fabrication.dxf import write_sheet_dxf
    from gridshell.fabrication.plan import write_plan
    from gridshell.fabrication.preview import write_sheet_png
    from gridshell.fabrication.svg import write_sheet_svg

    W, H = params.sheet
    axis_lengths = {int(lam.id): lam.length * params.mm_per_m for lam in bundle.net.lamellae}
    with atomic_dir(out, owner=OWNER, kind=f"fabrication of a {bundle.kind} design") as tmp:
        for k, name in enumerate(sheet_names(layout.n_sheets)):
            sp = layout.on_sheet(k)
            write_sheet_dxf(tmp / f"{name}.dxf", sp, (W, H), params)
            write_sheet_svg(tmp / f"{name}.svg", sp, (W, H), params,
                            title=f"{name}: {len(sp)} parts")
            write_sheet_png(tmp / f"{name}.png", sp, (W, H), params,
                            title=sheet_title(name, len(sp), params))
        write_cutlist(tmp / "cutlist.csv", cutlist_rows(layout, axis_lengths))
        if plan:
            say("drawing the assembly plan")
            write_plan(tmp / "plan.png", tmp / "plan.svg", bundle.net,
                       title=f"{bundle.kind} gridshell: lamella ids (blue family 1, red family 3)"
                       f"; {layout.n_sheets} sheet{'s' if layout.n_sheets != 1 else ''} "
                       f"{W:g} x {H:g} mm, {100 * layout.used():.0f} % of their area used")
        (tmp / REPORT).write_text(json.dumps(finite_json(report), indent=1, allow_nan=False,
                                             default=_json_default),
                                  encoding="utf-8")


def sheet_title(name: str, n_parts: int, params: FabParams) -> str:
    """Title of a sheet preview: name, sheet size (mm), part count, scale and material."""
    W, H = params.sheet
    return (f"{name}: {W:g} x {H:g} mm sheet, {n_parts} part{'s' if n_parts != 1 else ''} "
            f"(model {scale_text(params.scale)}, {params.thickness:g} mm thick)")


def _json_default(o: Any) -> Any:
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    return str(o)
