"""The collapse curve of an NCP net (paper 4.2.3, eq. 4.14, Fig. 15).

Every u-row ``u = u_i`` of the PHLW surface collapses onto one point ``C~_i`` of a planar curve.
On a dense ``a x b`` sampling (paper: 1200 x 1200):

- chord lengths ``l_i = |C~_i - C~_i+1| = (1/b) sum_j |S(u_i, v_j) - S(u_i+1, v_j)| / cos beta``
  (eq. 4.14; ``1 / cos beta`` is averaged over rows ``i`` and ``i+1``, which makes the sum
  second-order accurate in the row spacing),
- the curvature of the collapse curve at ``C~_i`` is the net's normal curvature ``n_i``
  (linear fit of eq. 4.8 on row ``i``),
- forward integration (Fig. 15): the circle through ``C~_i-1, C~_i, C~_i+1`` has curvature
  ``n_i``, so the polyline turns at ``C~_i`` by ``asin(n_i l_i-1 / 2) + asin(n_i l_i / 2)``
  (each chord makes the angle ``asin(n l / 2)`` with the circle's tangent at its ends).

The curve starts at the origin with tangent ``(1, 0)`` (increasing ``u``); the flattened surface
normal ``n~_i`` is the tangent turned by +90 degrees, and the curve bends towards ``n~`` where
``n > 0`` (the surface bends towards its normal ``S_u x S_v``, :mod:`gridshell.geometry.diffgeo`).
Everything is vectorized: the sampling is evaluated in blocks of rows with
:meth:`BSplineSurface.evaluate_grid`, and the integration is a cumulative sum of angles.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Literal

import numpy as np

from gridshell.geometry.bspline import BSplineSurface
from gridshell.core.errors import InputError, NoNetError
from gridshell.geometry.bspline import uniform_params
from gridshell.ncp.directions import (MAX_DROPPED, grid_curvature, net_angle, row_normal_curvature,
                         surface_size)
from gridshell.geometry.fit import fit_circle, fit_plane, line_deviation  # noqa: F401

__all__ = ["CollapseResult", "collapse_chords", "integrate_collapse", "collapse_curve",
           "fit_circle", "fit_plane", "line_deviation", "closest_on_polyline"]


@dataclass
class CollapseResult:
    """The collapse curve.

    u : (a,) parameters of the rows
    points : (a, 2) ``C~_i``, metres; normals : (a, 2) flattened unit normals ``n~_i``
    chords : (a-1,) ``l_i`` (eq. 4.14), metres; s : (a,) arc length (cumulative chords)
    n_rows : (a,) net normal curvature per row, 1/m
    shape : "circle" (cnc), "line" (aa) or "curve" (phlw); radius : ``1 / |n|`` for a circle
    fit : ``{"radius", "radius_error"}`` of a least-squares circle (cnc) or
        ``{"line_error"}`` (aa, max distance to the fitted line / span)
    """

    u: np.ndarray
    points: np.ndarray
    normals: np.ndarray
    chords: np.ndarray
    s: np.ndarray
    n_rows: np.ndarray
    shape: str
    radius: float | None
    fit: dict

    def at_u(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Points ``(k, 2)`` and unit normals ``(k, 2)`` at parameters ``u (k,)``, linear
        (barycentric) between the rows."""
        u = np.asarray(u, float).reshape(-1)
        P = np.stack([np.interp(u, self.u, self.points[:, c]) for c in range(2)], axis=1)
        N = np.stack([np.interp(u, self.u, self.normals[:, c]) for c in range(2)], axis=1)
        return P, N / np.linalg.norm(N, axis=1)[:, None]

    def s_at_u(self, u: np.ndarray) -> np.ndarray:
        """Arc length along the curve at parameters ``u``."""
        return np.interp(np.asarray(u, float), self.u, self.s)


def collapse_chords(S: np.ndarray, inv_cos: np.ndarray) -> np.ndarray:
    """Eq. 4.14 on a block of rows: ``S (a, b, 3)`` points, ``inv_cos (a, b)`` = 1/cos beta;
    returns ``(a-1,)`` chords. Samples with ``inv_cos`` NaN (no net direction) are left out
    of the mean; a chord without any sample is NaN."""
    d = np.linalg.norm(np.diff(S, axis=0), axis=2)
    w = 0.5 * (inv_cos[:-1] + inv_cos[1:])
    with np.errstate(invalid="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)     # a row without any direction
        return np.nanmean(d * w, axis=1)


def integrate_collapse(chords: np.ndarray, n_rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Forward integration of the collapse polyline (Fig. 15).

    Parameters
    ----------
    chords : (a-1,) positive chord lengths, metres
    n_rows : (a,) curvature at every point, 1/m

    Returns
    -------
    points, normals : (a, 2) polyline from the origin (first tangent (1, 0)) and unit normals
    """
    ell = np.asarray(chords, float)
    n = np.asarray(n_rows, float)
    if len(n) != len(ell) + 1:
        raise InputError(f"{len(ell)} chords need {len(ell) + 1} curvatures, got {len(n)}")
    if np.any(~(ell > 0)):
        raise InputError("collapse chords must be positive; the surface has degenerate rows")
    # half-angle of each chord at its two ends, with the curvature of either end
    xa, xb = n[:-1] * ell / 2, n[1:] * ell / 2
    if np.any(np.abs(xa) > 1) or np.any(np.abs(xb) > 1):
        raise NoNetError("a collapse chord is longer than the diameter of its curvature circle; "
                         "sample more rows")
    ha, hb = np.arcsin(xa), np.arcsin(xb)
    # chord i leaves C_i at angle phi_i; turning at C_i (interior) = hb[i-1] + ha[i]
    phi = np.concatenate([[ha[0]], ha[0] + np.cumsum(hb[:-1] + ha[1:])])
    steps = ell[:, None] * np.stack([np.cos(phi), np.sin(phi)], axis=1)
    P = np.vstack([[0.0, 0.0], np.cumsum(steps, axis=0)])
    tang = np.concatenate([[0.0], phi[:-1] + hb[:-1], [phi[-1] + hb[-1]]])
    tang[1:-1] = 0.5 * (phi[:-1] + hb[:-1] + phi[1:] - ha[1:])
    N = np.stack([-np.sin(tang), np.cos(tang)], axis=1)
    return P, N


def closest_on_polyline(P: np.ndarray, Q: np.ndarray, N: np.ndarray | None = None
                        ) -> tuple[np.ndarray, np.ndarray | None, np.ndarray]:
    """Closest points of the polyline ``Q (m, d)`` to ``P (k, d)``.

    Returns the points ``(k, d)``, the normals ``N`` interpolated there and renormalized (if
    given) and the continuous vertex parameter ``t (k,)`` (``t = i + f`` on segment ``i``).
    """
    from scipy.spatial import cKDTree

    P, Q = np.asarray(P, float), np.asarray(Q, float)
    _, i = cKDTree(Q).query(P)
    best_t = i.astype(float)
    best_d = np.linalg.norm(P - Q[i], axis=1)
    for off in (-1, 0):
        s = np.clip(i + off, 0, len(Q) - 2)
        a, b = Q[s], Q[s + 1]
        ab = b - a
        f = np.clip(np.einsum("ij,ij->i", P - a, ab) / np.einsum("ij,ij->i", ab, ab), 0, 1)
        X = a + f[:, None] * ab
        d = np.linalg.norm(P - X, axis=1)
        better = d < best_d
        best_d = np.where(better, d, best_d)
        best_t = np.where(better, s + f, best_t)
    s = np.clip(np.floor(best_t).astype(int), 0, len(Q) - 2)
    f = best_t - s
    X = Q[s] + f[:, None] * (Q[s + 1] - Q[s])
    Nc = None
    if N is not None:
        N = np.asarray(N, float)
        Nc = N[s] + f[:, None] * (N[s + 1] - N[s])
        Nc /= np.linalg.norm(Nc, axis=1)[:, None]
    return X, Nc, best_t


def collapse_curve(surf: BSplineSurface, *, mode: Literal["phlw", "cnc", "aa"] = "phlw",
                   n: float | None = None, samples: tuple[int, int] = (1200, 1200),
                   block: int = 100) -> CollapseResult:
    """Reconstruct the collapse curve of the NCP net on ``surf`` (paper 4.2.3).

    Parameters
    ----------
    surf : the PHLW / CNC / PK surface
    mode : "phlw" (``n_i`` per row), "cnc" (one ``n``), "aa" (``n = 0``)
    n : the constant normal curvature for "cnc" (default: fitted)
    samples : (rows, cols) of the dense sampling (paper: 1200 x 1200)
    block : rows evaluated at once (memory ~ ``block * cols * 150`` bytes)

    Returns
    -------
    CollapseResult
    """
    u, v = uniform_params(surf, samples)
    a = len(u)
    if mode == "cnc" and n is None:
        g = grid_curvature(surf, u[:: max(1, a // 64)], v[:: max(1, len(v) // 64)], points=False)
        n = float(row_normal_curvature(g["K"], g["H"], "cnc")[0])
    n_rows = np.empty(a)
    chords = np.empty(a - 1)
    prev_S = prev_ic = None
    invalid = 0
    floor = 1.0 / max(surface_size(surf.ctrl), 1e-300)
    for start in range(0, a, block):
        sl = slice(start, min(start + block, a))
        g = grid_curvature(surf, u[sl], v, normal=False)
        nr = row_normal_curvature(g["K"], g["H"], mode, n, kI=g["kI"], kII=g["kII"])
        n_rows[sl] = nr
        beta, valid = net_angle(g["kI"], g["kII"], nr[:, None], scale=floor)
        invalid += int(np.sum(~valid))
        ic = np.where(valid, 1.0 / np.cos(beta), np.nan)
        S = g["S"]
        if prev_S is not None:
            S = np.concatenate([prev_S[None], S])
            ic = np.concatenate([prev_ic[None], ic])
        c = collapse_chords(S, ic)
        first = sl.start - (1 if prev_S is not None else 0)
        chords[first:first + len(c)] = c
        prev_S, prev_ic = g["S"][-1], np.where(valid, 1.0 / np.cos(beta), np.nan)[-1]
    if invalid > MAX_DROPPED * a * len(v):
        raise NoNetError(f"the net has no real direction at {invalid} of {a * len(v)} collapse "
                         f"samples ({100.0 * invalid / (a * len(v)):.3g} %, more than the "
                         f"{100 * MAX_DROPPED:g} % left out; n outside [kappa_I, kappa_II] or "
                         "umbilic, eq. 4.10); re-run the PHLW optimization or trim the surface")
    gaps = ~np.isfinite(chords)
    if gaps.any() and not gaps.all():
        # rows without a net direction (at most MAX_DROPPED of the samples): interpolated
        k = np.arange(len(chords))
        chords[gaps] = np.interp(k[gaps], k[~gaps], chords[~gaps])
    P, N = integrate_collapse(chords, n_rows)
    s = np.concatenate([[0.0], np.cumsum(chords)])
    shape = {"cnc": "circle", "aa": "line"}.get(mode, "curve")
    radius = None
    fit: dict = {}
    if mode == "cnc":
        radius = float(1.0 / abs(n_rows[0])) if n_rows[0] != 0 else None
        if radius is not None:
            _, r = fit_circle(P)
            fit = {"radius": r, "radius_error": abs(r - radius) / radius}
    elif mode == "aa":
        fit = {"line_error": line_deviation(P)}
    # samples without a net direction (at most MAX_DROPPED of them) count with beta clipped
    fit["invalid_samples"] = int(invalid)
    return CollapseResult(u=u, points=P, normals=N, chords=chords, s=s, n_rows=n_rows,
                          shape=shape, radius=radius, fit=fit)
