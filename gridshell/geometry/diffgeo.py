"""Differential geometry of parametric surfaces and of polylines on surfaces (paper eqs. 4.2-4.6).

Sign conventions (used throughout the project)
----------------------------------------------
- The surface normal is ``n = (S_u x S_v) / |S_u x S_v|`` (eq. 4.2); it follows the
  parameterization, so swapping ``u`` and ``v`` flips it.
- Second fundamental form ``L = <S_uu, n>`` etc. (eq. 4.5). The normal curvature of a direction
  ``w`` is ``II(w) / I(w)``: **positive when the surface bends towards n**. A sphere with
  outward normal has ``k1 = k2 = -1/R``, ``H = -1/R``, ``K = 1/R^2``.
- Principal curvatures are ordered ``k1 <= k2``; ``d1``, ``d2`` are their unit directions in 3D
  with ``(d1, d2, n)`` right-handed.
- Curves: the curvature vector ``kappa_vec = dT/ds`` points to the centre of curvature;
  ``kn = <kappa_vec, n>`` (positive when the curve bends towards n) and
  ``kg = <kappa_vec, n x t>`` (positive when the curve turns left seen from the tip of n),
  so that ``dT/ds = kn n + kg (n x t)`` (Darboux frame).

Degenerate points (``delta = EG - F^2 = 0``) produce NaN normals and curvatures rather than
errors, since singular points (poles, collapsed edges) are legitimate on design surfaces.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from gridshell.core.errors import InputError

if TYPE_CHECKING:  # pragma: no cover
    from gridshell.geometry.bspline import BSplineSurface

__all__ = [
    "curvatures",
    "fundamental_forms",
    "normal_geodesic_curvature",
    "polyline_curvature",
    "principal_curvatures_along_params",
    "principal_directions",
    "surface_curvature",
]

#: Relative gap ``(k2 - k1) / max(|k1|, |k2|)`` below which a point counts as umbilic.
UMBILIC_TOL = 1e-9


def _vec3(name: str, a: np.ndarray) -> np.ndarray:
    a = np.asarray(a, dtype=float)
    if a.ndim != 2 or a.shape[1] != 3:
        raise InputError(f"{name} must have shape (k, 3), got {a.shape}")
    return a


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.einsum("ij,ij->i", a, b)


def fundamental_forms(Su: np.ndarray, Sv: np.ndarray, Suu: np.ndarray, Suv: np.ndarray,
                      Svv: np.ndarray) -> dict[str, np.ndarray]:
    """First and second fundamental forms from surface derivatives (eqs. 4.2-4.5).

    Parameters
    ----------
    Su, Sv : (k, 3) float
        First derivatives, metres per unit parameter.
    Suu, Suv, Svv : (k, 3) float
        Second derivatives, metres per unit parameter squared.

    Returns
    -------
    forms : dict
        ``u (k,3)`` unnormalized normal ``S_u x S_v`` (eq. 4.2); ``n (k,3)`` unit normal;
        ``E, F, G (k,)`` (eq. 4.3); ``delta (k,) = EG - F^2`` (eq. 4.4);
        ``L, M, N (k,) = <S_uu, u>/sqrt(delta), ...`` (eq. 4.5), i.e. ``<S_uu, n>``.
        Where ``delta <= 0`` (singular parameterization) ``n, L, M, N`` are NaN.
    """
    Su, Sv = _vec3("Su", Su), _vec3("Sv", Sv)
    Suu, Suv, Svv = _vec3("Suu", Suu), _vec3("Suv", Suv), _vec3("Svv", Svv)
    if not (Su.shape == Sv.shape == Suu.shape == Suv.shape == Svv.shape):
        raise InputError("Su, Sv, Suu, Suv, Svv must all have the same shape (k, 3); got "
                         f"{[a.shape for a in (Su, Sv, Suu, Suv, Svv)]}")
    u = np.cross(Su, Sv)                                  # eq. 4.2
    E, F, G = _dot(Su, Su), _dot(Su, Sv), _dot(Sv, Sv)    # eq. 4.3
    delta = E * G - F * F                                 # eq. 4.4
    # |u|^2 equals delta (Lagrange identity); use |u| for the normal, it is exact in floats.
    norm_u = np.linalg.norm(u, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = np.where(norm_u > 0, 1.0 / norm_u, np.nan)
    n = u * inv[:, None]
    L, M, N = _dot(Suu, n), _dot(Suv, n), _dot(Svv, n)    # eq. 4.5
    return {"u": u, "n": n, "E": E, "F": F, "G": G, "delta": delta, "L": L, "M": M, "N": N}


def curvatures(E: np.ndarray, F: np.ndarray, G: np.ndarray, L: np.ndarray, M: np.ndarray,
               N: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Gaussian, mean and principal curvatures from the fundamental forms (eq. 4.6).

    ``K = (LN - M^2) / delta`` and ``H = (LG - 2MF + NE) / (2 delta)``. The paper prints
    ``- NE`` in eq. 4.6; that is a typo (a sphere would get ``H = 0``): the standard ``+ NE``
    is used here.

    Parameters
    ----------
    E, F, G : (k,) float
        First fundamental form (m^2 per parameter^2).
    L, M, N : (k,) float
        Second fundamental form (m per parameter^2).

    Returns
    -------
    K : (k,) float
        Gaussian curvature, 1/m^2.
    H : (k,) float
        Mean curvature ``(k1 + k2) / 2``, 1/m, positive when bending towards ``n``.
    k1, k2 : (k,) float
        Principal curvatures, 1/m, ``k1 <= k2`` (``H -/+ sqrt(max(H^2 - K, 0))``).
    """
    E, F, G, L, M, N = (np.asarray(a, dtype=float) for a in (E, F, G, L, M, N))
    delta = E * G - F * F
    with np.errstate(divide="ignore", invalid="ignore"):
        K = (L * N - M * M) / delta                        # eq. 4.6
        H = (L * G - 2.0 * M * F + N * E) / (2.0 * delta)  # eq. 4.6 with +NE (paper typo)
    root = np.sqrt(np.maximum(H * H - K, 0.0))
    return K, H, H - root, H + root


def principal_curvatures_along_params(E: np.ndarray, G: np.ndarray, L: np.ndarray,
                                      N: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Normal curvatures along ``S_u`` and ``S_v``: ``(L/E, N/G)``, 1/m.

    For a principal parameterization (``F = M = 0``, eq. 4.7) these are the paper's
    ``kappa_I`` (along ``e5 = S_u``) and ``kappa_II`` (along ``e6 = S_v``), not sorted.
    """
    E, G, L, N = (np.asarray(a, dtype=float) for a in (E, G, L, N))
    with np.errstate(divide="ignore", invalid="ignore"):
        return L / E, N / G


def principal_directions(Su: np.ndarray, Sv: np.ndarray, E: np.ndarray, F: np.ndarray,
                         G: np.ndarray, L: np.ndarray, M: np.ndarray,
                         N: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Principal curvatures and unit principal directions in 3D.

    Solves ``(II - k I) w = 0`` for the parameter-space eigenvector ``w = (a, b)`` of ``k1``,
    taking whichever row of the 2x2 system is better conditioned, maps it to
    ``d1 = a S_u + b S_v`` and sets ``d2 = n x d1``. At umbilics (relative gap below
    :data:`UMBILIC_TOL`) every direction is principal and ``d1 = S_u / |S_u|`` is returned.

    Parameters
    ----------
    Su, Sv : (k, 3) float
        First derivatives.
    E, F, G, L, M, N : (k,) float
        Fundamental forms (see :func:`fundamental_forms`).

    Returns
    -------
    k1, k2 : (k,) float
        Principal curvatures, 1/m, ``k1 <= k2``.
    d1, d2 : (k, 3) float
        Unit directions of ``k1`` and ``k2``; ``(d1, d2, n)`` is right-handed.
    """
    Su, Sv = _vec3("Su", Su), _vec3("Sv", Sv)
    E, F, G, L, M, N = (np.asarray(a, dtype=float) for a in (E, F, G, L, M, N))
    _, _, k1, k2 = curvatures(E, F, G, L, M, N)
    # Rows of (II - k1 I): [L - k1 E, M - k1 F] and [M - k1 F, N - k1 G]; w is orthogonal to a row.
    a1, b1 = M - k1 * F, -(L - k1 * E)
    a2, b2 = N - k1 * G, -(M - k1 * F)
    w1 = a1[:, None] * Su + b1[:, None] * Sv
    w2 = a2[:, None] * Su + b2[:, None] * Sv
    n1, n2 = np.linalg.norm(w1, axis=1), np.linalg.norm(w2, axis=1)
    d1 = np.where((n1 >= n2)[:, None], w1, w2)
    nd = np.maximum(n1, n2)
    scale = np.maximum(np.abs(k1), np.abs(k2))
    umbilic = ~((k2 - k1) > UMBILIC_TOL * scale) | ~(nd > 0)
    nsu = np.linalg.norm(Su, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        d1 = np.where(umbilic[:, None], Su / nsu[:, None], d1 / nd[:, None])
        nrm = np.cross(Su, Sv)
        nrm = nrm / np.linalg.norm(nrm, axis=1)[:, None]
    d2 = np.cross(nrm, d1)
    return k1, k2, d1, d2


def surface_curvature(surf: "BSplineSurface", u: np.ndarray,
                      v: np.ndarray) -> dict[str, np.ndarray]:
    """Everything of this module at paired parameters of a B-spline surface.

    Parameters
    ----------
    surf : BSplineSurface
    u, v : (k,) float
        Paired parameters in the surface domain.

    Returns
    -------
    geo : dict
        ``S, Su, Sv, Suu, Suv, Svv (k,3)``; ``u, n (k,3)``; ``E, F, G, delta, L, M, N (k,)``;
        ``K, H, k1, k2 (k,)``; ``d1, d2 (k,3)``; ``kI, kII (k,)`` (normal curvatures along
        ``S_u`` and ``S_v``, the principal ones for a principal parameterization).
    """
    out: dict[str, np.ndarray] = dict(surf.derivatives(u, v))
    ff = fundamental_forms(out["Su"], out["Sv"], out["Suu"], out["Suv"], out["Svv"])
    out.update(ff)
    K, H, _, _ = curvatures(ff["E"], ff["F"], ff["G"], ff["L"], ff["M"], ff["N"])
    k1, k2, d1, d2 = principal_directions(out["Su"], out["Sv"], ff["E"], ff["F"], ff["G"],
                                          ff["L"], ff["M"], ff["N"])
    kI, kII = principal_curvatures_along_params(ff["E"], ff["G"], ff["L"], ff["N"])
    out.update({"K": K, "H": H, "k1": k1, "k2": k2, "d1": d1, "d2": d2, "kI": kI, "kII": kII})
    return out


# ----------------------------------------------------------------------------- polylines


def _polyline(P: np.ndarray, closed: bool) -> np.ndarray:
    P = _vec3("P", P)
    if len(P) < 3:
        raise InputError(f"a polyline needs at least 3 points for curvature, got {len(P)}")
    if not np.all(np.isfinite(P)):
        raise InputError("polyline contains NaN or infinite coordinates; remove them")
    seg = np.linalg.norm(np.diff(np.vstack([P, P[:1]]) if closed else P, axis=0), axis=1)
    if np.any(seg == 0):
        hint = " (for closed=True do not repeat the first point at the end)" if closed else ""
        raise InputError(f"polyline has {int(np.sum(seg == 0))} zero-length segment(s); "
                         f"remove repeated consecutive points{hint}")
    return P


def polyline_curvature(P: np.ndarray, closed: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Discrete curvature vector of a polyline from circumscribed circles.

    At vertex ``i`` the circle through ``P[i-1], P[i], P[i+1]`` has radius ``R``; the curvature
    vector has length ``1/R`` and points from ``P[i]`` to the circle's centre:
    ``kappa_vec = 2 ((|a|^2 b - |b|^2 a) x (a x b)) / (|a|^2 |b|^2 |a - b|^2)`` with
    ``a = P[i-1] - P[i]``, ``b = P[i+1] - P[i]`` (zero for collinear points). The estimate is
    second-order accurate for uniform sampling.

    Parameters
    ----------
    P : (k, 3) float
        Vertices, metres, ``k >= 3``, no repeated consecutive points.
    closed : bool
        If true, ``P[-1]`` connects back to ``P[0]`` (do not repeat the first point).

    Returns
    -------
    kappa_vec : (k, 3) float
        Curvature vectors, 1/m. For open polylines the two end rows are NaN.
    kappa : (k,) float
        ``|kappa_vec|``, 1/m (NaN at the ends of open polylines).
    """
    P = _polyline(P, closed)
    prev = np.roll(P, 1, axis=0)
    nxt = np.roll(P, -1, axis=0)
    a, b = prev - P, nxt - P
    aa, bb = _dot(a, a), _dot(b, b)
    cc = _dot(a - b, a - b)
    X = np.cross(aa[:, None] * b - bb[:, None] * a, np.cross(a, b))
    kvec = 2.0 * X / (aa * bb * cc)[:, None]
    if not closed:
        kvec[[0, -1]] = np.nan
    return kvec, np.linalg.norm(kvec, axis=1)


def normal_geodesic_curvature(P: np.ndarray, normals: np.ndarray,
                              closed: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Normal and geodesic curvature of a polyline lying on a surface.

    ``kn = <kappa_vec, n>``, ``kg = <kappa_vec, n x t>`` with ``kappa_vec`` from
    :func:`polyline_curvature` and ``t`` the unit central-difference tangent
    ``(P[i+1] - P[i-1]) / |...|``. ``kn > 0`` when the curve bends towards ``n``; ``kg > 0``
    when it turns left seen from the tip of ``n``.

    Parameters
    ----------
    P : (k, 3) float
        Vertices, metres.
    normals : (k, 3) float
        Unit surface normals at the vertices (normalized here anyway).
    closed : bool
        As in :func:`polyline_curvature`.

    Returns
    -------
    kn, kg : (k,) float
        1/m; NaN at the ends of open polylines.
    """
    kvec, _ = polyline_curvature(P, closed)
    P = np.asarray(P, dtype=float)
    n = _vec3("normals", normals)
    if n.shape != P.shape:
        raise InputError(f"normals must match the polyline shape {P.shape}, got {n.shape}")
    nn = np.linalg.norm(n, axis=1)
    if not np.all(nn > 0):
        raise InputError("normals contain zero vectors; pass unit surface normals")
    n = n / nn[:, None]
    t = np.roll(P, -1, axis=0) - np.roll(P, 1, axis=0)
    if not closed:
        t[0], t[-1] = P[1] - P[0], P[-1] - P[-2]
    t /= np.linalg.norm(t, axis=1)[:, None]
    return _dot(kvec, n), _dot(kvec, np.cross(n, t))
