"""The outcome of the PHLW step (:func:`gridshell.ncp.phlw.optimize.optimize_phlw`)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gridshell.geometry.bspline import BSplineSurface
from gridshell.ncp.phlw.checks import NetCheck


@dataclass
class PHLWResult:
    """Outcome of :func:`optimize_phlw` (metres, 1/m, 1/m^2).

    surface : optimized BSplineSurface
    mode : "phlw" | "cnc" | "aa"
    u_rows : (rows,) u of every optimization row; ``v_samples (cols,)``
    n_rows, t_rows : (rows,) eq. 4.8 per u-row (n equal in cnc, zero in aa), 1/m
    abc : (rows, 3) ``a = 1, b = -2 n, c = n^2 + t^2`` of ``aK + bH + c = 0``
    history : per outer round ``{"round", "iterations", "energy0", "energy", "message",
        "terms", "time"}``
    report_before, report_after : per term ``{"weight", "energy", "rms", "max"}`` (scaled units),
        plus ``"E_PHLW"`` (:func:`phlw_energy`) and the acceptance figures
    converged : every acceptance figure holds (:func:`acceptance_figures`): the energy and
        E_PHLW fell, relation, principal angle and deviation within their tolerances and a
        real net direction at every sample
    figures : :func:`acceptance_figures`
    energy_initial, energy_final : energy of the whole problem (auxiliaries exact) at the start
        and at the end, on unit-diagonal geometry
    deviation : max distance of the surface (check sampling) to the reference, % of the
        reference's bounding-box diagonal
    diagnostics : human-readable lines (clamped rows, umbilic / no-net regions)
    net_check : :class:`NetCheck` at the optimization samples
    """

    surface: BSplineSurface
    mode: str
    u_rows: np.ndarray
    v_samples: np.ndarray
    n_rows: np.ndarray
    t_rows: np.ndarray
    abc: np.ndarray
    history: list[dict] = field(default_factory=list)
    report_before: dict = field(default_factory=dict)
    report_after: dict = field(default_factory=dict)
    converged: bool = False
    deviation: float = float("nan")
    diagnostics: list[str] = field(default_factory=list)
    net_check: NetCheck | None = None
    weights: dict = field(default_factory=dict)
    reference_diagonal: float = float("nan")
    figures: dict = field(default_factory=dict)
    energy_initial: float = float("nan")
    energy_final: float = float("nan")
