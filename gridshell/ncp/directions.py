"""Directions of the normal-curvature-preserving net on a PHLW surface (paper 4.2.2).

On a principal parametrization (``F = M = 0``, eq. 4.7) the unit principal directions are
``e5 = S_u / |S_u|`` (normal curvature ``kappa_I = L / E``) and ``e6 = S_v / |S_v|``
(``kappa_II = N / G``). The net of normal curvature ``n_u`` (one value per u-row, linear fit of
eq. 4.8) makes the angle ``+-beta`` with ``e5``:

- ``sin^2 beta = (n_u - kappa_I) / (kappa_II - kappa_I)`` (eq. 4.10),
- ``e1 = cos b e5 - sin b e6``, ``e3 = cos b e5 + sin b e6`` (eq. 4.11),
- ``e2 = sin b e5 + cos b e6`` (orthogonal to ``e1``) and ``e4 = -sin b e5 + cos b e6``
  (orthogonal to ``e3``); both frames ``(e1, e2)`` and ``(e3, e4)`` are right-handed like
  ``(e5, e6)``.

Signs follow :mod:`gridshell.diffgeo` (curvatures positive when the surface bends towards
``S_u x S_v``), units 1/m. Arrays are on a tensor grid ``u (a,) x v (b,)``: scalars ``(a, b)``,
vectors ``(a, b, 3)``; row ``i`` is the curve ``u = u[i]``.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from ..bspline import BSplineSurface, uniform_params
from ..diffgeo import curvatures, fundamental_forms
from ..errors import InputError, NoNetError

Mode = Literal["phlw", "cnc", "aa"]

__all__ = ["NetDirections", "grid_curvature", "row_normal_curvature", "net_angle",
           "net_directions"]

#: samples per direction for a global fit of the constant normal curvature (mode "cnc")
CNC_FIT_SAMPLES = 64



def grid_curvature(surf: BSplineSurface, u: np.ndarray, v: np.ndarray,
                   points: bool = True) -> dict[str, np.ndarray]:
    """Curvature data on the grid ``u (a,) x v (b,)`` (eqs. 4.2-4.6).

    Returns
    -------
    dict
        ``S`` (only if ``points``), ``Su``, ``Sv``, ``normal`` ``(a, b, 3)``;
        ``E, G, kI, kII, K, H`` ``(a, b)`` (``kI = L/E``, ``kII = N/G``, 1/m).
    """
    u = np.atleast_1d(np.asarray(u, float))
    v = np.atleast_1d(np.asarray(v, float))
    a, b = len(u), len(v)
    D = {k: surf.evaluate_grid(u, v, du, dv).reshape(-1, 3)
         for k, (du, dv) in (("Su", (1, 0)), ("Sv", (0, 1)), ("Suu", (2, 0)), ("Suv", (1, 1)),
                             ("Svv", (0, 2)))}
    ff = fundamental_forms(D["Su"], D["Sv"], D["Suu"], D["Suv"], D["Svv"])
    K, H, _, _ = curvatures(ff["E"], ff["F"], ff["G"], ff["L"], ff["M"], ff["N"])
    with np.errstate(divide="ignore", invalid="ignore"):
        kI, kII = ff["L"] / ff["E"], ff["N"] / ff["G"]
    nrm = np.cross(D["Su"], D["Sv"])
    with np.errstate(divide="ignore", invalid="ignore"):
        nrm /= np.linalg.norm(nrm, axis=1)[:, None]
    out = {"Su": D["Su"].reshape(a, b, 3), "Sv": D["Sv"].reshape(a, b, 3),
           "normal": nrm.reshape(a, b, 3)}
    for k, val in (("E", ff["E"]), ("G", ff["G"]), ("kI", kI), ("kII", kII), ("K", K), ("H", H)):
        out[k] = np.asarray(val).reshape(a, b)
    if points:
        out["S"] = surf.evaluate_grid(u, v)
    return out


def row_normal_curvature(K: np.ndarray, H: np.ndarray, mode: Mode = "phlw",
                         n: float | None = None) -> np.ndarray:
    """Normal curvature ``n_u (a,)`` of every u-row of ``K, H (a, b)`` (linear fit of eq. 4.8).

    ``phlw``: one line ``K = 2 n H - (n^2 + t^2)`` per row (:func:`gridshell.ncp.phlw.fit_rows`);
    ``cnc``: the given constant ``n``, else one slope fitted over all rows (on a subsampled grid
    of at most :data:`CNC_FIT_SAMPLES` squared samples); ``aa``: ``n = 0``.
    """
    from .phlw import fit_rows

    K = np.atleast_2d(np.asarray(K, float))
    H = np.atleast_2d(np.asarray(H, float))
    R = K.shape[0]
    if mode == "aa":
        return np.zeros(R)
    if mode == "cnc":
        if n is None:
            si = np.unique(np.linspace(0, R - 1, min(R, CNC_FIT_SAMPLES)).astype(int))
            sj = np.unique(np.linspace(0, K.shape[1] - 1,
                                       min(K.shape[1], CNC_FIT_SAMPLES)).astype(int))
            n = float(fit_rows(K[np.ix_(si, sj)], H[np.ix_(si, sj)], "cnc").n[0])
        return np.full(R, float(n))
    if mode != "phlw":
        raise InputError(f"unknown mode {mode!r}; use 'phlw', 'cnc' or 'aa'")
    return fit_rows(K, H, "phlw").n


def net_angle(kI: np.ndarray, kII: np.ndarray, n: np.ndarray,
              umbilic_tol: float = 1e-6, scale: float | None = None
              ) -> tuple[np.ndarray, np.ndarray]:
    """Net angle ``beta`` to ``e5`` from ``sin^2 beta = (n - kI) / (kII - kI)`` (eq. 4.10).

    Parameters
    ----------
    kI, kII : (...) float
        Normal curvatures along ``S_u`` and ``S_v``, 1/m.
    n : (...) float
        Net normal curvature (broadcast against ``kI``).
    umbilic_tol : float
        ``|kII - kI|`` below this times the curvature scale counts as umbilic.
    scale : float, optional
        The curvature scale, 1/m (default: the largest ``|kI|``, ``|kII|``). Pass at least
        one over the surface's size, so that a flat surface (curvatures at rounding level)
        counts as umbilic.

    Returns
    -------
    beta : (...) float
        Radians in ``[0, pi/2]`` (``sin^2 beta`` clipped to ``[0, 1]``).
    valid : (...) bool
        Where the net has a real direction (not umbilic, ``sin^2 beta`` in ``[0, 1]`` up to
        1e-9).
    """
    kI, kII = np.asarray(kI, float), np.asarray(kII, float)
    gap = kII - kI
    if scale is None:
        scale = float(np.nanmax(np.maximum(np.abs(kI), np.abs(kII)))) if kI.size else 1.0
    umb = ~(np.abs(gap) > umbilic_tol * max(scale, 1e-300))
    with np.errstate(divide="ignore", invalid="ignore"):
        s2 = (np.asarray(n, float) - kI) / gap
    valid = ~umb & (s2 >= -1e-9) & (s2 <= 1 + 1e-9)
    beta = np.arcsin(np.sqrt(np.clip(np.nan_to_num(s2, nan=0.5), 0.0, 1.0)))
    return beta, valid


@dataclass
class NetDirections:
    """Net directions on the grid ``u (a,) x v (b,)`` (eqs. 4.9-4.11).

    ``S, normal, e1 .. e6 (a, b, 3)``; ``norm_u = |S_u|``, ``norm_v = |S_v|``, ``beta``
    (radians), ``kI, kII, K, H (a, b)``; ``n_rows (a,)`` the net normal curvature per row, 1/m;
    ``valid (a, b)`` where the net direction is real.
    """

    u: np.ndarray
    v: np.ndarray
    mode: str
    S: np.ndarray
    normal: np.ndarray
    norm_u: np.ndarray
    norm_v: np.ndarray
    beta: np.ndarray
    n_rows: np.ndarray
    kI: np.ndarray
    kII: np.ndarray
    K: np.ndarray
    H: np.ndarray
    valid: np.ndarray
    e: dict[int, np.ndarray] = field(default_factory=dict)

    def coefficients(self, family: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(a1, b1, a2, b2) (a, b)``: ``dxi(e_f) = a1 xi_u + b1 xi_v`` and
        ``dxi(e_f+1) = a2 xi_u + b2 xi_v`` for family ``f`` = 1 (eqs. 4.12, 4.13) or 3."""
        c, s = np.cos(self.beta), np.sin(self.beta)
        iu, iv = 1.0 / self.norm_u, 1.0 / self.norm_v
        if family == 1:
            return c * iu, -s * iv, s * iu, c * iv
        if family == 3:
            return c * iu, s * iv, -s * iu, c * iv
        raise InputError(f"family must be 1 or 3, got {family}")


def _raise_no_net(g: dict[str, np.ndarray], n_rows: np.ndarray, u: np.ndarray, v: np.ndarray,
                  valid: np.ndarray, mode: str, scale: float) -> None:
    """:class:`NoNetError` saying why the net has no direction at the ``~valid`` samples."""
    gap = np.abs(g["kII"] - g["kI"])
    bad = ~valid
    if np.all(gap <= 1e-6 * scale):
        raise NoNetError(
            f"the surface is umbilic at all {valid.size} samples (kappa_I = kappa_II, as on a "
            "plane or a sphere): its principal directions, and with them the directions of a "
            "normal-curvature-preserving net, are undefined; give a surface with distinct "
            "principal curvatures (e.g. a saddle or a torus patch), or design a geodesic "
            "gridshell (gridshell gg)")
    if mode == "aa" and np.all(g["K"][bad] > 0):
        raise NoNetError(
            f"the surface has K > 0 at {int(bad.sum())} of {valid.size} samples (it bends like a "
            "dome there), and asymptotic directions exist only where K <= 0, so the AA net "
            "(n = 0) has no direction there; use mode 'phlw' or 'cnc', or a surface with K < 0 "
            "(e.g. a pseudosphere or a saddle)")
    i, j = np.argwhere(bad)[0]
    near = (f"; |kappa_II - kappa_I| is only {100 * gap[i, j] / scale:.2g} % of the curvature "
            "there, the surface is nearly umbilic (like a sphere)"
            if gap[i, j] < 0.05 * scale else "")
    raise NoNetError(
        f"the net of normal curvature n has no real direction at {int(bad.sum())} of "
        f"{valid.size} samples (first at u={u[i]:.3f}, v={v[j]:.3f}: n={n_rows[i]:.4g} outside "
        f"[kappa_I, kappa_II] = [{g['kI'][i, j]:.4g}, {g['kII'][i, j]:.4g}] or umbilic, eq. "
        f"4.10{near}); re-run the PHLW optimization (gridshell phlw) or trim the surface")


def net_directions(surf: BSplineSurface, u: np.ndarray, v: np.ndarray, *, mode: Mode = "phlw",
                   n: float | np.ndarray | None = None, require: bool = True) -> NetDirections:
    """Principal frame, net angle and net directions on the grid ``u x v`` (paper 4.2.2).

    Parameters
    ----------
    surf : the PHLW / CNC / PK surface (principal parametrization, rows ``u = const``)
    u, v : (a,), (b,) parameters
    mode : "phlw" (``n_u`` fitted per row, eq. 4.8), "cnc" (one ``n``), "aa" (``n = 0``)
    n : the net normal curvature: per row ``(a,)``, or one value (cnc); default: fitted
    require : raise :class:`NoNetError` where the net has no real direction

    Returns
    -------
    NetDirections
    """
    g = grid_curvature(surf, u, v)
    if n is None:
        n_rows = row_normal_curvature(g["K"], g["H"], mode)
    else:
        n_rows = np.broadcast_to(np.asarray(n, float).reshape(-1), (len(np.atleast_1d(u)),)).copy()
    S = g["S"].reshape(-1, 3)
    size = float(np.linalg.norm(S.max(axis=0) - S.min(axis=0))) if len(S) else 0.0
    kmax = float(np.nanmax(np.maximum(np.abs(g["kI"]), np.abs(g["kII"]))))
    scale = max(kmax, 1.0 / size) if size > 0 else kmax
    beta, valid = net_angle(g["kI"], g["kII"], n_rows[:, None], scale=scale)
    if require and not valid.all():
        _raise_no_net(g, n_rows, np.atleast_1d(u), np.atleast_1d(v), valid, mode, scale)
    nu = np.sqrt(g["E"])
    nv = np.sqrt(g["G"])
    e5 = g["Su"] / nu[..., None]
    e6 = g["Sv"] / nv[..., None]
    c, s = np.cos(beta)[..., None], np.sin(beta)[..., None]
    e = {5: e5, 6: e6, 1: c * e5 - s * e6, 2: s * e5 + c * e6, 3: c * e5 + s * e6,
         4: -s * e5 + c * e6}
    return NetDirections(u=np.atleast_1d(np.asarray(u, float)),
                         v=np.atleast_1d(np.asarray(v, float)),
                         mode=mode, S=g["S"], normal=g["normal"], norm_u=nu, norm_v=nv, beta=beta,
                         n_rows=n_rows, kI=g["kI"], kII=g["kII"], K=g["K"], H=g["H"], valid=valid,
                         e=e)
