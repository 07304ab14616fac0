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

import os
from typing import Any

import numpy as np

from gridshell.analysis.recommend import MIN_COVERAGE, RING_COVERAGE
from gridshell.core.errors import ConvergenceError, NoNetError

__all__ = ["design_ncp_explained", "no_patch_finding", "ring_design"]

#: near-umbilic share of a target (%) from which a regular patch's net must cover
#: :data:`RING_COVERAGE` % by default: the patch ends at umbilics (an elliptic dome's)
UMBILIC_SHARE = 1.0
#: curves per family of the second design a net covering too little of the target gets
#: (default 10: its outer loops end a spacing short of the rim)
DENSE_CURVES = 16
#: net-direction samples and level-set control points on a ring (radius, angle)
RING_SAMPLES = (48, 96)
RING_LEVELSET = (8, 30)
#: curves across the ring's width (their spacing: the width over this)
RING_CURVES = 12


def _phlw_keywords(phlw_options: dict | None) -> dict:
    """The optimizer's keywords of the user's PHLW options (the ring fixes its B-spline)."""
    return {k: v for k, v in (phlw_options or {}).items()
            if k not in ("ctrl", "degree", "transpose", "align")}


def _umbilic_of(a: Any) -> tuple[np.ndarray | None, float]:
    """``(centre (3,) m, share of the target)`` of the analysis's largest near-umbilic
    region, ``(None, 0)`` without one."""
    umb = [r for r in a.regions if r.kind == "near umbilic"]
    return (np.asarray(umb[0].centre, float), float(umb[0].share)) if umb else (None, 0.0)


def _analysis(source: Any, units: Any, obj: str | None) -> Any:
    """The analysis of ``source`` without the GG trial, None where it cannot be made."""
    from gridshell.analysis.analyze import analyze_target
    from gridshell.core.errors import GridshellError

    try:
        return analyze_target(source, units=units, obj=obj, trial=False)
    except (GridshellError, ValueError):
        return None


def _where(a: Any) -> str:
    """Where the analysis ``a`` finds near-umbilic regions (or the signs of K without)."""
    umb = [r for r in a.regions if r.kind == "near umbilic"]
    return (f"near-umbilic regions cover {a.classes['near umbilic']:.0f} % of the target "
            f"(the largest {100 * umb[0].share:.0f} % around "
            f"({', '.join(f'{c:.3g}' for c in umb[0].centre)}) m)" if umb else
            f"K > 0 on {a.classes['K>0']:.0f} %, K < 0 on {a.classes['K<0']:.0f} % of it")


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
    return (f"no regular patch of the {mode} net covers {min_coverage:g} % of this target: "
            f"{_where(a)}; the largest admissible patch covers {cov:.0f} % "
            f"('gridshell analyze' maps it); a GG gridshell fits such shapes "
            f"('gridshell gg' or 'gridshell build')")


def design_ncp_explained(source: Any, *, mode: str = "phlw", units: Any = None,
                         obj: str | None = None, min_coverage: float | None = None,
                         **options: Any) -> Any:
    """:func:`gridshell.ncp.pipeline.design_ncp` (same arguments), its PHLW step's failure
    turned into :class:`NoNetError` (exit 3) where the analysis finds no admissible patch -
    after the ring around the umbilic (:func:`ring_design`) failed too.

    The coverage gate on a target file (% of its area within 2 % of the net): a design below
    ``min_coverage`` is replaced by a denser net's (:data:`DENSE_CURVES`, unless the user
    set ``curves`` or ``spacing``) or the ring's where that covers more and at least the
    gate, else refused (:class:`NoNetError`). ``None`` (the default): :data:`RING_COVERAGE` where
    the analysis finds no regular patch of the mode over :data:`MIN_COVERAGE` % (a dome, a
    hill), else a regular design under :data:`MIN_COVERAGE` % is kept unless the ring covers
    more (its coverage in the summary and design.json); ``0``: no gate."""
    from gridshell.ncp.pipeline import design_ncp

    try:
        design = design_ncp(source, mode=mode, units=units, obj=obj, **options)
    except ConvergenceError as exc:
        # the PHLW step's failure, or a design that misses its figures on a target file: where
        # the analysis finds no regular patch of the mode, the ring; else the failure stands
        if not (getattr(exc, "phlw_failure", False) or isinstance(source, (str, os.PathLike))):
            raise
        a = _analysis(source, units, obj)
        finding = no_patch_finding(source, mode, units=units, obj=obj, analysis=a)
        if finding is None:
            raise
        design, why = ring_design(source, a, mode=mode, units=units, obj=obj,
                                  min_coverage=max(min_coverage or 0.0, RING_COVERAGE),
                                  **options)
        if design is not None:
            return design
        raise NoNetError(f"{finding}; {why}") from exc
    return _coverage_gate(design, source, mode, units, obj, min_coverage, options)


def _coverage(design: Any) -> float:
    """The share (%) of the target its net covers (design.json ``metrics.fidelity``)."""
    return float((design.bundle.metrics.get("fidelity") or {}).get("coverage", 100.0))


def _coverage_gate(design: Any, source: Any, mode: str, units: Any, obj: str | None,
                   min_coverage: float | None, options: dict) -> Any:
    """``design`` when its net covers enough of the target (:func:`design_ncp_explained`),
    else (without ``curves`` or ``spacing``) the denser net of :data:`DENSE_CURVES` curves
    where that covers enough, else the ring's design, else ``design`` kept (default gate, a regular patch exists) or
    :class:`NoNetError` naming the coverage and the analysis's finding."""
    cov = _coverage(design)
    if not isinstance(source, (str, os.PathLike)) or min_coverage == 0 or \
            cov >= (RING_COVERAGE if min_coverage is None else min_coverage):
        return design
    if options.get("curves") is None and options.get("spacing") is None:
        # the net's outer loops fall a spacing short of the rim: a denser net reaches further
        from gridshell.core.errors import GridshellError
        from gridshell.ncp.pipeline import design_ncp

        try:
            denser = design_ncp(source, mode=mode, units=units, obj=obj,
                                **dict(options, curves=DENSE_CURVES))
        except GridshellError:
            denser = None
        if denser is not None and _coverage(denser) > cov:
            design, cov = denser, _coverage(denser)
        if cov >= (RING_COVERAGE if min_coverage is None else min_coverage):
            return design
    a = _analysis(source, units, obj)
    finding = no_patch_finding(source, mode, units=units, obj=obj, analysis=a)
    if finding is None and a is not None and a.classes["near umbilic"] >= UMBILIC_SHARE:
        finding = f"the regular patch ends at umbilics: {_where(a)}"
    gate = min_coverage if min_coverage is not None else \
        (RING_COVERAGE if finding is not None else MIN_COVERAGE)
    if cov >= gate:
        return design
    ring, why = ring_design(source, a, mode=mode, units=units, obj=obj,
                            min_coverage=max(cov + 1e-9, gate), **options)
    if ring is not None:
        return ring
    if min_coverage is None and finding is None:
        return design           # a regular patch exists: its net as it is, coverage said
    raise NoNetError(
        f"the {mode} net covers {cov:.0f} % of the target, less than "
        f"{'--min-coverage ' if min_coverage is not None else ''}{gate:g} %"
        f"{'; ' + finding if finding else ''}; {why}; nothing was written "
        "(--min-coverage 0 keeps the design as it is)")


def ring_design(source: Any, a: Any, *, mode: str, units: Any = None, obj: str | None = None,
                min_coverage: float = RING_COVERAGE, **options: Any) -> tuple[Any, str]:
    """The NCP design on the ring around the target's umbilic (:mod:`gridshell.ncp.ring`):
    ``(design, "")``, or ``(None, why)`` where there is no ring, its PHLW step or design fails,
    or its net covers less than ``min_coverage`` % of the target. Samples and level-set
    control points follow the ring's long side; without ``curves`` or ``spacing`` the curves
    are :data:`RING_CURVES` to the ring's width. The PHLW step runs on every fit of
    :data:`gridshell.ncp.ring.FITS`; the design on the converged ones nearest to the target
    (two at most)."""
    from gridshell.core.errors import GridshellError, InputError
    from gridshell.io.read import read_input
    from gridshell.ncp.phlw import optimize_phlw
    from gridshell.ncp.pipeline import design_ncp
    from gridshell.ncp.ring import FITS, RingSource, ring_patch, umbilic_frame

    if mode not in ("phlw", "cnc") or a is None:
        return None, f"no ring patch for mode {mode}"
    try:
        geo = read_input(source, units=units, obj=obj, what="the target")
    except (InputError, ValueError) as exc:
        return None, f"no ring around the umbilic: {exc}"
    patches, why = [], ""
    umbilic = _umbilic_of(a)
    for about in [umbilic] + ([(None, 0.0)] if umbilic[0] is not None else []):
        # about the umbilic, else about the crest (an umbilic on the rim: an elliptic dome's)
        try:
            found = umbilic_frame(geo.V, geo.F, *about)
            patches = [ring_patch(geo.V, geo.F, *found[:2], inner=found[2], fit=f)
                       for f in FITS]
            break
        except (InputError, ValueError) as exc:
            why = why or str(exc)
    if not patches:
        return None, f"no ring around the umbilic: {why}"
    steps, loose, why = [], [], ""
    for patch in patches:            # the PHLW step on the fits in turn, until two converge
        try:
            res = optimize_phlw(patch.surface, (patch.V, patch.F), mode=mode,
                                **_phlw_keywords(options.get("phlw_options")))
        except GridshellError as exc:
            why = str(exc)
            continue
        (steps if res.converged else loose).append((patch, res))
        if len(steps) == 2:
            break
    if not steps:        # none converged: the nearest to the target, the design's gates judge
        steps = sorted(loose, key=lambda pr: float(pr[1].deviation))[:2]
        why = why or "the PHLW step converged on none of its fits"
    for patch, res in steps:
        opts = dict(options, samples=RING_SAMPLES, levelset_ctrl=RING_LEVELSET)
        if opts.get("curves") is None and opts.get("spacing") is None:
            opts["spacing"] = (patch.outer - patch.inner) / RING_CURVES
        try:
            design = design_ncp(RingSource(geo, patch, result=res), mode=mode, **opts)
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
