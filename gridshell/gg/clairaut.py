"""Geodesics on a surface of revolution and the geodesic alignable net (paper 3.3, 4.1.2).

Surface of revolution with profile ``r(s)`` (``s`` arc length along the meridian, ``phi`` the
angle about the axis): metric ``ds^2 + r(s)^2 dphi^2``. In arc length ``sigma`` a geodesic
satisfies the second-order system

    s''   = r r_s phi'^2,
    phi'' = -2 (r_s / r) s' phi',

with ``s'^2 + r^2 phi'^2 = 1``. Leaving a point at angle ``xi`` to the parallel,
``s' = sin xi`` and ``phi' = cos xi / r``; Clairaut's relation ``r cos xi = r^2 phi' = c`` is a
first integral. The second-order form has no singularity at turning points (``r = c``, where
``s' = 0``), unlike ``dphi/ds = c / (r sqrt(r^2 - c^2))``.

The net (Theorem 1): family C1 = one geodesic rotated about the axis, family C3 = its mirror
image ``phi -> -phi`` rotated; at every point of a parallel both make the same angle with the
meridian, so the crossing angle is constant along parallels.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable, Sequence

import numpy as np
from scipy.integrate import solve_ivp
from scipy.interpolate import CubicHermiteSpline

from gridshell.core.errors import InputError, NoNetError
from gridshell.gg.revolution import Profile, Revolution

__all__ = ["IntrinsicNet", "clairaut_constant_for_angle", "geodesic_net", "trace_geodesic"]

#: Relative tolerance of the geodesic integration.
RTOL = 1e-10

#: relative margin of the phi-domain in which curves are kept (see :func:`_clip`)
BOUNDARY_MARGIN = 1e-9


def _profile(rev: Revolution | Profile) -> Profile:
    if isinstance(rev, Revolution):
        return rev.profile
    if isinstance(rev, Profile):
        return rev
    raise InputError(f"expected a Revolution or a Profile, got {type(rev).__name__}")


def _rhs(profile: Profile):
    r_f, dr_f = profile.r, profile.dr

    def f(_sigma: float, y: np.ndarray) -> np.ndarray:
        s, _phi, ds, dphi = y
        r, rs = float(r_f(s)), float(dr_f(s))
        return np.array([ds, dphi, r * rs * dphi * dphi, -2.0 * rs / r * ds * dphi])

    return f


def _events(s_range: tuple[float, float], phi_range: tuple[float, float] | None):
    """Terminal events: the curve leaves ``[s_lo, s_hi]`` (or ``[phi_lo, phi_hi]``).

    Each event function is positive inside and fires only when decreasing through zero, so a
    start on the boundary going inwards does not stop at once.
    """
    s_lo, s_hi = s_range
    evs = [lambda t, y: y[0] - s_lo, lambda t, y: s_hi - y[0]]
    if phi_range is not None:
        p_lo, p_hi = phi_range
        evs += [lambda t, y: y[1] - p_lo, lambda t, y: p_hi - y[1]]
    for e in evs:
        e.terminal = True
        e.direction = -1
    return evs


def trace_geodesic(rev: Revolution | Profile, s0: float, phi0: float, xi0: float, *,
                   s_range: tuple[float, float] | None = None,
                   phi_range: tuple[float, float] | None = None,
                   max_length: float | None = None, step: float | None = None,
                   both: bool = False, derivatives: bool = False) -> tuple[np.ndarray, ...]:
    """Trace a geodesic on a surface of revolution until it leaves the domain.

    Integrates the geodesic equations (module docstring) with ``solve_ivp`` (DOP853,
    ``rtol = 1e-10``) and samples the dense output every ``step`` of arc length.

    Parameters
    ----------
    rev : Revolution or Profile
        The surface; ``rev.profile.r`` / ``dr`` give ``r(s)``, ``dr/ds``.
    s0, phi0 : float
        Start point: arc length along the profile (metres) and angle (radians).
    xi0 : float
        Angle to the parallel at the start, radians: ``xi0 = pi/2`` runs up the meridian
        (``c = 0``), ``0 < xi0 < pi/2`` turns towards growing ``phi`` while ``s`` grows,
        ``xi0 + pi`` is the opposite direction. ``c = r(s0) cos(xi0)``.
    s_range : (float, float), optional
        Domain in ``s``; default the profile's ``[s_min, s_max]``.
    phi_range : (float, float), optional
        Domain in ``phi``; default unbounded.
    max_length : float, optional
        Longest arc length traced, metres; default 50 times the profile length. A geodesic
        trapped between two turning points stops there.
    step : float, optional
        Sampling step in arc length, metres; default the profile length / 400.
    both : bool
        Trace both ways from the start point; ``sigma`` then starts negative.
    derivatives : bool
        Also return ``ds/dsigma``, ``dphi/dsigma`` at the samples (for checks of Clairaut's
        relation ``r^2 dphi/dsigma = c``).

    Returns
    -------
    s, phi, sigma : (k,) float
        Samples along the geodesic (metres, radians, metres), ``sigma`` increasing, the last
        (and with ``both`` the first) sample exactly on the domain boundary where one was hit.
    ds, dphi : (k,) float
        Only with ``derivatives``.
    """
    prof = _profile(rev)
    s_range = prof.s_range if s_range is None else (float(s_range[0]), float(s_range[1]))
    length = s_range[1] - s_range[0]
    if not length > 0:
        raise InputError(f"the s range must be non-empty, got {s_range}")
    if not (s_range[0] - 1e-12 * length <= s0 <= s_range[1] + 1e-12 * length):
        raise InputError(f"start s0 = {s0} lies outside the profile range {s_range}")
    if both:
        out = _trace_both_ways(prof, s0, phi0, xi0, s_range, phi_range, max_length, step)
    else:
        out = _trace_one_way(prof, s0, phi0, xi0, s_range, phi_range, max_length, step)
    return out if derivatives else out[:3]


def _trace_both_ways(prof: Profile, s0: float, phi0: float, xi0: float,
                     s_range: tuple[float, float], phi_range: tuple[float, float] | None,
                     max_length: float | None, step: float | None) -> tuple[np.ndarray, ...]:
    """:func:`trace_geodesic` forwards and backwards (``xi0 + pi``) from the start, joined:
    ``(s, phi, sigma, ds, dphi)`` with ``sigma`` from negative through 0 at the start."""
    fw = trace_geodesic(prof, s0, phi0, xi0, s_range=s_range, phi_range=phi_range,
                        max_length=max_length, step=step, derivatives=True)
    bw = trace_geodesic(prof, s0, phi0, xi0 + np.pi, s_range=s_range, phi_range=phi_range,
                        max_length=max_length, step=step, derivatives=True)
    return (np.concatenate([bw[0][::-1], fw[0][1:]]),
            np.concatenate([bw[1][::-1], fw[1][1:]]),
            np.concatenate([-bw[2][::-1], fw[2][1:]]),
            np.concatenate([-bw[3][::-1], fw[3][1:]]),
            np.concatenate([-bw[4][::-1], fw[4][1:]]))


def _trace_one_way(prof: Profile, s0: float, phi0: float, xi0: float,
                   s_range: tuple[float, float], phi_range: tuple[float, float] | None,
                   max_length: float | None, step: float | None) -> tuple[np.ndarray, ...]:
    """The geodesic equations integrated from ``(s0, phi0)`` at ``xi0`` to the domain's
    boundary (DOP853, :data:`RTOL`) and sampled every ``step`` of arc length:
    ``(s, phi, sigma, ds, dphi)``, metres and radians, the last sample the exact end state."""
    length = s_range[1] - s_range[0]
    max_length = 50.0 * length if max_length is None else float(max_length)
    step = length / 400.0 if step is None else float(step)
    if not step > 0:
        raise InputError(f"step must be positive, got {step}")
    r0 = float(prof.r(s0))
    if not r0 > 0:
        raise InputError(f"the profile radius at s0 = {s0} is {r0}; it must be positive")
    y0 = np.array([s0, phi0, np.sin(xi0), np.cos(xi0) / r0])
    # absolute tolerances per state in its own unit (metres, radians, 1, 1/metres): the same
    # relative accuracy on a 0.5 m model and on a 60 m hall
    atol = 1e-12 * np.array([length, 1.0, 1.0, 1.0 / length])
    sol = solve_ivp(_rhs(prof), (0.0, max_length), y0, method="DOP853", rtol=RTOL,
                    atol=atol, dense_output=True,
                    events=_events(s_range, phi_range))
    if sol.status == -1:
        raise NoNetError(f"geodesic integration failed ({sol.message}); the profile may have "
                         "a zero radius inside the domain")
    end = float(sol.t[-1])
    n = max(int(np.ceil(end / step)), 1)
    sigma = np.linspace(0.0, end, n + 1)
    Y = sol.sol(sigma)
    Y[:, -1] = sol.y[:, -1]  # the exact end state (event location)
    # clip round-off at the boundary
    s = np.clip(Y[0], s_range[0], s_range[1])
    return s, Y[1], sigma, Y[2], Y[3]


def clairaut_constant_for_angle(rev: Revolution | Profile, crossing_angle: float,
                                s_star: float) -> tuple[float, float]:
    """Clairaut constant of a net with crossing angle ``alpha`` on the parallel ``s*``.

    The families are symmetric about the meridian, so each makes ``alpha / 2`` with it and
    ``xi = pi/2 - alpha/2`` with the parallel: ``c = r(s*) cos xi = r(s*) sin(alpha/2)``.

    Parameters
    ----------
    rev : Revolution or Profile
    crossing_angle : float
        ``alpha`` in radians, ``0 < alpha < pi``.
    s_star : float
        The parallel, metres along the profile.

    Returns
    -------
    c : float
        Clairaut constant, metres.
    xi : float
        Angle to the parallel at ``s*``, radians.
    """
    prof = _profile(rev)
    a = float(crossing_angle)
    if not 0 < a < np.pi:
        raise InputError(f"the crossing angle must lie strictly between 0 and 180 degrees, got "
                         f"{np.degrees(a):.6g}")
    xi = 0.5 * np.pi - 0.5 * a
    return float(prof.r(s_star)) * float(np.cos(xi)), float(xi)


@dataclass
class IntrinsicNet:
    """A geodesic net in the coordinates ``(s, phi)`` of a surface of revolution.

    Every curve is the base geodesic ``(s(sigma), g(sigma))`` through ``(s*, 0)``
    (:attr:`base`) turned about the axis: C1 curve ``k`` is ``(s(sigma), g(sigma) + o_k)``,
    C3 curve ``l`` is ``(s(sigma), -g(sigma) + o_l)``, for ``sigma`` in the curve's own range.

    Attributes
    ----------
    curves1, curves3 : list of (k_i, 2) float
        Dense samples of the curves of families C1 and C3, columns ``(s, phi)``, clipped to
        the domain (end points exactly on its boundary), in the direction of growing
        ``sigma`` (``s`` grows through the reference parallel; ``phi`` grows along C1 curves
        and decreases along C3 curves).
    sigma1, sigma3 : list of (k_i,) float
        Arc length ``sigma`` of the base geodesic at the samples, metres, increasing.
    offsets1, offsets3 : (n1,), (n3,) float
        ``phi`` where each curve crosses the reference parallel (radians): the rotation of
        the base geodesic (C1) or of its mirror image (C3).
    base : callable
        ``base(sigma, nu=0) -> (k, 2)``: ``(s, g)`` of the base geodesic (``nu``-th derivative),
        a cubic Hermite interpolant of the integrated state (error ~ step^4).
    c : float
        Clairaut constant, metres.
    s_star : float
        Reference parallel, metres; ``xi_star`` the angle to it there, radians.
    s_range, phi_range : (float, float)
        The domain.
    """

    curves1: list[np.ndarray]
    curves3: list[np.ndarray]
    sigma1: list[np.ndarray]
    sigma3: list[np.ndarray]
    offsets1: np.ndarray
    offsets3: np.ndarray
    base: Callable[..., np.ndarray]
    c: float
    s_star: float
    xi_star: float
    s_range: tuple[float, float]
    phi_range: tuple[float, float]
    info: dict[str, Any] = field(default_factory=dict)

    def points(self, family: int, offset: float, sigma: np.ndarray) -> np.ndarray:
        """``(s, phi)`` rows ``(k, 2)`` of the curve of ``family`` (1 or 3) with ``offset``."""
        b = self.base(np.asarray(sigma, float))
        sign = 1.0 if family == 1 else -1.0
        return np.stack([b[:, 0], sign * b[:, 1] + offset], axis=1)


def _clip(base: Callable[..., np.ndarray], sigma: np.ndarray, g: np.ndarray, sign: float,
          o: float, lo: float, hi: float, step: float) -> np.ndarray | None:
    """Arc-length samples of the part of curve ``phi = sign * g(sigma) + o`` inside
    ``[lo, hi]``; ``phi`` is monotone in ``sigma`` (``g' = c / r^2 > 0``). Crossings of the
    boundary are solved by Newton on the smooth base curve."""
    # the domain grows by a relative 1e-9 on both sides: with evenly spaced offsets a whole
    # column of joints lies exactly on phi = lo and phi = hi, where both of their curves end;
    # without the margin round-off decided which of them were found (a 24 x 16 hill had 261,
    # 262 or 263 loops at 0.5, 12 and 60 m, 255 shifted by 500 m); with it both curves cross
    # the boundary and every such joint is found
    eps = BOUNDARY_MARGIN * (hi - lo)
    lo, hi = lo - eps, hi + eps
    ph = sign * g + o
    inside = (ph >= lo) & (ph <= hi)
    if not inside.any():  # misses the domain, or crosses it within one sample step
        return None
    idx = np.flatnonzero(inside)
    a, b = int(idx[0]), int(idx[-1])
    sig = list(sigma[a:b + 1])
    for end, k in ((0, a - 1), (1, b)):
        if 0 <= k < len(sigma) - 1:
            v = None
            if (ph[k] - lo) * (ph[k + 1] - lo) < 0:
                v = lo
            elif (ph[k] - hi) * (ph[k + 1] - hi) < 0:
                v = hi
            if v is not None:
                x = _solve_phi(base, sigma, ph, k, sign, o, v)
                if end == 0:
                    sig.insert(0, x)
                else:
                    sig.append(x)
    out = np.asarray(sig)
    # a boundary crossing right next to a sample would make a sliver segment: drop the sample
    if len(out) > 2 and out[1] - out[0] < 1e-3 * step:
        out = np.delete(out, 1)
    if len(out) > 2 and out[-1] - out[-2] < 1e-3 * step:
        out = np.delete(out, -2)
    return out if len(out) >= 2 and out[-1] > out[0] else None


def _solve_phi(base, sigma, ph, k, sign, o, v) -> float:
    """``sigma`` in ``[sigma_k, sigma_k+1]`` with ``sign * g(sigma) + o = v`` (Newton from the
    linear guess, kept in the bracket)."""
    s0, s1 = float(sigma[k]), float(sigma[k + 1])
    x = s0 + (v - ph[k]) / (ph[k + 1] - ph[k]) * (s1 - s0)
    for _ in range(8):
        f = sign * float(base(x)[1]) + o - v
        d = sign * float(base(x, 1)[1])
        if d == 0:
            break
        nx = min(max(x - f / d, s0), s1)
        if abs(nx - x) <= 1e-15 * max(1.0, abs(x)):
            x = nx
            break
        x = nx
    return x


def geodesic_net(rev: Revolution, *, n_lamellae: int | None = None, spacing: float | None = None,
                 crossing_angle: float = 90.0, at_parallel: float = 0.5,
                 offsets1: Sequence[float] | None = None,
                 offsets3: Sequence[float] | None = None,
                 step: float | None = None, made: int | None = None) -> IntrinsicNet:
    """A geodesic alignable net on a surface of revolution (paper 3.3, 4.1.2).

    One geodesic is traced through ``(s*, 0)`` at ``xi* = 90 - alpha/2`` degrees to the
    parallel (:func:`clairaut_constant_for_angle`), both ways, until it leaves the domain or
    its ``phi`` leaves ``[-Phi, Phi]`` (``Phi`` the total angle). Family C1 is that curve
    rotated by the offsets, family C3 its mirror ``phi -> -phi`` rotated by the offsets, each
    clipped to the domain ``[s_0, s_end] x [0, Phi]``.

    Parameters
    ----------
    rev : Revolution
    n_lamellae : int, optional
        Number of curves of each family crossing the reference parallel inside the domain
        (evenly spaced, the first and last on the domain's side meridians); further curves at
        the same spacing are added where they still reach the domain, so the net covers it.
    spacing : float, optional
        Instead of ``n_lamellae``: distance between consecutive curves of a family, metres,
        measured along the reference parallel (``r(s*) dphi``).
    crossing_angle : float
        Angle ``alpha`` between the families on the reference parallel, degrees.
    at_parallel : float
        Reference parallel as a fraction of the ``s`` range (0 first parallel, 1 last).
    offsets1, offsets3 : sequence of float, optional
        Explicit (non-uniform) ``phi`` where the curves of each family cross the reference
        parallel, radians; override ``n_lamellae`` / ``spacing`` for that family.
    step : float, optional
        Sampling step along the curves, metres (default: profile length / 400).
    made : int, optional
        Instead of ``n_lamellae``: the number of curves made per family (all that reach the
        domain, evenly spaced along the reference parallel from its first side meridian: the
        densest spacing giving at most ``made`` curves in either family,
        :func:`_spacing_for_count`). ``info["lamellae"]`` says what was asked and made.

    Returns
    -------
    IntrinsicNet
    """
    if not 0.0 <= float(at_parallel) <= 1.0:
        raise InputError(f"at_parallel must be a fraction in [0, 1], got {at_parallel}")
    s_lo, s_hi = float(rev.s[0]), float(rev.s[-1])
    p_lo, p_hi = float(rev.phi[0]), float(rev.phi[-1])
    Phi = p_hi - p_lo
    s_star = s_lo + float(at_parallel) * (s_hi - s_lo)
    c, xi = clairaut_constant_for_angle(rev, np.radians(crossing_angle), s_star)
    r_star = float(rev.r_of_s(s_star))
    step = (s_hi - s_lo) / 400.0 if step is None else float(step)
    if made is not None and (n_lamellae is not None or spacing is not None):
        raise InputError("give one of made, n_lamellae and spacing")
    dstep = (_uniform_spacing(n_lamellae if made is None else made, spacing, Phi, r_star, step)
             if offsets1 is None or offsets3 is None else None)
    base, bs, bphi, bsig = _base_geodesic(rev, s_star, xi, (s_lo, s_hi), Phi, step)
    if dstep is not None and made is not None:      # the number made per family
        dstep = _spacing_for_count(int(made), base, bsig, bphi, (p_lo, p_hi), step,
                                   step / r_star)
    o1 = (np.asarray(offsets1, float) if offsets1 is not None
          else _uniform_offsets(bphi, +1, p_lo, p_hi, dstep))
    o3 = (np.asarray(offsets3, float) if offsets3 is not None
          else _uniform_offsets(bphi, -1, p_lo, p_hi, dstep))
    if o1.ndim != 1 or o3.ndim != 1 or len(o1) == 0 or len(o3) == 0:
        raise InputError("offsets must be non-empty 1D sequences of angles (radians)")
    o1, o3 = np.sort(o1), np.sort(o3)
    c1, s1, k1 = _family(base, bsig, bphi, +1, o1, (p_lo, p_hi), step)
    c3, s3, k3 = _family(base, bsig, bphi, -1, o3, (p_lo, p_hi), step)
    if not c1 or not c3:
        raise NoNetError("no curve of the net reaches the surface; check the offsets "
                         "(radians of the surface of revolution) or the spacing")
    turning = bool(np.any(np.diff(np.sign(np.diff(bs))) != 0))
    info = {"lamellae": {"asked": None if made is None else int(made),
                         "made": [len(c1), len(c3)]},
            "base_phi_range": (float(bphi.min()), float(bphi.max())),
            "base_length": float(bsig[-1] - bsig[0]), "turning_points": turning,
            "r_star": r_star, "step": step}
    return IntrinsicNet(curves1=c1, curves3=c3, sigma1=s1, sigma3=s3, offsets1=np.asarray(k1),
                        offsets3=np.asarray(k3), base=base, c=c, s_star=s_star, xi_star=xi,
                        s_range=(s_lo, s_hi), phi_range=(p_lo, p_hi), info=info)


def _uniform_spacing(n_lamellae: int | None, spacing: float | None, Phi: float, r_star: float,
                     step: float) -> float:
    """The angle between evenly spaced curves of a family, radians: ``Phi / (n - 1)`` for
    ``n_lamellae``, ``spacing / r(s*)`` for a ``spacing`` in metres along the reference
    parallel (radius ``r_star``, metres); InputError for both or neither, too few, too wide,
    or curves closer than their sampling ``step`` (metres)."""
    if (n_lamellae is None) == (spacing is None):
        raise InputError("give either n_lamellae or spacing (not both) for evenly spaced "
                         "curves, or explicit offsets for both families")
    if n_lamellae is not None:
        if int(n_lamellae) < 2:
            raise InputError(f"n_lamellae must be at least 2, got {n_lamellae}")
        dstep = Phi / (int(n_lamellae) - 1)
    else:
        if not float(spacing) > 0:
            raise InputError(f"spacing must be positive (metres), got {spacing}")
        dstep = float(spacing) / r_star
        if dstep > Phi:
            raise InputError(f"spacing {spacing} m is wider than the reference parallel "
                             f"({r_star * Phi:.4g} m); choose a smaller spacing")
    if dstep * r_star < step:
        n_max = int(r_star * Phi / step) + 1
        raise InputError(f"the curves would be {dstep * r_star:.3g} m apart on the reference "
                         f"parallel, closer than the {step:.3g} m they are sampled at; use at "
                         f"most {n_max} lamellae or a spacing of at least {step:.3g} m")
    return dstep


def _base_geodesic(rev: Revolution, s_star: float, xi: float, s_range: tuple[float, float],
                   Phi: float, step: float
                   ) -> tuple[CubicHermiteSpline, np.ndarray, np.ndarray, np.ndarray]:
    """The base geodesic through ``(s*, 0)`` at ``xi`` to the parallel, traced both ways until
    it leaves ``s_range`` or ``[-Phi, Phi]``: its cubic Hermite interpolant ``base(sigma)``
    of ``(s, g)`` and the samples ``s``, ``g`` (radians), ``sigma`` (metres)."""
    bs, bphi, bsig, bds, bdphi = trace_geodesic(
        rev, s_star, 0.0, xi, s_range=s_range, phi_range=(-Phi, Phi), both=True,
        step=step, max_length=None, derivatives=True)
    # drop samples forming slivers next to the event end points
    keep = np.concatenate([[True], np.diff(bsig) > 1e-6 * step])
    bs, bphi, bsig, bds, bdphi = (a[keep] for a in (bs, bphi, bsig, bds, bdphi))
    base = CubicHermiteSpline(bsig, np.stack([bs, bphi], 1), np.stack([bds, bdphi], 1))
    return base, bs, bphi, bsig


def _spacing_for_count(n: int, base: Callable[..., np.ndarray], bsig: np.ndarray,
                       bphi: np.ndarray, phi_range: tuple[float, float], step: float,
                       d_min: float) -> float:
    """The angle between evenly spaced curves (radians, at least ``d_min``) for which the
    larger family has ``n`` curves reaching ``phi_range`` (or the nearest count there is).

    First the paper's spacing ``Phi / (k - 1)`` (k curves across the reference parallel, the
    domain's side meridians on a curve) for the k that makes ``n``; else the middle of the
    spacings that make ``n`` (on 600 spacings from ``d_min`` up: the count of
    :func:`_uniform_offsets`, and where it is within 2 of ``n`` the curves traced), so that
    no curve only grazes the domain's corner; where no spacing makes ``n``, the nearest
    count."""
    p_lo, p_hi = phi_range
    Phi = p_hi - p_lo

    def offsets(d: float) -> int:
        return max(len(_uniform_offsets(bphi, sg, p_lo, p_hi, d)) for sg in (+1, -1))

    def traced(d: float) -> int:
        return max(len(_family(base, bsig, bphi, sg, _uniform_offsets(bphi, sg, p_lo, p_hi, d),
                               phi_range, step)[0]) for sg in (+1, -1))

    for k in range(2, 4 * n + 2):
        d = Phi / (k - 1)
        if d < d_min:
            break
        c = offsets(d)
        if c > n:
            break
        if c == n and traced(d) == n:
            return d

    width = Phi + float(np.ptp(bphi))
    ds = np.geomspace(d_min, 2.0 * width + d_min, 600)   # the count falls from many to <= 2
    cs = np.array([offsets(d) for d in ds])
    near = np.flatnonzero(np.abs(cs - n) <= 2)            # traced where the count is close
    for i in near:
        cs[i] = traced(ds[i])
    if not np.any(cs == n):                   # n is skipped here: the nearest count there is
        near = int(np.argmin(np.abs(cs - n) + 0.5 * (cs > n)))
        n = int(cs[near])
    idx = np.flatnonzero(cs == n)
    mid = idx[len(idx) // 2]
    return float(ds[mid])


def _uniform_offsets(bphi: np.ndarray, sign: int, p_lo: float, p_hi: float,
                     dstep: float) -> np.ndarray:
    """The evenly spaced offsets (radians, ``dstep`` apart from ``p_lo``) of every curve
    ``phi = sign * g + o`` of a family that meets ``[p_lo, p_hi]``: those with ``o`` in
    ``[p_lo - max(sign g), p_hi - min(sign g)]``."""
    sg = sign * bphi
    o_lo, o_hi = p_lo - sg.max(), p_hi - sg.min()
    k_lo = int(np.ceil((o_lo - p_lo) / dstep - 1e-9))
    k_hi = int(np.floor((o_hi - p_lo) / dstep + 1e-9))
    return p_lo + dstep * np.arange(k_lo, k_hi + 1)


def _family(base: Callable[..., np.ndarray], bsig: np.ndarray, bphi: np.ndarray, sign: int,
            offsets: np.ndarray, phi_range: tuple[float, float], step: float
            ) -> tuple[list[np.ndarray], list[np.ndarray], list[float]]:
    """The curves of one family (``sign`` +1: C1, -1: C3) clipped to ``phi_range``: their
    ``(s, phi)`` samples, their ``sigma`` and the offsets of the curves that reach it."""
    curves, sigmas, kept = [], [], []
    for o in offsets:
        sig = _clip(base, bsig, bphi, float(sign), float(o), phi_range[0], phi_range[1], step)
        if sig is None:
            continue
        b = base(sig)
        curves.append(np.stack([b[:, 0], sign * b[:, 1] + o], axis=1))
        sigmas.append(sig)
        kept.append(float(o))
    return curves, sigmas, kept
