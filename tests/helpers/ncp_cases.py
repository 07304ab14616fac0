"""Analytic surfaces of the NCP tests; their formulas are the reference data.

- pseudosphere x = (sech s cos p, sech s sin p, s - tanh s), s in [0.5, 1.5], p in [0, 1.5]:
  K = -1, rows s = const are parallels (principal lines): a PK surface (AA mode, n = 0);
- torus zone (R = 3, r = 1), theta in [-0.6, 0.6] (meridian angle), phi in [0, 1]: rows are
  parallels; kappa_I = 1 along the meridians, kappa_II = cos th / (3 + cos th) along the
  parallels; any constant n in [0.25, 1] gives a CNC net (K - 2nH + n^2 is constant on the
  parallels of any surface of revolution);
- the PHLW saddle of the PHLW issue: tests/helpers/data/phlw_saddle_surface.json (see its note).
Fitted with bspline.fit_grid, 12 x 12 control points, bi-degree 4 (residual < 1e-6 m).
"""
import functools
from pathlib import Path

import numpy as np

from gridshell.geometry.bspline import BSplineSurface, fit_grid

DATA = Path(__file__).parent / "data"
PHLW_SADDLE = DATA / "phlw_saddle_surface.json"


def pseudosphere_grid(a=40, b=40):
    s, p = np.meshgrid(np.linspace(0.5, 1.5, a), np.linspace(0, 1.5, b), indexing="ij")
    return np.stack([np.cos(p) / np.cosh(s), np.sin(p) / np.cosh(s), s - np.tanh(s)], -1)


def torus_grid(a=40, b=40, R=3.0, r=1.0):
    th, ph = np.meshgrid(np.linspace(-0.6, 0.6, a), np.linspace(0, 1.0, b), indexing="ij")
    rho = R + r * np.cos(th)
    return np.stack([rho * np.cos(ph), rho * np.sin(ph), r * np.sin(th)], -1)


@functools.lru_cache(maxsize=None)
def pseudosphere() -> BSplineSurface:
    return fit_grid(pseudosphere_grid(), 12, 12, 4, 4)[0]


@functools.lru_cache(maxsize=None)
def torus() -> BSplineSurface:
    return fit_grid(torus_grid(), 12, 12, 4, 4)[0]


@functools.lru_cache(maxsize=None)
def phlw_saddle() -> BSplineSurface:
    return BSplineSurface.load(PHLW_SADDLE)
