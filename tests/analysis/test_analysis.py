"""gridshell.analysis: the curvature map against closed forms (sphere cap, saddle, paraboloid
of revolution), the largest admissible rectangle against a brute-force search, and the
recommendation each shape gets."""
from __future__ import annotations

import itertools

import numpy as np
import pytest

from gridshell.analysis.analyze import analyze_target
from gridshell.analysis.maps import CurvatureMap
from gridshell.analysis.regions import largest_rectangle


def grid_mesh(f, half: float = 1.0, n: int = 25, aspect: float = 1.0):
    """Triangle mesh of ``z = f(x, y)`` over ``[-half, half] x [-aspect half, aspect half]``
    (metres)."""
    t = np.linspace(-half, half, n)
    X, Y = np.meshgrid(t, aspect * t, indexing="ij")
    V = np.column_stack([X.ravel(), Y.ravel(), f(X, Y).ravel()])
    idx = np.arange(n * n).reshape(n, n)
    a, b, c, d = idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]
    F = np.concatenate([np.column_stack([a.ravel(), b.ravel(), c.ravel()]),
                        np.column_stack([a.ravel(), c.ravel(), d.ravel()])])
    return V, F


def sphere_cap(R: float = 3.0, half: float = 1.0):
    return grid_mesh(lambda x, y: np.sqrt(R * R - x * x - y * y) - R, half)


def saddle(c: float = 0.4, half: float = 1.0):
    """A 2 x 1.4 m saddle (a rectangle: the fit's parameter lines follow its sides)."""
    return grid_mesh(lambda x, y: c * (x * x - y * y), half, aspect=0.7)


def paraboloid(a: float = 0.3, half: float = 1.0):
    """A round dome z = -a r^2: umbilic at the crown only (k1 = k2 = 2a at r = 0)."""
    return grid_mesh(lambda x, y: -a * (x * x + y * y), half)


def test_sphere_cap_is_umbilic_everywhere_and_no_ncp_patch():
    R = 3.0
    a = analyze_target(sphere_cap(R), units="m", samples=32, trial=False)
    m = a.map
    on = m.on_target
    assert np.allclose(m.K[on], 1 / R ** 2, rtol=0.05)        # K = 1/R^2 (fit of a 25 x 25 mesh)
    assert abs(np.median(m.K[on]) * R ** 2 - 1) < 0.02
    assert np.allclose(np.abs(m.k1[on]), 1 / R, rtol=0.05)
    assert a.classes["near umbilic"] > 95.0
    assert a.classes["K>0"] > 95.0
    assert a.coverage["phlw"] < 5.0 and a.coverage["cnc"] < 5.0 and a.coverage["aa"] == 0.0
    assert a.recommendation.pipeline == "gg"


def test_saddle_has_negative_K_and_admits_AA_everywhere():
    c = 0.4
    a = analyze_target(saddle(c), units="m", samples=32, trial=False)
    m = a.map
    # z = c (x^2 - y^2): K = -4 c^2 / (1 + 4 c^2 (x^2 + y^2))^2
    x, y = m.S[..., 0], m.S[..., 1]
    K = -4 * c * c / (1 + 4 * c * c * (x * x + y * y)) ** 2
    inner = m.on_target & (np.abs(x) < 0.85) & (np.abs(y) < 0.6)   # the fit is worst at the rim
    assert np.allclose(m.K[inner], K[inner], rtol=0.03)
    assert np.median(np.abs(m.K / K - 1)[m.on_target]) < 0.01
    assert a.classes["K<0"] > 99.0
    assert a.coverage["aa"] > 85.0                 # the rim samples off the mesh aside
    assert a.recommendation.pipeline in ("gg", "ncp")
    if a.recommendation.pipeline == "ncp":
        assert a.recommendation.mode in ("aa", "phlw", "cnc")


def test_round_dome_has_its_umbilic_at_the_crown_and_no_AA():
    a = analyze_target(paraboloid(), units="m", samples=48, trial=False)
    umb = [r for r in a.regions if r.kind == "near umbilic"]
    assert umb, "a round dome has a near-umbilic region"
    cx, cy, _ = umb[0].centre
    assert np.hypot(cx, cy) < 0.1                          # at the crown (0, 0)
    assert 0 < a.classes["near umbilic"] < 50
    assert a.coverage["aa"] == 0.0
    # the largest regular patch avoids the crown: it lies to one side of it
    box = a.patches["phlw"]
    assert box is not None and 0 < a.coverage["phlw"] < 60
    i0, i1 = box.rows
    j0, j1 = box.cols
    S = a.map.S[i0:i1 + 1, j0:j1 + 1].reshape(-1, 3)
    assert np.min(np.hypot(S[:, 0], S[:, 1])) > 0.05


def _map(mask_on: np.ndarray, area: np.ndarray) -> CurvatureMap:
    n, k = mask_on.shape
    z = np.zeros((n, k))
    return CurvatureMap(u=np.linspace(0, 1, n), v=np.linspace(0, 1, k),
                        S=np.zeros((n, k, 3)), K=z, k1=z, k2=z, d1=np.zeros((n, k, 3)),
                        area=area, on_target=mask_on, diagonal=1.0, fit_rms=0.0)


@pytest.mark.parametrize("seed", range(12))
def test_largest_rectangle_matches_brute_force(seed):
    rng = np.random.default_rng(seed)
    n, k = rng.integers(3, 8, size=2)
    on = rng.random((n, k)) < 0.9
    admitted = rng.random((n, k)) < 0.7
    area = rng.uniform(0.5, 2.0, (n, k))
    m = _map(on, area)
    ok = on & admitted
    best = 0.0
    for i0, i1 in itertools.combinations_with_replacement(range(n), 2):
        for j0, j1 in itertools.combinations_with_replacement(range(k), 2):
            if ok[i0:i1 + 1, j0:j1 + 1].all():
                best = max(best, area[i0:i1 + 1, j0:j1 + 1].sum())
    r = largest_rectangle(m, admitted)
    if best == 0.0:
        assert r is None
        return
    (i0, i1), (j0, j1) = r.rows, r.cols
    assert ok[i0:i1 + 1, j0:j1 + 1].all()
    assert np.isclose(r.share, best / area[on].sum())


def test_a_dome_without_a_regular_patch_gets_the_ring_around_its_umbilic():
    """The ring (inner to outer radius about the crown, a 10 % gap) on z = -a r^2: its share
    of the target is the closed-form area of the annulus sector, int sqrt(1 + 4 a^2 r^2) r dr
    dtheta, over the mesh's area; the recommendation without a GG trial stays GG and names
    the ring."""
    a_, (V, F) = 0.3, paraboloid()
    a = analyze_target((V, F), units="m", samples=48, trial=False)
    assert a.coverage["phlw"] < 50 and a.ring["kind"] == "ring around the umbilic"
    assert np.hypot(*a.ring["centre_m"][:2]) < 0.05
    i, o = a.ring["inner_m"], a.ring["outer_m"]
    assert 0.25 * o - 1e-9 <= i <= 0.45 * o + 1e-9 and 0.9 < o <= 1.0

    def prim(r):
        return (1 + 4 * a_ * a_ * r * r) ** 1.5 / (12 * a_ * a_)
    ring_area = 0.9 * 2 * np.pi * (prim(o) - prim(i))
    T = V[F]
    area = 0.5 * np.linalg.norm(np.cross(T[:, 1] - T[:, 0], T[:, 2] - T[:, 0]), axis=1).sum()
    assert a.ring["share_percent"] == pytest.approx(100 * ring_area / area, rel=0.05)
    rec = a.recommendation
    assert rec.pipeline == "gg" and "ring around the umbilic" in rec.why
    assert a.as_dict()["ring"] == a.ring
