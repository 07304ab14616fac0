"""The GG surface design's data types: :class:`GGWeights` (the weights of its terms,
dimensionless) and :class:`GGDesign` (its outcome: the mesh, metres, with its residuals and
history); :func:`gridshell.gg.design.design_gg_surface` takes the one and returns the other."""
from __future__ import annotations

from dataclasses import asdict, dataclass, field, fields
from typing import Mapping

import numpy as np

from gridshell.core.errors import InputError

__all__ = ["GGDesign", "GGWeights"]


@dataclass
class GGWeights:
    """Weights of the GG surface design; dimensionless (length residuals are divided by the
    mean edge length of the initial grid, the geodesic residual is in radians).

    Attributes
    ----------
    geodesic : float
        Geodesic meridians (angle sums), 1.
    lengths : float
        Equal edge lengths along parallels and across meridian strips, 1.
    orthogonal : float
        Equal diagonals in every quad (meridians orthogonal to the parallels, see
        :mod:`gridshell.gg.constraints`), 1; in the rounds and the polish like the others.
    closeness : float
        Gliding on the target (distance to the tangent plane at the closest point), 0.1:
        below the constraints so that they dominate.
    boundary : float
        Boundary vertices glide on the initial boundary polylines, 0.1.
    fairness : float
        Second differences along meridians and parallels in the first round, 1e-4;
        multiplied by ``fairness_decay`` every round (smooths noise in the target).
    fairness_decay : float
        Factor of the fairness weight per round, 0.3.
    elastic : float
        Change of the second differences from their values at the start of each round, 3:
        resists folding (without it the constraints fold the mesh over itself on targets far
        from a GG surface - on a dome parallels pile up and meridians reverse while every
        constraint holds) and leaves a GG mesh a fixed point.
    elastic_decay : float
        Factor of the elastic weight per round, 0.6.
    proximity : float
        Closeness to the positions at the start of each round, 1e-2: resists the tangential
        drift nothing else resists (and the fairness' pull along the surface).
    soften : float
        Factor per round on ``closeness``, ``boundary`` and ``proximity``, 0.5: a penalty
        continuation, so the constraints dominate more every round and the final polish only
        has round-off-sized work left.
    polish_proximity : float
        Proximity weight of the final projection onto the constraints (to the start of each
        iteration, so a metric term too), 1e-4: holds the smooth modes that the elastic term
        leaves nearly free (with 1e-8 a noisy 12 x 10 catenoid drifted to 7.6 % of the
        diagonal from its target, with 1e-4 it stays at 1.5 %).
    polish_elastic : float
        Change of the second differences in each step of the final projection, 3e-3. Its
        reference is refreshed every iteration, so it never pulls back (a GG mesh stays a
        fixed point): it only makes the projection take the least-bending correction instead
        of the least-motion one. The least-motion correction is an odd-even zig-zag (the
        constraints are most sensitive to it); the edge lengths and angle sums then hold while
        the smooth surface through the vertices, on which the net is traced, is not isometric
        to the surface of revolution: with the former 1e-5 halved every iteration, 20 polish
        iterations took a 40 x 40 height field from Delta_a max 0.52 % to 5.2 % and a
        rotated 60 x 40 hill from 2.3 % to 5.9 % (7 % with 40 iterations); with 3e-3 kept
        (and ``polish_proximity`` 1e-4) they reach 0.09 % and 0.62 %. 0: the plain
        projection.
    polish_elastic_decay : float
        Factor of ``polish_elastic`` alone per projection iteration, 1 (kept: a metric whose
        elastic part decays against the proximity ends in the zig-zag projection above).
    polish_decay : float
        Factor of ``polish_proximity`` and ``polish_elastic`` together per projection
        iteration, 0.3 (on top of their shrinking with the constraint energy, see
        :mod:`gridshell.gg.design`); 1: fixed weights, a linearly converging polish.
    """

    geodesic: float = 1.0
    lengths: float = 1.0
    orthogonal: float = 1.0
    closeness: float = 0.1
    boundary: float = 0.1
    fairness: float = 1e-4
    fairness_decay: float = 0.3
    elastic: float = 3.0
    elastic_decay: float = 0.6
    proximity: float = 1e-2
    soften: float = 0.5
    polish_proximity: float = 1e-4
    polish_elastic: float = 3e-3
    polish_elastic_decay: float = 1.0
    polish_decay: float = 0.3

    @classmethod
    def coerce(cls, weights: "GGWeights | Mapping[str, float] | None") -> "GGWeights":
        """``GGWeights`` from ``None`` (defaults), an instance, or a mapping of some fields."""
        if weights is None:
            return cls()
        if isinstance(weights, cls):
            w = weights
        elif isinstance(weights, Mapping):
            names = {f.name for f in fields(cls)}
            bad = sorted(set(weights) - names)
            if bad:
                raise InputError(f"unknown GG design weight(s) {bad}; valid names are "
                                 f"{sorted(names)}")
            w = cls(**{k: float(v) for k, v in weights.items()})
        else:
            raise InputError(f"weights must be a GGWeights, a dict or None, got {type(weights)}")
        for k, v in asdict(w).items():
            if not np.isfinite(v) or v < 0:
                raise InputError(f"GG design weight {k!r} must be finite and >= 0, got {v}")
        return w


@dataclass
class GGDesign:
    """Outcome of :func:`design_gg_surface`.

    Attributes
    ----------
    P : (R, C, 3) float
        The designed mesh, metres; meridians ``P[:, j]``, parallels ``P[i, :]``.
    l : (R,) float
        Parallel edge length of each parallel, metres.
    h : (R-1,) float
        Meridian edge length between consecutive parallels, metres.
    history : list of dict
        Per round (and the polish): weights used, energies, solver iterations and message,
        geodesic and length residuals, deviation, time.
    report : dict
        ``{"before": ..., "after": ...}``: per term (base weights) weight, energy, RMS, max of
        the unweighted residual at ``P0`` and at ``P``.
    converged : bool
        Geodesic residual <= ``tol_geodesic`` and relative length spread <= ``tol_length``
        (the residuals are at round-off; a design is *accepted* on its figures, see
        :func:`gridshell.gg.pipeline.design_gg`).
    stop : str
        Why the polish ended: ``"tolerance"``, ``"stagnation"``, ``"figures"`` (the score is
        acceptable and stagnates), ``"no descent"``, ``"iteration limit"``, ``"no polish"``.
    score : float or None
        ``evaluate(P)`` of the returned mesh (None without ``evaluate``).
    checkpoint : str
        Which iterate is returned: ``"rounds"`` (the end of the rounds) or ``"polish k"``.
    deviation : dict
        ``max``, ``mean`` distance of the vertices of ``P`` to the target, % of the target's
        bounding-box diagonal; ``diagonal`` in metres.
    geodesic_residual_max : float
        Largest |angle-sum difference|, radians.
    length_residual_rel_max : float
        Largest relative spread of edge lengths within a parallel or a meridian strip, or
        relative difference of the two diagonals of a quad.
    """

    P: np.ndarray
    l: np.ndarray
    h: np.ndarray
    history: list[dict] = field(default_factory=list)
    report: dict = field(default_factory=dict)
    converged: bool = False
    deviation: dict = field(default_factory=dict)
    geodesic_residual_max: float = float("nan")
    length_residual_rel_max: float = float("nan")
    stop: str = ""
    score: float | None = None
    checkpoint: str = ""
