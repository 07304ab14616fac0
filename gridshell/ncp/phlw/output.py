"""Output of the PHLW step (``gridshell phlw``): the JSON report and the design directory.

Split from :mod:`.phlw` (the optimization); both names are re-exported there.
"""
from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from gridshell.ncp.phlw.checks import _grid_geometry

if TYPE_CHECKING:
    from gridshell.ncp.phlw.result import PHLWResult


def result_summary(res: PHLWResult) -> dict[str, Any]:
    """JSON-ready report of a :class:`PHLWResult` (what ``report.json`` holds)."""
    def clean(o: Any) -> Any:
        if isinstance(o, dict):
            return {str(k): clean(v) for k, v in o.items()}
        if isinstance(o, (list, tuple)):
            return [clean(v) for v in o]
        if isinstance(o, np.ndarray):
            return clean(o.tolist())
        if isinstance(o, np.generic):
            return o.item()
        if isinstance(o, float) and not math.isfinite(o):
            return None
        return o

    return clean({
        "mode": res.mode, "converged": res.converged, "deviation_percent": res.deviation,
        "figures": res.figures, "energy_initial": res.energy_initial,
        "energy_final": res.energy_final,
        "reference_diagonal_m": res.reference_diagonal, "weights": res.weights,
        "samples": [len(res.u_rows), len(res.v_samples)],
        "control_points": list(res.surface.shape),
        "degree": [res.surface.degree_u, res.surface.degree_v],
        "before": res.report_before, "after": res.report_after,
        "rows": [{"u": float(u), "n": float(n), "t": float(t), "a": float(a), "b": float(b),
                  "c": float(c)} for u, n, t, (a, b, c) in zip(res.u_rows, res.n_rows, res.t_rows,
                                                             res.abc)],
        "history": res.history, "diagnostics": res.diagnostics,
        "net_regions": res.net_check.regions if res.net_check is not None else [],
    })


def write_phlw(directory: str | Any, res: PHLWResult, sample_grid: tuple[int, int] = (60, 60),
               overwrite: bool = True, units: Any = None,
               source: dict | None = None) -> dict[str, str]:
    """Write a PHLW design into ``directory`` atomically (all files or none).

    ``units`` (:class:`gridshell.io.Units`, None: metres) is the unit the reference was drawn
    in, recorded in report.json as ``"units": {"name", "metres_per_unit"}`` (the geometry is
    metres); ``source`` (``InputGeometry.info()``) as ``"input"``.

    Files: ``surface.json`` (:meth:`BSplineSurface.save`), ``surface.obj`` (quad mesh sampled
    ``sample_grid`` over the domain: rows = u, columns = v, so principal lines are mesh
    polylines), ``rows.csv`` (``u, n_u, t_u, a, b, c`` per optimization row, 1/m),
    ``report.json`` (:func:`result_summary`), ``curvature_diagram.png`` (paper Fig. 11 at the
    optimization samples).

    Returns
    -------
    dict : file role -> final path
    """
    import json
    from pathlib import Path

    from gridshell.core.atomic import atomic_dir, write_text
    from gridshell.design.bundle import finite_json
    from gridshell.geometry.meshfile import write_mesh
    from gridshell.render.curvature_diagram import curvature_diagram

    directory = Path(directory)
    rows, cols = (int(s) for s in sample_grid)
    # owned by `phlw` whether written by the CLI or the API (an `-o` later may replace it)
    with atomic_dir(directory, overwrite=overwrite, owner="phlw",
                    kind=f"PHLW {res.mode}") as tmp:
        res.surface.save(tmp / "surface.json")
        mesh = res.surface.sample(rows, cols)
        write_mesh(tmp / "surface.obj", mesh.V, mesh.F)
        lines = ["u,n_u,t_u,a,b,c"] + [
            f"{u:.12g},{n:.12g},{t:.12g},{a:.12g},{b:.12g},{c:.12g}"
            for u, n, t, (a, b, c) in zip(res.u_rows, res.n_rows, res.t_rows, res.abc)]
        write_text(tmp / "rows.csv", "\n".join(lines) + "\n")
        from gridshell.core.units import METRES

        summary = {**result_summary(res), "units": (units or METRES).to_json()}
        if source is not None:
            summary["input"] = source
        write_text(tmp / "report.json", json.dumps(finite_json(summary), indent=1,
                                                     allow_nan=False) + "\n")
        g = _grid_geometry(res.surface, res.u_rows, res.v_samples)
        curvature_diagram(tmp / "curvature_diagram.png", g["H"], g["K"], res.n_rows, res.t_rows,
                          u_rows=res.u_rows, title=f"curvature diagram ({res.mode})")
    names = ("surface.json", "surface.obj", "rows.csv", "report.json", "curvature_diagram.png")
    return {n.split(".")[0] if n != "surface.obj" else "mesh": str(directory / n) for n in names}
