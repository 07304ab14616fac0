"""Units at the edges (gridshell.core.units): parsing, conversion, the plausibility rule."""
from __future__ import annotations

import numpy as np
import pytest

from gridshell.core.errors import InputError
from gridshell.core.units import (METRES, PLAUSIBLE_DIAGONAL, UNITS, Units, check_plausible,
                                parse_units, to_metres)
from gridshell.geometry.quadmesh import bbox_diagonal


@pytest.mark.parametrize("text, name, f", [("m", "m", 1.0), ("MM", "mm", 1e-3),
                                           ("millimetres", "mm", 1e-3), ("cm", "cm", 0.01),
                                           ("inches", "in", 0.0254), ("feet", "ft", 0.3048),
                                           ("meters", "m", 1.0)])
def test_parse_units(text, name, f):
    u = parse_units(text)
    assert (u.name, u.metres_per_unit) == (name, f)
    assert Units.from_json(u.to_json()) == u


def test_unknown_unit_names_the_choices():
    with pytest.raises(InputError, match="furlong.*m, cm, mm, in, ft"):
        parse_units("furlong")


def test_units_record():
    assert Units.from_json(None) == METRES            # absent: metres
    assert Units.from_json("m") == METRES             # legacy design.json
    assert Units.from_json({"name": "mm", "metres_per_unit": 0.001}) == parse_units("mm")
    for bad in ({"name": "mm"}, {"name": "mm", "metres_per_unit": -1}, 3, [1]):
        with pytest.raises(InputError, match="units"):
            Units.from_json(bad)


def test_to_metres_is_correctly_rounded_and_round_trips():
    X = np.random.default_rng(0).normal(size=(2000, 3)) * 10   # metres
    for unit, k in (("mm", 1000.0), ("cm", 100.0)):
        P = X * k                                              # exported in mm / cm
        M = to_metres(P, parse_units(unit))
        assert np.all(np.abs(M - P / k) <= np.spacing(np.abs(P / k)))  # within an ulp
        assert np.all(M * k == P)                              # and back to the file's numbers
        assert np.mean(M == X) > 0.8                           # mostly the very metres
    V = np.random.default_rng(1).normal(size=(10, 3))
    np.testing.assert_array_equal(to_metres(V, parse_units("ft")), V * 0.3048)
    assert to_metres(V, METRES) is not V


def test_the_issue_hill_in_millimetres_names_both_readings():
    with pytest.raises(InputError) as exc:
        check_plausible(14600.0, "hill_mm.obj")
    msg = str(exc.value)
    assert "14.6 km as metres, 14.6 m as millimetres" in msg and "--units" in msg
    assert "\n" not in msg


@pytest.mark.parametrize("diagonal", [0.05, 0.1, 0.5, 14.6, 60.0, 200.0, 299.0, 300.0])
def test_plausible_metre_sizes_pass(diagonal):
    check_plausible(diagonal, "x.obj")  # 0.1 m models to 300 m halls (and small ones) pass


@pytest.mark.parametrize("diagonal, first", [(301.0, "m as "), (1200.0, "12 m as centimetres"),
                                             (472.0, "12 m as inches"),
                                             (200_000.0, "200 m as millimetres")])
def test_implausible_metre_sizes_are_refused(diagonal, first):
    with pytest.raises(InputError, match="as metres") as exc:
        check_plausible(diagonal, "x.obj")
    assert first in str(exc.value)


def test_no_unit_makes_it_plausible_is_left_to_the_extent_guard():
    check_plausible(1e7, "x.obj")  # 10 000 km: not a unit mistake among m, cm, mm, in, ft


def test_the_corpus_is_never_refused_as_metres():
    from gridshell.corpus.registry import select

    refs = select(None)
    sizes = []
    for ref in refs:
        V, _ = ref.mesh_arrays()
        d = bbox_diagonal(V)
        sizes.append(d)
        check_plausible(d, ref.name)
    assert min(sizes) < 1.0 and max(sizes) > 50.0  # the corpus spans 0.5 .. 60 m
    assert PLAUSIBLE_DIAGONAL[1] / PLAUSIBLE_DIAGONAL[0] > 1000  # mm vs m cannot both fit
    assert set(UNITS) == {"m", "cm", "mm", "in", "ft"}
