"""Turn the parameter domain of an initial B-spline onto the reference's principal directions.

A PHLW surface's parameter lines are its principal curvature lines (paper 4.2.1), and the
optimizer cannot rotate a parametrization by tens of degrees. The best a rotation of the
parameter plane can do is found here: the principal directions of a first fit, expressed as
angles in a roughly isometric parameter plane ``(x, y) = (u * mean|S_u|, v * mean|S_v|)``,
averaged with the quadrupled-angle trick (the pair of principal directions is defined modulo
90 degrees) and weighted by ``|k2 - k1|`` times the area element, so umbilic regions do not
count. The parameters of the reference's points are then rotated by that angle and the points
refitted over a rectangle chosen to balance the reference left uncovered against the patch
overhanging it.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gridshell.geometry.bspline import BSplineSurface, fit_points
from gridshell.geometry.diffgeo import surface_curvature

#: Below this mean misalignment (degrees) the parametrization is kept as it is.
ALIGN_MIN_DEG = 5.0
#: A turn is kept only if the refit's coverage and deviation (% of the reference's diagonal)
#: stay within this fraction of the PHLW step's tolerances (the optimizer loses coverage:
#: corpus associate-07, a 44 degree turn, 16 % before the PHLW step, 28 % after).
ALIGN_BUDGET = 1.0


@dataclass
class PrincipalAngle:
    """Outcome of :func:`principal_angle`.

    angle_deg : weighted mean angle of the k1 direction from the ``x`` (``u``) axis, degrees,
        in (-45, 45] (the pair of principal directions is defined modulo 90 degrees)
    misalignment_deg : weighted mean angle between the principal directions and the nearest
        parameter axis, degrees, in [0, 45]
    residual_deg : the same after turning the plane by ``angle_deg`` (how uniform the field is)
    scale : (mean |S_u|, mean |S_v|), metres per unit parameter, of the parameter plane
    """

    angle_deg: float
    misalignment_deg: float
    residual_deg: float
    scale: tuple[float, float]


def _wrap45(a: np.ndarray) -> np.ndarray:
    """Angles (radians) wrapped modulo pi/2 into [-pi/4, pi/4)."""
    return (a + math.pi / 4) % (math.pi / 2) - math.pi / 4


def principal_angle(surf: BSplineSurface, samples: tuple[int, int] = (24, 24),
                    margin: float = 0.05) -> PrincipalAngle:
    """Mean principal angle of ``surf`` in its parameter plane (4 theta averaging).

    Parameters
    ----------
    surf : BSplineSurface
    samples : uniform samples in u and v over the domain (less ``margin`` at each end)
    margin : fraction of the domain left out at each end (the fit is least reliable there)

    Returns
    -------
    PrincipalAngle
    """
    (u0, u1), (v0, v1) = surf.domain
    a, b = (int(s) for s in samples)
    uu = np.linspace(u0 + margin * (u1 - u0), u1 - margin * (u1 - u0), a)
    vv = np.linspace(v0 + margin * (v1 - v0), v1 - margin * (v1 - v0), b)
    U, W = (X.ravel() for X in np.meshgrid(uu, vv, indexing="ij"))
    g = surface_curvature(surf, U, W)
    lu = float(np.mean(np.sqrt(g["E"])))
    lv = float(np.mean(np.sqrt(g["G"])))
    # d1 = a S_u + b S_v: solve the 2x2 first-form system for (a, b)
    r1 = np.einsum("ij,ij->i", g["d1"], g["Su"])
    r2 = np.einsum("ij,ij->i", g["d1"], g["Sv"])
    det = g["E"] * g["G"] - g["F"] ** 2
    with np.errstate(divide="ignore", invalid="ignore"):
        ca = (g["G"] * r1 - g["F"] * r2) / det
        cb = (g["E"] * r2 - g["F"] * r1) / det
        theta = np.arctan2(cb * lv, ca * lu)
        gap = np.abs(g["k2"] - g["k1"])
        w = gap * np.sqrt(np.maximum(det, 0.0))
    ok = np.isfinite(theta) & np.isfinite(w)
    w = np.where(ok, w, 0.0)
    theta = np.where(ok, theta, 0.0)
    if not w.sum() > 0:
        return PrincipalAngle(0.0, 0.0, 0.0, (lu, lv))
    z = np.sum(w * np.exp(4j * theta)) / w.sum()
    phi = float(np.angle(z) / 4.0)
    if phi <= -math.pi / 4:          # the (-45, 45] representative
        phi += math.pi / 2
    mis = float(np.sum(w * np.abs(_wrap45(theta))) / w.sum())
    res = float(np.sum(w * np.abs(_wrap45(theta - phi))) / w.sum())
    return PrincipalAngle(math.degrees(phi), math.degrees(mis), math.degrees(res), (lu, lv))


def _balanced_rectangle(XY: np.ndarray, n_side: int = 24) -> tuple[np.ndarray, np.ndarray]:
    """Axis-aligned rectangle ``(lo (2,), hi (2,))`` over the planar points ``XY (k, 2)``
    minimizing the larger of (a) the farthest point outside it and (b) the farthest point of
    its boundary from every point (the overhang), searched between half and the whole
    bounding box, centred on it."""
    from scipy.spatial import cKDTree

    tree = cKDTree(XY)
    lo, hi = XY.min(axis=0), XY.max(axis=0)
    c, h = (lo + hi) / 2, (hi - lo) / 2
    t = np.linspace(0.0, 1.0, n_side)
    best = (math.inf, lo, hi)
    for sx in np.linspace(0.5, 1.0, 11):
        for sy in np.linspace(0.5, 1.0, 11):
            r_lo, r_hi = c - h * (sx, sy), c + h * (sx, sy)
            gap = float(np.max(np.linalg.norm(XY - np.clip(XY, r_lo, r_hi), axis=1)))
            bx = r_lo[0] + t * (r_hi[0] - r_lo[0])
            by = r_lo[1] + t * (r_hi[1] - r_lo[1])
            B = np.concatenate([np.column_stack([bx, np.full_like(bx, r_lo[1])]),
                                np.column_stack([bx, np.full_like(bx, r_hi[1])]),
                                np.column_stack([np.full_like(by, r_lo[0]), by]),
                                np.column_stack([np.full_like(by, r_hi[0]), by])])
            over = float(np.max(tree.query(B)[0]))
            cost = max(gap, over)
            if cost < best[0]:
                best = (cost, r_lo, r_hi)
    return best[1], best[2]


def rotated_fit(P: np.ndarray, u: np.ndarray, v: np.ndarray, pa: PrincipalAngle,
                n_ctrl: tuple[int, int], degree: tuple[int, int],
                smoothing: float, angle_deg: float | None = None) -> tuple[BSplineSurface, float]:
    """Refit the points ``P (k, 3)`` with parameters ``u, v (k,)`` of a first fit, the
    parameter plane turned by ``-pa.angle_deg`` so that ``u`` follows the k1 direction.

    The new domain is the rectangle of :func:`_balanced_rectangle`, mapped onto [0, 1]^2;
    points outside it are left out of the fit. Returns the surface and the RMS residual of
    the points fitted (metres). ``angle_deg`` turns by another angle than ``pa.angle_deg``.
    """
    lu, lv = pa.scale
    phi = math.radians(pa.angle_deg if angle_deg is None else angle_deg)
    X = np.column_stack([u * lu, v * lv])
    c, s = math.cos(phi), math.sin(phi)
    XY = X @ np.array([[c, -s], [s, c]])            # rows: (x, y) . (cos, sin), (-sin, cos)
    lo, hi = _balanced_rectangle(XY)
    inside = np.all((XY >= lo) & (XY <= hi), axis=1)
    UV = (XY[inside] - lo) / (hi - lo)
    return fit_points(P[inside], UV[:, 0], UV[:, 1], *n_ctrl, *degree, smoothing=smoothing)
