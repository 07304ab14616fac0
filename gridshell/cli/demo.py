"""``gridshell demo``: the whole product on the bundled meshes, in one output directory.

1. **GG** on the freeform dome (``gridshell/data/dome.obj``): design, design bundle, alignment
   sequence (``sequence/frame_*``, ``alignment.gif``, ``states.png``), verification from the
   files, ribbons ``render.png``, Rhino ``.3dm``, DXF/SVG cut files, ``report.html``;
2. **CNC** pavilion from the torus zone (``gridshell/data/torus_patch.obj``): PHLW step (mode
   ``cnc``, with its curvature diagram), net, collapse circle, post-optimization, alignment
   sequence (``sequence/frame_*``, ``alignment.gif``), colour maps, verification, render, Rhino
   ``.3dm``, cut files (arcs of one circle), ``report.html``.

Everything is written into a temporary directory that replaces ``-o DIR`` only when all of it
succeeded; ``DIR/demo.json`` holds the summary printed at the end. An existing non-empty ``DIR``
without ``demo.json`` is refused before any work (:func:`gridshell.core.atomic.check_output`,
exit code 5, as for the other commands).
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path
from typing import Any

HELP = ("run the bundled demo: a GG gridshell on a dome and a CNC gridshell for a pavilion, "
        "verified, simulated, rendered, exported to Rhino and cut (DXF/SVG)")

MARKER = "demo.json"

#: sizes of the full and the --quick demo
SIZES: dict[str, dict[str, Any]] = {
    "full": {"gg": {"grid": (16, 16), "n_lamellae": 18, "frames": 12},
             "phlw": {"samples": (18, 18), "outer": 4, "max_iter": 40},
             "ncp": {"curves": 12, "samples": (48, 48), "collapse_samples": (1200, 1200),
                     "frames": 12, "postopt_rounds": 3}},
    "quick": {"gg": {"grid": (12, 12), "n_lamellae": 12, "frames": 4},
              "phlw": {"samples": (10, 10), "outer": 1, "max_iter": 10},
              "ncp": {"curves": 8, "samples": (32, 32), "collapse_samples": (400, 400),
                      "frames": 4, "postopt_rounds": 2}},
}

#: cut files of a 1:10 model in 1 mm polypropylene (the paper's prototypes, Fig. 21), mm
FABRICATION = {"width": 20.0, "thickness": 1.0, "hole": 3.0, "sheet": "600x400",
               "scale": "1:10"}


def add_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("-o", "--output", default="out/demo", metavar="DIR",
                   help="output directory, replaced only when the whole demo succeeded "
                        "(default out/demo); an existing directory must be an earlier demo "
                        "output")
    p.add_argument("--quick", action="store_true",
                   help="smaller sizes: coarser grids, fewer lamellae and frames (a check that "
                        "everything runs, in a fraction of the time)")
    p.add_argument("--only", choices=("gg", "ncp"),
                   help="run only the GG or only the NCP (CNC) part")


def _agrees(v: dict, stored: dict, keys: tuple[tuple[str, str], ...]) -> bool:
    """Whether the verified figures reproduce the stored ones (relative 1e-6)."""
    import math

    for vk, sk in keys:
        for stat in ("mean", "max"):
            a, b = float(v[vk][stat]), float(stored[sk][stat])
            if not math.isclose(a, b, rel_tol=1e-6, abs_tol=1e-12):
                return False
    return True


def _checks(kind: str, metrics: dict) -> str:
    """The design's verdict on the paper's figures (:func:`gridshell.measure.quality.design_gates`)."""
    from gridshell.measure.quality import design_gates, gate_summary, passed

    gates = design_gates(kind, metrics)
    return ("pass (" if passed(gates) else "FAIL (") + gate_summary(gates) + ")"


#: the GG demo built at full size: a 3 m pavilion of spruce C24 strips under snow (issue 28).
#: 60 x 6 mm (measured on the quick demo): at 10 mm bending the strips into the dome alone
#: overstresses them (equilibrium utilisation 1.32 with the snow), at 4 mm the snow buckles
#: the net (no equilibrium); at 6 mm the peak utilisation under snow is 0.96, deflection 4.3 mm
FULL_SCALE = {"material": "spruce", "width": 60.0, "thickness": 6.0, "scale": "1:1",
              "snow": 1.0}


def _full_scale(d: Path, label: str, progress) -> dict[str, Any]:
    """``gridshell simulate`` of the design built at 1:1 in spruce under self-weight and
    :data:`FULL_SCALE` snow (kN/m2): deflection, span / deflection, the bolts' shear
    (``d/equilibrium``)."""
    from gridshell.api import simulate

    fs = FULL_SCALE
    progress(f"{label}: at full scale in {fs['material']} {fs['width']:g} x "
             f"{fs['thickness']:g} mm under self-weight + {fs['snow']:g} kN/m2 snow "
             "(equilibrium/)")
    f = simulate(d, material=fs["material"], width=fs["width"], thickness=fs["thickness"],
                 scale=fs["scale"], snow=fs["snow"]).figures
    return {k: f[k] for k in ("gravity", "section", "deflection_max_mm", "span_m",
                              "span_over_deflection", "bolt_shear_max_N", "bolt_shear_mean_N",
                              "utilisation_peak", "snow_total_kN", "weight_N", "converged")}


def _finish(d: Path, label: str, name: str, fab_params: dict, progress,
            full_scale: bool = False) -> dict[str, Any]:
    """Cut, check, render, export and report a written bundle ``d``; returns the fabrication
    report. The pictures, the report and the .3dm come from one call
    (:func:`gridshell.workflow.outputs.write_outputs`: the .3dm built beside the pictures)."""
    from gridshell.fabrication import fabricate

    from gridshell.workflow.outputs import write_outputs

    progress(f"{label}: cut files ({fab_params['scale']}, {fab_params['thickness']:g} mm "
             "polypropylene)")
    fab = fabricate(d, d / "fabrication", fab_params, progress=progress.detail)
    fab = dict(fab, structure=_structure(d, label, fab_params, progress))
    if full_scale:
        fab["full_scale"] = _full_scale(d, label, progress)
    write_outputs(d, report=True, rhino=d / f"{name}.3dm", rhino_options={"params": fab_params},
                  progress=lambda msg: progress(f"{label}: {msg}"))
    return fab


def _structure(d: Path, label: str, fab_params: dict, progress) -> dict[str, Any]:
    """``gridshell check`` of the cut strips in polypropylene: structure.json and .png."""
    from gridshell.api import check_structure
    from gridshell.render.utilisation import PICTURE

    progress(f"{label}: stresses in the strips (structure.json, {PICTURE})")
    res = check_structure(d, material="pp", width=fab_params["width"],
                          thickness=fab_params["thickness"], scale=fab_params["scale"]).result
    return {k: res[k] for k in ("verdict", "max_utilisation", "max_utilisation_deployed",
                                "governing_state", "max_elastic_thickness_mm")}


def _snow_line(f: dict) -> str:
    return (f"{f['section']}, spruce, {f['gravity']}: deflection {f['deflection_max_mm']:.3g} mm "
            f"(span {f['span_m']:.2f} m / {f['span_over_deflection']:.0f}), largest bolt shear "
            f"{f['bolt_shear_max_N']:.3g} N, peak utilisation {f['utilisation_peak']:.2f} "
            f"({'elastic' if f['utilisation_peak'] <= 1 else 'OVERSTRESSED'}; equilibrium/)")


def _strength(fab: dict) -> str:
    s = fab["structure"]
    return (f"{s['verdict']}: max utilisation {s['max_utilisation_deployed']:.2f} deployed, "
            f"{s['max_utilisation']:.2f} governing ({s['governing_state']}); elastic up to "
            f"{s['max_elastic_thickness_mm']:.2f} mm thick (gridshell check)")


def _gg(root: Path, sizes: dict, progress) -> dict[str, Any]:
    from gridshell import data
    from gridshell.api import design_gg, write
    from gridshell.design.verification import verify_bundle

    t0 = time.perf_counter()
    target = data.path("dome.obj")
    progress(f"GG: designing a geodesic gridshell on {target.name} (grid "
             f"{sizes['grid'][0]} x {sizes['grid'][1]}, {sizes['n_lamellae']} lamellae per family)")
    design = design_gg(target, grid=sizes["grid"], n_lamellae=sizes["n_lamellae"],
                       frames=sizes["frames"], progress=progress.detail)
    bundle, report = design
    d = root / "gg"
    progress("GG: writing the bundle, the alignment sequence, alignment.gif and states.png")
    write(d, design, progress=progress.detail)
    progress("GG: verifying the bundle from its files")
    v = verify_bundle(d)
    fab = _finish(d, "GG", "gg", FABRICATION, progress, full_scale=True)
    m = bundle.metrics
    return {
        "dir": d, "kind": "GG", "target": target.name,
        "lamellae": f"{m['n_lamellae']['C1']} + {m['n_lamellae']['C3']}",
        "joints": v["n_joints"], "loops": v["n_loops"],
        "delta_a": v["alignability"], "delta_a_arc": v["alignability_arc"],
        "geodesic_turning": v["geodesic_turning"], "deviation": v["deviation"],
        "deviation_target": m["deviation_target"], "coverage": m["coverage"],
        "frames": len(report["sequence"].V), "sequence_length_error": m["sequence_length_error"],
        "verified": _agrees(v, m, (("alignability", "alignability"),
                                   ("alignability_arc", "alignability_arc"))),
        "checks": _checks("GG", m), "revolution": report["revolution"]["method"],
        "fabrication": fab, "time": time.perf_counter() - t0,
    }


def _ncp(root: Path, sizes: dict, progress) -> dict[str, Any]:
    from gridshell import data
    from gridshell.core.atomic import write_bytes
    from gridshell.ncp.phlw import optimize_phlw, write_phlw
    from gridshell.api import design_ncp, write
    from gridshell.ncp.reference import initial_surface
    from gridshell.geometry.meshfile import read_mesh
    from gridshell.design.verification import verify_bundle

    t0 = time.perf_counter()
    ref = data.path("torus_patch.obj")
    ph = sizes["phlw"]
    progress(f"CNC: PHLW step on {ref.name} (mode cnc, {ph['samples'][0]} x {ph['samples'][1]} "
             f"samples, {ph['outer']} rounds)")
    mesh = read_mesh(ref, kind="any")
    init = initial_surface(mesh.V, mesh.F)
    res = optimize_phlw(init.surface, (mesh.V, mesh.F), mode="cnc", samples=ph["samples"],
                        outer=ph["outer"], max_iter=ph["max_iter"],
                        progress=lambda msg: progress(f"CNC: PHLW {msg}"))
    write_phlw(root / "phlw", res)
    nc = sizes["ncp"]
    progress(f"CNC: tracing the net ({nc['curves']} curves per family), collapse circle, "
             "post-optimization, alignment simulation")
    design = design_ncp(res, mode="cnc", curves=nc["curves"], samples=nc["samples"],
                        collapse_samples=nc["collapse_samples"], frames=nc["frames"],
                        postopt_rounds=nc["postopt_rounds"], progress=progress.detail)
    bundle, report = design
    bundle.params.update(source=str(ref), phlw_deviation=res.deviation,
                         phlw_converged=res.converged)
    d = root / "ncp"
    progress("CNC: writing the bundle, the alignment sequence, alignment.gif and colour maps")
    write(d, design, progress=progress.detail)
    write_bytes(d / "curvature_diagram.png", (root / "phlw" / "curvature_diagram.png").read_bytes())
    progress("CNC: verifying the bundle from its files")
    v = verify_bundle(d)
    fab = _finish(d, "CNC", "ncp", FABRICATION, progress)
    m = bundle.metrics
    return {
        "dir": d, "kind": bundle.kind, "reference": ref.name,
        "lamellae": f"{m['n_lamellae']['C1']} + {m['n_lamellae']['C3']}",
        "joints": m["n_joints"], "loops": m["n_loops"],
        "delta_a_before": m["delta_a_before"], "delta_a_after": v["alignability"],
        "delta_l": v["delta_l"], "delta_n": v["delta_n"],
        "deviation": m["deviation"], "phlw_deviation": res.deviation,
        "n": m["n"], "collapse_radius": m["collapse_radius"],
        "aligned_radius_error": m["aligned_radius_error"],
        "frames": len(list((d / "sequence").glob("frame_*.obj"))),
        "sequence_length_error": m["sequence_length_error"],
        "verified": _agrees(v, m, (("alignability", "delta_a_after"), ("delta_l", "delta_l"),
                                   ("delta_n", "delta_n"))),
        "checks": _checks("CNC", m), "fabrication": fab, "time": time.perf_counter() - t0,
    }


def _mm(d: dict) -> dict[str, float]:
    return {"mean": d["mean"], "max": d["max"]}


def _sheets(fab: dict) -> str:
    W, H = fab["params"]["sheet"]
    f = FABRICATION
    used = ", ".join(f"{100 * u:.1f}" for u in fab["material_used_per_sheet"])
    return (f"{fab['n_sheets']} x {W:g} x {H:g} mm ({used} % of the sheet area used), "
            f"{fab['n_pieces']} {fab['shape']} strips "
            f"({f['scale']}, {f['width']:g} mm wide, {f['thickness']:g} mm polypropylene)")


def _summary(out: Path, gg: dict | None, ncp: dict | None, total: float) -> dict[str, Any]:
    s: dict[str, Any] = {"output": str(out)}
    if gg is not None:
        s["GG dome"] = (f"{out / 'gg'}/ (report.html, render.png, alignment.gif, states.png, "
                        "gg.3dm, fabrication/)")
        s["GG lamellae / joints / loops"] = f"{gg['lamellae']} / {gg['joints']} / {gg['loops']}"
        s["GG Delta_a [%]"] = _mm(gg["delta_a"])
        s["GG Delta_a arc length [%]"] = _mm(gg["delta_a_arc"])
        s["GG geodesic turning [%]"] = gg["geodesic_turning"]
        s["GG deviation [% diag]"] = {"surface->dome max": gg["deviation"]["max"],
                                      "dome->surface max": gg["deviation_target"]["max"],
                                      "coverage %": gg["coverage"]}
        s["GG alignment"] = (f"{gg['frames']} states, joint-to-joint lengths within "
                             f"{gg['sequence_length_error']:.2g} % of the deployed net")
        s["GG paper thresholds"] = gg["checks"]
        s["GG cut files"] = _sheets(gg["fabrication"])
        s["GG strips 1 mm pp"] = _strength(gg["fabrication"])
        s["GG at 1:1 under snow"] = _snow_line(gg["fabrication"]["full_scale"])
    if ncp is not None:
        s["CNC pavilion"] = (f"{out / 'ncp'}/ (report.html, render.png, alignment.gif, "
                             "ncp.3dm, fabrication/)")
        s["CNC lamellae / joints / loops"] = (f"{ncp['lamellae']} / {ncp['joints']} / "
                                              f"{ncp['loops']}")
        s["CNC Delta_a traced [%]"] = _mm(ncp["delta_a_before"])
        s["CNC Delta_a post-optimized [%]"] = _mm(ncp["delta_a_after"])
        s["CNC Delta_l [%]"] = _mm(ncp["delta_l"])
        s["CNC Delta_n [%]"] = _mm(ncp["delta_n"])
        s["CNC deviation [% diag]"] = {"joints from surface": ncp["deviation"]["max"],
                                       "surface from reference": ncp["phlw_deviation"]}
        s["CNC collapse circle"] = (f"radius {ncp['collapse_radius']:.4g} m (n = {ncp['n']:.4g} "
                                    f"1/m), aligned joints off it "
                                    f"{ncp['aligned_radius_error']:.2g} %")
        s["CNC alignment"] = (f"{ncp['frames']} states, joint-to-joint lengths within "
                              f"{ncp['sequence_length_error']:.2g} % of the deployed net")
        s["CNC paper thresholds"] = ncp["checks"]
        s["CNC cut files"] = _sheets(ncp["fabrication"])
        s["CNC strips 1 mm pp"] = _strength(ncp["fabrication"])
    s["verified from the files"] = "yes" if all(
        r["verified"] for r in (gg, ncp) if r is not None) else "NO: stored and recomputed differ"
    s["time [s]"] = {**({"gg": gg["time"]} if gg else {}), **({"ncp": ncp["time"]} if ncp else {}),
                     "total": total}
    return s


def _nested(summary: dict, gg: dict | None, ncp: dict | None) -> dict[str, Any]:
    """``demo.json``: the printed summary and the figures of each part (no tmp paths)."""
    def part(r: dict | None) -> dict | None:
        if r is None:
            return None
        keep = {k: v for k, v in r.items() if k not in ("dir", "fabrication")}
        f = r["fabrication"]
        keep["fabrication"] = {k: f[k] for k in ("n_strips", "n_pieces", "n_sheets", "shape",
                                                  "utilisation", "material_used",
                                                  "material_used_per_sheet", "structure")}
        if "full_scale" in f:
            keep["full_scale"] = f["full_scale"]
        return keep

    return {"summary": summary, "gg": part(gg), "ncp": part(ncp)}


def run(args: Any) -> int:
    from gridshell.core.atomic import atomic_dir, check_output, write_text
    from gridshell.cli.common import Progress, print_summary

    progress = Progress(args)
    out = check_output(args.output, marker=MARKER)
    sizes = SIZES["quick" if args.quick else "full"]
    t0 = time.perf_counter()
    gg = ncp = None
    with atomic_dir(out) as tmp:
        if args.only in (None, "gg"):
            gg = _gg(tmp, sizes["gg"], progress)
        if args.only in (None, "ncp"):
            ncp = _ncp(tmp, sizes, progress)
        summary = _summary(out, gg, ncp, time.perf_counter() - t0)
        write_text(tmp / MARKER, json.dumps(_nested(summary, gg, ncp), indent=1,
                                            default=str) + "\n")
    progress(f"done: {out}")
    print_summary(args, f"gridshell demo{' (--quick)' if args.quick else ''}: "
                        f"{time.perf_counter() - t0:.0f} s", summary)
    return 0
