"""Closed-form surfaces of revolution (and the helicoid) sampled as GG meshes for the GG tests.

Each profile is parameterized by meridian arc length ``s``: ``r(s)``, ``dr/ds``, ``z(s)``.
A grid ``P[i, j] = (r(s_i) cos phi_j, r(s_i) sin phi_j, z(s_i))`` satisfies the discrete GG model
exactly (equal parallel edges, equal meridian edges per row, planar meridians).
"""
from __future__ import annotations

import numpy as np

from gridshell.gg.revolution import Profile


def catenoid(a: float = 1.0):
    """r = sqrt(a^2 + s^2), z = a asinh(s / a) (the catenoid with neck radius a)."""
    return (lambda s: np.sqrt(a * a + np.asarray(s) ** 2),
            lambda s: np.asarray(s) / np.sqrt(a * a + np.asarray(s) ** 2),
            lambda s: a * np.arcsinh(np.asarray(s) / a))


def sphere(rho: float = 1.0):
    """Sphere of radius rho, s from the south pole: r = rho sin(s/rho), z = -rho cos(s/rho)."""
    return (lambda s: rho * np.sin(np.asarray(s) / rho),
            lambda s: np.cos(np.asarray(s) / rho),
            lambda s: -rho * np.cos(np.asarray(s) / rho))


def cone(r0: float = 0.5, beta: float = 0.4):
    """Cone r = r0 + s sin(beta), z = s cos(beta) (half-opening angle beta)."""
    return (lambda s: r0 + np.asarray(s) * np.sin(beta),
            lambda s: np.full_like(np.asarray(s, float), np.sin(beta)),
            lambda s: np.asarray(s) * np.cos(beta))


def cylinder(R: float = 1.0):
    return (lambda s: np.full_like(np.asarray(s, float), R),
            lambda s: np.zeros_like(np.asarray(s, float)),
            lambda s: np.asarray(s, float))


def profile(funcs, s0: float, s1: float) -> Profile:
    return Profile(r=funcs[0], dr=funcs[1], s_min=s0, s_max=s1)


def revolution_grid(funcs, s: np.ndarray, phi: np.ndarray) -> np.ndarray:
    """P (R, C, 3) of a surface of revolution sampled at arc lengths s and angles phi."""
    r, _, z = funcs
    rr, zz = r(s), z(s)
    return np.stack([rr[:, None] * np.cos(phi)[None], rr[:, None] * np.sin(phi)[None],
                     np.broadcast_to(zz[:, None], (len(s), len(phi)))], axis=-1)


def helicoid_grid(R: int, C: int, c: float = 0.5, u=(-1.0, 1.0), v=(0.0, 2.0)) -> np.ndarray:
    """Helicoid (u cos v, u sin v, c v): rulings (rows i <-> u) are geodesic meridians, helices
    (columns j <-> v) have constant edges; isometric to the catenoid r = sqrt(c^2 + s^2)."""
    uu = np.linspace(*u, R)
    vv = np.linspace(*v, C)
    U, W = np.meshgrid(uu, vv, indexing="ij")
    return np.stack([U * np.cos(W), U * np.sin(W), c * W], axis=-1)


def hill_grid(R: int = 30, C: int = 20, size: float = 12.0, rot_deg: float = 30.0,
              shift=(0.0, 0.0, 0.0)) -> np.ndarray:
    """A freeform hill, no surface of revolution: ``z = 2.5 exp(-(x^2/16 + y^2/9))`` plus an
    off-centre bump, over ``[-6, 6] x [-4, 4]`` scaled to ``size`` metres along x, turned by
    ``rot_deg`` about z and shifted; ``P (R, C, 3)`` with rows along x."""
    x, y = np.linspace(-6, 6, R), np.linspace(-4, 4, C)
    X, Y = np.meshgrid(x, y, indexing="ij")
    Z = 2.5 * np.exp(-(X ** 2 / 16.0 + Y ** 2 / 9.0))
    Z = Z + 0.25 * np.sin(0.7 * X + 0.3) * np.cos(0.9 * Y - 0.5) * np.exp(
        -((X - 1) ** 2 + (Y + 1) ** 2) / 8)
    P = np.stack([X, Y, Z], axis=-1) * (size / 12.0)
    th = np.radians(rot_deg)
    Rz = np.array([[np.cos(th), -np.sin(th), 0], [np.sin(th), np.cos(th), 0], [0, 0, 1]])
    return P @ Rz.T + np.asarray(shift, float)
