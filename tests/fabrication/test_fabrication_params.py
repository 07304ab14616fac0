"""Parameter parsing and the checks that run before anything is written."""
from __future__ import annotations

import pytest

from gridshell.fabrication.params import FabParams, parse_scale, parse_sheet, scale_text
from gridshell.core.errors import InputError


@pytest.mark.parametrize("text,value", [("1:10", 0.1), ("1:1", 1.0), ("0.1", 0.1), (" 2:1 ", 2.0),
                                        (0.05, 0.05)])
def test_parse_scale(text, value):
    assert parse_scale(text) == pytest.approx(value)


@pytest.mark.parametrize("text", ["1:0", "ten", "-1:10", "0", "1:2:3"])
def test_parse_scale_rejects(text):
    with pytest.raises(InputError, match="scale"):
        parse_scale(text)


def test_parse_sheet_and_scale_text():
    assert parse_sheet("600x400") == (600.0, 400.0)
    assert parse_sheet("1000X500") == (1000.0, 500.0)
    assert scale_text(0.1) == "1:10" and scale_text(2.0) == "2:1"
    for bad in ("600", "600x-4", "axb", "0x400"):
        with pytest.raises(InputError, match="sheet"):
            parse_sheet(bad)


@pytest.mark.parametrize("kw,match", [
    ({"hole": 20}, "hole diameter 20 mm is not smaller than the strip width"),
    ({"hole": 25, "width": 20}, "--hole"),
    ({"width": -5}, "--width must be a positive"),
    ({"thickness": 0}, "--thickness"),
    ({"gap": -1}, "--gap must be a length >= 0"),
    ({"kerf": -0.1}, "--kerf"),
    ({"sheet": "15x400"}, "does not fit the sheet"),
    ({"width": 500, "hole": 3}, "does not fit the sheet"),
    ({"margin": 1}, "--margin"),
    ({"overlap": 10}, "--overlap"),
    ({"kerf": 3.5}, "kerf"),
    ({"joints": "glue"}, "--joints"),
    ({"axis": "left"}, "--axis"),
    ({"dxf_version": "R14"}, "--dxf-version"),
    ({"joints": "slots", "clearance": 0.0, "kerf": 1.0}, "--clearance"),
])
def test_nonsensical_parameters_are_named(kw, match):
    with pytest.raises(InputError, match=match):
        FabParams(**kw)


def test_defaults_are_the_papers_prototype():
    p = FabParams()
    assert (p.width, p.thickness, p.hole, p.sheet, p.scale) == (20, 1, 3, (600, 400), 0.1)
    assert p.mm_per_m == pytest.approx(100.0) and p.slot_width == pytest.approx(1.2)


@pytest.mark.parametrize("kw,match", [({"axis": "edge"}, "--axis edge .* use --axis centre"),
                                      ({"joints": "slots"}, "--joints slots needs orthogonal")])
def test_tangent_lamellae_refuse_edge_axis_and_slots(kw, match):
    """GG lamellae are tangent to the surface: no edge stands on it, no notch crosses them."""
    params = FabParams(**kw)
    with pytest.raises(InputError, match=match):
        params.check_orientation("tangent", "GG")
    params.check_orientation("orthogonal", "CNC")      # standing lamellae take both
