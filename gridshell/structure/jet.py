"""Second-order forward differentiation over batches of small stencils (exact gradients and
Hessians of the rod energies).

A :class:`Jet` carries, for a batch of ``B`` stencils each with ``n`` local variables, a value
``v (B, *s)``, its gradient ``g (B, *s, n)`` and its Hessian ``h (B, *s, n, n)`` with respect to
the stencil's variables (``s`` is ``()`` for scalars, ``(3,)`` for vectors). Arithmetic follows
the product and chain rules, so an energy written once with these operations yields its exact
gradient and Hessian (no finite differences, no hand-derived formulas to keep in step).
``order`` 0 skips the derivatives (cheap energy evaluations for line searches), 1 skips the
Hessian.
"""
from __future__ import annotations

from typing import Callable

import numpy as np


class Jet:
    """Value with gradient and Hessian over ``n`` stencil variables (see the module docstring)."""

    __slots__ = ("v", "g", "h")

    def __init__(self, v: np.ndarray, g: np.ndarray | None = None,
                 h: np.ndarray | None = None) -> None:
        self.v, self.g, self.h = v, g, h

    # -- construction -------------------------------------------------------------------------
    @staticmethod
    def variables(X: np.ndarray, order: int = 2) -> list["Jet"]:
        """Independent variables from ``X (B, n)``: one scalar Jet per column."""
        X = np.asarray(X, float)
        B, n = X.shape
        out = []
        for k in range(n):
            g = h = None
            if order >= 1:
                g = np.zeros((B, n))
                g[:, k] = 1.0
            if order >= 2:
                h = np.zeros((B, n, n))
            out.append(Jet(X[:, k].copy(), g, h))
        return out

    @property
    def order(self) -> int:
        return 0 if self.g is None else (1 if self.h is None else 2)

    # -- helpers ------------------------------------------------------------------------------
    @staticmethod
    def _lift(o, like: "Jet") -> "Jet":
        if isinstance(o, Jet):
            return o
        v = np.asarray(o, float)
        return Jet(v, None, None)

    def __getitem__(self, k) -> "Jet":
        """Component ``k`` of the value's trailing axes (``J[..., k]``)."""
        idx = (Ellipsis, k)
        return Jet(self.v[idx],
                   None if self.g is None else self.g[(Ellipsis, k, slice(None))],
                   None if self.h is None else self.h[(Ellipsis, k, slice(None), slice(None))])

    def expand(self) -> "Jet":
        """Append a value axis of length 1 (broadcast a scalar against a vector)."""
        return Jet(self.v[..., None],
                   None if self.g is None else self.g[..., None, :],
                   None if self.h is None else self.h[..., None, :, :])

    def sum(self) -> "Jet":
        """Sum over the last value axis."""
        return Jet(self.v.sum(-1),
                   None if self.g is None else self.g.sum(-2),
                   None if self.h is None else self.h.sum(-3))

    # -- arithmetic ---------------------------------------------------------------------------
    def __add__(self, o) -> "Jet":
        o = Jet._lift(o, self)
        return Jet(self.v + o.v, _add(self.g, o.g), _add(self.h, o.h))

    __radd__ = __add__

    def __neg__(self) -> "Jet":
        return Jet(-self.v, None if self.g is None else -self.g,
                   None if self.h is None else -self.h)

    def __sub__(self, o) -> "Jet":
        return self + (-Jet._lift(o, self))

    def __rsub__(self, o) -> "Jet":
        return (-self) + o

    def __mul__(self, o) -> "Jet":
        o = Jet._lift(o, self)
        a, b = self, o
        v = a.v * b.v
        g = _add(None if a.g is None else a.g * b.v[..., None],
                 None if b.g is None else b.g * a.v[..., None])
        h = None
        if a.h is not None or b.h is not None:
            h = _add(None if a.h is None else a.h * b.v[..., None, None],
                     None if b.h is None else b.h * a.v[..., None, None])
            if a.g is not None and b.g is not None:
                cross = a.g[..., :, None] * b.g[..., None, :]
                h = h + cross + np.swapaxes(cross, -1, -2)
        return Jet(v, g, h)

    __rmul__ = __mul__

    def __truediv__(self, o) -> "Jet":
        if isinstance(o, Jet):
            return self * o.reciprocal()
        return self * (1.0 / np.asarray(o, float))

    def __rtruediv__(self, o) -> "Jet":
        return self.reciprocal() * o

    def apply(self, f: np.ndarray, f1: np.ndarray, f2: np.ndarray) -> "Jet":
        """Chain rule of a scalar function with value ``f``, first ``f1`` and second ``f2``
        derivative at ``self.v``."""
        g = None if self.g is None else self.g * f1[..., None]
        h = None
        if self.h is not None:
            h = self.h * f1[..., None, None] + \
                f2[..., None, None] * self.g[..., :, None] * self.g[..., None, :]
        return Jet(f, g, h)

    def reciprocal(self) -> "Jet":
        r = 1.0 / self.v
        return self.apply(r, -r * r, 2.0 * r * r * r)

    def sqrt(self) -> "Jet":
        s = np.sqrt(self.v)
        return self.apply(s, 0.5 / s, -0.25 / (s * self.v))

    def sin(self) -> "Jet":
        s = np.sin(self.v)
        return self.apply(s, np.cos(self.v), -s)

    def cos(self) -> "Jet":
        c = np.cos(self.v)
        return self.apply(c, -np.sin(self.v), -c)

    def square(self) -> "Jet":
        return self * self


def _add(a, b):
    if a is None:
        return b
    if b is None:
        return a
    return a + b


def atan2(y: Jet, x: Jet) -> Jet:
    """``atan2(y, x)`` of two scalar Jets with its exact derivatives."""
    r2 = x.v * x.v + y.v * y.v
    v = np.arctan2(y.v, x.v)
    if x.g is None and y.g is None:
        return Jet(v)
    fx, fy = -y.v / r2, x.v / r2
    gx = np.zeros_like(y.g) if x.g is None else x.g
    gy = np.zeros_like(x.g) if y.g is None else y.g
    g = gx * fx[..., None] + gy * fy[..., None]
    h = None
    if (x.h is not None) or (y.h is not None):
        hx = 0.0 if x.h is None else x.h
        hy = 0.0 if y.h is None else y.h
        r4 = r2 * r2
        fxx, fyy, fxy = 2 * x.v * y.v / r4, -2 * x.v * y.v / r4, (y.v * y.v - x.v * x.v) / r4
        oxx = gx[..., :, None] * gx[..., None, :]
        oyy = gy[..., :, None] * gy[..., None, :]
        oxy = gx[..., :, None] * gy[..., None, :]
        h = (hx * fx[..., None, None] + hy * fy[..., None, None] + oxx * fxx[..., None, None]
             + oyy * fyy[..., None, None] + (oxy + np.swapaxes(oxy, -1, -2)) * fxy[..., None, None])
    return Jet(v, g, h)


def dot(a: Jet, b: Jet) -> Jet:
    """``a . b`` of two vector Jets ``(B, 3)``."""
    return (a * b).sum()


def cross(a: Jet, b: Jet) -> Jet:
    """``a x b`` of two vector Jets ``(B, 3)``."""
    comps = [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
    return stack(comps)


def stack(comps: list[Jet]) -> Jet:
    """Scalar Jets stacked into a vector Jet (new last value axis)."""
    v = np.stack([c.v for c in comps], axis=-1)
    g = None if comps[0].g is None else np.stack([c.g for c in comps], axis=-2)
    h = None if comps[0].h is None else np.stack([c.h for c in comps], axis=-3)
    return Jet(v, g, h)


def norm(a: Jet) -> Jet:
    """Euclidean length of a vector Jet."""
    return dot(a, a).sqrt()


def vector(X: list[Jet]) -> Jet:
    """Three scalar variable Jets as one vector Jet."""
    return stack(X)


def evaluate(fn: Callable[[list[Jet]], Jet], X: np.ndarray, order: int = 2) -> Jet:
    """``fn`` of the variables ``X (B, n)``: a scalar Jet with value ``(B,)``, gradient
    ``(B, n)`` and Hessian ``(B, n, n)`` (as far as ``order``)."""
    return fn(Jet.variables(X, order))
