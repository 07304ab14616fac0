"""The planar axis of a flat strip and its strip coordinates ``(s, t) -> (x, y)``, millimetres.

``s`` is the arc length along the axis (the lamella's own arc length, so joint ``k`` sits at
``s = joint_s[k]``), ``t`` the signed distance along the left unit normal. Three shapes:

* :class:`LineAxis` - straight (GG geodesic and AA asymptotic axes unroll to lines);
* :class:`ArcAxis` - circular arc of signed curvature ``kappa`` (CNC, radius ``1/n``);
* :class:`CurveAxis` - a dense planar polyline (NCP collapse curve), offset along its normals.

Each shape gives ``point(s, t)``, ``tangent(s)``, the vertices and bulges of a constant-``t``
edge (exact arcs for :class:`ArcAxis`), and ``shift(s, d, t)`` - the ``s`` on the offset curve
``t`` at signed distance ``d`` from the normal line at ``s`` (exact for lines and arcs), which
the kerf offset needs.
"""
from __future__ import annotations

import numpy as np
from scipy.interpolate import CubicSpline
from shapely.geometry import LineString

from gridshell.core.errors import InputError


class LineAxis:
    """Straight axis along +x from the origin: ``point(s, t) = (s, t)``."""

    kind = "line"
    radius = None

    def point(self, s, t):
        if isinstance(s, float) and isinstance(t, float):   # one point (labels): same array
            return np.array([s, t])
        s, t = np.broadcast_arrays(np.asarray(s, float), np.asarray(t, float))
        return np.stack([s, t], axis=-1)

    def tangent(self, s):
        if isinstance(s, float):
            return np.array([1.0, 0.0])
        s = np.asarray(s, float)
        return np.stack([np.ones_like(s), np.zeros_like(s)], axis=-1)

    def edge(self, sa: float, sb: float, t: float, tol: float) -> tuple[np.ndarray, np.ndarray]:
        """Vertices ``(k,2)`` of the constant-``t`` edge from ``sa`` towards ``sb`` (``sb``
        excluded) and the bulge ``(k,)`` of the span after each vertex."""
        return self.point(sa, t)[None], np.zeros(1)

    def shift(self, s: float, d: float, t: float) -> float:
        return s + d

    def check_width(self, t_lo: float, t_hi: float, s0: float, s1: float) -> None:
        return None


class ArcAxis:
    """Circular axis from the origin along +x, turning left for ``kappa > 0``.

    ``point(s, t) = c + (1/kappa - t) (sin(kappa s), -cos(kappa s))`` with centre
    ``c = (0, 1/kappa)``; the offset curve ``t`` is the concentric arc of radius
    ``|1/kappa - t|``.
    """

    kind = "arc"

    def __init__(self, kappa: float):
        if not np.isfinite(kappa) or kappa == 0:
            raise InputError(f"arc axis needs a finite non-zero curvature, got {kappa}")
        self.kappa = float(kappa)

    @property
    def radius(self) -> float:
        return 1.0 / abs(self.kappa)

    def point(self, s, t):
        s, t = np.broadcast_arrays(np.asarray(s, float), np.asarray(t, float))
        k = self.kappa
        a = k * s
        return np.stack([np.sin(a) * (1 / k - t), 1 / k - np.cos(a) * (1 / k - t)], axis=-1)

    def tangent(self, s):
        a = self.kappa * np.asarray(s, float)
        return np.stack([np.cos(a), np.sin(a)], axis=-1)

    def edge(self, sa, sb, t, tol):
        return self.point(sa, t)[None], np.array([np.tan(self.kappa * (sb - sa) / 4.0)])

    def shift(self, s, d, t):
        k = self.kappa
        return s + float(np.arcsin(d * k / (1 - k * t))) / k

    def check_width(self, t_lo, t_hi, s0, s1):
        if max(t_lo * self.kappa, t_hi * self.kappa) >= 1.0:
            raise InputError(f"the strip (width {t_hi - t_lo:g} mm) is wider than the radius "
                             f"{self.radius:.4g} mm of its circular axis allows; reduce --width, "
                             "use --axis centre or a larger --scale")
        if abs(self.kappa) * (s1 - s0) >= 2 * np.pi:
            raise InputError(f"the circular strip ({s1 - s0:.4g} mm on radius "
                             f"{self.radius:.4g} mm) "
                             "closes on itself; use a smaller --scale or a larger sheet")


class CurveAxis:
    """Axis along a dense planar polyline ``Q (N,2)`` with arc length ``S (N,)`` (``S[0]``
    may be non-zero so that ``s`` is the lamella's own arc length)."""

    kind = "curve"
    radius = None

    def __init__(self, Q: np.ndarray, s0: float = 0.0):
        Q = np.asarray(Q, float).reshape(-1, 2)
        seg = np.linalg.norm(np.diff(Q, axis=0), axis=1)
        keep = np.concatenate([[True], seg > 1e-12])
        Q = Q[keep]
        if len(Q) < 2:
            raise InputError("a curved strip axis needs at least two distinct points")
        self.Q = Q
        self.S = s0 + np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(Q, axis=0), axis=1))])
        T = np.diff(Q, axis=0)
        T /= np.linalg.norm(T, axis=1, keepdims=True)
        # vertex normals: left normal of the averaged neighbouring segment directions
        Tv = np.concatenate([T[:1], T[:-1] + T[1:], T[-1:]])
        Tv /= np.linalg.norm(Tv, axis=1, keepdims=True)
        self.T = Tv
        self.N = np.stack([-Tv[:, 1], Tv[:, 0]], axis=1)
        # signed curvature at vertices: turning angle / mean adjacent segment length
        ang = np.arctan2(T[:-1, 0] * T[1:, 1] - T[:-1, 1] * T[1:, 0],
                         np.einsum("ij,ij->i", T[:-1], T[1:]))
        ls = np.diff(self.S)
        k = ang / (0.5 * (ls[:-1] + ls[1:]))
        self.K = np.concatenate([[k[0] if len(k) else 0.0], k, [k[-1] if len(k) else 0.0]])

    def _interp(self, A, s):
        s = np.asarray(s, float)
        return np.stack([np.interp(s, self.S, A[:, j]) for j in range(A.shape[1])], axis=-1)

    def tangent(self, s):
        T = self._interp(self.T, s)
        return T / np.linalg.norm(T, axis=-1, keepdims=True)

    def point(self, s, t):
        s, t = np.broadcast_arrays(np.asarray(s, float), np.asarray(t, float))
        Nn = self._interp(self.N, s)
        Nn /= np.linalg.norm(Nn, axis=-1, keepdims=True)
        return self._interp(self.Q, s) + t[..., None] * Nn

    def edge(self, sa, sb, t, tol):
        lo, hi = min(sa, sb), max(sa, sb)
        inner = self.S[(self.S > lo + 1e-9) & (self.S < hi - 1e-9)]
        if sb < sa:
            inner = inner[::-1]
        s = np.concatenate([[sa], inner, [sb]])
        P = self.point(s, t)
        if tol > 0 and len(P) > 2:   # drop vertices the chord tolerance does not need
            P = np.asarray(LineString(P).simplify(tol, preserve_topology=False).coords)
        return P[:-1], np.zeros(len(P) - 1)

    def shift(self, s, d, t):
        k = float(np.interp(s, self.S, self.K))
        return s + d / (1 - k * t)

    def check_width(self, t_lo, t_hi, s0, s1):
        m = (self.S >= s0 - 1e-9) & (self.S <= s1 + 1e-9)
        k = self.K[m]
        worst = max(np.max(k * t_lo, initial=0.0), np.max(k * t_hi, initial=0.0))
        if worst >= 0.98:
            r = 1 / np.max(np.abs(k))
            raise InputError(f"the collapse curve's radius of curvature ({r:.4g} mm at this scale) "
                             f"is too small for a {t_hi - t_lo:g} mm wide strip: its offset edge "
                             "would cross itself; reduce --width (or use --axis centre) or "
                             "increase --scale")


class DenseCurve:
    """A smooth planar curve through polyline points ``P (k,2)`` (mm), sampled densely.

    The points are interpolated by a cubic spline in their chord length ``tau`` (exact on a
    straight polyline), sampled at about ``step`` mm, and extended by tangent lines beyond
    both ends. ``arclength(tau)`` maps a chord-length position on ``P`` (how design.json
    measures ``collapse_s``) to the arc length of the dense curve.
    """

    def __init__(self, P: np.ndarray, step: float = 0.25):
        P = np.asarray(P, float).reshape(-1, 2)
        seg = np.linalg.norm(np.diff(P, axis=0), axis=1)
        P = P[np.concatenate([[True], seg > 1e-12])]
        if len(P) < 2:
            raise InputError("the collapse curve has fewer than two distinct points; "
                             "re-run the NCP design")
        tau = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(P, axis=0), axis=1))])
        n = max(int(np.ceil(tau[-1] / step)), 8 * len(P)) + 1
        tt = np.linspace(0.0, tau[-1], n)
        if len(P) >= 4:
            D = CubicSpline(tau, P, bc_type="natural")(tt)
        else:
            D = np.stack([np.interp(tt, tau, P[:, j]) for j in range(2)], axis=1)
        self.tau = tt
        self.D = D
        self.C = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(D, axis=0), axis=1))])
        self.step = tau[-1] / (n - 1)

    @property
    def length(self) -> float:
        return float(self.C[-1])

    def arclength(self, tau: float) -> float:
        """Arc length of the dense curve at chord-length position ``tau`` (linear outside)."""
        if tau < 0:
            return float(tau)
        if tau > self.tau[-1]:
            return float(self.C[-1] + tau - self.tau[-1])
        return float(np.interp(tau, self.tau, self.C))

    def piece(self, c0: float, c1: float) -> np.ndarray:
        """Points ``(m,2)`` of the curve between arc lengths ``c0 < c1``: the dense samples
        in between (so a piece's points do not depend on where it starts) and both ends;
        beyond the curve's ends it continues along its end tangents (straight)."""
        C = self.C
        inner = C[(C > c0) & (C < c1)]
        c = np.unique(np.concatenate([[c0], inner, [c1]]))
        out = np.stack([np.interp(c, C, self.D[:, j]) for j in range(2)], axis=1)
        for end, sel in ((0, c < 0), (-1, c > C[-1])):
            if sel.any():
                i, j = (0, 1) if end == 0 else (-2, -1)
                T = self.D[j] - self.D[i]
                T /= np.linalg.norm(T)
                out[sel] = self.D[end] + (c[sel] - C[end])[:, None] * T
        return out
