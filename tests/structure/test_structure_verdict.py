"""Cut files only for strips that survive: ``fabricate`` refuses an overstressed design (exit 4)
naming the lamella, the state, the governing stress term and sections that hold; the sections
it names do hold when checked; the advice fits the governing term; ``check --suggest``."""
from __future__ import annotations

import json
import re

import numpy as np
import pytest
from tests.helpers.gg_cases import catenoid, revolution_grid

from gridshell import api
from gridshell.cli.main import main
from gridshell.geometry.grid import grid_quads
from gridshell.structure import Section, get_material
from gridshell.structure.check import check_bundle
from gridshell.structure.sizing import (Demand, governing_term, smallest_scale,
                                        thickest_elastic_mm, widest_elastic_mm)
from gridshell.structure.verdict import verdict_line

PP = get_material("pp")


@pytest.fixture(scope="module")
def gg(tmp_path_factory):
    d = tmp_path_factory.mktemp("gg") / "gg"
    P = revolution_grid(catenoid(1.0), np.linspace(-0.8, 0.8, 10), np.linspace(0.0, 1.5, 10))
    api.write(d, api.design_gg((P.reshape(-1, 3), grid_quads(10, 10)), grid=(10, 10),
                               n_lamellae=4, frames=2))
    return d


def _fab(d, *extra):
    return main(["fabricate", str(d), "-o", str(d.parent / "fab"), "--no-plan", "-q",
                 "--joints", "marks", *extra])


def test_fabricate_refuses_an_overstressed_design_and_the_named_sections_hold(gg, capsys):
    capsys.readouterr()
    assert _fab(gg, "--scale", "1:40", "--width", "30", "--margin", "5") == 4
    err = capsys.readouterr().err
    assert "\n" not in err.strip() and "OVERSTRESSED" in err and "--force" in err
    assert re.search(r"lamella \d+", err) and ("deployed" in err or "state" in err)
    assert "governed by" in err and "0.00 mm" not in err
    assert not (gg.parent / "fab").exists()
    res = check_bundle(gg, PP, Section(30, 1, 1 / 40))
    adv = res["advice"]
    # the smallest scale named holds (exactly at the limit: u scales with 1 / scale)
    s_min = smallest_scale(1 / 40, res["max_utilisation"])
    assert adv["smallest_scale_text"] in err
    at = check_bundle(gg, PP, Section(30, 1, s_min * 1.0001))
    assert at["max_utilisation"] <= 1.0 < res["max_utilisation"]
    # the thickest / widest elastic strip named holds in every state (checked anew)
    for w, t in ((30, adv["thickest_elastic_mm"]), (adv["widest_elastic_mm"], 1)):
        if w > 0 and t > 0:
            assert check_bundle(gg, PP, Section(w, t, 1 / 40))["verdict"] == "ok"
    assert _fab(gg, "--scale", "1:40", "--width", "30", "--margin", "5", "--force") == 0
    rep = json.loads((gg.parent / "fab" / "fabrication.json").read_text())
    assert rep["structure"]["verdict"] == "overstressed" and rep["structure"]["forced"]


def test_fabricate_of_a_design_that_holds_prints_its_verdict(gg, capsys):
    capsys.readouterr()
    assert main(["fabricate", str(gg), "-o", str(gg.parent / "fab2"), "--no-plan",
                 "--scale", "1:10"]) == 0
    out = capsys.readouterr().out
    assert re.search(r"structure\s+.*ok: 20 x 1 mm pp at 1:10 stays elastic", out)


def test_check_suggest_lists_sections_that_hold(gg, capsys):
    capsys.readouterr()
    main(["check", str(gg), "--scale", "1:40", "--suggest", "--json", "-q", "--no-picture"])
    rows = json.loads(capsys.readouterr().out)["suggest"]
    assert [r["thickness_mm"] for r in rows] == sorted(PP.sheet_thicknesses_mm, reverse=True)
    some = [(r["thickness_mm"], r["widths_mm"][-1]) for r in rows if r["widths_mm"]]
    assert some
    for t, w in some[:2]:       # the widest suggested section of the two thickest stocks
        assert check_bundle(gg, PP, Section(w, t, 1 / 40))["verdict"] == "ok"


def _demand(weak, strong, twist):
    a = lambda v: np.atleast_1d(np.asarray(v, float))  # noqa: E731
    return Demand(a(weak), a(strong), a(twist), np.array(["deployed"], dtype=object),
                  np.array([0]))


def test_the_advice_fits_the_governing_term():
    """Strong-axis bending (in-plane curvature 0.5 1/m of a 20 mm strip at 1:10: E k w / 2 =
    1.5 GPa * 5 * 0.01 = 75 MPa) is helped by a narrower strip, not a thinner one: the thickest
    elastic strip is 0 and the widest is where E k w / 2 = 32 MPa (8.53 mm); weak-axis bending
    (k = 2 1/m of the design: E k t / 2 = 15 MPa per mm) by a thinner one (32/15 mm)."""
    sec = Section(20, 1, 0.1)
    d = _demand(0.0, 0.5, 0.0)
    assert governing_term(d, PP, sec)["term"] == "strong"
    assert thickest_elastic_mm(d, PP, sec) == 0.0
    assert widest_elastic_mm(d, PP, sec) == pytest.approx(2 * 32e6 / (1.5e9 * 5.0) * 1e3,
                                                          rel=1e-6)
    d = _demand(2.0, 0.0, 0.0)
    assert governing_term(d, PP, sec)["term"] == "weak"
    assert thickest_elastic_mm(d, PP, sec) == pytest.approx(2 * 32e6 / (1.5e9 * 20.0) * 1e3,
                                                            rel=1e-6)

