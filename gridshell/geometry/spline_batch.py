"""Many small cubic splines at once, with the numbers of ``scipy.interpolate.CubicSpline``
bit for bit (scipy's formulas, one tridiagonal solve for all). Pure numpy and scipy."""
from __future__ import annotations

import numpy as np

_ROWS = 1024                                               # evaluation chunk, fits in cache


def cubic_splines_at(xs: list[np.ndarray], ys: list[np.ndarray], ss: list[np.ndarray]
                     ) -> np.ndarray:
    """The splines ``cs = CubicSpline(xs[i], ys[i], axis=0, bc_type="natural" if k > 2 else
    "not-a-knot")`` through values ``ys[i] (k,q)`` at knots ``xs[i] (k,)`` (finite, strictly
    increasing, ``k >= 2``; the same ``q`` for all), continued linearly beyond the end knots,
    at ``ss[i] (p,)``: ``cs(t) + (s - t) * cs(end, 1)`` with ``t`` the ``s`` clipped to the
    knots and ``end`` the end knot on the side of ``s``; all splines' rows stacked,
    ``(sum p, q)``, units of ``ys``.

    The blocks of one banded system are scipy's systems with zero coupling entries, which
    LAPACK gtsv eliminates without changing a nonzero number; the evaluation is scipy's
    ``_ppoly.evaluate`` (``evaluate_poly1``) term by term, so the floats are scipy's."""
    from scipy.linalg import solve_banded

    k = np.array([len(x) for x in xs])
    end = np.cumsum(k) - 1
    start = end - k + 1
    x = np.concatenate(xs).astype(float)
    y = np.concatenate(ys).astype(float)
    N, q = y.shape
    inner = np.ones(N - 1, dtype=bool)
    inner[end[:-1]] = False                                # intervals across two splines
    dx = np.where(inner, np.diff(x), 1.0)
    dxr = dx[:, None]
    slope = np.diff(y, axis=0) / dxr
    # CubicSpline.__init__: the slopes s at the knots, banded rows upper, diagonal, lower
    ab = np.zeros((3, N))
    b = np.empty((N, q))
    mid = np.ones(N, dtype=bool)
    mid[start] = mid[end] = False
    i = np.flatnonzero(mid)
    ab[1, i] = 2 * (dx[i - 1] + dx[i])
    ab[0, i + 1] = dx[i - 1]
    ab[2, i - 1] = dx[i]
    b[i] = 3 * (dxr[i] * slope[i - 1] + dxr[i - 1] * slope[i])
    nat = k > 2
    a, e = start[nat], end[nat]                            # natural: bc (2, 0.0) at both ends
    zero = np.zeros((len(a), q))
    ab[1, a] = 2 * dx[a]
    ab[0, a + 1] = dx[a]
    b[a] = -0.5 * zero * (dx[a] ** 2)[:, None] + 3 * (y[a + 1] - y[a])
    ab[1, e] = 2 * dx[e - 1]
    ab[2, e - 1] = dx[e - 1]
    b[e] = 0.5 * zero * (dx[e - 1] ** 2)[:, None] + 3 * (y[e] - y[e - 1])
    a, e = start[~nat], end[~nat]                          # two knots: bc (1, slope[0]) at both
    ab[1, a] = ab[1, e] = 1.0
    b[a] = b[e] = slope[a]
    s = solve_banded((1, 1), ab, b, overwrite_ab=True, overwrite_b=True, check_finite=False)
    # CubicHermiteSpline.__init__: each interval's coefficients of (x - x[j])^3 .. ^0
    s = np.ascontiguousarray(s)                            # LAPACK's is Fortran-ordered
    t = (s[:-1] + s[1:] - 2 * slope) / dxr
    c0, c1, c2, c3 = np.stack([t / dxr, (slope - s[:-1]) / dxr - t, s[:-1], y[:-1]])
    # the first derivative at the end knots: intervals start and end - 1, offsets 0 and dx
    j = np.stack([start, end - 1], axis=1).reshape(-1)
    u = (x[np.stack([start, end], axis=1).reshape(-1)] - x[j])[:, None]
    slopes = ((0.0 + c2[j]) + c1[j] * u * 2.0) + c0[j] * (u * u) * 3.0   # (2 * splines, q)
    # each point's interval j: x[j] <= t < x[j+1], the last one closed on the right
    T, iv, side = [], [], []
    for n, (xi, si) in enumerate(zip(xs, ss)):
        ti = np.clip(si, xi[0], xi[-1])
        T.append(ti)
        iv.append(start[n] + np.minimum(np.searchsorted(xi, ti, side="right") - 1, k[n] - 2))
        side.append(2 * n + 1 - (si < xi[0]))              # the slope at x[0] below, else x[-1]
    S, T, iv, side = (np.concatenate(v) for v in ([np.asarray(v, float) for v in ss], T, iv, side))
    out = np.empty((len(S), q))
    for r in range(0, len(S), _ROWS):
        w = slice(r, r + _ROWS)
        j = iv[w]
        u = (T[w] - x[j])[:, None]
        uu = u * u
        out[w] = ((((0.0 + c3[j]) + c2[j] * u) + c1[j] * uu) + c0[j] * (uu * u)) \
            + (S[w] - T[w])[:, None] * slopes[side[w]]
    return out
