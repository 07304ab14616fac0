"""The analysis' NCP trials (the coarse PHLW step per mode) against closed forms: a torus zone
is a linear Weingarten surface (H = 1/(2r) + (r/2) K along every line), so a PHLW and a CNC
surface, and the pseudosphere has K = -1/a^2 everywhere, so a PK surface; both lie at a
fraction of the fit's residual from the trial surface. A hill with an umbilic and both signs
of K has no such surface; the area-weighted spread against a hand computation; the
recommendation's expected deviation from the trial."""
from __future__ import annotations

import numpy as np
import pytest

from gridshell.analysis.analyze import analyze_target, summary_of
from gridshell.analysis.recommend import recommend
from gridshell.analysis.trial import NCPTrial, _spread


def param_mesh(f, a, b):
    """Quad mesh of the parametrization ``f(A, B) -> (..., 3)`` on the grid ``a x b``."""
    A, B = np.meshgrid(a, b, indexing="ij")
    V = f(A, B).reshape(-1, 3)
    n, k = len(a), len(b)
    idx = np.arange(n * k).reshape(n, k)
    F = np.column_stack([idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(),
                         idx[:-1, 1:].ravel()])
    return V, F


def torus_zone(R=3.0, r=1.0):
    """The outer zone of a torus, |theta| <= 0.6, |phi| <= 0.7 (K > 0, no umbilic)."""
    def f(t, p):
        w = R + r * np.cos(t)
        return np.stack([w * np.cos(p), w * np.sin(p), r * np.sin(t)], -1)
    return param_mesh(f, np.linspace(-0.6, 0.6, 25), np.linspace(-0.7, 0.7, 25))


def pseudosphere(a=1.0):
    """A pseudosphere zone, s in [0.4, 1.2] (r = a / cosh s), |phi| <= 0.8: K = -1/a^2."""
    def f(s, p):
        r = a / np.cosh(s)
        return np.stack([r * np.cos(p), r * np.sin(p), a * (s - np.tanh(s))], -1)
    return param_mesh(f, np.linspace(0.4, 1.2, 25), np.linspace(-0.8, 0.8, 25))


@pytest.fixture(scope="module")
def torus():
    return analyze_target(torus_zone(), units="m", samples=32)


def test_a_torus_zone_is_a_phlw_and_a_cnc_surface_and_no_pk_one(torus):
    t = torus.ncp_trials
    rms = 100 * torus.map.fit_rms / torus.map.diagonal
    for mode in ("phlw", "cnc"):
        assert t[mode].error is None and t[mode].of_kind, t[mode]
        assert t[mode].relation < 1e-2 and t[mode].no_net_percent == 0.0
        # the nearest PHLW / CNC surface is the torus itself: the fit's residual, not more
        assert t[mode].deviation["mean"] < max(0.1, 3 * rms), t[mode].deviation
        assert t[mode].deviation["mean"] <= t[mode].deviation["p95"] <= t[mode].deviation["max"]
    assert t["aa"].deviation is None and "K > 0" in t["aa"].error        # no PK net on K > 0
    d = torus.as_dict()["ncp_trials"]
    assert d["cnc"]["surface"] == "CNC" and d["aa"]["error"]
    s = summary_of(torus)
    assert s["NCP trial phlw"].startswith("nearest PHLW surface")
    assert s["NCP trial aa"].startswith("none:")


def test_the_pseudosphere_is_a_pk_surface():
    a = analyze_target(pseudosphere(), units="m", samples=32)
    aa = a.ncp_trials["aa"]
    assert aa.error is None and aa.of_kind, aa
    assert aa.deviation["mean"] < 0.1, aa.deviation
    # one region (K < 0 everywhere): its figures are the whole target's
    assert [r["kind"] for r in aa.regions] == ["K<0"]
    assert aa.regions[0]["mean"] == pytest.approx(aa.deviation["mean"], rel=1e-3, abs=1e-4)


def test_a_hill_with_an_umbilic_and_both_signs_has_no_phlw_surface_over_it():
    def f(x, y):
        return np.stack([x, y, 1.2 * np.exp(-(x * x + y * y)) - 0.2 * x], -1)
    V, F = param_mesh(f, np.linspace(-2, 2, 30), np.linspace(-1.5, 1.5, 24))
    a = analyze_target((V, F), units="m", samples=32)
    t = a.ncp_trials["phlw"]
    assert t.error is None and not t.of_kind
    assert t.no_net_percent > 0 or t.relation > 1e-2
    kinds = {r["kind"] for r in t.regions}
    assert {"K>0", "K<0"} <= kinds
    assert "not yet of its kind" in summary_of(a)["NCP trial phlw"]


def test_spread_is_area_weighted():
    d = np.array([[1.0, 2.0], [3.0, 10.0]])
    w = np.array([[1.0, 1.0], [2.0, 0.0]])
    sel = np.ones((2, 2), bool)
    s = _spread(d, w, sel, ("mean", "p95", "max"))
    assert s["mean"] == pytest.approx((1 + 2 + 6) / 4)
    assert s["p95"] == 3.0            # the weightless 10 is above the 95 % of the area
    assert s["max"] == 10.0
    assert np.isnan(_spread(d, w, np.zeros((2, 2), bool), ("mean",))["mean"])


def test_the_recommendation_takes_its_expected_deviation_from_the_trial():
    trial = NCPTrial("aa", {"mean": 0.4, "p95": 0.9, "max": 1.2}, of_kind=True)
    r = recommend({"phlw": 10.0, "cnc": 10.0, "aa": 90.0}, None, trials={"aa": trial})
    assert (r.mode, r.deviation_percent) == ("aa", 0.4) and "PK surface lies 0.40 %" in r.why
    off = NCPTrial("aa", {"mean": 0.4, "p95": 0.9, "max": 1.2}, of_kind=False)
    r = recommend({"phlw": 10.0, "cnc": 10.0, "aa": 90.0}, None, trials={"aa": off})
    assert r.mode == "aa" and r.deviation_percent is None
