"""The principal angle of a parameter plane (4 theta average) and the turned initial fit,
against closed forms: catenoid-helicoid associates, z = x y, a torus zone."""
import math

import numpy as np
import pytest

from gridshell.geometry.bspline import fit_grid
from gridshell.ncp.principal_frame import ALIGN_MIN_DEG, principal_angle
from gridshell.ncp.reference import initial_surface


def _associate(t: float, n: int = 24, r: float = 0.6, scale: float = 1.0) -> np.ndarray:
    """Associate X_t = cos t C + sin t H of the catenoid C = (cosh v cos u, cosh v sin u, v)
    and the helicoid H = (sinh v sin u, -sinh v cos u, u), conformal in (u, v) (E = G =
    cosh^2 v). With the normal of C_u x C_v: II_C = diag(-1, 1), II_H = [[0, 1], [1, 0]], so
    II_t = [[-cos t, sin t], [sin t, cos t]] = a reflection; its eigenvectors lie at -t/2 and
    90 - t/2 degrees from the u axis: the principal angle is -t/2 modulo 90 degrees."""
    u, v = np.meshgrid(np.linspace(-r, r, n), np.linspace(-r, r, n), indexing="ij")
    C = np.stack([np.cosh(v) * np.cos(u), np.cosh(v) * np.sin(u), v], -1)
    H = np.stack([np.sinh(v) * np.sin(u), -np.sinh(v) * np.cos(u), u], -1)
    return scale * (math.cos(t) * C + math.sin(t) * H)


def _mod90(a: float) -> float:
    """Distance of an angle (degrees) from 0 modulo 90."""
    return abs((a + 45.0) % 90.0 - 45.0)


def _quads(R: int, C: int) -> np.ndarray:
    i, j = np.meshgrid(np.arange(R - 1), np.arange(C - 1), indexing="ij")
    a = (i * C + j).ravel()
    return np.stack([a, a + C, a + C + 1, a + 1], 1)


def _tris(R: int, C: int) -> np.ndarray:
    Q = _quads(R, C)
    return np.concatenate([Q[:, [0, 1, 2]], Q[:, [0, 2, 3]]])


def _rotation(rng: np.random.Generator) -> np.ndarray:
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return Q * np.sign(np.linalg.det(Q))


@pytest.mark.parametrize("seed", range(4))
def test_associate_angle_is_minus_half_t(seed):
    rng = np.random.default_rng(seed)
    t = rng.uniform(0.0, math.pi)
    scale = 10 ** rng.uniform(math.log10(0.5), math.log10(60.0))
    P = _associate(t, n=int(rng.integers(16, 32)), scale=scale) @ _rotation(rng).T
    surf, _ = fit_grid(P, 9, 9, 4, 4, params="uniform")
    pa = principal_angle(surf)
    assert _mod90(pa.angle_deg - (-math.degrees(t) / 2)) < 0.2
    assert -45.0 < pa.angle_deg <= 45.0
    assert pa.residual_deg < 0.2                      # a uniform field
    assert abs(pa.misalignment_deg - _mod90(math.degrees(t) / 2)) < 0.5


@pytest.mark.parametrize("seed", range(3))
def test_hyperbolic_paraboloid_is_45_degrees(seed):
    """z = x y / c on an x / y grid: S_u, S_v orthogonal at the origin, II = [[0, 1], [1, 0]] / c
    there: principal directions at 45 degrees (away from the origin they bend a little)."""
    rng = np.random.default_rng(10 + seed)
    a, b = rng.uniform(1.0, 3.0, 2)
    c = rng.uniform(2.0, 6.0) * max(a, b)
    x, y = np.meshgrid(np.linspace(-a, a, 25), np.linspace(-b, b, 21), indexing="ij")
    P = np.stack([x, y, x * y / c], -1) @ _rotation(rng).T
    surf, _ = fit_grid(P, 9, 9, 4, 4)
    assert _mod90(principal_angle(surf).angle_deg - 45.0) < 1.0


def test_torus_zone_along_meridians_is_zero_and_kept():
    R, r = 3.0, 1.0
    th, ph = np.meshgrid(np.linspace(-0.8, 0.8, 20), np.linspace(0.0, 1.5, 24), indexing="ij")
    P = np.stack([(R + r * np.cos(th)) * np.cos(ph), (R + r * np.cos(th)) * np.sin(ph),
                  r * np.sin(th)], -1)
    surf, _ = fit_grid(P, 9, 9, 4, 4)
    pa = principal_angle(surf)
    assert abs(pa.angle_deg) < 0.1 and pa.misalignment_deg < 0.1
    F = _quads(20, 24)
    on, off = initial_surface(P.reshape(-1, 3), F, align=True), initial_surface(P.reshape(-1, 3), F)
    assert on.rotated_deg == 0.0
    np.testing.assert_array_equal(on.surface.ctrl, off.surface.ctrl)


def _disk_associate(t: float, n: int = 600, r: float = 0.6) -> tuple[np.ndarray, np.ndarray]:
    """A triangulated disk |(u, v)| <= r of the associate at angle t (its boundary is no
    rectangle, so a turned rectangle covers it as well as the unturned one)."""
    from scipy.spatial import Delaunay

    rad = np.sqrt(np.linspace(0.0, 1.0, n)) * r
    ang = np.arange(n) * 2.399963
    ring = np.linspace(0.0, 2 * np.pi, 80, endpoint=False)
    uv = np.vstack([np.column_stack([rad * np.cos(ang), rad * np.sin(ang)])[rad < 0.95 * r],
                    r * np.column_stack([np.cos(ring), np.sin(ring)])])
    u, v = uv.T
    C = np.stack([np.cosh(v) * np.cos(u), np.cosh(v) * np.sin(u), v], -1)
    H = np.stack([np.sinh(v) * np.sin(u), -np.sinh(v) * np.cos(u), u], -1)
    return math.cos(t) * C + math.sin(t) * H, Delaunay(uv).simplices


@pytest.mark.parametrize("tdeg", [40.0, 70.0])
def test_initial_surface_turns_a_disk_onto_its_principal_directions(tdeg):
    from gridshell.ncp.phlw import COVERAGE_TOL, deviation_percent, coverage_percent

    P, T = _disk_associate(math.radians(tdeg))
    off, on = initial_surface(P, T), initial_surface(P, T, align=True)
    before = principal_angle(off.surface).misalignment_deg
    assert before > 20.0 and abs(abs(on.rotated_deg) - before) < 3.0
    assert principal_angle(on.surface).misalignment_deg < 3.0
    assert coverage_percent(on.surface, P, T) < COVERAGE_TOL
    assert deviation_percent(on.surface, P, T) < deviation_percent(off.surface, P, T)


def test_initial_surface_turns_a_rectangle_only_within_the_tolerances():
    """A square patch at 25 degrees to its principal directions: a full turn would leave
    > 10 % of the diagonal uncovered; the turn stops where coverage and deviation hold."""
    from gridshell.ncp.phlw import COVERAGE_TOL, DEVIATION_TOL, coverage_percent, \
        deviation_percent

    P = _associate(math.radians(50.0), n=24).reshape(-1, 3)
    F = _quads(24, 24)
    on = initial_surface(P, F, align=True)
    assert on.principal is not None and abs(on.principal.angle_deg) > 20.0
    assert 0.0 < abs(on.rotated_deg) < abs(on.principal.angle_deg)
    assert coverage_percent(on.surface, P, F) <= COVERAGE_TOL
    assert deviation_percent(on.surface, P, F) <= DEVIATION_TOL
    left = principal_angle(on.surface).misalignment_deg
    assert abs(left - (abs(on.principal.angle_deg) - abs(on.rotated_deg))) < 2.0


def test_small_misalignment_keeps_the_fit():
    t = math.radians(2 * (ALIGN_MIN_DEG - 2.0))   # principal angle ALIGN_MIN_DEG - 2 degrees
    P = _associate(t, n=20).reshape(-1, 3)
    F = _quads(20, 20)
    on, off = initial_surface(P, F, align=True), initial_surface(P, F)
    assert on.rotated_deg == 0.0
    np.testing.assert_array_equal(on.surface.ctrl, off.surface.ctrl)


def test_default_keeps_the_parametrization():
    P = _associate(math.radians(50.0), n=20).reshape(-1, 3)
    fit = initial_surface(P, _quads(20, 20))
    assert fit.rotated_deg == 0.0 and fit.principal is None
