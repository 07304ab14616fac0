"""The target's curvature map: its least-squares B-spline (paper 4.2.1, the NCP pipeline's
initial fit) sampled on a uniform grid, with the Gaussian and principal curvatures
(eqs. 4.2-4.6), the near-umbilic samples and the samples that lie on the target.

Classes are scale-free, as in the corpus (:mod:`gridshell.corpus.registry`): ``K D^2`` below
:data:`K_ZERO` in magnitude is flat, ``|k1 - k2| D`` below :data:`UMBILIC_GAP` is near
umbilic (``D`` the target's bounding-box diagonal).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gridshell.geometry.bspline import BSplineSurface
from gridshell.geometry.diffgeo import surface_curvature

__all__ = ["K_ZERO", "ON_TARGET", "UMBILIC_GAP", "CurvatureMap", "curvature_map"]

#: |K| D^2 below which K counts as zero
K_ZERO = 1e-3
#: |k1 - k2| D below which a point counts as near umbilic (principal directions undefined)
UMBILIC_GAP = 0.1
#: a sample lies on the target when it is within this share of the diagonal of the mesh
ON_TARGET = 0.01


@dataclass(frozen=True)
class CurvatureMap:
    """The fitted surface sampled on ``n x n`` parameters (arrays ``(n, n)``; metres, 1/m).

    u, v : (n,) parameters; S : (n, n, 3) points; K (1/m^2), k1 <= k2 (1/m); d1 : (n, n, 3)
    unit direction of k1; area : (n, n) area of each sample's cell (m^2); on_target : (n, n)
    the sample lies on the target mesh; diagonal : the target's bounding-box diagonal (m);
    fit_rms : the fit's residual (m)
    """

    u: np.ndarray
    v: np.ndarray
    S: np.ndarray
    K: np.ndarray
    k1: np.ndarray
    k2: np.ndarray
    d1: np.ndarray
    area: np.ndarray
    on_target: np.ndarray
    diagonal: float
    fit_rms: float

    @property
    def sign(self) -> np.ndarray:
        """+1 where K > 0, -1 where K < 0, 0 where flat (``|K| D^2 < K_ZERO``)."""
        Kn = self.K * self.diagonal ** 2
        return np.where(Kn > K_ZERO, 1, np.where(Kn < -K_ZERO, -1, 0))

    @property
    def umbilic(self) -> np.ndarray:
        """Near-umbilic samples: ``|k1 - k2| D < UMBILIC_GAP``."""
        return np.abs(self.k2 - self.k1) * self.diagonal < UMBILIC_GAP

    def share(self, mask: np.ndarray) -> float:
        """Area of the on-target samples of ``mask`` over the target's sampled area (0..1)."""
        w = np.where(self.on_target, self.area, 0.0)
        total = float(w.sum())
        return float(np.where(mask, w, 0.0).sum() / total) if total > 0 else 0.0


def curvature_map(surface: BSplineSurface, V: np.ndarray, F: np.ndarray, *, fit_rms: float = 0.0,
                  samples: int = 64) -> CurvatureMap:
    """Sample ``surface`` (fitted to the mesh ``V, F``, metres) on ``samples x samples``
    parameters and mark which samples lie on the mesh (within :data:`ON_TARGET` of the
    diagonal: a scattered fit's square domain overhangs a round target)."""
    from gridshell.geometry.igl_adapter import closest_points

    (u0, u1), (v0, v1) = surface.domain
    n = int(samples)
    u, v = np.linspace(u0, u1, n), np.linspace(v0, v1, n)
    U, W = (X.ravel() for X in np.meshgrid(u, v, indexing="ij"))
    g = surface_curvature(surface, U, W)
    V = np.asarray(V, float)
    D = float(np.linalg.norm(V.max(0) - V.min(0)))
    d2, _, _ = closest_points(g["S"], V, F)
    cell = (u1 - u0) / (n - 1) * (v1 - v0) / (n - 1)
    area = np.sqrt(np.maximum(g["E"] * g["G"] - g["F"] ** 2, 0.0)) * cell
    shape = (n, n)
    return CurvatureMap(u=u, v=v, S=g["S"].reshape(n, n, 3), K=g["K"].reshape(shape),
                        k1=g["k1"].reshape(shape), k2=g["k2"].reshape(shape),
                        d1=g["d1"].reshape(n, n, 3), area=area.reshape(shape),
                        on_target=(np.sqrt(d2) <= ON_TARGET * D).reshape(shape),
                        diagonal=D, fit_rms=float(fit_rms))
