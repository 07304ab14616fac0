"""The Python API: design, write, read, verify, cut and export, the same calls for GG and NCP.

::

    import gridshell as gs

    design = gs.design_gg("target.obj", grid=(16, 16), n_lamellae=8)   # or gs.design_ncp(...)
    gs.analyze("target.obj").recommendation      # before any design: which pipeline and mode
    gs.write("out/gg", design)                  # the design bundle (same layout for every kind)
    gs.verify("out/gg")["ok"]                   # the figures recomputed from the files
    gs.fabricate("out/gg", "out/gg/fabrication", {"width": 20, "scale": "1:10"})
    gs.check_structure("out/gg").ok             # the strips stay elastic (structure.json)
    gs.simulate("out/gg").figures               # the elastic equilibrium (out/gg/equilibrium)
    gs.export_3dm("out/gg", "out/gg/gg.3dm")    # strips, holes, surface, cut sheets for Rhino
    gs.write_outputs("out/gg", report=True, rhino="out/gg/gg.3dm")  # render.png, report.html,
                                                # and the .3dm built meanwhile (two cores)
    study = gs.Study("target.obj", {"lamellae": [8, 12], "material": ["pp", "petg"]})
    gs.sweep(study, "out/study").table          # every variant on Dask: a pandas DataFrame

The functions are those of the modules that implement them (named in each docstring); the
``gridshell`` command calls the same ones.
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Callable, Sequence

from gridshell.design.bundle import Design, DesignBundle, read_bundle
from gridshell.design.verification import verify_bundle

__all__ = ["Design", "DesignBundle", "analyze", "check_structure", "design_gg", "design_ncp", "export_3dm",
           "fabricate", "load_results", "optimize_phlw", "read", "simulate", "Study", "sweep", "verify",
           "write", "write_outputs"]

Progress = Callable[[str], None] | None


# The pipelines are imported by the functions that run them (``gridshell gg`` loads neither
# NCP nor PHLW: ~0.2 s of a command) and looked up at each call (a test or a plug-in
# replacing gridshell.gg.pipeline.design_gg reaches the CLI and the API alike). Each function
# spells out its pipeline's parameters (tests/test_api.py keeps names and defaults the same).
def analyze(target: Any, *, units: Any = None, clean: bool = True, obj: str | None = None,
            samples: int = 64, trial: bool = True, min_coverage: float = 50.0,
            output: str | os.PathLike | None = None) -> Any:
    """Where each kind of net can exist on ``target`` and which pipeline and mode to run
    (:func:`gridshell.analysis.analyze.analyze_target`; an
    :class:`~gridshell.analysis.analyze.Analysis`); with ``output`` also the directory of
    analysis.json and analysis.png (:func:`~gridshell.analysis.analyze.write_analysis`)."""
    from gridshell.analysis.analyze import analyze_target, write_analysis

    a = analyze_target(target, units=units, clean=clean, obj=obj, samples=samples, trial=trial,
                       min_coverage=min_coverage)
    if output is not None:
        write_analysis(a, output)
    return a


def design_gg(target: Any, *, meridians: str = "cols", grid: tuple[int, int] | None = None,
              direction: float | None = None, n_lamellae: int | None = None,
              spacing: float | None = None, crossing_angle: float = 90.0,
              at_parallel: float = 0.5,
              offsets: tuple[Sequence[float], Sequence[float]] | None = None,
              weights: dict[str, float] | None = None, angle: float | None = None,
              rounds: int = 10, polish_iter: int = 20, allow_unconverged: bool = False,
              frames: int = 12, units: Any = None, clean: bool = True, obj: str | None = None,
              progress: Progress = None) -> Design:
    """Design a geodesic (GG) gridshell on a target surface: ``(bundle, report)``;
    parameters and results of :func:`gridshell.gg.pipeline.design_gg`."""
    from gridshell.gg import pipeline

    return pipeline.design_gg(
        target, meridians=meridians, grid=grid, direction=direction, n_lamellae=n_lamellae,
        spacing=spacing, crossing_angle=crossing_angle, at_parallel=at_parallel,
        offsets=offsets, weights=weights, angle=angle, rounds=rounds, polish_iter=polish_iter,
        allow_unconverged=allow_unconverged, frames=frames, units=units, clean=clean, obj=obj,
        progress=progress)


def design_ncp(source: Any, *, mode: str = "phlw", curves: int | tuple[int, int] | None = None,
               spacing: float | None = None, n: float | None = None,
               samples: tuple[int, int] = (48, 48), levelset_ctrl: tuple[int, int] = (12, 12),
               levelset_degree: tuple[int, int] = (3, 3), omega_f: float = 0.01,
               trace_grid: tuple[int, int] = (240, 240),
               collapse_samples: tuple[int, int] = (1200, 1200),
               postopt_weights: dict[str, float] | None = None, postopt_rounds: int = 3,
               frames: int = 12, sim_weights: dict[str, float] | None = None,
               surface_samples: tuple[int, int] = (100, 100), phlw_options: dict | None = None,
               allow_unconverged: bool = False, strict: bool = False, units: Any = None,
               clean: bool = True, obj: str | None = None, min_coverage: float | None = None,
               progress: Progress = None) -> Design:
    """Design an NCP gridshell (PHLW, CNC or AA) on a reference surface: ``(bundle,
    report)``; parameters and results of :func:`gridshell.ncp.pipeline.design_ncp`. Where
    the PHLW step fails on a reference with no regular patch of the mode (the analysis's
    finding), the design is made on the ring around the umbilic, or
    :class:`~gridshell.core.errors.NoNetError` (exit 3) says why
    (:func:`gridshell.analysis.admissible.design_ncp_explained`, which also gates the net's
    coverage of a target file: ``min_coverage`` %, None its default, 0 no gate)."""
    from gridshell.analysis.admissible import design_ncp_explained

    return design_ncp_explained(
        source, mode=mode, curves=curves, spacing=spacing, n=n, samples=samples,
        levelset_ctrl=levelset_ctrl, levelset_degree=levelset_degree, omega_f=omega_f,
        trace_grid=trace_grid, collapse_samples=collapse_samples,
        postopt_weights=postopt_weights, postopt_rounds=postopt_rounds, frames=frames,
        sim_weights=sim_weights, surface_samples=surface_samples, phlw_options=phlw_options,
        allow_unconverged=allow_unconverged, strict=strict, units=units, clean=clean, obj=obj,
        min_coverage=min_coverage, progress=progress)


def optimize_phlw(surf: Any, reference: Any, *, mode: str = "phlw",
                  samples: tuple[int, int] = (18, 18), weights: dict[str, float] | None = None,
                  outer: int = 4, max_iter: int = 40, check_samples: tuple[int, int] = (60, 60),
                  early_stop: bool = True, progress: Progress = None) -> Any:
    """The PHLW optimization of a B-spline surface (paper 4.2.1); parameters and result
    (a PHLWResult) of :func:`gridshell.ncp.phlw.optimize_phlw`."""
    from gridshell.ncp import phlw

    return phlw.optimize_phlw(surf, reference, mode=mode, samples=samples, weights=weights,
                              outer=outer, max_iter=max_iter, check_samples=check_samples,
                              early_stop=early_stop, progress=progress)


def _parts(design: Any, report: dict | None = None) -> tuple[DesignBundle, dict | None]:
    """``(bundle, report)`` of a design (:func:`gridshell.workflow.cut.design_parts`)."""
    from gridshell.workflow.cut import design_parts

    return design_parts(design, report)


def write(path: str | os.PathLike, design: Design | DesignBundle, report: dict | None = None,
          *, render: bool = True, frames: int = 12, progress: Progress = None) -> Path:
    """Write a design to the bundle directory ``path`` atomically; returns ``path``.

    One call and one layout for every kind (GG, NCP, CNC, AA): design.json, net.obj,
    aligned.obj, axes.obj, surface.obj, report.json, the alignment sequence and, with
    ``render``, the pictures; see :func:`gridshell.workflow.cut.write_design`."""
    from gridshell.workflow.cut import write_design

    return write_design(path, design, report, render=render, frames=frames, progress=progress)


def read(path: str | os.PathLike) -> DesignBundle:
    """The design bundle at ``path`` (:func:`gridshell.design.bundle.read_bundle`), validated."""
    return read_bundle(path)


def verify(path: str | os.PathLike) -> dict[str, Any]:
    """Every figure of the bundle at ``path`` recomputed from its files and gated by the
    paper's thresholds (:func:`gridshell.design.verification.verify_bundle`): ``ok``, ``gates``,
    ``checks``, ``problems`` and the figures."""
    return verify_bundle(path)


def fabricate(design: Any, out_dir: str | os.PathLike, params: Any = None, *,
              force: bool = False, plan: bool = True, progress: Progress = None,
              material: str | None = None) -> dict[str, Any]:
    """Cut files (DXF, SVG, PNG per sheet), cut list and plan of a design into ``out_dir``
    (:func:`gridshell.workflow.cut.fabricate_checked`: refused when its figures or its strips'
    stresses fail, unless ``force``)."""
    from gridshell.workflow.cut import fabricate_checked

    return fabricate_checked(design, out_dir, params, force=force, plan=plan,
                             progress=progress, material=material)


#: the names the API takes from their modules as they are (the very functions, real signatures),
#: imported on first use: name -> module
_FROM = {"check_structure": "gridshell.workflow.structure",
         "simulate": "gridshell.workflow.structure",
         "export_3dm": "gridshell.export.rhino",
         "write_outputs": "gridshell.workflow.outputs",
         "sweep": "gridshell.workflow.sweep",
         "Study": "gridshell.workflow.study",
         "load_results": "gridshell.workflow.sweep"}


def __getattr__(name: str) -> Any:
    """The functions of :data:`_FROM`: ``check_structure`` (will the strips bend into the
    design without breaking: structure.json, ``gridshell check``), ``simulate`` (the elastic
    equilibrium, ``gridshell simulate``), ``export_3dm`` (the Rhino model, ``gridshell
    export``) and ``write_outputs`` (render.png, alignment.gif, report.html and a .3dm in one
    call, ``gridshell render``)."""
    if name in _FROM:
        import importlib

        fn = getattr(importlib.import_module(_FROM[name]), name)
        globals()[name] = fn
        return fn
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_FROM))
