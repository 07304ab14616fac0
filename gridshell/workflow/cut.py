"""A design written to its bundle and a bundle cut to sheets, with the gates every face applies.

- :func:`write_design`: a design (the result of ``design_gg`` / ``design_ncp``) to its bundle
  directory with the files of its kind (``gridshell gg|ncp``, :func:`gridshell.api.write`);
- :func:`fabricate_checked`: cut files of a bundle once its figures and its strips' stresses
  hold, unless forced (``gridshell fabricate``, :func:`gridshell.api.fabricate`).
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Callable

from gridshell.core.errors import InputError
from gridshell.design.bundle import Design, DesignBundle, write_bundle
from gridshell.design.verification import require_design

__all__ = ["design_parts", "fabricate_checked", "made_from", "require_no_made_from",
           "write_design"]

#: files other commands add to a bundle from its design (render, export, check)
MADE_FROM = ("render.png", "report.html", "structure.json", "structure.png", "build.json")


def made_from(path: str | os.PathLike) -> list[str]:
    """What other commands made from the design in the bundle directory ``path`` (cut files,
    equilibrium, the .3dm, render.png, report.html, structure.json: the nested outputs and
    files its manifest lists), which a new design there would leave stale."""
    from gridshell.core import manifest

    m = manifest.read(path) if Path(path).is_dir() else None
    if not m:
        return []
    files = [f for f in m.get("files", {}) if f in MADE_FROM or f.endswith(".3dm")]
    return sorted(set(m.get("outputs", [])) | set(files))


def require_no_made_from(path: str | os.PathLike) -> None:
    """:class:`OutputError` before any work when a new design at ``path`` would delete what
    other commands made from the old one (:func:`made_from`)."""
    from gridshell.core.errors import OutputError

    found = made_from(path)
    if found:
        raise OutputError(
            f"{path} holds what was made from its design ({', '.join(found[:6])}"
            f"{', ...' if len(found) > 6 else ''}); a new design would delete it: write to "
            "another -o, or remove them (or the directory) first (nothing was changed)")

Progress = Callable[[str], None] | None


def design_parts(design: Any, report: dict | None = None) -> tuple[DesignBundle, dict | None]:
    """``(bundle, report)`` of a :class:`Design` (or ``(bundle, report)`` pair) or a bare
    bundle with an optional ``report``."""
    if isinstance(design, DesignBundle):
        return design, report
    if isinstance(design, tuple) and len(design) == 2 and isinstance(design[0], DesignBundle):
        return design[0], report if report is not None else design[1]
    raise InputError(f"expected a design (the result of design_gg / design_ncp) or a "
                     f"DesignBundle, got {type(design).__name__}")


def write_design(path: str | os.PathLike, design: Design | DesignBundle, report: dict | None = None,
          *, render: bool = True, frames: int = 12, progress: Progress = None,
          owner: str | None = None) -> Path:
    """Write a design to the bundle directory ``path`` atomically; returns ``path``.

    One call and one layout for every kind (GG, NCP, CNC, AA): design.json, net.obj,
    aligned.obj, axes.obj, surface.obj, report.json, the alignment sequence
    ``sequence/frame_*.obj`` and, with ``render``, the pictures (``preview.png`` /
    ``delta_*.png``, ``sequence/frame_*.png``, ``alignment.gif``); and what a kind has of its
    own: revolution.obj and states.png (GG), surface.json, axes_r.npy, aligned_r.npy and
    collapse.png (NCP kinds). See :func:`gridshell.gg.pipeline.gg_files` and
    :func:`gridshell.ncp.pipeline.ncp_files`.

    Parameters
    ----------
    design : Design (the result of :func:`design_gg` / :func:`design_ncp`) or DesignBundle
    report : dict, optional
        The run's report when ``design`` is a bare bundle. An NCP design needs it (its
        ``"state"`` holds the surface and the rotation axes); for a GG bundle without one the
        alignment sequence is computed (``frames`` steps; 0: none).
    render : bool
        Also draw the pictures and the animation (the slowest part).
    owner : str, optional
        The command the bundle's manifest names (default ``gg`` / ``ncp`` by kind).
    """
    bundle, report = design_parts(design, report)
    if owner != "build":                # a build re-makes what it made from the design
        require_no_made_from(path)
    if bundle.kind == "GG":
        from gridshell.gg.pipeline import gg_files

        extra = gg_files(bundle, report, render=render, frames=frames, progress=progress)
    else:
        if not isinstance(report, dict) or "state" not in report:
            raise InputError(f"an {bundle.kind} design is written with the report of "
                             "design_ncp (it holds the B-spline and the rotation axes): "
                             "write(path, design_ncp(...))")
        from gridshell.ncp.pipeline import ncp_files

        extra = ncp_files(bundle, report, render=render, progress=progress)
    return write_bundle(path, bundle, extra=extra, owner=owner)


def fabricate_checked(design: Any, out_dir: str | os.PathLike, params: Any = None, *,
              force: bool = False, plan: bool = True, progress: Progress = None,
              material: str | None = None, verified: bool = False,
              structure: dict[str, Any] | None = None) -> dict[str, Any]:
    """Cut files (DXF, SVG, PNG per sheet), cut list and plan of a design into ``out_dir``
    (:func:`gridshell.fabrication.pipeline.fabricate`; ``params``: a FabParams or a dict of its fields,
    mm of the model). A design that fails its figures (recomputed from the files of a bundle
    directory) is refused with :class:`~gridshell.core.errors.InputError`, one whose strips of
    ``material`` (a preset name; default the strips' default material) would be overstressed
    with :class:`~gridshell.structure.verdict.Overstressed`, unless ``force``; the structural
    verdict is the report's ``"structure"``. A caller that has just verified these very files
    says so (``verified``), and one that has their check for this material and section gives
    it (``structure``: :func:`gridshell.structure.check.check_bundle`'s result, e.g.
    structure.json): neither is computed again (the given check still refuses an
    overstressed design unless ``force``)."""
    from gridshell.fabrication.params import FabParams
    from gridshell.fabrication.pipeline import fabricate as _fabricate
    from gridshell.structure import Section, get_material
    from gridshell.design.section import DEFAULTS
    from gridshell.structure.verdict import require_elastic, verdict_record

    bundle = design if isinstance(design, (str, os.PathLike)) else design_parts(design)[0]
    where = Path(bundle) if isinstance(bundle, (str, os.PathLike)) else bundle
    retry = "fabricate(..., force=True) cuts it anyway"
    if not verified:
        require_design(where, force, retry)
    fp = params if isinstance(params, FabParams) else FabParams(**(params or {}))
    if structure is not None:
        from gridshell.structure.verdict import refuse_overstressed

        refuse_overstressed(structure, force, retry)
        res = structure
    else:
        res = require_elastic(where, get_material(material or DEFAULTS["material"]),
                              Section.from_params(fp), force, retry)
    return _fabricate(bundle, out_dir, fp, progress=progress, plan=plan,
                      structure=verdict_record(res, force))


