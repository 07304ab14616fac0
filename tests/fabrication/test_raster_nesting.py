"""Raster nesting (gridshell.fabrication.raster): the scanline fill against shapely, and placements of
random arcs and strips checked exactly with shapely: every part once, on one sheet, inside
the gap-wide margin, no two parts closer than the gap, rigid motions only."""
from __future__ import annotations

import numpy as np
import pytest
import shapely
from shapely.geometry import Polygon

from gridshell.fabrication.path import Motion
from gridshell.fabrication.raster import fill, raster_nest
from gridshell.core.errors import InputError


def _arc(R: float, w: float, span: float, n: int = 60) -> Polygon:
    """Annular sector: centre-line radius R, width w (mm), angle span (radians)."""
    t = np.linspace(-span / 2, span / 2, n) + np.pi / 2
    out = (R + w / 2) * np.c_[np.cos(t), np.sin(t)]
    inn = (R - w / 2) * np.c_[np.cos(t), np.sin(t)]
    return Polygon(np.vstack([out, inn[::-1]]))


def _parts(rng, n: int) -> list[Polygon]:
    polys = []
    for _ in range(n):
        if rng.random() < 0.6:
            polys.append(_arc(rng.uniform(60, 200), rng.uniform(8, 25), rng.uniform(0.3, 1.8)))
        else:
            L, w = rng.uniform(20, 250), rng.uniform(8, 25)
            polys.append(shapely.affinity.rotate(shapely.box(0, 0, L, w),
                                                 rng.uniform(0, 360)))
        polys[-1] = shapely.affinity.translate(polys[-1], *rng.uniform(-500, 500, 2))
    return polys


def _moved(P: Polygon, m: Motion) -> Polygon:
    return Polygon(m.apply(np.asarray(P.exterior.coords)))


def test_fill_matches_pixel_centres_inside():
    """Pixels whose centre lies inside the ring, as shapely says (centres on the ring aside)."""
    rng = np.random.default_rng(3)
    rings = [shapely.affinity.translate(_arc(30, 8, 2.5), 45, 10),
             shapely.affinity.rotate(shapely.box(10, 10, 80, 30), 33)]
    rings += [shapely.convex_hull(shapely.MultiPoint(rng.uniform(0, 75, (8, 2))))
              for _ in range(3)]
    yy, xx = np.mgrid[0:80, 0:100] + 0.5
    for P in rings:
        m = fill(np.asarray(P.exterior.coords), 100, 80, 1.0)
        on = shapely.distance(P.exterior, shapely.points(xx, yy)) < 1e-9
        ref = shapely.contains_xy(P, xx, yy)
        assert m.sum() > 50 and np.array_equal(m[~on], ref[~on])


@pytest.mark.parametrize("seed,gap,turns", [(0, 5.0, "free"), (1, 2.0, "free"),
                                            (2, 5.0, "grain"), (3, 0.0, "free")])
def test_raster_placement_keeps_gap_and_margin(seed, gap, turns):
    rng = np.random.default_rng(seed)
    polys = _parts(rng, 10)
    polys += [shapely.affinity.translate(polys[0], 70.0, -30.0),      # copies share poses
              shapely.affinity.translate(polys[1], -20.0, 45.0)]
    Lx, Ly = 400.0, 300.0
    order = sorted(range(len(polys)), key=lambda i: -polys[i].area)
    sheet_of, motion, n = raster_nest(polys, Lx, Ly, gap, order, step=30.0, turns=turns,
                                      res=1.5)
    assert len(sheet_of) == len(motion) == len(polys) and n >= 1
    assert set(sheet_of) == set(range(n))                      # no empty sheet
    inner = shapely.box(gap, gap, Lx - gap, Ly - gap).buffer(1e-6, join_style="mitre")
    placed = [_moved(P, m) for P, m in zip(polys, motion)]
    for P, Q, m in zip(polys, placed, motion):
        assert Q.area == pytest.approx(P.area, rel=1e-9)       # rigid
        assert inner.contains(Q)
        if turns == "grain":
            assert np.isclose(np.sin(m.angle), 0.0, atol=1e-12)
    for k in range(n):
        on = [Q for Q, s in zip(placed, sheet_of) if s == k]
        for i in range(len(on)):
            for j in range(i + 1, len(on)):
                assert on[i].distance(on[j]) >= gap - 1e-6, (k, i, j)
    # area check: the sheets used are not far from the parts' need
    grown = sum(P.buffer(gap / 2).area for P in polys)
    assert n <= int(np.ceil(grown / ((Lx - gap) * (Ly - gap)))) + 1


def test_raster_part_too_large_is_none():
    assert raster_nest([shapely.box(0, 0, 500, 10)], 400.0, 300.0, 5.0, [0],
                       turns="grain") is None


def test_rotation_option_is_checked():
    from gridshell.fabrication import FabParams

    assert FabParams(rotation="grain").rotation == "grain"
    with pytest.raises(InputError, match="--rotation"):
        FabParams(rotation="diagonal")


def test_depth_of_a_mask_inside_another_is_not_larger():
    """depth: a disc of radius r is about r deep; a mask translated inside another is at most as
    deep (the rule that lets a sheet skip rotations without an FFT)."""
    from gridshell.fabrication.raster import depth

    yy, xx = np.mgrid[0:120, 0:160]
    disc = (xx - 60) ** 2 + (yy - 50) ** 2 <= 20 ** 2
    assert abs(depth(disc) - 21) <= 1.0 and depth(np.zeros((5, 5), bool)) == 0.0
    rng = np.random.default_rng(7)
    for _ in range(20):
        big = fill(np.asarray(_parts(rng, 1)[0].exterior.coords)
                   - np.asarray(_parts(rng, 1)[0].centroid.coords) + (80, 60), 160, 120, 1.0)
        big |= rng.random(big.shape) < 0.3
        small = big & (rng.random(big.shape) < 0.7)         # a subset, then translated
        small = np.roll(small, (3, -5), axis=(0, 1))
        assert depth(small) <= depth(np.roll(big, (3, -5), axis=(0, 1))) + 1e-12


def test_depth_pruning_keeps_the_layout_and_skips_products(monkeypatch):
    """The same sheets and motions with and without the depth rule; with it, a full sheet whose
    free band is thinner than a bar costs the bar no FFT product."""
    import scipy.fft

    import gridshell.fabrication.raster as raster

    rng = np.random.default_rng(11)
    bars = [shapely.affinity.rotate(shapely.box(0, 0, rng.uniform(200, 280), 40),
                                    rng.uniform(0, 360)) for _ in range(8)]
    polys = [shapely.box(0, 0, 290, 170)] + bars + _parts(rng, 6)
    order = sorted(range(len(polys)), key=lambda i: -polys[i].area)
    calls = {"n": 0}
    irfft2 = scipy.fft.irfft2

    def counted(*a, **k):
        calls["n"] += 1
        return irfft2(*a, **k)
    monkeypatch.setattr(raster.scipy.fft, "irfft2", counted)
    with_rule = raster_nest(polys, 300.0, 200.0, 2.0, order, step=30.0)
    n_with = calls["n"]
    monkeypatch.setattr(raster, "depth", lambda mask: 0.0)   # every rotation fits: no pruning
    calls["n"] = 0
    without = raster_nest(polys, 300.0, 200.0, 2.0, order, step=30.0)
    assert with_rule[0] == without[0] and with_rule[2] == without[2] >= 3
    assert with_rule[1] == without[1]
    assert n_with <= calls["n"] - 8            # each bar skips at least the first sheet


def test_pose_cache_and_work_budget(monkeypatch):
    """Keeping the poses of one outline at a time (POSES = 1) gives the layout of a cache of
    every outline; a pass whose correlations exceed ``budget`` gives None (the drop layout is
    kept), one within the budget the same layout as without a budget."""
    import gridshell.fabrication.raster as raster

    rng = np.random.default_rng(5)
    base = _parts(rng, 4)
    polys = base + base + _parts(rng, 8)            # congruent parts share their poses
    order = sorted(range(len(polys)), key=lambda i: -polys[i].area)
    free = raster_nest(polys, 300.0, 200.0, 2.0, order, step=30.0)
    monkeypatch.setattr(raster, "POSES", 1)
    one = raster_nest(polys, 300.0, 200.0, 2.0, order, step=30.0)
    assert one[0] == free[0] and one[1] == free[1] and one[2] == free[2] >= 2
    assert raster_nest(polys, 300.0, 200.0, 2.0, order, step=30.0, budget=5) is None
    big = raster_nest(polys, 300.0, 200.0, 2.0, order, step=30.0, budget=10 ** 6)
    assert big[0] == free[0] and big[1] == free[1]
