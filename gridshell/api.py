"""The Python API: design, write, read, verify, cut and export, the same calls for GG and NCP.

::

    import gridshell as gs

    design = gs.design_gg("target.obj", grid=(16, 16), n_lamellae=8)   # or gs.design_ncp(...)
    gs.write("out/gg", design)                  # the design bundle (same layout for every kind)
    gs.verify("out/gg")["ok"]                   # the figures recomputed from the files
    gs.fabricate("out/gg", "out/gg/fabrication", {"width": 20, "scale": "1:10"})
    gs.export_3dm("out/gg", "out/gg/gg.3dm")    # strips, holes, surface, cut sheets for Rhino
    gs.write_outputs("out/gg", report=True, rhino="out/gg/gg.3dm")  # render.png, report.html,
                                                # and the .3dm built meanwhile (two cores)

The functions are those of the modules that implement them (named in each docstring); the
``gridshell`` command calls the same ones.
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Callable

from gridshell.design.bundle import Design, DesignBundle, read_bundle, write_bundle
from gridshell.core.errors import InputError
from gridshell.design.verification import require_design, verify_bundle

__all__ = ["Design", "DesignBundle", "design_gg", "design_ncp", "export_3dm", "fabricate",
           "optimize_phlw", "read", "verify", "write", "write_outputs"]

Progress = Callable[[str], None] | None


# The pipelines are imported by the functions that run them (``gridshell gg`` loads neither
# NCP nor PHLW: ~0.2 s of a command) and looked up at each call (a test or a plug-in
# replacing gridshell.gg.pipeline.design_gg reaches the CLI and the API alike).
def design_gg(*args: Any, **kwargs: Any) -> Design:
    """Design a geodesic (GG) gridshell on a target surface: ``(bundle, report)``;
    parameters and results of :func:`gridshell.gg.pipeline.design_gg`."""
    from gridshell.gg import pipeline

    return pipeline.design_gg(*args, **kwargs)


def design_ncp(*args: Any, **kwargs: Any) -> Design:
    """Design an NCP gridshell (PHLW, CNC or AA) on a reference surface: ``(bundle,
    report)``; parameters and results of :func:`gridshell.ncp.pipeline.design_ncp`."""
    from gridshell.ncp import pipeline

    return pipeline.design_ncp(*args, **kwargs)


def optimize_phlw(*args: Any, **kwargs: Any) -> Any:
    """The PHLW optimization of a B-spline surface (paper 4.2.1); parameters and result of
    :func:`gridshell.ncp.phlw.optimize_phlw`."""
    from gridshell.ncp import phlw

    return phlw.optimize_phlw(*args, **kwargs)


def _parts(design: Any, report: dict | None = None) -> tuple[DesignBundle, dict | None]:
    """``(bundle, report)`` of a :class:`Design` (or ``(bundle, report)`` pair) or a bare
    bundle with an optional ``report``."""
    if isinstance(design, DesignBundle):
        return design, report
    if isinstance(design, tuple) and len(design) == 2 and isinstance(design[0], DesignBundle):
        return design[0], report if report is not None else design[1]
    raise InputError(f"expected a design (the result of design_gg / design_ncp) or a "
                     f"DesignBundle, got {type(design).__name__}")


def write(path: str | os.PathLike, design: Design | DesignBundle, report: dict | None = None,
          *, render: bool = True, frames: int = 12, progress: Progress = None) -> Path:
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
    """
    bundle, report = _parts(design, report)
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
    return write_bundle(path, bundle, extra=extra)


def read(path: str | os.PathLike) -> DesignBundle:
    """The design bundle at ``path`` (:func:`gridshell.design.bundle.read_bundle`), validated."""
    return read_bundle(path)


def verify(path: str | os.PathLike) -> dict[str, Any]:
    """Every figure of the bundle at ``path`` recomputed from its files and gated by the
    paper's thresholds (:func:`gridshell.design.verification.verify_bundle`): ``ok``, ``gates``,
    ``checks``, ``problems`` and the figures."""
    return verify_bundle(path)


def fabricate(design: Any, out_dir: str | os.PathLike, params: Any = None, *,
              force: bool = False, plan: bool = True, progress: Progress = None
              ) -> dict[str, Any]:
    """Cut files (DXF, SVG, PNG per sheet), cut list and plan of a design into ``out_dir``
    (:func:`gridshell.fabrication.pipeline.fabricate`; ``params``: a FabParams or a dict of its fields,
    mm of the model). A design that fails its figures (recomputed from the files of a bundle
    directory) is refused with :class:`~gridshell.core.errors.InputError` unless ``force``."""
    from gridshell.fabrication.pipeline import fabricate as _fabricate

    bundle = design if isinstance(design, (str, os.PathLike)) else _parts(design)[0]
    require_design(Path(bundle) if isinstance(bundle, (str, os.PathLike)) else bundle, force,
                   "fabricate(..., force=True) cuts it anyway")
    return _fabricate(bundle, out_dir, params, progress=progress, plan=plan)


def export_3dm(design: Any, path: str | os.PathLike, **options: Any) -> dict[str, Any]:
    """Write a design (bundle directory, Design or DesignBundle) to a Rhino ``.3dm`` file
    (:func:`gridshell.export.rhino.write_3dm`: strips of their real width and thickness,
    holes, surface, collapsed state and cut sheets, in the input's unit); returns what was
    written (``path``, ``units``, ``layers`` ...). ``options``: ``width``, ``thickness``,
    ``hole``, ``scale``, ``sheet``, ``params``, ``units``, ``sheets``, ``force``, ``progress``."""
    from gridshell.export.rhino import write_3dm

    bundle = design if isinstance(design, (str, os.PathLike)) else _parts(design)[0]
    return write_3dm(bundle, path, **options)


def write_outputs(bundle: str | os.PathLike, **options: Any) -> dict[str, Any]:
    """render.png, alignment.gif, report.html and a .3dm of a bundle directory in one call
    (``gridshell render``), the .3dm built in a second process meanwhile; options and result of
    :func:`gridshell.workflow.outputs.write_outputs`."""
    from gridshell.workflow.outputs import write_outputs as run

    return run(bundle, **options)
