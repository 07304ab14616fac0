"""The fabrication parameters an export builds its strips and sheets from, and the cut sheets.

The strip's real section is the cut strip's (mm of the physical model) divided by the scale:
20 mm x 1 mm at 1:10 is 200 mm x 10 mm. The parameters come from, in this order:

1. the caller's values (``--width``, ``--thickness``, ``--hole``, ``--scale`` ...);
2. the bundle's fabrication report ``DIR/fabrication/fabrication.json`` (the parameters the
   cut files were written with), when there is one, read by
   :func:`gridshell.design.section.stored_params` (the one reader: a corrupt report is an
   error naming it, as for every command);
3. :class:`gridshell.fabrication.params.FabParams` defaults (20 x 1 mm, 3 mm holes, 1:10, 600 x 400 mm;
   the strip's from :data:`gridshell.design.section.DEFAULTS`).

The order and the strip's section are those of :func:`gridshell.design.section.resolve_section`
(a test keeps the two the same for every bundle).

The cut sheets are planned in memory with :func:`gridshell.fabrication.pipeline.plan_parts` from these
parameters: the same nesting as ``gridshell fabricate`` writes (deterministic).
"""
from __future__ import annotations

from dataclasses import fields
from pathlib import Path
from typing import Any, Callable

from gridshell.core.errors import InputError
from gridshell.design.section import FABRICATION_REPORT, stored_params

__all__ = ["FABRICATION_REPORT", "export_params", "plan_sheets"]

def export_params(bundle_dir: str | Path | None = None, params: Any = None,
                  **overrides: Any):
    """``(FabParams, source)``: the fabrication parameters of an export (see the module
    docstring for the order), ``source`` saying where they came from.

    Parameters
    ----------
    bundle_dir : path, optional
        The design bundle directory (its ``fabrication/fabrication.json`` is read).
    params : FabParams or dict, optional
        Parameters to start from instead of the stored ones.
    **overrides
        Fields of :class:`~gridshell.fabrication.params.FabParams` (``width``, ``thickness``, ``hole``,
        ``scale``, ``sheet`` ...; mm of the model); None values are ignored.
    """
    from gridshell.fabrication.params import FabParams

    names = {f.name for f in fields(FabParams)}
    unknown = sorted(set(overrides) - names)
    if unknown:
        raise InputError(f"unknown fabrication parameter(s) {', '.join(unknown)}; known: "
                         f"{', '.join(sorted(names))}")
    if params is not None:
        base = params.to_json() if isinstance(params, FabParams) else dict(params)
        source = "given parameters"
    else:
        base, path = stored_params(bundle_dir)
        source = path if base else "defaults"
    d = {k: v for k, v in base.items() if k in names}
    given = {k: v for k, v in overrides.items() if v is not None}
    if given:
        source = f"{source} with {', '.join(sorted(given))} given"
    d.update(given)
    if d.get("sheet") is not None and not isinstance(d["sheet"], str):
        d["sheet"] = tuple(d["sheet"])
    return FabParams(**d), source


def plan_sheets(bundle, params, progress: Callable[[str], None] | None = None):
    """``(layout, params, fallback)``: the parts of ``bundle`` nested on sheets (mm, each
    sheet's own frame ``[0, W] x [0, H]``), as :func:`gridshell.fabrication.pipeline.plan_parts` plans
    them, the parameters it used, and ``fallback``: why joints too close for holes became
    engraved marks (None when they did not)."""
    from gridshell.fabrication.pipeline import plan_parts

    _, layout, info = plan_parts(bundle, params, progress)
    return layout, info["params"], info["joints_fallback"]
