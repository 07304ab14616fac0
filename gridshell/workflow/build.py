"""``gridshell build``: one command from a model to a build pack.

:func:`build` runs the stages a user would otherwise type as seven commands, into one
directory ``out`` (the pack: a design bundle with everything made from it)::

    analysis/          where each kind of net can exist (gridshell analyze), the choice made
    design.json ...    the design bundle of the chosen pipeline and mode (gridshell gg | ncp)
    structure.json     the strips' stresses in the chosen section (gridshell check)
    equilibrium/       the elastic equilibrium of the deployed gridshell (gridshell simulate)
    fabrication/       cut files, nested on sheets, DXF + SVG in mm (gridshell fabricate)
    model.3dm          the Rhino model (gridshell export)
    render.png, report.html, report.pdf   (gridshell render --report --pdf)
    build.json         what was chosen and why, each stage's key, time and verdict
    manifest.json      every file of the pack

Stages: ``analyze`` -> ``design`` -> ``verify`` -> ``check`` (the section: the thinnest stock
thickness of the material, which holds if any does, and its stresses) -> ``fabricate`` and
``simulate`` (the equilibrium computed in a forked process while the cut files are made,
:mod:`gridshell.core.aside`) -> ``outputs`` (render, report, .3dm). Each stage has a key, the SHA-256 of
what it depends on (the model's bytes, the options that reach it, the tool's version and the
keys of the stages before); a re-run with the same arguments reuses every stage whose key is
unchanged and whose files are still the ones the pack's manifest lists, so a change of
material re-runs only the stages from ``check`` on. A stage that fails ends the build with
its exit code (3 no net of the kind, 4 figures or stresses fail); nothing the tool did not
write is touched (the pack is refused, exit 5, if it holds foreign files).
"""
from __future__ import annotations

import hashlib
import json
import os
import time
from contextlib import ExitStack
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

from gridshell.core.aside import Aside
from gridshell.core.errors import GridshellError, InputError

__all__ = ["BUILD_JSON", "KINDS", "STAGES", "BuildResult", "build", "build_key"]

BUILD_JSON = "build.json"
RHINO = "model.3dm"
#: the stages in order (build.json's "stages")
STAGES = ("analyze", "design", "verify", "check", "fabricate", "simulate", "outputs")
#: --kind: auto (the analysis chooses), GG or an NCP mode
KINDS = ("auto", "gg", "phlw", "cnc", "aa")

Progress = Callable[[str], None] | None


@dataclass
class BuildResult:
    """What :func:`build` did: the pack directory, the chosen ``kind`` and ``section``, the
    per-stage records (``stages[name]``: key, seconds, reused, and the stage's figures) and
    the wall time."""

    out: Path
    kind: str
    why: str
    section: dict[str, Any]
    stages: dict[str, dict[str, Any]] = field(default_factory=dict)
    seconds: float = 0.0

    @property
    def reused(self) -> list[str]:
        return [k for k, v in self.stages.items() if v.get("reused")]

    def figure(self, stage: str, name: str, default: Any = None) -> Any:
        return self.stages.get(stage, {}).get(name, default)


def build_key(*parts: Any) -> str:
    """SHA-256 of ``parts`` (JSON, sorted keys): a stage's key."""
    text = json.dumps(parts, sort_keys=True, default=str)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def _version() -> str:
    from gridshell.core.version import __version__

    return __version__


def _previous(out: Path) -> dict[str, Any]:
    """The stages of the last build of ``out`` whose files are unchanged (the pack's manifest
    lists every file as it is); {} when there is none or anything changed."""
    from gridshell.core import manifest

    rec = out / BUILD_JSON
    if not rec.is_file() or manifest.refusal(out, "build") is not None:
        return {}
    try:
        return json.loads(rec.read_text(encoding="utf-8")).get("stages", {})
    except (OSError, ValueError):
        return {}


def build(model: str | os.PathLike, out: str | os.PathLike, *, kind: str = "auto",
          material: str | None = None, lamellae: int | None = None, scale: Any = None,
          width: float | None = None, sheet: str | None = None, units: Any = None,
          obj: str | None = None, frames: int = 12, max_deviation: float | None = None,
          progress: Progress = None) -> BuildResult:
    """Build the pack of ``model`` (a mesh or .3dm path; ``units`` when the file does not say,
    ``obj`` the .3dm object) in ``out``.

    ``kind``: "auto" (the analysis recommends) or gg / phlw / cnc / aa; ``material``: a
    preset (default pp); ``lamellae``: per family; ``scale`` (e.g. "1:10"), ``width`` (mm as
    cut), ``sheet`` ("600x400" mm); ``frames``: states of the alignment sequence;
    ``max_deviation``: refuse a net farther from the target than this on average (% of the
    diagonal, :func:`gridshell.measure.fidelity.require_fidelity`)."""
    from gridshell.core.atomic import check_output
    from gridshell.workflow.study import file_sha256

    t0 = time.perf_counter()
    say = progress or (lambda _m: None)
    if kind not in KINDS:
        raise InputError(f"kind {kind!r} is not one of {', '.join(KINDS)}")
    model = Path(model)
    if not model.is_file():
        raise InputError(f"the model {model} is not a file; give a mesh (OBJ, PLY, OFF) or a "
                         ".3dm")
    out = Path(out)
    check_output(out, owner="build")
    before = _previous(out)
    opts = {"units": None if units is None else str(units), "object": obj}
    k_in = build_key("input", file_sha256(model), opts, _version())
    res = BuildResult(out, kind, "", {})
    held: dict[str, Any] = {}           # what one stage hands the next within this run

    def reusable(name: str, key: str, files: tuple[str, ...]) -> bool:
        old = before.get(name)
        return bool(old) and old.get("key") == key and all((out / f).exists() for f in files)

    def stage(name: str, key: str, run: Callable[[], dict[str, Any]],
              files: tuple[str, ...] = ()) -> dict[str, Any]:
        old = before.get(name)
        if reusable(name, key, files):
            res.stages[name] = {**old, "reused": True}
            say(f"{name}: unchanged, reused")
            return res.stages[name]
        say(f"{name} ...")
        s0 = time.perf_counter()
        rec = run()
        res.stages[name] = {**rec, "key": key, "seconds": round(time.perf_counter() - s0, 3),
                            "reused": False}
        return res.stages[name]

    try:
        a = stage("analyze", build_key(k_in, "analyze"),
                  lambda: _analyze(model, opts, kind, held), ())
        res.kind, res.why = a["kind"], a["why"]
        k_design = build_key(k_in, "design", res.kind, lamellae, frames, max_deviation)
        stage("design", k_design, lambda: _design(model, out, opts, res.kind, lamellae, frames,
                                                  max_deviation, held), ("design.json",))
        stage("verify", build_key(k_design, "verify"), lambda: _verify(out), ())
        k_sec = build_key(k_design, "check", material, str(scale), width)
        sec = stage("check", k_sec, lambda: _check(out, material, scale, width),
                    ("structure.json",))
        res.section = sec["section"]
        pick = {"material": sec["section"]["material"], "scale": sec["section"]["scale"],
                "width": sec["section"]["width_mm"], "thickness": sec["section"]["thickness_mm"]}
        k_sim, k_fab = build_key(k_sec, "simulate"), build_key(k_sec, "fabricate", sheet)
        with ExitStack() as stack:      # the equilibrium computed beside the cut files
            job = None
            if not reusable("simulate", k_sim, ("equilibrium",)) and \
                    not reusable("fabricate", k_fab, ("fabrication",)):
                job = stack.enter_context(Aside(_equilibrium, out, pick))
            stage("fabricate", k_fab, lambda: _fabricate(out, pick, sheet), ("fabrication",))
            stage("simulate", k_sim, lambda: _simulate(out, pick, job), ("equilibrium",))
        stage("outputs", build_key(k_fab, "outputs"), lambda: _outputs(out, pick, sheet),
              (RHINO, "report.html", "report.pdf"))
    finally:
        if (out / "design.json").is_file():
            _record(out, res, time.perf_counter() - t0)
    res.seconds = time.perf_counter() - t0
    return res


def _record(out: Path, res: BuildResult, seconds: float) -> None:
    """build.json (listed in the pack's manifest)."""
    from gridshell.core import manifest
    from gridshell.core.atomic import write_text
    from gridshell.design.bundle import finite_json

    doc = {"format": "gridshell.build", "version": 1, "kind": res.kind, "why": res.why,
           "section": res.section, "stages": res.stages, "seconds": round(seconds, 3)}
    write_text(out / BUILD_JSON, json.dumps(finite_json(doc), indent=1, allow_nan=False))
    manifest.register(out / BUILD_JSON)


# ----------------------------------------------------------------------------- the stages


def _analyze(model: Path, opts: dict, kind: str, held: dict[str, Any]) -> dict[str, Any]:
    """The analysis (kept in memory until the design has made the pack) and the choice."""
    from gridshell.analysis.analyze import analyze_target

    a = analyze_target(str(model), units=opts["units"], obj=opts["object"],
                       trial=kind == "auto")
    rec = a.recommendation
    if kind == "auto":
        chosen = "gg" if rec.pipeline == "gg" else str(rec.mode)
        why = f"analysis: {rec.why}"
    else:
        chosen = kind
        why = f"--kind {kind} (the analysis would choose {rec.pipeline}"\
              f"{'' if rec.mode is None else ' ' + rec.mode}: {rec.why})"
    held["analysis"] = a                # written into the pack once the design has made it
    return {"kind": chosen, "why": why, "recommended": rec.as_dict(),
            "coverage_percent": a.coverage}


def _design(model: Path, out: Path, opts: dict, kind: str, lamellae: int | None, frames: int,
            max_deviation: float | None, held: dict[str, Any]) -> dict[str, Any]:
    """The design of the chosen kind, gated on its fidelity to the target, written as the
    pack's bundle with the analysis beside it (this run's, ``held["analysis"]``, or made again
    when the analysis stage was reused: the new bundle replaces the pack's directory)."""
    from gridshell.measure.fidelity import require_fidelity

    from gridshell.core import manifest
    from gridshell.workflow.cut import write_design

    if kind == "gg":
        from gridshell.gg.pipeline import design_gg

        design = design_gg(str(model), n_lamellae=lamellae, frames=frames,
                           units=opts["units"], obj=opts["object"])
    else:
        from gridshell.analysis.admissible import design_ncp_explained as design_ncp

        design = design_ncp(str(model), mode=kind, curves=lamellae, frames=frames,
                            units=opts["units"], obj=opts["object"])
    require_fidelity(design.bundle.metrics, max_deviation)
    write_design(out, design, render=False, frames=frames, owner="build")
    from gridshell.analysis.analyze import analyze_target, write_analysis

    a = held.get("analysis") or analyze_target(str(model), units=opts["units"],
                                               obj=opts["object"], trial=False)
    write_analysis(a, out / "analysis")
    manifest.register(out / "analysis", output=True)
    b = design.bundle
    counts = b.metrics.get("n_lamellae") or {}
    return {"kind": b.kind, "n_lamellae": counts, "n_joints": int(len(b.net.joints)),
            "lamellae_asked": lamellae, "fidelity": b.metrics.get("fidelity")}


def _verify(out: Path) -> dict[str, Any]:
    """Every figure recomputed from the pack's files (gridshell verify); exit 4 when one
    fails."""
    from gridshell.core.errors import ConvergenceError
    from gridshell.design.verification import design_verdict

    v = design_verdict(out)
    if not v.ok:
        raise ConvergenceError("the design misses the paper's figures: " + "; ".join(
            [g.line() for g in v.gates if not g.ok] + list(v.problems)))
    return {"ok": True, "checks": list(v.report["checks"])}


def _check(out: Path, material: str | None, scale: Any, width: float | None
           ) -> dict[str, Any]:
    """The section and its stresses (gridshell check, structure.json): the thinnest stock
    thickness of ``material`` for a strip ``width`` mm wide at ``scale``. The utilisation
    cannot fall as the strip thickens (weak-axis bending and twist stresses grow with the
    thickness, strong-axis bending does not depend on it), so the thinnest stock thickness
    holds if any does; when it does not, :class:`Overstressed` names the best there is and
    the smallest scale that would hold."""
    from gridshell.design.section import resolve_section, scale_text
    from gridshell.structure.materials import get_material
    from gridshell.structure.sizing import smallest_scale
    from gridshell.structure.verdict import Overstressed
    from gridshell.workflow.structure import check_structure

    strip = resolve_section(out, material=material, width=width, scale=scale)
    mat = get_material(strip.material)
    t = min(mat.sheet_thicknesses_mm) if mat.sheet_thicknesses_mm else strip.thickness_mm
    c = check_structure(out, material=mat.name, width=strip.width_mm, thickness=t,
                        scale=strip.scale)
    r = c.result
    u = float(r["max_utilisation"])
    sc = scale_text(strip.scale)
    if not c.ok:
        small = smallest_scale(strip.scale, u)
        larger = (f"build at {scale_text(small)} or larger (--scale), " if small <= 1.0 else
                  "not even at full size (1:1) would it hold; ")
        raise Overstressed(
            f"no stock thickness of {mat.name} holds a {strip.width_mm:g} mm strip at {sc}: "
            f"the thinnest, {t:g} mm, reaches utilisation {u:.2f} ({r['governing_state']}); "
            f"{larger}a narrower strip (--width) or a stronger --material ('gridshell check "
            "--suggest' lists the sections)")
    return {"section": {"material": mat.name, "scale": sc, "width_mm": float(strip.width_mm),
                        "thickness_mm": float(t), "utilisation": u},
            "why": f"the thinnest {mat.name} stock thickness ({t:g} mm) holds at "
                   f"{strip.width_mm:g} mm wide, {sc}",
            "verdict": r["verdict"], "max_utilisation": u,
            "max_utilisation_deployed": r["max_utilisation_deployed"],
            "governing_state": r["governing_state"], "min_radius_m": r["min_radius_m"]}


def _equilibrium(out: Path, pick: dict[str, Any]) -> Any:
    """The equilibrium under self-weight, computed and not written (a pure function: it may
    run in a forked process, :mod:`gridshell.core.aside`)."""
    from gridshell.workflow.structure import simulate

    return simulate(out, gravity=True, write=False, **pick)


def _simulate(out: Path, pick: dict[str, Any], job: Any = None) -> dict[str, Any]:
    """equilibrium/ (gridshell simulate --gravity): from ``job`` (an Aside computing
    :func:`_equilibrium`) when given, else computed here."""
    from gridshell.workflow.structure import write_simulation

    sim = job.result() if job is not None else _equilibrium(out, pick)
    f = write_simulation(out, sim).figures
    keep = ("converged", "deviation_mean_pct", "deviation_max_pct", "utilisation_peak",
            "reaction_max_N", "weight_N", "newton")
    return {k: f[k] for k in keep if k in f}


def _fabricate(out: Path, pick: dict[str, Any], sheet: str | None) -> dict[str, Any]:
    from gridshell.structure.materials import get_material
    from gridshell.workflow.cut import fabricate_checked

    params = {"width": pick["width"], "thickness": pick["thickness"], "scale": pick["scale"]}
    if sheet:
        params["sheet"] = sheet
    checked = json.loads((out / "structure.json").read_text(encoding="utf-8"))
    # the verify and check stages of this pack gated these very files (their keys match)
    rep = fabricate_checked(out, out / "fabrication", params, material=pick["material"],
                            verified=True, structure=checked)
    length_m = sum(float(q.get("flat_length_mm", 0.0)) for q in rep["pieces"]) / 1000.0
    rho = get_material(pick["material"]).density
    return {"sheets": int(rep["n_sheets"]), "material_used_pct": 100.0 * rep["material_used"],
            "pieces": len(rep["pieces"]), "strip_length_m": length_m,
            "mass_kg": length_m * pick["width"] * pick["thickness"] * 1e-6 * rho}


def _outputs(out: Path, pick: dict[str, Any], sheet: str | None) -> dict[str, Any]:
    """render.png, report.html, report.pdf and the Rhino model (the .3dm and the PDF in second
    processes; the verify stage has gated these very files, so the export does not judge the
    design again)."""
    from gridshell.workflow.outputs import write_outputs

    opts = {"width": pick["width"], "thickness": pick["thickness"], "scale": pick["scale"],
            "verified": True}
    if sheet:
        opts["sheet"] = sheet
    done = write_outputs(out, png=True, report=True, pdf=True, rhino=out / RHINO,
                         rhino_options=opts)
    return {"files": [str(p.relative_to(out)) for p in (done.get("render"), done.get("report"),
                                                        done.get("pdf"))
                      if p is not None] + [RHINO]}
