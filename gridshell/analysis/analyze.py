"""``analyze``: where each kind of net can exist on a target, and which pipeline to use.

Reads the target (any format and unit, :func:`gridshell.io.read.read_input`; a big mesh is
analysed on its working copy, :func:`gridshell.io.working.working_mesh`), takes its B-spline
(a .3dm NURBS surface as it is, else the least-squares fit of the NCP pipeline, paper 4.2.1),
samples the curvature map (:mod:`~gridshell.analysis.maps`), finds the regions and the
largest patch each NCP mode admits (:mod:`~gridshell.analysis.regions`), runs the coarse GG
and NCP trials (:mod:`~gridshell.analysis.trial`) and recommends (:mod:`~gridshell.analysis.recommend`).
:func:`write_analysis` writes analysis.json and analysis.png.
"""
from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from gridshell.analysis.maps import K_ZERO, UMBILIC_GAP, CurvatureMap, curvature_map
from gridshell.analysis.recommend import MIN_COVERAGE, Recommendation, recommend
from gridshell.analysis.regions import Rectangle, Region, largest_rectangle, regions
from gridshell.analysis.trial import GGTrial, NCPTrial, gg_trial, ncp_trial

__all__ = ["ANALYSIS_FACES", "Analysis", "analyze_target", "summary_of", "write_analysis"]

#: faces of the working copy the analysis runs on (a 200k-triangle target is decimated)
ANALYSIS_FACES = 20000
#: faces of the copy the NCP trials fit against
TRIAL_FACES = 2000
#: what each NCP mode needs of the surface (paper 3-4), as said in analysis.json
CONDITIONS = {"phlw": "a regular patch of curvature lines: no near-umbilic sample, K of one "
                      "sign (no parabolic line)",
              "cnc": "as PHLW (a CNC net is a PHLW net whose lamellae collapse onto a circle)",
              "aa": "K < 0 everywhere (real asymptotic directions)"}


@dataclass(frozen=True)
class Analysis:
    """The outcome of :func:`analyze_target` (shares in %, lengths in metres)."""

    target: dict[str, Any]
    map: CurvatureMap = field(repr=False)
    classes: dict[str, float]
    regions: list[Region]
    patches: dict[str, Rectangle | None]
    gg: GGTrial | None
    recommendation: Recommendation
    seconds: float
    ring: dict[str, Any] | None = None
    ncp_trials: dict[str, NCPTrial] = field(default_factory=dict)

    @property
    def coverage(self) -> dict[str, float]:
        """NCP mode -> % of the target its largest admissible patch covers."""
        return {m: 0.0 if r is None else 100.0 * r.share for m, r in self.patches.items()}

    def as_dict(self) -> dict[str, Any]:
        """analysis.json's content."""
        return {
            "target": self.target,
            "classes_percent": {k: round(v, 2) for k, v in self.classes.items()},
            "rules": {"K_zero": f"|K| D^2 < {K_ZERO:g}",
                      "umbilic": f"|k1 - k2| D < {UMBILIC_GAP:g}", "D": "bounding-box diagonal"},
            "regions": [r.as_dict() for r in self.regions],
            "ncp": {m: {"condition": CONDITIONS[m],
                        "largest_patch": None if r is None else r.as_dict(),
                        "coverage_percent": round(self.coverage[m], 2)}
                    for m, r in self.patches.items()},
            "ring": self.ring,
            "gg": None if self.gg is None else self.gg.as_dict(),
            "ncp_trials": {m: t.as_dict() for m, t in self.ncp_trials.items()},
            "recommendation": self.recommendation.as_dict(),
            "seconds": round(self.seconds, 2),
            "method": ("the target's B-spline (9 x 9, bi-degree 4 least squares, or the .3dm "
                       "NURBS itself) sampled on a uniform grid; patches are the largest "
                       "parameter rectangles of admitted samples (their sides are the fit's "
                       "parameter lines, which the PHLW step turns onto the principal ones)"),
        }


def analyze_target(target: Any, *, units: Any = None, clean: bool = True, obj: str | None = None,
                   samples: int = 64, trial: bool = True,
                   min_coverage: float = MIN_COVERAGE) -> Analysis:
    """Analyse ``target`` (a path, an InputGeometry or ``(V, F)``; ``units``, ``clean``,
    ``obj`` as for :func:`~gridshell.io.read.read_input`). ``samples`` per parameter
    direction; ``trial``: run the coarse GG design and the coarse PHLW step of each NCP mode
    (the distance of the nearest GG / PHLW / CNC / PK surface); ``min_coverage`` (%) for a
    mode to be recommended."""
    from gridshell.io.read import read_input

    t0 = time.perf_counter()
    g = read_input(target, units=units, clean=clean, obj=obj)
    V, F, surface, rms, working = _surface_of(g)
    m = curvature_map(surface, V, F, fit_rms=rms, samples=samples)
    sign, umb = m.sign, m.umbilic
    classes = {"K>0": 100 * m.share(sign > 0), "K<0": 100 * m.share(sign < 0),
               "flat": 100 * m.share(sign == 0), "near umbilic": 100 * m.share(umb),
               "sampled on the target": 100.0 * float(m.on_target.mean())}
    found = (regions(m, umb, "near umbilic") + regions(m, sign > 0, "K>0")
             + regions(m, sign < 0, "K<0"))
    regular = _larger(largest_rectangle(m, ~umb & (sign > 0)),
                      largest_rectangle(m, ~umb & (sign < 0)))
    patches = {"phlw": regular, "cnc": regular, "aa": largest_rectangle(m, sign < 0)}
    cov = {k: 0.0 if r is None else 100.0 * r.share for k, r in patches.items()}
    # no regular patch of curvature lines (a dome, a hill): the ring around its umbilic
    ring = _ring(V, F, found) if cov["phlw"] < min_coverage else None
    # the trials on the map's working copy (not a second decimation)
    gg = gg_trial(dataclasses.replace(g, V=V, F=F) if working else g) if trial else None
    trials = _ncp_trials(surface, V, F, m, found) if trial else {}
    rec = _for_target(recommend(cov, gg, min_coverage, ring=ring, trials=trials), g.path,
                      units, obj)
    info = {"name": g.name, "path": g.path, "units": g.units.name, "vertices": int(len(g.V)),
            "faces": int(len(g.F)), "diagonal_m": round(m.diagonal, 6),
            "surface": "the .3dm NURBS surface" if g.surface is not None else
            f"least-squares B-spline (rms {rms:.3g} m)", "working_copy": working}
    return Analysis(info, m, classes, found, patches, gg, rec, time.perf_counter() - t0, ring,
                    trials)


def _ncp_trials(surface: Any, V: np.ndarray, F: np.ndarray, m: CurvatureMap,
                found: list[Region]) -> dict[str, NCPTrial]:
    """The coarse PHLW step of each NCP mode against a copy of the target of at most
    :data:`TRIAL_FACES` faces (the step's closest points are most of its time; its 8 x 8
    samples need no more), its distances measured on the map's samples."""
    from gridshell.io.working import working_mesh

    Vt, Ft, _ = working_mesh(V, F, TRIAL_FACES)
    return {k: ncp_trial(surface, Vt, Ft, k, m, found) for k in ("phlw", "cnc", "aa")}


def _ring(V: np.ndarray, F: np.ndarray, found: list[Region]) -> dict[str, Any]:
    """The ring around the target's largest near-umbilic region (or its crest) on which
    ``gridshell ncp`` designs a PHLW or CNC net where no regular patch exists
    (:func:`gridshell.ncp.ring.ring_patch`): its radii, centre and share of the target, or
    ``{"none": why}``. Its loops are curvature lines on a surface of revolution; elsewhere
    the PHLW step moves them there."""
    from gridshell.core.errors import InputError
    from gridshell.ncp.ring import ring_patch, umbilic_frame

    umb = [r for r in found if r.kind == "near umbilic"]
    try:
        frame = umbilic_frame(V, F, *((np.asarray(umb[0].centre), umb[0].share) if umb
                                      else (None, 0.0)))
        p = ring_patch(V, F, *frame[:2], inner=frame[2])
    except (InputError, ValueError) as exc:
        return {"none": str(exc)}
    return {"kind": "ring around the umbilic" if umb else "ring around the crest",
            "modes": ["phlw", "cnc"], "centre_m": [round(float(c), 6) for c in p.origin],
            "inner_m": round(p.inner, 6), "outer_m": round(p.outer, 6),
            "share_percent": round(p.share, 2)}


def _for_target(rec: Recommendation, path: Any, units: Any, obj: str | None) -> Recommendation:
    """The recommendation with its command spelt for this target: its path, and the
    ``--units`` / ``--object`` the analysis was given."""
    import shlex

    cmd = rec.command.replace("TARGET", shlex.quote(str(path)) if path else "TARGET")
    if units is not None:
        cmd += f" --units {getattr(units, 'name', units)}"
    if obj is not None:
        cmd += f" --object {shlex.quote(str(obj))}"
    return dataclasses.replace(rec, command=cmd)


def _larger(a: Rectangle | None, b: Rectangle | None) -> Rectangle | None:
    """The rectangle of the larger share (None where neither exists)."""
    if a is None or b is None:
        return a or b
    return a if a.share >= b.share else b


def _surface_of(g: Any) -> tuple[np.ndarray, np.ndarray, Any, float, Any]:
    """``(V, F, surface, rms, working-copy info)`` of an InputGeometry."""
    from gridshell.io.working import working_mesh

    V, F, working = working_mesh(np.asarray(g.V, float), np.asarray(g.F), ANALYSIS_FACES)
    if g.surface is not None:
        return V, F, g.surface, 0.0, working
    from gridshell.ncp.reference import initial_surface

    fit = initial_surface(V, F)
    return V, F, fit.surface, float(fit.rms), working


def write_analysis(a: Analysis, out: str | Path) -> dict[str, Path]:
    """Write the directory ``out`` with analysis.json and analysis.png (atomically, with its
    manifest; an existing ``out`` is replaced only if it is empty or an earlier analysis,
    :func:`gridshell.core.atomic.atomic_dir`); returns the two paths."""
    import json

    from gridshell.core.atomic import atomic_dir
    from gridshell.design.bundle import finite_json
    from gridshell.render.analysis_map import analysis_png

    out = Path(out)
    m = a.map
    boxes = {k: None if r is None else (*r.rows, *r.cols) for k, r in a.patches.items()}
    png = analysis_png(m.S, m.sign, np.abs(m.k2 - m.k1) * m.diagonal, m.umbilic, m.on_target,
                       {"phlw": boxes["phlw"], "aa": boxes["aa"]},
                       title=f"{a.target['name']}: recommended {a.recommendation.command}")
    text = json.dumps(finite_json(a.as_dict()), indent=1, allow_nan=False)
    with atomic_dir(out, owner="analyze", kind="analysis") as tmp:
        (tmp / "analysis.png").write_bytes(png)
        (tmp / "analysis.json").write_text(text)
    return {"json": out / "analysis.json", "png": out / "analysis.png"}


def summary_of(a: Analysis) -> dict[str, Any]:
    """The one-screen summary of an :class:`Analysis` (the CLI's and the server's)."""
    t, rec = a.target, a.recommendation
    d = {"target": f"{t['vertices']} vertices, {t['faces']} faces, {t['units']}, diagonal "
                   f"{t['diagonal_m']:.3g} m; {t['surface']}",
         "classes [%]": {k: round(v, 1) for k, v in a.classes.items()}}
    big = sorted(a.regions, key=lambda r: -r.share)[:4]
    d["regions"] = "; ".join(f"{r.kind} {100 * r.share:.0f} % at ({r.centre[0]:.2f}, "
                             f"{r.centre[1]:.2f}, {r.centre[2]:.2f}) m" for r in big) or "-"
    d["NCP largest regular patch [%]"] = {m: round(c, 1) for m, c in a.coverage.items()}
    if a.ring is not None:
        d["NCP ring"] = (f"no ring: {a.ring['none']}" if "none" in a.ring else
                         f"{a.ring['kind']}, radius {a.ring['inner_m']:.3g} to "
                         f"{a.ring['outer_m']:.3g} m: {a.ring['share_percent']:.0f} % of the "
                         "target (phlw, cnc: 'gridshell ncp' designs there)")
    if a.gg is None:
        d["GG trial"] = "not run (--no-trial)"
    elif a.gg.error:
        d["GG trial"] = f"failed: {a.gg.error}"
    else:
        d["GG trial"] = (f"deviation mean {a.gg.deviation_mean:.2f} %, max "
                         f"{a.gg.deviation_max:.2f} % of the diagonal; net covers "
                         f"{a.gg.coverage:.0f} % ({a.gg.seconds:.1f} s, coarse)")
    for mode, t in a.ncp_trials.items():
        d[f"NCP trial {mode}"] = _trial_line(t)
    d["recommended"] = rec.command
    d["why"] = rec.why
    d["time [s]"] = round(a.seconds, 2)
    return d


def _trial_line(t: NCPTrial) -> str:
    """One line of the summary for an NCP trial: how far its surface lies, and where most."""
    if t.error is not None:
        return f"none: {t.error}"
    kind = t.surface
    d = t.deviation
    line = (f"nearest {kind} surface {d['mean']:.2f} % mean, {d['max']:.2f} % max of the diagonal "
            "from the target")
    worst = max((r for r in t.regions if r["share_percent"] >= 5), default=None,
                key=lambda r: r["mean"])
    if worst is not None and len(t.regions) > 1:
        line += f" (most over the {worst['kind']} region: {worst['mean']:.2f} % mean)"
    if not t.of_kind:
        line += (f"; not yet of its kind (relation {t.relation:.2g}, angle {t.angle_deg:.1f} deg, "
                 f"no real net at {t.no_net_percent:.0f} % of the samples): no {kind} surface "
                 "this close over the whole target")
    return line + f" ({t.seconds:.1f} s)"
