"""The surface an NCP design starts from (paper 4.2.1): a B-spline as it is, or the PHLW step
on a reference.

:func:`load_surface` takes a B-spline (a ``surface.json`` written by ``gridshell phlw``, a
:class:`~gridshell.geometry.bspline.BSplineSurface` or a ``PHLWResult``) as it is, or reads a
reference (mesh, .3dm, ``(V, F)``), fits its initial B-spline (a NURBS surface is one as it is)
and optimizes it towards a PHLW / CNC / PK surface (:func:`gridshell.ncp.phlw.optimize_phlw`).
Metres throughout; ``info["units"]`` is the unit the input was drawn in.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Callable

import numpy as np

from gridshell.core.errors import ConvergenceError, InputError, NoNetError
from gridshell.geometry.bspline import BSplineSurface
from gridshell.ncp.directions import reference_net_check

__all__ = ["load_surface"]


def load_surface(source: Any, *, mode: str, phlw_options: dict | None = None,
                 progress: Callable[[str], None] | None = None, units: Any = None,
                 clean: bool = True, obj: str | None = None
                 ) -> tuple[BSplineSurface, float | None, dict]:
    """``(surface, n, info)`` from a B-spline JSON path, a :class:`BSplineSurface`, a
    ``PHLWResult`` or a reference (mesh or .3dm path, ``InputGeometry`` or ``(V, F)``, read
    through :func:`gridshell.io.read.read_input` with ``units``, ``clean``, ``obj``; optimized
    with :func:`gridshell.ncp.phlw.optimize_phlw` first: a .3dm NURBS surface is its initial
    B-spline directly, a mesh is fitted). ``n`` is the CNC normal curvature when the source
    provides it. ``info["units"]`` is the unit of the input (:class:`gridshell.io.Units`)."""
    from gridshell.core.units import METRES
    from gridshell.ncp.phlw import PHLWResult

    if isinstance(source, BSplineSurface):
        return source, None, {"source": "bspline", "units": METRES}
    if isinstance(source, PHLWResult):
        n = float(source.n_rows[0]) if source.mode == "cnc" else None
        return source.surface, n, {"source": "phlw-result", "phlw_mode": source.mode,
                                   "units": METRES}
    from gridshell.ncp.ring import RingSource

    if isinstance(source, RingSource):        # the ring around an umbilic (gridshell.ncp.ring)
        return _ring_surface(source, mode, dict(phlw_options or {}), progress)
    if isinstance(source, (str, Path)) and str(source).lower().endswith(".json"):
        if units is not None or obj is not None:
            raise InputError(f"{Path(source).name} is a B-spline in metres written by 'gridshell "
                             "phlw' (its input unit is in report.json): drop --units / --object")
        return BSplineSurface.load(source), None, {"source": str(source),
                                                   "units": _phlw_units(Path(source))}
    geo = _read_reference(source, units=units, clean=clean, obj=obj)
    if progress is not None and geo.path is not None:
        progress(f"input: {geo.summary()}")
    opts = dict(phlw_options or {})
    init = _initial_fit(geo, opts, progress)
    # a reference without the net anywhere (umbilic everywhere; K > 0 everywhere for aa) is a
    # true no-net answer (exit 3); any later no-net answer is the PHLW step's failure (exit 4)
    reference_net_check(init.surface, mode)
    res = _phlw_step(init.surface, (geo.V, geo.F), mode, opts, progress)
    return res.surface, float(res.n_rows[0]) if mode == "cnc" else None, \
        _phlw_info(res, init, geo)


def _read_reference(source: Any, *, units: Any, clean: bool, obj: str | None) -> Any:
    """The reference of the PHLW step as :class:`gridshell.io.read.InputGeometry` (metres):
    a mesh or .3dm path, an ``InputGeometry``, a mesh with ``V`` or ``(V, F)``."""
    from gridshell.io.read import InputGeometry, read_input

    if isinstance(source, (str, Path, InputGeometry)) or hasattr(source, "V"):
        return read_input(source, units=units, clean=clean, obj=obj, what="the reference")
    try:
        V, F = source
    except (TypeError, ValueError):
        raise InputError("the NCP source must be a B-spline .json, a mesh file, (V, F), a "
                         "BSplineSurface or a PHLWResult") from None
    return read_input((V, F), units=units, clean=clean, what="the reference")


def _initial_fit(geo: Any, opts: dict, progress: Callable[[str], None] | None) -> Any:
    """The initial B-spline of the PHLW step (:class:`gridshell.ncp.reference.InitialFit`): a
    NURBS surface as it is, else fitted to the mesh of ``geo``. Takes the keys ``ctrl``,
    ``degree``, ``transpose``, ``align`` out of ``opts`` (the rest is for the optimizer)."""
    from gridshell.ncp.reference import InitialFit, initial_surface

    ctrl, degree = tuple(opts.pop("ctrl", (9, 9))), tuple(opts.pop("degree", (4, 4)))
    transpose, align = bool(opts.pop("transpose", False)), bool(opts.pop("align", False))
    if geo.surface is not None:  # a NURBS surface is the initial B-spline as it is
        from gridshell.io.read import swap_uv

        srf = swap_uv(geo.surface) if transpose else geo.surface
        if progress is not None:
            progress(f"PHLW step: initial B-spline = the NURBS surface ({srf.shape[0]} x "
                     f"{srf.shape[1]} control points, degree {srf.degree_u} x {srf.degree_v})")
        return InitialFit(surface=srf, rms=0.0, method="NURBS")
    init = initial_surface(geo.V, geo.F, n_ctrl=ctrl, degree=degree, transpose=transpose,
                           align=align)
    if progress is not None:
        turned = (f", parameter plane turned {init.rotated_deg:.1f} deg onto the principal "
                  "directions" if init.rotated_deg else "")
        progress(f"PHLW step: initial B-spline ({init.method} fit, rms {init.rms:.3g} m{turned})")
    return init


def _phlw_step(surf: BSplineSurface, reference: tuple[np.ndarray, np.ndarray], mode: str,
               opts: dict, progress: Callable[[str], None] | None) -> Any:
    """:func:`gridshell.ncp.phlw.optimize_phlw` from ``surf`` towards ``reference (V, F)``
    with the keywords ``opts``; its no-net answer on its own surface is its failure
    (:class:`ConvergenceError`), the reference's own no-net answer stays one."""
    from gridshell.ncp.phlw import optimize_phlw

    try:
        return optimize_phlw(surf, reference, mode=mode, progress=progress, **opts)
    except NoNetError as exc:
        if str(exc).startswith("the reference"):
            raise
        raise ConvergenceError(
            f"the PHLW step failed: {exc}. The reference itself has distinct principal "
            f"curvatures{' and K < 0 somewhere' if mode == 'aa' else ''}, so a net may exist "
            "near it; raise --phlw-outer / --phlw-max-iter, or run 'gridshell phlw' on it and "
            "inspect the curvature diagram") from exc


def _phlw_info(res: Any, init: Any, geo: Any) -> dict[str, Any]:
    """The ``info`` of a surface the PHLW step made: source, deviation (% of the diagonal),
    convergence, diagnostics, E_PHLW before and after, figures, the turn of the parameter
    plane (degrees), the input's unit and description."""
    e0 = res.report_before.get("E_PHLW", {}).get("total") if res.report_before else None
    e1 = res.report_after.get("E_PHLW", {}).get("total") if res.report_after else None
    return {"source": geo.path or "(V, F)", "phlw_deviation": res.deviation,
            "phlw_converged": res.converged, "phlw_diagnostics": res.diagnostics,
            "phlw_energy": [e0, e1],
            "phlw_figures": {k: f["value"] for k, f in (res.figures or {}).items()},
            "phlw_aligned_deg": float(init.rotated_deg),
            "units": geo.units, "input": geo.info(),
            "reference": (geo.V, geo.F)}   # taken out by the pipeline (fidelity), not stored


def _ring_surface(src: Any, mode: str, opts: dict, progress: Callable[[str], None] | None
                  ) -> tuple[BSplineSurface, float | None, dict]:
    """The PHLW step on a ring patch towards the target's faces inside it; the info's
    reference is the whole target (the net's fidelity and coverage are measured on it)."""
    from gridshell.ncp.reference import InitialFit

    for key in ("ctrl", "degree", "transpose", "align"):    # the ring fixes its own B-spline
        opts.pop(key, None)
    patch = src.patch
    if progress is not None:
        progress(f"PHLW step on the ring around the umbilic: radius {patch.inner:.3g} to "
                 f"{patch.outer:.3g} m, {patch.share:.0f} % of the target (fit rms "
                 f"{patch.fit_rms:.2g} m)")
    res = src.result if src.result is not None else \
        _phlw_step(patch.surface, (patch.V, patch.F), mode, opts, progress)
    info = _phlw_info(res, InitialFit(surface=patch.surface, rms=patch.fit_rms,
                                      method="ring"), src.geo)
    info["region"] = patch.record()
    return res.surface, float(res.n_rows[0]) if mode == "cnc" else None, info


def _phlw_units(path: Path) -> Any:
    """The input unit recorded in the ``report.json`` beside a ``surface.json`` written by
    ``gridshell phlw`` (metres when there is none)."""
    from gridshell.core.units import METRES, Units

    report = path.parent / "report.json"
    try:
        return Units.from_json(json.loads(report.read_text()).get("units"))
    except (OSError, ValueError, AttributeError):
        return METRES
