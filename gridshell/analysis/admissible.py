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

from gridshell.analysis.recommend import MIN_COVERAGE
from gridshell.core.errors import ConvergenceError, NoNetError

__all__ = ["design_ncp_explained", "no_patch_finding"]


def no_patch_finding(source: Any, mode: str, *, units: Any = None, obj: str | None = None,
                     min_coverage: float = MIN_COVERAGE) -> str | None:
    """The analysis's finding when ``mode`` has no regular patch over ``min_coverage`` % of
    ``source`` (one line), None when it has one (or the source cannot be analysed)."""
    from gridshell.analysis.analyze import analyze_target
    from gridshell.core.errors import GridshellError

    try:
        a = analyze_target(source, units=units, obj=obj, trial=False)
    except (GridshellError, ValueError):
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
        finding = no_patch_finding(source, mode, units=units, obj=obj)
        if finding is None:
            raise
        raise NoNetError(finding) from exc
