"""Analytic surface families of the corpus, in canonical units (a patch about 1-3 units wide).

Every family is a function ``make_<family>(rng) -> Shape`` drawing its coefficients from a
``numpy.random.Generator``; the shape's ``f(a, b)`` maps the unit square to points ``(..., 3)``:
``a`` runs along the grid's rows index ``i`` (the grid's columns ``P[:, j]`` are the lines
``b = const``), ``b`` along its columns index ``j``. Columns are the meridians where the
surface has them (surfaces of revolution, catenoid associates, pseudosphere, Dini).

Canonical placement (done by :mod:`gridshell.corpus.registry`, not here): each patch is
built roof-like, its normal at the centre about +z, so that the corpus' orientations are the
random rotations applied afterwards.

Closed forms (``Shape.closed``), in canonical units, for the tests of the generator:

- ``"K"``: Gaussian curvature ``K(a, b)``;
- ``"metric"``: ``(E, F, G)(a, b)``, the first fundamental form in the ``(a, b)`` parameters
  (catenoid associates: the catenoid's metric, whatever the angle).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

__all__ = ["FAMILIES", "Shape", "height_terms"]

Fn = Callable[[np.ndarray, np.ndarray], np.ndarray]


@dataclass(frozen=True)
class Shape:
    """A canonical surface patch.

    family : family name (a key of :data:`FAMILIES`)
    params : the drawn coefficients (JSON-able numbers)
    f : ``f(a, b) -> (..., 3)`` over the unit square, canonical units
    revolution : isometric to a surface of revolution, exactly (by construction or theorem)
    closed : closed-form extras (see the module docstring)
    """

    family: str
    params: dict[str, Any]
    f: Fn = field(repr=False)
    revolution: bool
    closed: dict[str, Callable[..., Any]] = field(default_factory=dict, repr=False)


def _u(rng: np.random.Generator, lo: float, hi: float) -> float:
    return float(rng.uniform(lo, hi))


# ----------------------------------------------------------------------------- revolution


def _revolution_f(r: Callable, z: Callable, half_angle: float) -> Fn:
    """Axis along y, the patch around the top: ``(r(t) sin phi, z(t), r(t) cos phi)``, ``t = a``,
    ``phi = half_angle (2 b - 1)``; rows are parallels, columns meridians."""
    def f(a: np.ndarray, b: np.ndarray) -> np.ndarray:
        a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
        phi = half_angle * (2 * b - 1)
        ra = r(a)[0]
        return np.stack([ra * np.sin(phi), z(a)[0], ra * np.cos(phi)], axis=-1)
    return f


def _revolution_K(r: Callable, z: Callable) -> Callable:
    """``K = z' (r' z'' - r'' z') / (r (r'^2 + z'^2)^2)`` of the profile ``(r(t), z(t))``."""
    def K(a: np.ndarray, b: np.ndarray) -> np.ndarray:
        a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
        r0, r1, r2 = r(a)
        z0, z1, z2 = z(a)
        return z1 * (r1 * z2 - r2 * z1) / (r0 * (r1**2 + z1**2) ** 2)
    return K


def make_revolution(rng: np.random.Generator) -> Shape:
    """A vault cut from a surface of revolution with a random profile ``r(t)``, ``z = H t``:
    ``vase`` (``1 + A sin(w t + p)``, K of both signs), ``neck`` (``sqrt(r0^2 + k^2 (t -
    t0)^2)``, a hyperboloid-like waist, K < 0) or ``barrel`` (``1 - A (2 t - 1)^2 + B t``,
    K > 0)."""
    kind = str(rng.choice(["vase", "neck", "barrel"]))
    H = _u(rng, 0.9, 1.8)
    p: dict[str, Any] = {"profile": kind, "H": H}
    if kind == "vase":
        A, w, ph = _u(rng, 0.1, 0.3), _u(rng, 1.5, 4.0), _u(rng, 0.0, 2 * np.pi)
        p.update(A=A, w=w, phase=ph)

        def r(t):
            return (1 + A * np.sin(w * t + ph), A * w * np.cos(w * t + ph),
                    -A * w * w * np.sin(w * t + ph))
    elif kind == "neck":
        r0, k, t0 = _u(rng, 0.5, 0.9), _u(rng, 0.8, 1.6), _u(rng, 0.3, 0.7)
        p.update(r0=r0, k=k, t0=t0)

        def r(t):
            q = np.sqrt(r0**2 + k**2 * (t - t0) ** 2)
            return q, k**2 * (t - t0) / q, k**2 * r0**2 / q**3
    else:
        A, B = _u(rng, 0.15, 0.35), _u(rng, -0.2, 0.2)
        p.update(A=A, B=B)

        def r(t):
            return 1 - A * (2 * t - 1) ** 2 + B * t, -4 * A * (2 * t - 1) + B, -8 * A + 0 * t

    def z(t):
        return H * t, H + 0 * t, 0 * t
    # the parallel at mid-height 0.6-1.6 times as long as the meridian
    half = float(np.clip(_u(rng, 0.6, 1.6) * H / (2 * r(np.array(0.5))[0]), 0.3, 1.3))
    p["half_angle"] = half
    return Shape("revolution", p, _revolution_f(r, z, half), True,
                 {"K": _revolution_K(r, z)})


def make_pseudosphere(rng: np.random.Generator) -> Shape:
    """A canopy of the pseudosphere of radius 1 (``K = -1``): profile ``r = sech s``,
    ``z = s - tanh s``, ``s`` in ``[s0, s0 + L]``."""
    s0, L = _u(rng, 0.35, 0.7), _u(rng, 0.8, 1.3)
    half = _u(rng, 0.6, 1.0)

    def r(t):
        s = s0 + L * t
        return 1 / np.cosh(s), -L * np.tanh(s) / np.cosh(s), \
            L * L * (np.tanh(s) ** 2 - 1 / np.cosh(s) ** 2) / np.cosh(s)

    def z(t):
        s = s0 + L * t
        return s - np.tanh(s), L * np.tanh(s) ** 2, 2 * L * L * np.tanh(s) / np.cosh(s) ** 2
    return Shape("pseudosphere", {"s0": s0, "L": L, "half_angle": half},
                 _revolution_f(r, z, half), True,
                 {"K": lambda a, b: -1.0 + 0 * np.asarray(a, float) * np.asarray(b, float)})


def make_near_pseudosphere(rng: np.random.Generator) -> Shape:
    """The pseudosphere canopy perturbed: ``profile`` (``r = sech s (1 + e sin(w s + p))``, still
    a surface of revolution, K near -1) or ``bump`` (a Gaussian bump of relative height ``e``
    added in z: not a surface of revolution)."""
    base = make_pseudosphere(rng)
    kind = str(rng.choice(["profile", "bump"]))
    e = _u(rng, 0.01, 0.025) if kind == "profile" else _u(rng, 0.004, 0.01)
    p = dict(base.params, variant=kind, e=e)
    s0, L, half = p["s0"], p["L"], p["half_angle"]
    if kind == "profile":
        w, ph = _u(rng, 1.5, 3.0), _u(rng, 0, 2 * np.pi)
        p.update(w=w, phase=ph)

        def r(t):
            s = s0 + L * t
            g, g1 = 1 / np.cosh(s), -np.tanh(s) / np.cosh(s)
            g2 = (np.tanh(s) ** 2 - 1 / np.cosh(s) ** 2) / np.cosh(s)
            m, m1, m2 = (1 + e * np.sin(w * s + ph), e * w * np.cos(w * s + ph),
                         -e * w * w * np.sin(w * s + ph))
            return g * m, L * (g1 * m + g * m1), L * L * (g2 * m + 2 * g1 * m1 + g * m2)

        def z(t):
            s = s0 + L * t
            return s - np.tanh(s), L * np.tanh(s) ** 2, 2 * L * L * np.tanh(s) / np.cosh(s) ** 2
        return Shape("near-pseudosphere", p, _revolution_f(r, z, half), True,
                     {"K": _revolution_K(r, z)})
    ca, cb, sw = _u(rng, 0.3, 0.7), _u(rng, 0.3, 0.7), _u(rng, 0.35, 0.5)
    p.update(ca=ca, cb=cb, width=sw)
    f0 = base.f

    def f(a, b):
        P = f0(a, b)
        a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
        bump = e * np.exp(-((a - ca) ** 2 + (b - cb) ** 2) / sw**2)
        return P + np.stack([0 * bump, 0 * bump, bump], axis=-1)
    return Shape("near-pseudosphere", p, f, False)


def make_dini(rng: np.random.Generator) -> Shape:
    """A patch of Dini's surface ``(sin v sin u, cos v + ln tan(v/2) + c u, sin v cos u)``
    (the pseudosphere twisted along its axis y; ``K = -1 / (1 + c^2)``), ``v`` in ``[v0, v1]``
    inside ``(0, pi/2)``; helicoidal, hence isometric to a surface of revolution (Bour)."""
    c = _u(rng, 0.1, 0.3)
    v0 = _u(rng, 0.45, 0.6)
    v1 = v0 + _u(rng, 0.45, 0.6)
    half = _u(rng, 0.4, 0.7)

    def f(a, b):
        a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
        v, u = v0 + (v1 - v0) * a, half * (2 * b - 1)
        return np.stack([np.sin(v) * np.sin(u), np.cos(v) + np.log(np.tan(v / 2)) + c * u,
                         np.sin(v) * np.cos(u)], axis=-1)
    return Shape("dini", {"c": c, "v0": v0, "v1": v1, "half_angle": half}, f, True,
                 {"K": lambda a, b: -1 / (1 + c * c) + 0 * np.asarray(a, float)
                  * np.asarray(b, float)})


def make_associate(rng: np.random.Generator) -> Shape:
    """A patch of the catenoid-helicoid associate family at angle ``theta`` (0: helicoid,
    pi/2: catenoid): ``cos(theta) (sinh v sin u, -sinh v cos u, u) + sin(theta) (cosh v cos u,
    cosh v sin u, v)``, ``v = v0 + 2 V a``, ``u = U (2 b - 1)``; turned so that the common
    normal at ``u = v = 0`` is +z. Isometric to the catenoid for every theta: ``E = G =
    cosh^2 v``, ``F = 0`` in ``(u, v)``; ``K = -1 / cosh^4 v``."""
    th = _u(rng, 0.0, np.pi / 2)
    V = _u(rng, 0.45, 0.8)
    v0 = _u(rng, -0.3, 0.3) - V
    U = _u(rng, 0.6, 1.1)

    def f(a, b):
        a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
        v, u = v0 + 2 * V * a, U * (2 * b - 1)
        X = np.cos(th) * np.stack([np.sinh(v) * np.sin(u), -np.sinh(v) * np.cos(u), u], -1) \
            + np.sin(th) * np.stack([np.cosh(v) * np.cos(u), np.cosh(v) * np.sin(u), v], -1)
        # old (x, y, z) -> new (y, z, x): the normal at the centre, old +x, becomes +z
        return X[..., [1, 2, 0]]

    def metric(a, b):
        a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
        ch2 = np.cosh(v0 + 2 * V * a) ** 2
        return ch2 * (2 * V) ** 2, 0 * ch2, ch2 * (2 * U) ** 2

    def K(a, b):
        a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
        return -1 / np.cosh(v0 + 2 * V * a) ** 4
    return Shape("associate", {"theta": th, "v0": v0, "V": V, "U": U}, f, True,
                 {"K": K, "metric": metric})


# ----------------------------------------------------------------------------- height fields


def height_terms(terms: list[tuple]) -> Callable:
    """``h(x, y) -> (h, hx, hy, hxx, hxy, hyy)`` of a sum of terms, closed form:
    ``("poly", c, p, q)``: ``c x^p y^q``; ``("gauss", A, x0, y0, sx, sy)``:
    ``A exp(-(x-x0)^2/sx^2 - (y-y0)^2/sy^2)``; ``("ellipsoid", a, b, c)``:
    ``c sqrt(1 - x^2/a^2 - y^2/b^2)``."""
    def h(x, y):
        out = [np.zeros(np.broadcast(x, y).shape) for _ in range(6)]
        for t in terms:
            if t[0] == "poly":
                _, c, p, q = t

                def m(k, e):  # d^k/dx^k of x^e, as coefficient and power
                    co = 1.0
                    for i in range(k):
                        co *= e - i
                    return co, max(e - k, 0)

                def mono(kx, ky):
                    cx, ex = m(kx, p)
                    cy, ey = m(ky, q)
                    return c * cx * cy * x**ex * y**ey
                parts = [mono(0, 0), mono(1, 0), mono(0, 1), mono(2, 0), mono(1, 1), mono(0, 2)]
            elif t[0] == "gauss":
                _, A, x0, y0, sx, sy = t
                g = A * np.exp(-(x - x0) ** 2 / sx**2 - (y - y0) ** 2 / sy**2)
                gx, gy = -2 * (x - x0) / sx**2, -2 * (y - y0) / sy**2
                parts = [g, g * gx, g * gy, g * (gx * gx - 2 / sx**2), g * gx * gy,
                         g * (gy * gy - 2 / sy**2)]
            elif t[0] == "ellipsoid":
                _, ea, eb, ec = t
                A, B = ea * ea, eb * eb
                g = 1 - x * x / A - y * y / B
                s = np.sqrt(g)
                parts = [ec * s, -ec * x / (A * s), -ec * y / (B * s),
                         -ec / (A * s) - ec * x * x / (A * A * s**3), -ec * x * y / (A * B * s**3),
                         -ec / (B * s) - ec * y * y / (B * B * s**3)]
            else:  # pragma: no cover - a programming error in this module
                raise ValueError(f"unknown height term {t[0]!r}")
            for o, v in zip(out, parts):
                o += v
        return out
    return h


def _height_shape(family: str, params: dict, terms: list[tuple], X: float, Y: float,
                  revolution: bool = False) -> Shape:
    """The graph of ``h`` over ``[-X, X] x [-Y, Y]``, ``x`` along ``b`` (columns index ``j``),
    ``y`` along ``a`` (rows), so that the grid's faces face +z."""
    h = height_terms(terms)

    def f(a, b):
        a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
        x, y = X * (2 * b - 1), Y * (2 * a - 1)
        return np.stack([x, y, h(x, y)[0]], axis=-1)

    def K(a, b):
        a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
        _, hx, hy, hxx, hxy, hyy = h(X * (2 * b - 1), Y * (2 * a - 1))
        return (hxx * hyy - hxy**2) / (1 + hx**2 + hy**2) ** 2
    p = dict(params, X=X, Y=Y, terms=[list(t) for t in terms])
    return Shape(family, p, f, revolution, {"K": K, "height": h})


def make_hill(rng: np.random.Generator) -> Shape:
    """A freeform hill: 2-4 Gaussian bumps of random heights, centres and widths on a gentle
    slope (K of both signs)."""
    Y = _u(rng, 0.55, 1.0)
    n = int(rng.integers(2, 5))
    terms: list[tuple] = [("gauss", _u(rng, 0.25, 0.5), 0.0, 0.0, _u(rng, 0.7, 1.0),
                           _u(rng, 0.6, 0.9) * Y)]
    for _ in range(n - 1):
        terms.append(("gauss", _u(rng, 0.05, 0.2), _u(rng, -0.6, 0.6), _u(rng, -0.6, 0.6) * Y,
                      _u(rng, 0.3, 0.6), _u(rng, 0.3, 0.6) * Y))
    terms.append(("poly", _u(rng, -0.08, 0.08), 1, 0))
    return _height_shape("hill", {"bumps": n}, terms, 1.0, Y)


def make_dome(rng: np.random.Generator) -> Shape:
    """A freeform dome ``h (1 - p x^2 - q y^2) + cubic terms``, ``p != q`` (K > 0 everywhere;
    the principal curvatures differ by a factor 2-3.5 at the crown, but the elliptic
    paraboloid's two umbilic points may fall on the patch)."""
    Y = _u(rng, 0.55, 1.0)
    h = _u(rng, 0.35, 0.6)
    rho = _u(rng, 2.0, 3.5) ** float(rng.choice([1.0, -1.0]))  # q / p
    p = _u(rng, 0.7, 1.0) / (1 + rho * Y * Y)                  # p X^2 + q Y^2 in [0.7, 1]
    q = rho * p
    terms = [("poly", h, 0, 0), ("poly", -h * p, 2, 0), ("poly", -h * q, 0, 2),
             ("poly", _u(rng, -0.05, 0.05), 3, 0), ("poly", _u(rng, -0.05, 0.05), 1, 2),
             ("poly", _u(rng, -0.05, 0.05), 1, 0)]
    return _height_shape("dome", {}, terms, 1.0, Y)


def make_ridge(rng: np.random.Generator) -> Shape:
    """A ridge: a Gaussian crest ``h exp(-y^2/w^2)`` along ``x``, its height modulated along
    ``x`` by three Gaussians of the same cross-section (relative amounts ``e``, ``g``); nearly
    developable, K of both signs."""
    Y = _u(rng, 0.6, 1.0)
    h, w = _u(rng, 0.25, 0.45), _u(rng, 0.45, 0.75) * Y
    e, g = _u(rng, 0.1, 0.3), _u(rng, -0.15, 0.15)
    terms = [("gauss", h, 0.0, 0.0, 1e6, w), ("gauss", -h * e, 0.0, 0.0, 1.0, w),
             ("gauss", h * g, 0.8, 0.0, 0.9, w), ("gauss", -h * g, -0.8, 0.0, 0.9, w)]
    return _height_shape("ridge", {"h": h, "w": w, "e": e, "g": g}, terms, 1.0, Y)


def make_saddle(rng: np.random.Generator) -> Shape:
    """A saddle ``p x^2 - q y^2 + r x y + small cubic terms`` (K < 0 everywhere)."""
    Y = _u(rng, 0.6, 1.0)
    p, q = _u(rng, 0.2, 0.45), _u(rng, 0.2, 0.45) / Y
    r = _u(rng, -0.15, 0.15)
    terms = [("poly", p, 2, 0), ("poly", -q, 0, 2), ("poly", r, 1, 1),
             ("poly", _u(rng, -0.04, 0.04), 3, 0), ("poly", _u(rng, -0.04, 0.04), 0, 3),
             ("poly", _u(rng, -0.05, 0.05), 1, 0)]
    return _height_shape("saddle", {}, terms, 1.0, Y)


def make_monkey(rng: np.random.Generator) -> Shape:
    """A monkey saddle ``c Re((x + i y) e^{-i t})^3 + tilt`` (K <= 0, a flat umbilic point at
    the centre)."""
    Y = _u(rng, 0.7, 1.0)
    c, t = _u(rng, 0.2, 0.35), _u(rng, 0.0, 2 * np.pi / 3)
    # Re (x + i y)^3 e^{-3 i t} = cos3t (x^3 - 3 x y^2) + sin3t (3 x^2 y - y^3)
    c3, s3 = c * np.cos(3 * t), c * np.sin(3 * t)
    terms = [("poly", c3, 3, 0), ("poly", -3 * c3, 1, 2), ("poly", 3 * s3, 2, 1),
             ("poly", -s3, 0, 3), ("poly", _u(rng, -0.05, 0.05), 0, 1)]
    return _height_shape("monkey", {"c": c, "t": t}, terms, 1.0, Y)


def make_sphere_cap(rng: np.random.Generator) -> Shape:
    """A spherical cap of radius 1 over a rectangle ``[-X, X] x [-Y, Y]`` (``K = 1``; every
    point umbilic)."""
    X = _u(rng, 0.5, 0.7)
    Y = X * _u(rng, 0.6, 1.0)
    terms = [("ellipsoid", 1.0, 1.0, 1.0)]
    return _height_shape("sphere-cap", {"R": 1.0}, terms, X, Y, revolution=True)


def make_near_sphere(rng: np.random.Generator) -> Shape:
    """A cap of the ellipsoid ``x^2/a^2 + y^2/b^2 + z^2/c^2 = 1`` near the unit sphere (axes
    ratios 1.25-1.6; ``K = 1 / (a^2 b^2 c^2 (x^2/a^4 + y^2/b^4 + z^2/c^4)^2)``, no umbilic on
    the cap)."""
    ea = 1.0
    eb = _u(rng, 1.25, 1.6)
    ec = _u(rng, 0.7, 1.3)
    X = _u(rng, 0.45, 0.65)
    Y = X * _u(rng, 0.8, 1.3)
    terms = [("ellipsoid", ea, eb, ec)]
    s = _height_shape("near-sphere", {"a": ea, "b": eb, "c": ec}, terms, X, Y)
    return s


# ---- the shapes architects draw: domes and hills with an umbilic or near-umbilic top ------

def _turned_shape(family: str, params: dict, terms: list[tuple], X: float, Y: float,
                  turn: float) -> Shape:
    """The graph of the height terms over the rectangle ``[-X, X] x [-Y, Y]`` turned by
    ``turn`` (rad) in the plane: the bumps' axes are not the patch's (a user's hill drawn at
    an angle to its footprint). Closed-form K as for :func:`_height_shape` (K is invariant
    under a turn of the plane)."""
    h = height_terms(terms)
    c, s = np.cos(turn), np.sin(turn)

    def local(a, b):
        a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
        x, y = X * (2 * b - 1), Y * (2 * a - 1)
        return x, y, c * x + s * y, -s * x + c * y

    def f(a, b):
        x, y, xl, yl = local(a, b)
        return np.stack([x, y, h(xl, yl)[0]], axis=-1)

    def K(a, b):
        _, _, xl, yl = local(a, b)
        _, hx, hy, hxx, hxy, hyy = h(xl, yl)
        return (hxx * hyy - hxy**2) / (1 + hx**2 + hy**2) ** 2
    p = dict(params, X=X, Y=Y, turn=turn, terms=[list(t) for t in terms])
    return Shape(family, p, f, False, {"K": K, "height": h})


def make_bump(rng: np.random.Generator) -> Shape:
    """A single Gaussian bump ``h exp(-x'^2/sx^2 - y'^2/sy^2)`` on a flat skirt, its axes
    turned against the footprint (K > 0 on the crown, K < 0 on the skirt; the crown is
    near-umbilic when ``sx`` is close to ``sy``)."""
    Y = _u(rng, 0.6, 1.0)
    sx = _u(rng, 0.45, 0.8)
    sy = sx * _u(rng, 0.8, 1.25)
    terms = [("gauss", _u(rng, 0.3, 0.6), 0.0, 0.0, sx, sy * Y)]
    return _turned_shape("bump", {"sx": sx, "sy": sy}, terms, 1.0, Y, _u(rng, 0.0, np.pi))


def make_round_dome(rng: np.random.Generator) -> Shape:
    """A paraboloid of revolution ``h (1 - ((x-x0)^2 + (y-y0)^2) / R^2)``, its crown off the
    centre of the footprint: the dome of a pavilion, an umbilic point at the crown
    (``k1 = k2 = 2h/R^2`` there), K > 0 everywhere, exactly of revolution."""
    Y = _u(rng, 0.6, 1.0)
    h = _u(rng, 0.3, 0.6)
    x0, y0 = _u(rng, -0.2, 0.2), _u(rng, -0.2, 0.2) * Y
    R2 = 1.0 + Y * Y
    terms = [("poly", h * (1 - (x0 * x0 + y0 * y0) / R2), 0, 0), ("poly", -h / R2, 2, 0),
             ("poly", -h / R2, 0, 2), ("poly", 2 * h * x0 / R2, 1, 0),
             ("poly", 2 * h * y0 / R2, 0, 1)]
    return _height_shape("round-dome", {"h": h, "x0": x0, "y0": y0}, terms, 1.0, Y,
                         revolution=True)


def make_asym_hill(rng: np.random.Generator) -> Shape:
    """An asymmetric hill: a main bump off the centre, a shoulder and a cubic skew (one crest
    that is not a point of symmetry; K of both signs, a near-umbilic region on the crest)."""
    Y = _u(rng, 0.55, 0.9)
    x0 = _u(rng, -0.35, 0.35)
    terms: list[tuple] = [("gauss", _u(rng, 0.35, 0.55), x0, _u(rng, -0.2, 0.2) * Y,
                           _u(rng, 0.55, 0.9), _u(rng, 0.5, 0.8) * Y),
                          ("gauss", _u(rng, 0.08, 0.18), -x0 + _u(rng, -0.3, 0.3),
                           _u(rng, -0.5, 0.5) * Y, _u(rng, 0.3, 0.5), _u(rng, 0.3, 0.5) * Y),
                          ("poly", _u(rng, -0.06, 0.06), 3, 0),
                          ("poly", _u(rng, -0.06, 0.06), 1, 2)]
    return _turned_shape("asym-hill", {"x0": x0}, terms, 1.0, Y, _u(rng, 0.0, np.pi))


def make_pavilion(rng: np.random.Generator) -> Shape:
    """A pavilion hill as a user draws it: a 3:2 footprint (12 x 8 m in the canonical units
    times the size bin), one broad bump of height 0.2-0.35 of the long side turned by a
    random angle, and a second low one (K > 0 on the top, K < 0 around it)."""
    Y = _u(rng, 0.6, 0.72)
    terms: list[tuple] = [("gauss", _u(rng, 0.4, 0.7), 0.0, 0.0, _u(rng, 0.6, 0.85),
                           _u(rng, 0.6, 0.85) * Y)]
    if rng.uniform() < 0.5:
        terms.append(("gauss", _u(rng, 0.05, 0.15), _u(rng, -0.6, 0.6), _u(rng, -0.5, 0.5) * Y,
                      _u(rng, 0.25, 0.45), _u(rng, 0.25, 0.45) * Y))
    return _turned_shape("pavilion", {"bumps": len(terms)}, terms, 1.0, Y, _u(rng, 0.0, np.pi))


def _plan_xy(a: np.ndarray, b: np.ndarray, X: float, Y: float) -> tuple[np.ndarray, np.ndarray]:
    """The unit square onto the (nearly) elliptic plan of semi-axes ``X, Y``: ``u = 2 b - 1``,
    ``w = 2 a - 1``, ``x = X u sqrt(1 - 0.4 w^2)``, ``y = Y w sqrt(1 - 0.4 u^2)``: the
    square's sides onto a rim through ``(+-X, 0)`` and ``(0, +-Y)`` whose corners bulge 10 %
    out (``0.5`` instead of ``0.4`` is the ellipse, but its map folds the square's corners
    flat: a grid cell of angle 180 degrees)."""
    a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
    u, w = 2 * b - 1, 2 * a - 1
    return X * u * np.sqrt(1 - 0.4 * w * w), Y * w * np.sqrt(1 - 0.4 * u * u)


#: the shapes of the round-plan family, drawn in turn
ROUND_PLAN_KINDS = ("paraboloid", "sphere", "elliptic", "bump", "asymmetric", "oblate")


def make_round_plan(rng: np.random.Generator) -> Shape:
    """Domes and hills on round and elliptic plans, as architects draw them (issue 29): a
    paraboloid, sphere cap or oblate dome of revolution about the plan's centre (an umbilic at
    the crown; the sphere umbilic everywhere), an elliptic paraboloid (two umbilics on its long
    axis), a Gaussian bump on a flat skirt (K of both signs) or an asymmetric hill (an off-centre
    bump and a cubic skew). The plan is the unit square mapped onto the ellipse of semi-axes 1
    and ``Y`` (:func:`_plan_xy`): the grid's outer rows and columns run along the rim. K in
    closed form from the height (K does not depend on the parametrization)."""
    kind = str(rng.choice(ROUND_PLAN_KINDS))
    Y = 1.0 if kind in ("paraboloid", "sphere", "oblate", "bump") else _u(rng, 0.6, 0.85)
    if kind == "paraboloid":
        h, R2 = _u(rng, 0.25, 0.5), _u(rng, 1.0, 1.3)
        terms: list[tuple] = [("poly", h, 0, 0), ("poly", -h / R2, 2, 0),
                              ("poly", -h / R2, 0, 2)]
    elif kind in ("sphere", "oblate"):
        R = _u(rng, 1.3, 2.2)
        c = R if kind == "sphere" else R * _u(rng, 0.35, 0.6)
        terms = [("ellipsoid", R, R, c), ("poly", -c * np.sqrt(1 - 1 / (R * R)), 0, 0)]
    elif kind == "elliptic":
        h = _u(rng, 0.3, 0.5)
        terms = [("poly", h, 0, 0), ("poly", -h / 1.1, 2, 0), ("poly", -h / (1.1 * Y * Y), 0, 2)]
    elif kind == "bump":
        sx = _u(rng, 0.4, 0.55)
        terms = [("gauss", _u(rng, 0.3, 0.45), 0.0, 0.0, sx, sx * _u(rng, 0.85, 1.15))]
    else:
        terms = [("gauss", _u(rng, 0.35, 0.5), _u(rng, -0.2, 0.2), _u(rng, -0.1, 0.1) * Y,
                  _u(rng, 0.45, 0.6), _u(rng, 0.4, 0.55) * Y),
                 ("poly", _u(rng, -0.05, 0.05), 3, 0), ("poly", _u(rng, -0.05, 0.05), 1, 2)]
    h = height_terms(terms)

    def f(a, b):
        x, y = _plan_xy(a, b, 1.0, Y)
        return np.stack([x, y, h(x, y)[0]], axis=-1)

    def K(a, b):
        _, hx, hy, hxx, hxy, hyy = h(*_plan_xy(a, b, 1.0, Y))
        return (hxx * hyy - hxy**2) / (1 + hx**2 + hy**2) ** 2
    p = {"kind": kind, "X": 1.0, "Y": Y, "terms": [list(t) for t in terms]}
    return Shape("round-plan", p, f, kind in ("paraboloid", "sphere", "oblate"),
                 {"K": K, "height": h})


#: family -> generator, in registry order
FAMILIES: dict[str, Callable[[np.random.Generator], Shape]] = {
    "revolution": make_revolution,
    "associate": make_associate,
    "hill": make_hill,
    "dome": make_dome,
    "ridge": make_ridge,
    "saddle": make_saddle,
    "monkey": make_monkey,
    "sphere-cap": make_sphere_cap,
    "near-sphere": make_near_sphere,
    "pseudosphere": make_pseudosphere,
    "near-pseudosphere": make_near_pseudosphere,
    "dini": make_dini,
    "bump": make_bump,
    "round-dome": make_round_dome,
    "asym-hill": make_asym_hill,
    "pavilion": make_pavilion,
    "round-plan": make_round_plan,
}
