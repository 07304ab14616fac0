"""Planar polylines with bulges (the DXF LWPOLYLINE model), and rigid motions of the plane.

A span from vertex ``i`` to ``i+1`` with bulge ``b`` is a circular arc of included angle
``4 atan(b)``, counter-clockwise for ``b > 0``; ``b = 0`` is a straight segment.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Motion:
    """Rigid motion ``x -> R(angle) x + (dx, dy)``; angle in radians."""

    angle: float = 0.0
    dx: float = 0.0
    dy: float = 0.0

    def apply(self, X: np.ndarray) -> np.ndarray:
        """The points ``X (..., 2)`` moved (mm)."""
        return self.apply_each([X])[0]

    def apply_each(self, Xs: list[np.ndarray]) -> list[np.ndarray]:
        """Each of the point arrays ``Xs`` moved, as :meth:`apply` moves it (the rotation
        made once)."""
        c, s = np.cos(self.angle), np.sin(self.angle)
        R, t = np.array([[c, s], [-s, c]]), np.array([self.dx, self.dy])
        return [np.asarray(X, float) @ R + t for X in Xs]

    def then(self, other: "Motion") -> "Motion":
        """This motion followed by ``other``."""
        o = other.apply(np.array([[self.dx, self.dy]]))[0]
        return Motion(self.angle + other.angle, float(o[0]), float(o[1]))

    def to_json(self) -> dict:
        return {"angle_deg": float(np.degrees(self.angle)), "dx": self.dx, "dy": self.dy}


@dataclass
class Path:
    """Vertices ``V (n,2)`` mm, bulges ``B (n,)`` (span after each vertex), closed or open."""

    V: np.ndarray
    B: np.ndarray
    closed: bool = True

    def __post_init__(self) -> None:
        self.V = np.asarray(self.V, float).reshape(-1, 2)
        self.B = np.zeros(len(self.V)) if self.B is None else np.asarray(self.B, float).reshape(-1)

    def moved(self, m: Motion) -> "Path":
        return Path(m.apply(self.V), self.B.copy(), self.closed)

    @property
    def has_arcs(self) -> bool:
        return bool(np.any(self.B != 0))

    def flatten(self, tol: float = 0.01) -> np.ndarray:
        """Points ``(m,2)`` of the path with arcs replaced by chords at most ``tol`` mm off
        (closed paths do not repeat the first point)."""
        n = len(self.V)
        spans = n if self.closed else n - 1
        arcs = np.flatnonzero(self.B[:spans] != 0)
        if len(arcs) == 0:
            return self.V.copy()
        out, start = [], 0
        for i in arcs:
            out.append(self.V[start:i + 1])
            out.append(arc_points(self.V[i], self.V[(i + 1) % n], self.B[i], tol)[1:-1])
            start = i + 1
        out.append(self.V[start:])
        return np.concatenate(out)

    def segments(self, tol: float) -> "Path":
        """The same path with bulges replaced by short straight segments."""
        return Path(self.flatten(tol), None, self.closed)


def arc_points(p0: np.ndarray, p1: np.ndarray, b: float, tol: float) -> np.ndarray:
    """Points ``(k,2)`` from ``p0`` to ``p1`` (both included) on the arc of bulge ``b``."""
    centre, rr, theta = arc_geometry(p0, p1, b)
    step = 2.0 * np.arccos(max(-1.0, 1.0 - tol / rr)) if tol < rr else np.pi / 4
    k = max(int(np.ceil(abs(theta) / step)), 1)
    a0 = np.arctan2(*(p0 - centre)[::-1])
    a = a0 + theta * np.linspace(0.0, 1.0, k + 1)
    P = centre + rr * np.stack([np.cos(a), np.sin(a)], axis=1)
    P[0], P[-1] = p0, p1
    return P


def arc_geometry(p0: np.ndarray, p1: np.ndarray, b: float) -> tuple[np.ndarray, float, float]:
    """Centre ``(2,)``, radius and signed included angle of the bulge arc ``p0 -> p1``."""
    theta = 4.0 * np.arctan(b)
    chord = p1 - p0
    c = np.linalg.norm(chord)
    r = c / (2.0 * np.sin(theta / 2.0))
    u = chord / c
    centre = 0.5 * (p0 + p1) + np.array([-u[1], u[0]]) * r * np.cos(theta / 2.0)
    return centre, abs(r), theta
