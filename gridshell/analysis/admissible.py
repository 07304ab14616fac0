"""An NCP design that fails where no regular patch exists says so: exit 3 with the map's
finding, not exit 4 "the optimizer's failure" (issue 29, item 3).

:func:`design_ncp_explained` runs :func:`gridshell.ncp.pipeline.design_ncp`; when its PHLW
step leaves a surface without the net (a :class:`ConvergenceError` marked ``phlw_failure``),
the analysis of the reference (:func:`gridshell.analysis.analyze.analyze_target`, no GG trial)
decides: if the largest patch the mode admits covers less than ``min_coverage`` of the target,
no optimizer could have found the net there, and the answer is :class:`NoNetError` naming the
near-umbilic regions, the largest admissible patch and its coverage, and the pipeline that
fits (GG); otherwise the optimizer's failure stands (exit 4).
"""
from __future__ import annotations

from typing import Any

import numpy as np

from gridshell.analysis.recommend import MIN_COVERAGE
from gridshell.core.errors import ConvergenceError, NoNetError

__all__ = ["design_ncp_explained", "no_patch_finding", "ring_design"]

#: the oculus left open on a ring: a disc of this many times the near-umbilic region's area
OCULUS = 1.5
#: net-direction samples and level-set control points on a ring (radius, angle)
RING_SAMPLES = (48, 96)
RING_LEVELSET = (8, 30)


def _analysis(source: Any, units: Any, obj: str | None) -> Any:
    """The analysis of ``source`` without the GG trial, None where it cannot be made."""
    from gridshell.analysis.analyze import analyze_target
    from gridshell.core.errors import GridshellError

    try:
        return analyze_target(source, units=units, obj=obj, trial=False)
    except (GridshellError, ValueError):
        return None


def no_patch_finding(source: Any, mode: str, *, units: Any = None, obj: str | None = None,
                     min_coverage: float = MIN_COVERAGE, analysis: Any = None) -> str | None:
    """The analysis's finding when ``mode`` has no regular patch over ``min_coverage`` % of
    ``source`` (one line), None when it has one (or the source cannot be analysed)."""
    a = analysis if analysis is not None else _analysis(source, units, obj)
    if a is None:
        return None
    cov = a.coverage.get(mode, 0.0)
    if cov >= min_coverage:
        return None
    umb = [r for r in a.regions if r.kind == "near umbilic"]
    where = (f"near-umbilic regions cover {a.classes['near umbilic']:.0f} % of the target "
             f"(the largest {100 * umb[0].share:.0f} % around "
             f"({', '.join(f'{c:.3g}' for c in umb[0].centre)}) m)" if umb else
             f"K > 0 on {a.classes['K>0']:.0f} %, K < 0 on {a.classes['K<0']:.0f} % of it")
    return (f"no regular patch of the {mode} net covers {min_coverage:g} % of this target: "
            f"{where}; the largest admissible patch covers {cov:.0f} % "
            f"('gridshell analyze' maps it); a GG gridshell fits such shapes "
            f"('gridshell gg' or 'gridshell build')")


def design_ncp_explained(source: Any, *, mode: str = "phlw", units: Any = None,
                         obj: str | None = None, **options: Any) -> Any:
    """:func:`gridshell.ncp.pipeline.design_ncp` (same arguments), its PHLW step's failure
    turned into :class:`NoNetError` (exit 3) where the analysis finds no admissible patch."""
    from gridshell.ncp.pipeline import design_ncp

    try:
        return design_ncp(source, mode=mode, units=units, obj=obj, **options)
    except ConvergenceError as exc:
        if not getattr(exc, "phlw_failure", False):
            raise
        a = _analysis(source, units, obj)
        finding = no_patch_finding(source, mode, units=units, obj=obj, analysis=a)
        if finding is None:
            raise
        design, why = ring_design(source, a, mode=mode, units=units, obj=obj, **options)
        if design is not None:
            return design
        raise NoNetError(f"{finding}; {why}") from exc


def _umbilic_frame(geo: Any, a: Any) -> tuple[np.ndarray, np.ndarray, float] | None:
    """``(centre, normal, oculus radius)`` of the target's largest near-umbilic region: its
    centre moved onto the target, the target's normal there, the radius of a disc 1.5 times
    the region's area (m); None without one."""
    from gridshell.geometry.igl_adapter import closest_points, triangulate

    umb = [r for r in a.regions if r.kind == "near umbilic"]
    if not umb:
        return None
    tV, T, _ = triangulate(np.asarray(geo.V, float), geo.F)
    _, _, C = closest_points(np.asarray([umb[0].centre], float), tV, T)
    N = np.cross(tV[T[:, 1]] - tV[T[:, 0]], tV[T[:, 2]] - tV[T[:, 0]])   # 2 x area normals
    area = 0.5 * np.linalg.norm(N, axis=1).sum()
    inner = float(np.sqrt(OCULUS * umb[0].share * area / np.pi))
    # the normal: the area-weighted mean over the faces within the oculus (one face at the
    # apex of a fan is tilted)
    near = np.linalg.norm(tV[T].mean(axis=1) - C[0], axis=1) <= max(inner, 1e-9)
    normal = N[near].sum(axis=0) if near.any() else N.sum(axis=0)
    return np.asarray(C[0], float), normal, inner


def ring_design(source: Any, a: Any, *, mode: str, units: Any = None, obj: str | None = None,
                min_coverage: float = MIN_COVERAGE, **options: Any) -> tuple[Any, str]:
    """The NCP design on the ring around the target's umbilic (:mod:`gridshell.ncp.ring`):
    ``(design, "")``, or ``(None, why)`` where there is no ring, its PHLW step or design fails,
    or its net covers less than ``min_coverage`` % of the target. Samples and level-set
    control points follow the ring's long side; without ``curves`` or ``spacing`` the curves
    are an eighth of the ring's width apart."""
    from gridshell.core.errors import GridshellError, InputError
    from gridshell.io.read import read_input
    from gridshell.ncp.pipeline import design_ncp
    from gridshell.ncp.ring import FITS, RingSource, ring_patch

    if mode not in ("phlw", "cnc") or a is None:
        return None, f"no ring patch for mode {mode}"
    try:
        geo = read_input(source, units=units, obj=obj, what="the target")
        found = _umbilic_frame(geo, a)
        if found is None:
            return None, "no near-umbilic region to put a ring around"
        patches = [ring_patch(geo.V, geo.F, *found[:2], inner=found[2], fit=f) for f in FITS]
    except (InputError, ValueError) as exc:
        return None, f"no ring around the umbilic: {exc}"
    why = ""
    for patch in patches:            # the first fit whose PHLW step and design hold
        opts = dict(options, samples=RING_SAMPLES, levelset_ctrl=RING_LEVELSET)
        if opts.get("curves") is None and opts.get("spacing") is None:
            opts["spacing"] = (patch.outer - patch.inner) / 8.0
        try:
            design = design_ncp(RingSource(geo, patch), mode=mode, **opts)
            break
        except GridshellError as exc:
            why = str(exc)
    else:
        return None, (f"on the ring around the umbilic ({patches[0].share:.0f} % of the "
                      f"target) the design fails too: {why[:300]}")
    fid = design.bundle.metrics.get("fidelity") or {}
    cov = float(fid.get("coverage", 0.0))
    if cov < min_coverage:
        return None, (f"the net on the ring around the umbilic covers {cov:.0f} % of the "
                      f"target (< {min_coverage:g} %)")
    design.bundle.metrics["region"] = patch.record()
    return design, ""
