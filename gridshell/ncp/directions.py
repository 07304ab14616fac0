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

Signs follow :mod:`gridshell.geometry.diffgeo` (curvatures positive when the surface bends towards
``S_u x S_v``), units 1/m. Arrays are on a tensor grid ``u (a,) x v (b,)``: scalars ``(a, b)``,
vectors ``(a, b, 3)``; row ``i`` is the curve ``u = u[i]``.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from gridshell.geometry.bspline import BSplineSurface, uniform_params
from gridshell.geometry.diffgeo import curvatures, fundamental_forms
from gridshell.core.errors import InputError, NoNetError

Mode = Literal["phlw", "cnc", "aa"]

__all__ = ["MAX_DROPPED", "NetDirections", "UMBILIC_TOL", "classify_samples",
           "cnc_normal_curvature", "describe_region", "grid_curvature", "net_angle",
           "net_directions", "no_net_error", "reference_net_check", "row_normal_curvature",
           "surface_size"]

#: samples per direction for a global fit of the constant normal curvature (mode "cnc")
CNC_FIT_SAMPLES = 64
#: ``|kappa_II - kappa_I|`` below this fraction of the local curvature counts as umbilic: the
#: principal directions of a B-spline fit of a sphere scatter at 1e-5 relative gaps
UMBILIC_TOL = 1e-3
#: ``sin^2 beta`` within this of 0 or 1: the two net directions touch (beta < 0.6 degrees)
TANGENT_TOL = 1e-4
#: the fraction of the samples at which the net may lack a direction (isolated umbilic spots,
#: a rim where n leaves the principal range): those samples are left out of the level-set fit
#: with a note; more than this is no net on the surface
MAX_DROPPED = 0.05
#: a CNC n is kept this fraction of the common principal range inside its ends
CNC_MARGIN = 0.1
#: a CNC collapse circle larger than this many surface sizes counts as a line
CNC_LINE_RADIUS = 20.0



def grid_curvature(surf: BSplineSurface, u: np.ndarray, v: np.ndarray,
                   points: bool = True, normal: bool = True) -> dict[str, np.ndarray]:
    """Curvature data on the grid ``u (a,) x v (b,)`` (eqs. 4.2-4.6).

    Returns
    -------
    dict
        ``S`` (only if ``points``), ``Su``, ``Sv``, ``normal`` (only if ``normal``) ``(a, b, 3)``;
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
    out = {"Su": D["Su"].reshape(a, b, 3), "Sv": D["Sv"].reshape(a, b, 3)}
    if normal:
        nrm = np.cross(D["Su"], D["Sv"])
        with np.errstate(divide="ignore", invalid="ignore"):
            nrm /= np.linalg.norm(nrm, axis=1)[:, None]
        out["normal"] = nrm.reshape(a, b, 3)
    for k, val in (("E", ff["E"]), ("G", ff["G"]), ("kI", kI), ("kII", kII), ("K", K), ("H", H)):
        out[k] = np.asarray(val).reshape(a, b)
    if points:
        out["S"] = surf.evaluate_grid(u, v)
    return out


def row_normal_curvature(K: np.ndarray, H: np.ndarray, mode: Mode = "phlw",
                         n: float | None = None, kI: np.ndarray | None = None,
                         kII: np.ndarray | None = None) -> np.ndarray:
    """Normal curvature ``n_u (a,)`` of every u-row of ``K, H (a, b)`` (linear fit of eq. 4.8).

    ``phlw``: one line ``K = 2 n H - (n^2 + t^2)`` per row (:func:`gridshell.ncp.phlw.fit_rows`);
    with the principal curvatures ``kI, kII (a, b)`` a row's ``n`` outside the range common
    to its samples' ``[kappa_I, kappa_II]`` (where the net has a direction at every sample of
    the row) is moved :data:`CNC_MARGIN` of that range inside it, if the range is not empty;
    ``cnc``: the given constant ``n``, else one slope fitted over all rows (on a subsampled grid
    of at most :data:`CNC_FIT_SAMPLES` squared samples); ``aa``: ``n = 0``.
    """
    from gridshell.ncp.phlw.checks import fit_rows

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
    nr = fit_rows(K, H, "phlw").n
    if kI is None or kII is None:
        return nr
    kI, kII = np.atleast_2d(kI), np.atleast_2d(kII)
    c = classify_samples(kI, kII, nr[:, None])
    keep = ~c["umbilic"]
    lo = np.where(keep, np.minimum(kI, kII), -np.inf).max(axis=1)
    hi = np.where(keep, np.maximum(kI, kII), np.inf).min(axis=1)
    fix = np.isfinite(lo) & np.isfinite(hi) & (lo < hi) & ((nr < lo) | (nr > hi))
    nr = nr.copy()
    m = CNC_MARGIN * (hi[fix] - lo[fix])
    nr[fix] = np.clip(nr[fix], lo[fix] + m, hi[fix] - m)
    return nr


def net_angle(kI: np.ndarray, kII: np.ndarray, n: np.ndarray,
              umbilic_tol: float = UMBILIC_TOL, scale: float | None = None
              ) -> tuple[np.ndarray, np.ndarray]:
    """Net angle ``beta`` to ``e5`` from ``sin^2 beta = (n - kI) / (kII - kI)`` (eq. 4.10).

    Parameters
    ----------
    kI, kII : (...) float
        Normal curvatures along ``S_u`` and ``S_v``, 1/m.
    n : (...) float
        Net normal curvature (broadcast against ``kI``).
    umbilic_tol : float
        ``|kII - kI|`` below this fraction of the local curvature ``max(|kI|, |kII|, scale)``
        counts as umbilic.
    scale : float, optional
        The curvature floor, 1/m: pass one over the surface's size, so that a flat region
        (curvatures at rounding level) counts as umbilic. Default 0.

    Returns
    -------
    beta : (...) float
        Radians in ``[0, pi/2]`` (``sin^2 beta`` clipped to ``[0, 1]``).
    valid : (...) bool
        Where the net has a real direction (see :func:`classify_samples`).
    """
    c = classify_samples(kI, kII, n, umbilic_tol=umbilic_tol, floor=scale or 0.0)
    beta = np.arcsin(np.sqrt(np.clip(np.nan_to_num(c["sin2beta"], nan=0.5), 0.0, 1.0)))
    return beta, c["valid"]


def classify_samples(kI: np.ndarray, kII: np.ndarray, n: np.ndarray, *,
                     umbilic_tol: float = UMBILIC_TOL, floor: float = 0.0
                     ) -> dict[str, np.ndarray]:
    """Why the net of normal curvature ``n`` has, or lacks, a direction at each sample (eq. 4.10).

    Returns ``sin2beta = (n - kI) / (kII - kI)`` (NaN at umbilics) and boolean masks:
    ``umbilic`` (``|kII - kI| <= umbilic_tol * max(|kI|, |kII|, floor)``), ``outside``
    (``n`` outside ``[kI, kII]``: ``sin^2 beta`` outside ``[0, 1]``), ``tangent`` (``sin^2
    beta`` within :data:`TANGENT_TOL` of 0 or 1: the two families touch, as the asymptotic
    directions of a developable surface do) and ``valid`` (none of these).
    """
    kI = np.asarray(kI, float)
    kII = np.asarray(kII, float)
    n = np.asarray(n, float)
    gap = kII - kI
    local = np.maximum(np.maximum(np.abs(kI), np.abs(kII)), float(floor))
    umb = ~(np.abs(gap) > umbilic_tol * np.maximum(local, 1e-300))
    with np.errstate(divide="ignore", invalid="ignore"):
        s2 = np.where(umb, np.nan, (n - kI) / np.where(umb, 1.0, gap))
    s2 = np.broadcast_to(s2, np.broadcast_shapes(kI.shape, n.shape))
    umb = np.broadcast_to(umb, s2.shape)
    outside = ~umb & ((s2 < -1e-9) | (s2 > 1 + 1e-9))
    tangent = ~umb & ~outside & ((s2 < TANGENT_TOL) | (s2 > 1 - TANGENT_TOL))
    return {"sin2beta": s2, "umbilic": umb, "outside": outside, "tangent": tangent,
            "valid": ~(umb | outside | tangent)}


def surface_size(S: np.ndarray) -> float:
    """Bounding-box diagonal of the points ``S (..., 3)``, metres."""
    P = np.asarray(S, float).reshape(-1, 3)
    return float(np.linalg.norm(P.max(axis=0) - P.min(axis=0))) if len(P) else 0.0


def cnc_normal_curvature(kI: np.ndarray, kII: np.ndarray, K: np.ndarray, H: np.ndarray, *,
                         size: float, hint: float | None = None
                         ) -> tuple[float, dict[str, Any]]:
    """The one normal curvature ``n`` of a CNC net on samples ``(a, b)`` of a surface, 1/m.

    A CNC net has a direction at every sample exactly when ``n`` lies in every sample's range
    ``[min(kI, kII), max(kI, kII)]``, i.e. in ``[lo, hi]`` with ``lo`` the largest lower and
    ``hi`` the smallest upper bound (umbilic samples left out). ``hint`` (e.g. the PHLW
    step's ``n``) is kept when it lies in ``[lo, hi]``; otherwise the least-squares slope of
    ``K = 2 n H + c_u`` (eq. 4.8) is moved into ``[lo, hi]`` by :data:`CNC_MARGIN` of its
    width. If that ``n`` is so small that the collapse circle (radius ``1 / |n|``) is more
    than :data:`CNC_LINE_RADIUS` surface sizes, practically a line, the end of the margin
    with the larger ``|n|`` is taken instead. Without a common range (``lo > hi``) the ``n``
    covering the most samples is returned.

    Returns
    -------
    n : float
    info : ``{"lo", "hi", "lo_at", "hi_at" (sample indices (i, j)), "fit", "choice", "note"}``
    """
    from gridshell.ncp.phlw.checks import fit_rows

    c = classify_samples(kI, kII, np.zeros(1), floor=1.0 / max(size, 1e-300))
    keep = ~c["umbilic"]
    lo_s = np.where(keep, np.minimum(kI, kII), -np.inf)
    hi_s = np.where(keep, np.maximum(kI, kII), np.inf)
    ilo = np.unravel_index(int(np.argmax(lo_s)), lo_s.shape)
    ihi = np.unravel_index(int(np.argmin(hi_s)), hi_s.shape)
    lo, hi = float(lo_s[ilo]), float(hi_s[ihi])
    R, C = K.shape
    si = np.unique(np.linspace(0, R - 1, min(R, CNC_FIT_SAMPLES)).astype(int))
    sj = np.unique(np.linspace(0, C - 1, min(C, CNC_FIT_SAMPLES)).astype(int))
    fit = float(fit_rows(K[np.ix_(si, sj)], H[np.ix_(si, sj)], "cnc").n[0])
    info: dict[str, Any] = {"lo": lo, "hi": hi, "lo_at": tuple(int(k) for k in ilo),
                            "hi_at": tuple(int(k) for k in ihi), "fit": fit, "note": None}
    if not np.isfinite(lo) or not np.isfinite(hi):
        info["choice"] = "fit"
        return fit, info
    if lo <= hi:
        if hint is not None and np.isfinite(hint) and lo < hint < hi:
            info["choice"] = "hint"
            return float(hint), info
        m = CNC_MARGIN * (hi - lo)
        a, b = lo + m, hi - m
        n = float(np.clip(fit, a, b))
        if abs(n) * size < 1.0 / CNC_LINE_RADIUS:
            alt = b if abs(b) >= abs(a) else a
            if abs(alt) > abs(n):
                n = float(alt)
        info["choice"] = "range"
        if hint is not None:
            info["note"] = (f"the given n = {hint:.4g} 1/m lies outside [{lo:.4g}, {hi:.4g}] "
                            f"1/m, where the CNC net has a direction at every sample; using "
                            f"n = {n:.4g} 1/m")
        elif n != fit:
            info["note"] = (f"CNC normal curvature n = {n:.4g} 1/m (the least-squares "
                            f"{fit:.4g} 1/m moved into [{lo:.4g}, {hi:.4g}] 1/m, where the net "
                            "has a direction at every sample)")
        return n, info
    # no common range: the n inside the ranges of the most samples
    cand = np.unique(np.concatenate([lo_s[keep], hi_s[keep], [fit]]))
    cand = cand[np.isfinite(cand)]
    lo_k, hi_k = lo_s[keep], hi_s[keep]
    if len(cand) > 400:
        cand = np.unique(np.concatenate([np.quantile(cand, np.linspace(0, 1, 400)), [fit]]))
    cover = [(np.count_nonzero((lo_k <= x) & (x <= hi_k)), -abs(x - fit), x) for x in cand]
    best = max(cover)
    info["choice"] = "coverage"
    info["coverage"] = best[0] / max(int(keep.sum()), 1)
    return float(best[2]), info


def _regions(mask: np.ndarray, u: np.ndarray, v: np.ndarray) -> list[dict[str, Any]]:
    """Connected regions of a boolean sample grid ``(a, b)`` as parameter boxes, largest
    first: ``{"u": (u0, u1), "v": (v0, v1), "samples"}``."""
    from scipy import ndimage

    lab, _ = ndimage.label(mask)
    out = []
    for k, sl in enumerate(ndimage.find_objects(lab), start=1):
        su, sv = sl
        out.append({"u": (float(u[su.start]), float(u[su.stop - 1])),
                    "v": (float(v[sv.start]), float(v[sv.stop - 1])),
                    "samples": int(np.sum(lab[sl] == k))})
    return sorted(out, key=lambda r: -r["samples"])


def describe_region(mask: np.ndarray, u: np.ndarray, v: np.ndarray) -> str:
    """``"123 of 2304 samples (5.3 %), 2 regions, the largest u in [0, 0.2], v in [0.5, 1]
    (100 samples)"``."""
    regs = _regions(mask, u, v)
    cnt, tot = int(mask.sum()), int(mask.size)
    if not regs:
        return f"0 of {tot} samples"
    r = regs[0]
    box = f"u in [{r['u'][0]:.3g}, {r['u'][1]:.3g}], v in [{r['v'][0]:.3g}, {r['v'][1]:.3g}]"
    where = (f"{box}" if len(regs) == 1 else
             f"{len(regs)} regions, the largest {box} ({r['samples']} samples)")
    return f"{cnt} of {tot} samples ({100.0 * cnt / tot:.3g} %), {where}"


@dataclass
class NetDirections:
    """Net directions on the grid ``u (a,) x v (b,)`` (eqs. 4.9-4.11).

    ``S, normal, e1 .. e6 (a, b, 3)``; ``norm_u = |S_u|``, ``norm_v = |S_v|``, ``beta``
    (radians), ``kI, kII, K, H (a, b)``; ``n_rows (a,)`` the net normal curvature per row, 1/m;
    ``valid (a, b)`` where the net direction is real; ``notes`` what was chosen or left out.
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
    notes: list[str] = field(default_factory=list)

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


def _sample(u: np.ndarray, v: np.ndarray, i: int, j: int) -> str:
    return f"u = {u[i]:.3f}, v = {v[j]:.3f}"


def no_net_error(g: dict[str, np.ndarray], n_rows: np.ndarray, u: np.ndarray, v: np.ndarray,
                 cls: dict[str, np.ndarray], mode: str, *, n_given: bool = False,
                 cnc: dict[str, Any] | None = None) -> NoNetError:
    """:class:`NoNetError` saying where and why the net has no direction (eq. 4.10).

    Every number in the message is one of the sample's own (``n``, ``kappa_I``,
    ``kappa_II``, ``sin^2 beta`` from those, gaps relative to that sample's curvature), and
    the region is named by its sample count, fraction and ``(u, v)`` box.
    """
    umb, out, tan = cls["umbilic"], cls["outside"], cls["tangent"]
    bad = umb | out | tan
    tot = int(bad.size)
    kI, kII, K = g["kI"], g["kII"], g["K"]
    nn = np.broadcast_to(np.asarray(n_rows, float)[:, None], kI.shape)
    if umb.sum() >= 0.95 * tot:
        i, j = np.unravel_index(int(np.nanargmax(np.abs(kII - kI))), kI.shape)
        rel = abs(kII[i, j] - kI[i, j]) / max(abs(kI[i, j]), abs(kII[i, j]), 1e-300)
        return NoNetError(
            f"the surface is umbilic at {describe_region(umb, u, v)} (kappa_I = kappa_II within "
            f"{100 * UMBILIC_TOL:g} % of the curvature, as on a plane or a sphere; the largest "
            f"gap is {100 * rel:.3g} % at {_sample(u, v, i, j)}): its principal directions, and "
            "with them the directions of a normal-curvature-preserving net, are undefined; give "
            "a surface with distinct principal curvatures (e.g. a saddle or a torus patch), or "
            "design a geodesic gridshell (gridshell gg)")
    if mode == "aa" and (out | tan).any():
        local = np.maximum(np.abs(kI), np.abs(kII))
        flat = (out | tan) & (np.abs(K) <= UMBILIC_TOL * local * local)
        pos, tan = (out | tan) & ~flat, flat
        what = (f"K > 0 at {describe_region(pos, u, v)}" if pos.any() else "")
        if tan.any():
            what += (", and " if what else "") + (
                f"K = 0 at {describe_region(tan, u, v)} (there the two asymptotic directions "
                "coincide, as on a developable surface)")
        return NoNetError(
            f"an AA net (n = 0) follows the asymptotic directions, which exist only where "
            f"K < 0; the surface has {what} (largest K {float(np.nanmax(K)):.4g} 1/m^2, "
            f"K < 0 at {int(np.sum(~bad))} samples); use mode 'phlw' or 'cnc', or a surface "
            "with K < 0 (e.g. a pseudosphere or a saddle)")
    # n outside the principal range (or touching an end of it)
    s2 = cls["sin2beta"]
    dist = np.where(out | tan, np.maximum(-np.nan_to_num(s2), np.nan_to_num(s2) - 1.0), -np.inf)
    i, j = np.unravel_index(int(np.argmax(dist)), dist.shape)
    if not np.isfinite(dist[i, j]):
        i, j = np.argwhere(bad)[0]
    n0, a, b = float(nn[i, j]), float(kI[i, j]), float(kII[i, j])
    gap = abs(b - a) / max(abs(a), abs(b), 1e-300)
    parts = [f"the net of normal curvature n has no real direction at {describe_region(bad, u, v)}"
             f" (eq. 4.10: n must lie in [kappa_I, kappa_II], sin^2 beta = (n - kappa_I) / "
             f"(kappa_II - kappa_I) in [0, 1]); e.g. at {_sample(u, v, i, j)}: n = {n0:.6g}, "
             f"kappa_I = {a:.6g}, kappa_II = {b:.6g} 1/m, sin^2 beta = "
             f"{(n0 - a) / (b - a) if b != a else float('nan'):.4g}"]
    if gap < 0.05:
        parts.append(f"; there |kappa_II - kappa_I| is only {100 * gap:.2g} % of the curvature "
                     "(nearly umbilic)")
    if umb.any():
        parts.append(f"; umbilic (kappa_I = kappa_II within {100 * UMBILIC_TOL:g} %) at "
                     f"{int(umb.sum())} of these samples")
    if tan.any():
        parts.append(f"; at {int(tan.sum())} of them n equals a principal curvature, so the "
                     "two net directions touch")
    if cnc is not None and cnc["lo"] > cnc["hi"]:
        parts.append(f"; no single n lies in [kappa_I, kappa_II] at every sample: it would have "
                     f"to be >= {cnc['lo']:.4g} (at {_sample(u, v, *cnc['lo_at'])}) and <= "
                     f"{cnc['hi']:.4g} 1/m (at {_sample(u, v, *cnc['hi_at'])}), so this surface "
                     "has no CNC net; use mode 'phlw', a mesh reference (the PHLW step makes a "
                     "CNC surface near it) or trim the surface")
    elif n_given:
        sgn = (out & (np.sign(nn) * np.sign(kI) < 0) & (np.sign(kI) == np.sign(kII)))
        if sgn.sum() > 0.5 * bad.sum():
            flip = (cnc is not None and cnc["lo"] <= -n0 <= cnc["hi"])
            parts.append(f"; n has the opposite sign of both principal curvatures there "
                         "(curvatures are signed with the normal S_u x S_v of the surface)"
                         + (f": did you mean n = {-n0:.4g}?" if flip else ""))
        if cnc is not None and cnc["lo"] <= cnc["hi"]:
            parts.append(f"; the net has a direction at every sample for n in "
                         f"[{cnc['lo']:.4g}, {cnc['hi']:.4g}] 1/m")
    else:
        parts.append("; re-run the PHLW optimization (gridshell phlw), or trim the surface")
    return NoNetError("".join(parts))


def net_directions(surf: BSplineSurface, u: np.ndarray, v: np.ndarray, *, mode: Mode = "phlw",
                   n: float | np.ndarray | None = None, n_hint: float | None = None,
                   require: bool = True, max_dropped: float = MAX_DROPPED) -> NetDirections:
    """Principal frame, net angle and net directions on the grid ``u x v`` (paper 4.2.2).

    Parameters
    ----------
    surf : the PHLW / CNC / PK surface (principal parametrization, rows ``u = const``)
    u, v : (a,), (b,) parameters
    mode : "phlw" (``n_u`` fitted per row, eq. 4.8), "cnc" (one ``n``), "aa" (``n = 0``)
    n : the net normal curvature, kept as given: per row ``(a,)``, or one value (cnc);
        default: fitted (cnc: :func:`cnc_normal_curvature`)
    n_hint : cnc: a suggested ``n`` (the PHLW step's), kept if the net exists with it
    require : raise :class:`NoNetError` (:func:`no_net_error`) where the net has no real
        direction at more than ``max_dropped`` of the samples; at fewer, those samples are
        left out (``valid`` False) with a note
    max_dropped : fraction of the samples

    Returns
    -------
    NetDirections
    """
    g = grid_curvature(surf, u, v)
    u = np.atleast_1d(np.asarray(u, float))
    v = np.atleast_1d(np.asarray(v, float))
    size = surface_size(g["S"])
    floor = 1.0 / size if size > 0 else 0.0
    notes: list[str] = []
    cnc = None
    given = n is not None
    if not (np.all(np.isfinite(g["kI"])) and np.all(np.isfinite(g["kII"]))):
        raise InputError("the surface's curvatures are not finite at some samples (S_u or S_v "
                         "vanishes: a singular parametrization); refit the surface")
    if mode == "cnc":
        n_c, cnc = cnc_normal_curvature(g["kI"], g["kII"], g["K"], g["H"], size=size,
                                        hint=n_hint)
        if n is None:
            n = n_c
            if cnc.get("note"):
                notes.append(cnc["note"])
    if n is None:
        n_rows = row_normal_curvature(g["K"], g["H"], mode, kI=g["kI"], kII=g["kII"])
    else:
        n_rows = np.broadcast_to(np.asarray(n, float).reshape(-1), (len(u),)).copy()
    cls = classify_samples(g["kI"], g["kII"], n_rows[:, None], floor=floor)
    beta = np.arcsin(np.sqrt(np.clip(np.nan_to_num(cls["sin2beta"], nan=0.5), 0.0, 1.0)))
    valid = cls["valid"]
    if require and not valid.all():
        if np.mean(~valid) > max_dropped or valid.sum() < 4:
            raise no_net_error(g, n_rows, u, v, cls, mode, n_given=given, cnc=cnc)
        kinds = [f"{int(cls[k].sum())} {w}" for k, w in (("umbilic", "umbilic"),
                                                        ("outside", "with n outside "
                                                         "[kappa_I, kappa_II]"),
                                                        ("tangent", "with touching directions"))
                 if cls[k].any()]
        notes.append(f"the net has no direction at {describe_region(~valid, u, v)} "
                     f"({', '.join(kinds)}); those samples are left out of the level-set fit")
    nu = np.sqrt(g["E"])
    nv = np.sqrt(g["G"])
    e5 = g["Su"] / nu[..., None]
    e6 = g["Sv"] / nv[..., None]
    c, s = np.cos(beta)[..., None], np.sin(beta)[..., None]
    e = {5: e5, 6: e6, 1: c * e5 - s * e6, 2: s * e5 + c * e6, 3: c * e5 + s * e6,
         4: -s * e5 + c * e6}
    return NetDirections(u=u, v=v, mode=mode, S=g["S"], normal=g["normal"], norm_u=nu, norm_v=nv,
                         beta=beta, n_rows=n_rows, kI=g["kI"], kII=g["kII"], K=g["K"], H=g["H"],
                         valid=valid, e=e, notes=notes)


def reference_net_check(surf: BSplineSurface, mode: str, samples: tuple[int, int] = (24, 24)
                        ) -> None:
    """Raise :class:`NoNetError` if no surface near ``surf`` can carry a net of ``mode``
    because ``surf`` itself has none anywhere: umbilic at every sample (a plane or sphere
    patch: no principal directions), or, for ``aa``, ``K < 0`` at fewer than
    :data:`MAX_DROPPED` of the samples (asymptotic directions exist only there). Uses only ``K`` and ``H``, so any parametrization of ``surf`` will do (e.g.
    the initial fit of a reference mesh, before the PHLW step)."""
    u, v = uniform_params(surf, samples)
    g = grid_curvature(surf, u, v)
    K, H = g["K"], g["H"]
    if not (np.all(np.isfinite(K)) and np.all(np.isfinite(H))):
        return
    d = np.sqrt(np.maximum(H * H - K, 0.0))
    size = surface_size(g["S"])
    local = np.maximum(np.abs(H) + d, 1.0 / max(size, 1e-300))
    if np.all(2 * d <= UMBILIC_TOL * local):
        raise NoNetError(
            f"the reference is umbilic at all {K.size} samples (kappa_I = kappa_II within "
            f"{100 * UMBILIC_TOL:g} % of the curvature, as on a plane or a sphere; largest gap "
            f"{100 * float(np.max(2 * d / local)):.3g} %): it has no principal directions, so no "
            "PHLW / CNC / PK net can start from it; give a reference with distinct principal "
            "curvatures (e.g. a saddle or a torus patch), or design a geodesic gridshell "
            "(gridshell gg)")
    flat = np.abs(K) <= UMBILIC_TOL * local * local
    if mode == "aa":
        _aa_check(K, flat)


def _aa_check(K: np.ndarray, flat: np.ndarray) -> None:
    """:class:`NoNetError` unless ``K < 0`` (1/m^2; ``flat``: K = 0 within the tolerance) at
    more than :data:`MAX_DROPPED` of the samples: asymptotic directions exist only there, and
    a net may lack its directions on no more than that fraction (which the level-set fit
    leaves out), so a reference with less has no AA net near it, before any PHLW work."""
    neg, pos = (K < 0) & ~flat, (K > 0) & ~flat
    if neg.mean() >= MAX_DROPPED:
        return
    if not neg.any():
        what = (f"K > 0 at all {K.size} samples (smallest K {float(K.min()):.4g} 1/m^2: it "
                "bends like a dome)" if not flat.any() else
                f"K > 0 at {int(np.sum(~flat))} and K = 0 at {int(flat.sum())} of {K.size} "
                "samples (developable there: the two asymptotic directions coincide), K < 0 "
                "nowhere")
    else:
        what = (f"K < 0 at only {int(neg.sum())} of {K.size} samples ({100 * neg.mean():.2g} %,"
                f" fewer than the {100 * MAX_DROPPED:g} % a net may lack its directions on; "
                f"K > 0 at {int(pos.sum())}" + (f", up to {float(K.max()):.4g} 1/m^2" if
                                                pos.any() else "")
                + f", K = 0 at {int(flat.sum())})")
    raise NoNetError(
        f"the reference has {what}, and asymptotic directions exist only where K < 0, so "
        "no AA net (n = 0) exists on it or near it; use mode 'phlw' or 'cnc', or a reference "
        "with K < 0 (e.g. a saddle)")
