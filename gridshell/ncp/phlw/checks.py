"""Row fits, acceptance figures and net checks of PHLW / CNC / PK surfaces (paper 3.4, 4.2.1,
4.2.2, eq. 4.10): how far a B-spline is from the relation of eq. 4.8 and where its net exists.

Curvatures in the units of the surface passed (1/m on a surface in metres).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np
import scipy.sparse as sp

from gridshell.geometry.bspline import BSplineSurface, uniform_params
from gridshell.geometry.diffgeo import curvatures, fundamental_forms, principal_directions
from gridshell.core.errors import InputError, NoNetError
from gridshell.ncp.phlw.terms import Mode, _check_mode


#: The reference is (nearly) umbilic at a sample if ``|kappa_2 - kappa_1|`` is at most this
#: fraction of ``max(|kappa_1|, |kappa_2|, FLAT_CURVATURE)`` (unit-diagonal units). A
#: reference umbilic at every sample (a plane, a sphere patch: up to 2.7 % measured on a 5 x 5
#: control-point fit of a sphere) has no principal directions to start the PHLW net from.
NEAR_UMBILIC = 0.05
#: Curvatures below this, on unit-diagonal geometry (radius above 1000 diagonals), are flat.
FLAT_CURVATURE = 1e-3


class RowFit(NamedTuple):
    """Per-row coefficients of eq. 4.8 from linear fitting, and rows whose ``t^2 < 0``."""

    n: np.ndarray
    t: np.ndarray
    clamped: np.ndarray


#: a row whose H spreads less than this share of the curvature scale has no defined slope
FLAT_ROW = 1e-2


def fit_rows(K: np.ndarray, H: np.ndarray, mode: Mode = "phlw", rtol: float = 1e-4) -> RowFit:
    """Least-squares fit of ``K = 2 n H - (n^2 + t^2)`` per u-row (rows of ``K, H (rows, cols)``).

    ``phlw``: a line ``K = alpha H + beta`` per row, ``n = alpha / 2``, ``t^2 = -beta - n^2``;
    a row whose ``H`` hardly varies (its spread below :data:`FLAT_ROW` of the curvature
    scale, e.g. a parallel of a surface of revolution, where a B-spline's wiggles alone would
    set the slope) has no defined slope and gets ``n = mean H`` (the net angle pi/4, as
    E_beta prefers).
    ``cnc``: one slope for all rows, one intercept per row. ``aa``: ``n = 0``,
    ``t^2 = -mean K``. Rows where the fitted line has ``t^2 < 0`` (``b^2 - 4ac > 0``: a
    secant of the parabola ``K = H^2``, no net) are listed in ``clamped``; in ``phlw`` mode
    they restart from ``n = mean H`` (net angle pi/4) with ``t^2 = (mean H)^2 - mean K``,
    elsewhere ``t = 0``.

    Returns
    -------
    RowFit : ``n (rows,)`` (all equal in cnc, zero in aa), ``t (rows,) >= 0``, ``clamped``
        indices of rows whose ``t^2`` was negative.
    """
    _check_mode(mode)
    K = np.atleast_2d(np.asarray(K, float))
    H = np.atleast_2d(np.asarray(H, float))
    if K.shape != H.shape:
        raise InputError(f"K and H must have the same (rows, cols) shape, got {K.shape} and "
                         f"{H.shape}")
    if not (np.all(np.isfinite(K)) and np.all(np.isfinite(H))):
        raise InputError("curvatures are not finite at some samples (singular "
                         "parametrization); check the initial surface")
    R, m = K.shape
    scale = max(float(np.max(np.abs(H))), math.sqrt(float(np.max(np.abs(K)))), 1e-300)
    if mode == "aa":
        n = np.zeros(R)
        beta = K.mean(axis=1)
    elif mode == "phlw":
        # all rows at once: the least-squares line of centred data (what np.polyfit(h, k, 1)
        # returns per row, tests/ncp/test_phlw.py compares them)
        hm, km = H.mean(axis=1), K.mean(axis=1)
        Hc = H - hm[:, None]
        var = np.einsum("ij,ij->i", Hc, Hc)
        flat = np.sqrt(var / m) <= FLAT_ROW * scale      # np.std(h) <= FLAT_ROW * scale
        with np.errstate(divide="ignore", invalid="ignore"):
            alpha = np.einsum("ij,ij->i", Hc, K - km[:, None]) / var
        n = np.where(flat, hm, 0.5 * alpha)
        beta = np.where(flat, km - 2 * hm * hm, km - alpha * hm)
    else:  # cnc: K_ij = 2 n H_ij + beta_i
        A = sp.hstack([sp.csr_matrix(2 * H.reshape(-1, 1)),
                       sp.kron(sp.identity(R), np.ones((m, 1)))]).toarray()
        Hc = H - H.mean(axis=1, keepdims=True)
        if np.linalg.norm(Hc) <= rtol * scale * math.sqrt(H.size):
            n0 = float(H.mean())
            n = np.full(R, n0)
            beta = (K - 2 * n0 * H).mean(axis=1)
        else:
            sol = np.linalg.lstsq(A, K.ravel(), rcond=None)[0]
            n, beta = np.full(R, sol[0]), sol[1:]
    t2 = -beta - n * n
    clamped = np.flatnonzero(t2 < 0)
    if mode == "phlw":
        # t = 0 would start from a degenerate net (beta = 0); start at beta = pi/4 instead:
        # n = mean H and the best intercept for it, t^2 = (mean H)^2 - mean K
        for i in clamped:
            n[i] = H[i].mean()
            t2[i] = n[i] ** 2 - K[i].mean()
    elif mode == "cnc" and len(clamped):
        n[:] = H.mean()
        t2 = (2 * n[:, None] * H - K).mean(axis=1) - n * n
    return RowFit(n, np.sqrt(np.maximum(t2, 0.0)), clamped)


def _inside_principal(k1: np.ndarray, k2: np.ndarray, prefer: float) -> float:
    """The ``n`` nearest to ``prefer`` that lies in every ``[k1_s, k2_s]``, or, where these
    intervals have no common point, the ``n`` minimizing ``sum dist(n, [k1_s, k2_s])^2``."""
    lo, hi = float(np.max(k1)), float(np.min(k2))
    if lo <= hi:
        return float(np.clip(prefer, lo, hi))
    # convex, piecewise quadratic: its minimum lies between the largest k2 and smallest k1
    # below and above it; a few bisection-free Newton-like passes on the active set suffice
    from scipy.optimize import minimize_scalar

    cost = lambda n: float(np.sum(np.maximum(0.0, k1 - n) ** 2 + np.maximum(0.0, n - k2) ** 2))  # noqa: E731
    return float(minimize_scalar(cost, bounds=(hi, lo), method="bounded",
                                 options={"xatol": 1e-12 * max(abs(lo), abs(hi), 1e-300)}).x)


def start_rows(K: np.ndarray, H: np.ndarray, mode: Mode = "phlw") -> RowFit:
    """Row coefficients to start the optimization from: :func:`fit_rows`, with every ``n``
    moved inside the principal range ``[kappa_1, kappa_2]`` of its samples.

    A real net of normal curvature ``n`` exists at a sample exactly when
    ``kappa_1 <= n <= kappa_2`` (eq. 4.10); a least-squares line of a row (or, in ``cnc``, one
    slope for the whole surface) need not satisfy it (a hill whose curvatures are all
    negative can get ``n > 0``). ``n`` is clipped to the common range of the row's samples
    (``cnc``: of all samples), or, where these ranges have no common point, set to the value
    nearest to all of them (least squares); then ``t^2 = mean (kappa_r^2 - (n - H)^2)`` per row
    (eq. 4.8 with ``kappa_r = sqrt(H^2 - K)``), at least a ``1e-3`` of ``kappa_r^2``.
    Signs follow the normal ``U``: a surface bending away from ``U`` everywhere gets ``n < 0``.

    Returns
    -------
    RowFit : ``clamped`` lists the rows whose ``n`` was moved or whose ``t^2`` was negative.
    """
    fit = fit_rows(K, H, mode)
    if mode == "aa":
        return fit
    K = np.atleast_2d(np.asarray(K, float))
    H = np.atleast_2d(np.asarray(H, float))
    r2 = np.maximum(H * H - K, 0.0)
    k1, k2 = H - np.sqrt(r2), H + np.sqrt(r2)
    n = fit.n.copy()
    if mode == "cnc":
        n[:] = _inside_principal(k1.ravel(), k2.ravel(), float(fit.n[0]))
    else:
        for i in range(len(n)):
            n[i] = _inside_principal(k1[i], k2[i], float(fit.n[i]))
    t2 = np.mean(r2 - (n[:, None] - H) ** 2, axis=1)
    t2 = np.maximum(t2, 1e-3 * np.mean(r2, axis=1))
    moved = np.flatnonzero(~np.isclose(n, fit.n, rtol=1e-9, atol=0.0))
    clamped = np.union1d(fit.clamped, moved).astype(int)
    t = np.where(np.isin(np.arange(len(n)), clamped), np.sqrt(t2), fit.t)
    return RowFit(n, t, clamped)


# ============================================================================ evaluation helpers

def _grid_geometry(surf: BSplineSurface, u: np.ndarray, v: np.ndarray) -> dict[str, np.ndarray]:
    """Fundamental forms and curvatures on the grid ``u x v``, each ``(rows, cols)``."""
    D = surf.derivatives_grid(u, v)
    R, Cn = len(u), len(v)
    flat = {k: a.reshape(-1, 3) for k, a in D.items()}
    ff = fundamental_forms(flat["Su"], flat["Sv"], flat["Suu"], flat["Suv"], flat["Svv"])
    K, H, k1, k2 = curvatures(ff["E"], ff["F"], ff["G"], ff["L"], ff["M"], ff["N"])
    _, _, d1, _ = principal_directions(flat["Su"], flat["Sv"], ff["E"], ff["F"], ff["G"],
                                       ff["L"], ff["M"], ff["N"])
    with np.errstate(divide="ignore", invalid="ignore"):
        kI, kII = ff["L"] / ff["E"], ff["N"] / ff["G"]
        cos1 = np.abs(np.einsum("ij,ij->i", flat["Su"], d1)) / np.sqrt(ff["E"])
    ang = np.degrees(np.arccos(np.clip(cos1, 0.0, 1.0)))
    ang = np.minimum(ang, 90.0 - ang)           # S_u may follow either principal direction
    with np.errstate(divide="ignore", invalid="ignore"):
        ortho = np.degrees(np.abs(np.arcsin(np.clip(ff["F"] / np.sqrt(ff["E"] * ff["G"]),
                                                    -1, 1))))
    out = {"S": D["S"], "K": K, "H": H, "k1": k1, "k2": k2, "kI": kI, "kII": kII,
           "E": ff["E"], "F": ff["F"], "G": ff["G"], "M": ff["M"],
           "angle": np.maximum(ang, ortho)}
    return {k: (a.reshape(R, Cn) if k != "S" else a) for k, a in out.items()}


def row_relation_residual(surf: BSplineSurface, u_samples: np.ndarray, v_samples: np.ndarray,
                          n_rows: np.ndarray | None = None, t_rows: np.ndarray | None = None,
                          mode: Mode = "phlw") -> np.ndarray:
    """Relative residual of eq. 4.8 on the grid ``u_samples x v_samples``: ``(rows, cols)``.

    ``|K - 2 n H + n^2 + t^2| / max(|K|, |2 n H|, n^2 + t^2)``, i.e. the violation relative to
    the largest term of the relation (for ``n = 0`` this is ``|K - K_row| / |K|``). Without
    ``n_rows``/``t_rows`` they are fitted per row (:func:`fit_rows` with ``mode``), as paper
    4.2.2 does on a sampling other than the optimization's.
    """
    u = np.atleast_1d(np.asarray(u_samples, float))
    v = np.atleast_1d(np.asarray(v_samples, float))
    g = _grid_geometry(surf, u, v)
    K, H = g["K"], g["H"]
    if n_rows is None or t_rows is None:
        fit = fit_rows(K, H, mode)
        n_rows = fit.n if n_rows is None else n_rows
        t_rows = fit.t if t_rows is None else t_rows
    n = np.broadcast_to(np.asarray(n_rows, float).reshape(-1), (len(u),))[:, None]
    t = np.broadcast_to(np.asarray(t_rows, float).reshape(-1), (len(u),))[:, None]
    num = np.abs(K - 2 * n * H + n * n + t * t)
    den = np.maximum.reduce([np.abs(K), np.abs(2 * n * H), np.broadcast_to(n * n + t * t, K.shape)])
    with np.errstate(divide="ignore", invalid="ignore"):
        return num / np.maximum(den, 1e-300)


def principal_angle_error(surf: BSplineSurface, u_samples: np.ndarray,
                          v_samples: np.ndarray) -> np.ndarray:
    """Degrees by which the parameter lines miss the principal directions, ``(rows, cols)``:
    the larger of the angle between ``S_u`` and its nearest principal direction and the
    deviation of the angle between ``S_u`` and ``S_v`` from 90 degrees."""
    return _grid_geometry(surf, np.atleast_1d(u_samples), np.atleast_1d(v_samples))["angle"]


def phlw_energy(surf: BSplineSurface, n_rows: np.ndarray | None, t_rows: np.ndarray,
                samples: tuple[int, int] = (18, 18), *, omega_t: float = 0.1,
                scale: float | None = None) -> dict[str, float]:
    """E_PHLW (paper 4.2.1) of a surface with its auxiliary variables exact.

    With every auxiliary variable computed from the surface the residuals of eqs. 4.2-4.6
    vanish and ``E_PHLW = sum (F^2 + M^2) + omega_t sum chi_t^2`` over the samples. Evaluated
    on geometry scaled by ``1 / scale`` (default: the bounding-box diagonal of the samples)
    so that it is dimensionless.

    Returns
    -------
    dict : ``total``, ``principal`` (the ``F, M`` part), ``target`` (``omega_t * sum chi_t^2``),
        ``target_rms`` (RMS of ``chi_t`` in 1/m^2 of the scaled geometry).
    """
    u, v = uniform_params(surf, samples)
    g = _grid_geometry(surf, u, v)
    if scale is None:
        S = g["S"].reshape(-1, 3)
        scale = float(np.linalg.norm(S.max(0) - S.min(0))) or 1.0
    n = np.zeros(len(u)) if n_rows is None else \
        np.broadcast_to(np.asarray(n_rows, float).reshape(-1), (len(u),))
    t = np.asarray(t_rows, float).reshape(-1)
    # scale lengths by 1/scale: E, F, G by 1/scale^2 (param speeds), M by 1/scale, K by scale^2
    F = g["F"] / scale ** 2
    M = g["M"] / scale
    chi = (g["K"] - 2 * n[:, None] * g["H"] + (n * n + t * t)[:, None]) * scale ** 2
    Ep = float(np.sum(F * F) + np.sum(M * M))
    Et = float(omega_t * np.sum(chi * chi))
    return {"total": Ep + Et, "principal": Ep, "target": Et,
            "target_rms": float(np.sqrt(np.mean(chi * chi)))}


# ============================================================================ diagnostics

def _regions(mask: np.ndarray, u: np.ndarray, v: np.ndarray) -> list[dict[str, Any]]:
    """Connected regions of a boolean sample grid as parameter boxes."""
    from scipy import ndimage

    lab, nlab = ndimage.label(mask)
    out = []
    for sl in ndimage.find_objects(lab):
        su, sv = sl
        cnt = int(np.sum(lab[sl] > 0))
        out.append({"u": (float(u[su.start]), float(u[su.stop - 1])),
                    "v": (float(v[sv.start]), float(v[sv.stop - 1])), "samples": cnt})
    return out


@dataclass
class NetCheck:
    """Outcome of :func:`net_direction_check` on a ``rows x cols`` grid.

    sin2beta : (rows, cols) ``(n - kappa_I) / (kappa_II - kappa_I)`` (eq. 4.10), NaN at umbilics
    umbilic, out_of_range : (rows, cols) bool
    regions : list of ``{"kind": "umbilic" | "no-net", "u": (u0, u1), "v": (v0, v1), "samples"}``
    messages : one human-readable line per region
    """

    u: np.ndarray
    v: np.ndarray
    sin2beta: np.ndarray
    umbilic: np.ndarray
    out_of_range: np.ndarray
    regions: list[dict[str, Any]] = field(default_factory=list)
    messages: list[str] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return not self.regions


def net_direction_check(surf: BSplineSurface, n_rows: np.ndarray | None,
                        u_rows: np.ndarray | None = None, *,
                        samples: tuple[int, int] | None = None,
                        u_samples: np.ndarray | None = None, v_samples: np.ndarray | None = None,
                        umbilic_tol: float = 1e-3) -> NetCheck:
    """Where the net of normal curvature ``n_u`` has a real direction (eq. 4.10).

    ``sin^2 beta = (n_u - kappa_I) / (kappa_II - kappa_I)`` with ``kappa_I = L / E``,
    ``kappa_II = N / G`` (normal curvatures along ``S_u``, ``S_v``: the principal ones on a
    principal parametrization). Umbilics (``|kappa_II - kappa_I| <= umbilic_tol *`` the
    surface's curvature scale) leave ``beta`` undefined; ``sin^2 beta`` outside ``[0, 1]``
    (``n_u`` outside ``[kappa_I, kappa_II]``) means no real net direction.

    Parameters
    ----------
    surf : the (optimized) surface
    n_rows : (len(u_rows),) ``n_u`` per row, a single value (cnc) or None (aa: ``n = 0``)
    u_rows : (len(n_rows),) u values of ``n_rows``; default: the uniform sampling of
        ``len(n_rows)`` rows. ``n_u`` is interpolated linearly onto the check rows.
    samples : (rows, cols) check grid (default: ``len(n_rows) x len(n_rows)``), or explicit
        ``u_samples`` / ``v_samples``.
    """
    if u_samples is None or v_samples is None:
        if samples is None:
            m = 18 if n_rows is None or np.size(n_rows) == 1 else int(np.size(n_rows))
            samples = (m, m)
        u_samples, v_samples = uniform_params(surf, samples)
    u = np.asarray(u_samples, float)
    v = np.asarray(v_samples, float)
    if n_rows is None:
        n = np.zeros(len(u))
    elif np.size(n_rows) == 1:
        n = np.full(len(u), float(np.ravel(n_rows)[0]))
    else:
        nr = np.asarray(n_rows, float).ravel()
        ur = uniform_params(surf, (len(nr), 2))[0] if u_rows is None else np.asarray(u_rows, float)
        n = np.interp(u, ur, nr)
    g = _grid_geometry(surf, u, v)
    kI, kII = g["kI"], g["kII"]
    scale = float(np.nanmax(np.maximum(np.abs(kI), np.abs(kII))))
    gap = kII - kI
    umb = ~(np.abs(gap) > umbilic_tol * max(scale, 1e-300))
    with np.errstate(divide="ignore", invalid="ignore"):
        s2 = np.where(umb, np.nan, (n[:, None] - kI) / gap)
    bad = ~umb & ~((s2 >= 0) & (s2 <= 1))
    regions, msgs = [], []
    for kind, mask, what in (("umbilic", umb, "umbilic (kappa_I = kappa_II: net angle undefined)"),
                             ("no-net", bad, "n_u outside [kappa_I, kappa_II]: no real net "
                                             "direction (eq. 4.10)")):
        for reg in _regions(mask, u, v):
            reg = {"kind": kind, **reg}
            regions.append(reg)
            msgs.append(f"{what} at u in [{reg['u'][0]:.3f}, {reg['u'][1]:.3f}], v in "
                        f"[{reg['v'][0]:.3f}, {reg['v'][1]:.3f}] ({reg['samples']} samples)")
    return NetCheck(u, v, s2, umb, bad, regions, msgs)


# ============================================================================ optimization

def check_reference_net(K: np.ndarray, H: np.ndarray, mode: str, scale: float = 1.0) -> None:
    """Raise :class:`NoNetError` if a surface with curvatures ``K, H`` at its samples (unit
    bounding-box diagonal) admits no net of ``mode`` anywhere: umbilic at every sample (no
    principal directions), or, in mode ``aa``, ``K > 0`` at every sample (no asymptotic
    directions). ``scale`` (the diagonal in metres) converts the figures of the message to
    1/m and 1/m^2."""
    K, H = np.asarray(K, float), np.asarray(H, float)
    d = np.sqrt(np.maximum(H * H - K, 0.0))
    curv = np.maximum(np.abs(H) + d, FLAT_CURVATURE)
    if np.all(2 * d <= NEAR_UMBILIC * curv):
        i = int(np.argmax(2 * d / curv))
        raise NoNetError(
            f"the reference is umbilic at all {K.size} samples over the whole patch (u, v in "
            f"[0, 1]): kappa_2 - kappa_1 is at most {100 * 2 * d.flat[i] / curv.flat[i]:.3g} % "
            f"of |kappa| (limit {100 * NEAR_UMBILIC:g} %; e.g. {2 * d.flat[i] / scale:.4g} 1/m "
            f"against {curv.flat[i] / scale:.4g} 1/m), as on a plane or a sphere: it has no "
            "principal directions, so no PHLW / CNC / PK net can start from it; give a "
            "reference with distinct principal curvatures (e.g. a saddle or a torus patch), or "
            "design a geodesic gridshell (gridshell gg)")
    if mode == "aa" and np.all(K > 0):
        raise NoNetError(
            f"the reference has K > 0 at all {K.size} samples over the whole patch (u, v in "
            f"[0, 1]; K from {K.min() / scale ** 2:.4g} to {K.max() / scale ** 2:.4g} 1/m^2): "
            "it bends like a dome, and asymptotic directions exist only where K <= 0, so no "
            "AA net (n = 0) exists near it; use mode 'phlw' or 'cnc', or a reference with "
            "K < 0 (e.g. a saddle)")
