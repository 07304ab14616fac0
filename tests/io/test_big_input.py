"""The shortcuts that make ``gg`` on a 200k-triangle target fast (issue 18, big inputs) give
the same numbers as the plain computations: the geodesic equations' one-point spline, the
deviations of several point sets from one closest-point query, the sort-based unique, and the
working copy of a big target stays on it. (Time and memory: benchmarks/big_input.py.)"""
from __future__ import annotations

import numpy as np
from tests.helpers.io_cases import hill
from scipy.interpolate import CubicSpline

from gridshell.gg.revolution import _PointSpline, rebuild_revolution
from gridshell.io.read import check_disk
from gridshell.io.working import working_mesh
from gridshell.measure.metrics import deviation, deviations
from gridshell.geometry.quadmesh import unique_ints


def _bits(a) -> np.ndarray:
    return np.asarray(a, dtype=np.float64).view(np.int64)


def test_the_one_point_spline_gives_the_splines_bits_inside_at_knots_and_outside():
    rng = np.random.default_rng(3)
    for _ in range(5):
        x = np.cumsum(rng.uniform(0.05, 1.0, rng.integers(4, 30)))
        sp = CubicSpline(x, rng.normal(size=len(x)) * 10.0)
        for f in (sp, sp.derivative(), sp.derivative(2)):
            fast = _PointSpline(f)
            s = np.r_[rng.uniform(x[0] - 2, x[-1] + 2, 400), x, np.nextafter(x, -np.inf),
                      np.nextafter(x, np.inf)]
            got = [fast(v) for v in s]  # numpy scalars, as the ODE solver passes them
            assert np.array_equal(_bits(got), _bits(f(s)))
            assert np.array_equal(fast(s), f(s))  # arrays go to the spline itself
    assert np.isnan(_PointSpline(sp)(np.float64("nan")))


def test_the_profile_of_a_revolution_is_its_cubic_spline():
    V, T = hill(12, 10)  # a GG-like grid: the hill's rows as parallels
    rev = rebuild_revolution(V.reshape(12, 10, 3))
    prof = rev.profile
    s = np.linspace(rev.s[0], rev.s[-1], 97)
    assert np.array_equal(_bits([prof.r(v) for v in s]), _bits(rev.r_of_s(s)))
    assert np.array_equal(_bits([prof.dr(v) for v in s]), _bits(rev.dr_of_s(s)))


def test_deviations_of_several_point_sets_are_each_ones_deviation():
    V, T = hill(30, 24)
    rng = np.random.default_rng(0)
    A = V[rng.choice(len(V), 50)] + rng.normal(scale=0.05, size=(50, 3))
    B = rng.uniform(-5, 5, size=(7, 3))
    got = deviations([A, B, V], V, T)
    assert got == [deviation(A, V, T), deviation(B, V, T), deviation(V, V, T)]
    assert got[2]["max"] < 1e-12 and got[0]["max"] > 0


def test_unique_ints_is_numpys_unique():
    rng = np.random.default_rng(1)
    for a in (rng.integers(0, 10 ** 12, 5000), rng.integers(-3, 4, (40, 3)),
              np.zeros(0, np.int64), np.array([7])):
        assert np.array_equal(unique_ints(a), np.unique(a))


def test_the_working_copy_of_a_big_target_is_a_disk_on_it():
    V, T = hill(60, 48)  # 5 546 triangles, reduced to ~1 000
    Vw, Tw, info = working_mesh(V, T, max_faces=1000)
    assert info["faces"][0] == len(T) and info["faces"][1] == len(Tw)
    assert 500 <= len(Tw) <= 1500, info
    check_disk(Vw, Tw, "working copy")  # one disk, as the target
    # on the target: its vertices within a small fraction of the diagonal
    assert deviation(Vw, V, T)["max"] < 0.1
    # and a small target is used as it is
    V2, T2, info2 = working_mesh(V, T, max_faces=len(T))
    assert info2 is None and V2 is V


def test_polygon_vector_areas_are_the_shoelace_sums_bit_for_bit():
    from gridshell.geometry.quadmesh import polygon_vector_areas

    rng = np.random.default_rng(2)
    V = rng.normal(size=(60, 3))
    for k in (3, 4, 9):
        F = np.stack([rng.permutation(60)[:k] for _ in range(40)])
        F[::3, k - 1] = -1  # padded: some faces one vertex shorter
        got = polygon_vector_areas(V, F)
        for f, row in zip(F, got):
            P = V[f[f >= 0]]
            want = np.cross(P, np.roll(P, -1, axis=0))
            acc = want[0].copy()
            for c in want[1:]:
                acc += c
            assert np.array_equal(_bits(row), _bits(0.5 * acc))
