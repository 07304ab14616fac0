"""The surface of revolution isometric to a designed GG mesh (paper 4.1.2, after Wang et al. 2019).

A designed GG mesh ``P (R, C, 3)`` has meridians ``P[:, j]`` (discrete geodesics) and parallels
``P[i, :]`` whose edges all have one length ``l_i``; the meridian edges between parallels ``i``
and ``i+1`` all have one length ``h_i``. It is discretely isometric to the surface of revolution
whose parallel ``i`` is a circle of radius ``r_i`` at arc length ``s_i = sum(h[:i])`` along the
profile, with meridians at angles ``phi_j = j dphi``:

* a parallel edge is a chord of its circle: ``l_i = 2 r_i sin(dphi / 2)``;
* a meridian edge is a chord of the profile: ``h_i^2 = (r_{i+1} - r_i)^2 + (z_{i+1} - z_i)^2``.

``dphi`` is free (the isometric family ``r -> lambda r``, ``dphi -> dphi / lambda``); it must
keep the profile embeddable, ``|r_{i+1} - r_i| <= h_i``, i.e.
``2 sin(dphi / 2) >= max_i |l_{i+1} - l_i| / h_i``. The intrinsic geometry - and so every
geodesic in the coordinates ``(s, j)`` - does not depend on the choice.
"""
from __future__ import annotations

from bisect import bisect_right
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np
from scipy.interpolate import CubicSpline

from gridshell.core.errors import InputError, NoNetError

__all__ = ["Profile", "Revolution", "embeddable_range", "parallel_turning_angle",
           "rebuild_revolution"]


@dataclass
class Profile:
    """A meridian profile ``r(s)`` of a surface of revolution, ``s`` in ``[s_min, s_max]``.

    Attributes
    ----------
    r, dr : callable
        ``r(s)`` radius, metres, and ``dr/ds``; both vectorized over ``s`` (metres).
    s_min, s_max : float
        Arc-length range of the profile, metres.
    """

    r: Callable[[Any], Any]
    dr: Callable[[Any], Any]
    s_min: float
    s_max: float

    @property
    def s_range(self) -> tuple[float, float]:
        return float(self.s_min), float(self.s_max)


class _PointSpline:
    """A cubic spline (``scipy.interpolate.PPoly``) fast at one point: a scalar is evaluated
    here, with PPoly's own interval search (extrapolating) and sum ``c_k + c_(k-1) t + ...``
    in the same order, so the same bits; anything else goes to the spline. The geodesic
    equations evaluate ``r`` and ``dr/ds`` at one point ~3k times per traced curve, where a
    PPoly call costs ~30 us of overhead (half of the tracing time)."""

    def __init__(self, spline: Any) -> None:
        self.spline = spline
        self.x = [float(v) for v in spline.x]
        self.c = np.ascontiguousarray(spline.c[::-1].T).tolist()  # per interval, c_k first
        self.last = len(self.x) - 2

    def __call__(self, s: Any) -> Any:
        if not isinstance(s, float):
            return self.spline(s)
        s = float(s)
        x = self.x
        if s != s:
            return float("nan")
        i = min(max(bisect_right(x, s) - 1, 0), self.last)
        t = s - x[i]
        res, z = 0.0, 1.0
        for c in self.c[i]:
            res = res + c * z
            z *= t
        return res


@dataclass
class Revolution:
    """A discrete surface of revolution rebuilt from a GG mesh, with a smooth profile.

    Attributes
    ----------
    s : (R,) float
        Arc length of parallel ``i`` along the profile, metres, ``s[0] = 0``.
    r : (R,) float
        Radius of parallel ``i``, metres.
    z : (R,) float
        Height of parallel ``i`` on the axis, metres, ``z[0] = 0``, increasing.
    phi : (C,) float
        Angle of meridian ``j``, radians, ``phi_j = j * dphi``.
    dphi : float
        Angle between consecutive meridians, radians.
    info : dict
        How ``dphi`` was chosen: ``method`` ("given", "turning", "clamped"), the embeddable range
        ``dphi_min``, ``dphi_max``, the turning estimate ``dphi_turning``, ``total_angle``,
        ``overlaps`` (total angle above 2 pi: the surface covers itself), ``max_slope``
        (``max |dr/ds|`` of the discrete profile), and the spread of the mesh edge lengths about
        the discrete model: ``parallel_spread``, ``meridian_spread`` (max relative deviation).
    """

    s: np.ndarray
    r: np.ndarray
    z: np.ndarray
    phi: np.ndarray
    dphi: float
    info: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self._r_spline = CubicSpline(self.s, self.r)
        self._z_spline = CubicSpline(self.s, self.z)
        self._dr_spline = self._r_spline.derivative()
        self._profile = Profile(r=_PointSpline(self._r_spline), dr=_PointSpline(self._dr_spline),
                                s_min=float(self.s[0]), s_max=float(self.s[-1]))

    # -- smooth profile ---------------------------------------------------------------------

    def r_of_s(self, s: Any) -> np.ndarray:
        """Radius ``r(s)``, metres: cubic spline (not-a-knot) through ``(s_i, r_i)``."""
        return self._r_spline(s)

    def dr_of_s(self, s: Any) -> np.ndarray:
        """``dr/ds`` of :meth:`r_of_s`."""
        return self._dr_spline(s)

    def z_of_s(self, s: Any) -> np.ndarray:
        """Height ``z(s)``, metres: cubic spline through ``(s_i, z_i)``."""
        return self._z_spline(s)

    @property
    def profile(self) -> Profile:
        """The smooth profile for :mod:`gridshell.gg.clairaut`."""
        return self._profile

    @property
    def total_angle(self) -> float:
        """Angle spanned by the meridians, radians."""
        return float(self.phi[-1] - self.phi[0])

    @property
    def shape(self) -> tuple[int, int]:
        return len(self.s), len(self.phi)

    def points(self, s: Any, phi: Any) -> np.ndarray:
        """Points ``(..., 3)`` of the smooth surface ``(r(s) cos phi, r(s) sin phi, z(s))``."""
        s, phi = np.broadcast_arrays(np.asarray(s, float), np.asarray(phi, float))
        r = self.r_of_s(s)
        return np.stack([r * np.cos(phi), r * np.sin(phi), self.z_of_s(s)], axis=-1)

    def grid_points(self) -> np.ndarray:
        """The discrete surface ``(R, C, 3)``: vertex ``(i, j)`` at ``(r_i cos phi_j, r_i sin phi_j,
        z_i)``, isometric (edge for edge) to the GG mesh it was rebuilt from."""
        c, sn = np.cos(self.phi), np.sin(self.phi)
        return np.stack([self.r[:, None] * c[None, :], self.r[:, None] * sn[None, :],
                         np.broadcast_to(self.z[:, None], (len(self.s), len(self.phi)))], axis=-1)

    def mesh(self, n_phi: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Quad mesh of the surface of revolution, rows = parallels (as ``P``).

        Parameters
        ----------
        n_phi : int, optional
            Number of meridians; default the mesh's own ``C`` (then the vertices are exactly
            :meth:`grid_points`), otherwise evenly spaced over the same angle.

        Returns
        -------
        V : (R * n_phi, 3) float
            Vertex ``(i, j)`` at row ``i * n_phi + j``, metres.
        F : ((R-1)(n_phi-1), 4) int64
            Quads ``[(i,j), (i,j+1), (i+1,j+1), (i+1,j)]``, oriented as the GG mesh's grid.
        """
        from gridshell.geometry.grid import grid_quads

        R, C = self.shape
        if n_phi is None or int(n_phi) == C:
            X = self.grid_points()
            n_phi = C
        else:
            n_phi = int(n_phi)
            if n_phi < 2:
                raise InputError(f"n_phi must be at least 2, got {n_phi}")
            phi = np.linspace(self.phi[0], self.phi[-1], n_phi)
            X = np.stack([self.r[:, None] * np.cos(phi)[None], self.r[:, None] * np.sin(phi)[None],
                          np.broadcast_to(self.z[:, None], (R, n_phi))], axis=-1)
        return X.reshape(-1, 3), grid_quads(R, n_phi)


# ----------------------------------------------------------------------------- rebuilding


def _check_grid(P: np.ndarray) -> np.ndarray:
    P = np.asarray(P, dtype=float)
    if P.ndim != 3 or P.shape[2] != 3 or P.shape[0] < 2 or P.shape[1] < 2:
        raise InputError(f"a GG mesh must be a point grid P (R, C, 3) with R, C >= 2, got "
                         f"shape {P.shape}")
    if not np.all(np.isfinite(P)):
        raise InputError("the GG mesh has NaN or infinite coordinates; re-run the surface design")
    return P


def edge_lengths(P: np.ndarray) -> tuple[np.ndarray, np.ndarray, dict[str, float]]:
    """Mean parallel edge lengths ``l (R,)``, mean meridian edge lengths ``h (R-1,)`` of a GG
    mesh ``P (R, C, 3)``, and the spread of the edges about those means (max relative
    deviation; zero for an exact discrete model)."""
    P = _check_grid(P)
    lp = np.linalg.norm(np.diff(P, axis=1), axis=2)      # (R, C-1)
    lm = np.linalg.norm(np.diff(P, axis=0), axis=2)      # (R-1, C)
    l, h = lp.mean(axis=1), lm.mean(axis=1)
    if np.any(l <= 0) or np.any(h <= 0):
        raise InputError("the GG mesh has a collapsed parallel or meridian (zero edge length); "
                         "re-run the surface design with a regular grid")
    spread = {"parallel_spread": float(np.max(np.abs(lp - l[:, None]) / l[:, None])),
              "meridian_spread": float(np.max(np.abs(lm - h[:, None]) / h[:, None]))}
    return l, h, spread


def embeddable_range(l: np.ndarray, h: np.ndarray) -> tuple[float, float]:
    """Range ``[dphi_min, pi]`` of meridian angles giving an embeddable profile.

    ``|r_{i+1} - r_i| <= h_i`` with ``r_i = l_i / (2 sin(dphi/2))`` holds iff
    ``2 sin(dphi/2) >= m = max_i |l_{i+1} - l_i| / h_i``; ``sin`` grows on ``(0, pi]``.

    Raises
    ------
    NoNetError
        If ``m > 2``: no scale makes the profile embeddable.
    """
    l, h = np.asarray(l, float), np.asarray(h, float)
    m = float(np.max(np.abs(np.diff(l)) / h)) if len(h) else 0.0
    if m > 2.0:
        i = int(np.argmax(np.abs(np.diff(l)) / h))
        raise NoNetError(f"no surface of revolution is isometric to this mesh: between parallels "
                         f"{i} and {i + 1} the parallel length changes by {m:.3g} times the "
                         "meridian edge (at most 2 is embeddable); re-run the surface design "
                         "with a finer grid or a smoother target")
    return 2.0 * float(np.arcsin(m / 2.0)), float(np.pi)


def parallel_turning_angle(P: np.ndarray) -> float:
    """Mean 3D turning angle between consecutive edges of the parallels ``P[i, :]``, radians.

    On a surface of revolution a parallel with equal edges is a regular polygon on its circle
    and turns by exactly ``dphi`` at each vertex, so this recovers ``dphi``; on an isometric
    deformation it is a scale estimate. Needs ``C >= 3``; returns NaN otherwise.
    """
    P = _check_grid(P)
    if P.shape[1] < 3:
        return float("nan")
    e = np.diff(P, axis=1)
    e = e / np.linalg.norm(e, axis=2, keepdims=True)
    cosang = np.clip(np.einsum("ijk,ijk->ij", e[:, :-1], e[:, 1:]), -1.0, 1.0)
    return float(np.mean(np.arccos(cosang)))


def rebuild_revolution(P: np.ndarray, angle: float | None = None) -> Revolution:
    """The surface of revolution isometric to a GG mesh (paper 4.1.2).

    ``r_i = l_i / (2 sin(dphi/2))``, ``s = [0, cumsum(h)]``, ``z_{i+1} - z_i =
    sqrt(h_i^2 - (r_{i+1} - r_i)^2)`` with ``l_i``, ``h_i`` the mean parallel / meridian edge
    lengths (see the module docstring).

    Parameters
    ----------
    P : (R, C, 3) float
        The designed GG mesh, metres: ``P[i, j]``, ``i`` the parallel, ``j`` the meridian.
    angle : float, optional
        Total angle ``(C - 1) dphi`` spanned by the meridians, radians. Default: ``dphi`` is
        the mean 3D turning angle of the parallels (:func:`parallel_turning_angle`; exact for a
        surface of revolution), clamped to the embeddable range (:func:`embeddable_range`).

    Returns
    -------
    Revolution

    Raises
    ------
    InputError
        Bad grid, or ``angle`` outside the embeddable range (the message gives the range).
    NoNetError
        No angle makes the profile embeddable.
    """
    P = _check_grid(P)
    R, C = P.shape[:2]
    l, h, spread = edge_lengths(P)
    lo, hi = embeddable_range(l, h)
    turning = parallel_turning_angle(P)
    if angle is not None:
        angle = float(angle)
        dphi = angle / (C - 1)
        if not (np.isfinite(dphi) and lo * (1 - 1e-12) <= dphi <= hi):
            raise InputError(f"angle {np.degrees(angle):.6g} deg gives an unembeddable surface "
                             f"of revolution; choose a total angle between "
                             f"{np.degrees(lo * (C - 1)):.6g} and {np.degrees(hi * (C - 1)):.6g} "
                             "deg, or leave it out to choose automatically")
        method = "given"
    else:
        dphi = turning if np.isfinite(turning) and turning > 0 else lo
        method = "turning"
        if dphi < lo or dphi > hi:
            dphi = min(max(dphi, lo), hi)
            method = "clamped"
        if dphi <= 0:  # a developable strip with constant parallels: any scale works
            dphi = min(hi, 2 * np.pi / max(C - 1, 1) / 4)
            method = "clamped"
    r = l / (2.0 * np.sin(dphi / 2.0))
    dr = np.diff(r)
    dz = np.sqrt(np.maximum(h * h - dr * dr, 0.0))
    s = np.concatenate([[0.0], np.cumsum(h)])
    z = np.concatenate([[0.0], np.cumsum(dz)])
    phi = dphi * np.arange(C)
    info = {"method": method, "dphi_min": lo, "dphi_max": hi, "dphi_turning": turning,
            "total_angle": float(dphi * (C - 1)),
            "overlaps": bool(dphi * (C - 1) > 2 * np.pi + 1e-12),
            "max_slope": float(np.max(np.abs(dr) / h)) if len(h) else 0.0, **spread}
    return Revolution(s=s, r=r, z=z, phi=phi, dphi=float(dphi), info=info)
