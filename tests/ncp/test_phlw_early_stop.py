"""The PHLW rounds stop when the design's figures hold (issue 17), and not before they hold.

References of the corpus the stopping rule was not tuned to (a 0.5 m saddle grid, a
triangulated dome, a pseudosphere canopy, a 60 m saddle), small samplings. After the early
stop every acceptance figure holds, and holds between the samples too: the row relation
(eq. 4.8) refitted on a 60 x 60 grid and the principal angle there, the deviation from the
reference mesh. A stop that fired too early (on the solver's relaxed auxiliaries, or on the
coarse level's own samples) fails here.
"""
import numpy as np
import pytest

from gridshell.corpus import get
from gridshell.ncp import phlw as P
from gridshell.ncp.phlw import optimize as O
from gridshell.ncp.reference import initial_surface

DENSE = np.linspace(0, 1, 60)


def run(name, mode, samples, **kw):
    V, F = get(name).mesh_arrays()
    init = initial_surface(V, F)
    return P.optimize_phlw(init.surface, (V, F), mode=mode, samples=samples, **kw), (V, F)


def assert_figures_hold(res, ref):
    assert res.converged, res.history
    assert all(f["ok"] for f in res.figures.values()), res.figures
    assert res.report_after["E_PHLW"]["total"] <= max(res.report_before["E_PHLW"]["total"],
                                                      P.E_PHLW_FLOOR)
    # between the samples: the relation refitted per row on a dense grid, the angle there
    assert np.max(P.row_relation_residual(res.surface, DENSE, DENSE, mode=res.mode)) \
        < P.RELATION_TOL
    assert np.max(P.principal_angle_error(res.surface, DENSE, DENSE)) < P.ANGLE_TOL_DEG
    # the surface stays on the reference and covers it (denser check than the figures')
    assert P.deviation_percent(res.surface, *ref, (90, 90)) < P.DEVIATION_TOL
    assert P.coverage_percent(res.surface, *ref, (90, 90)) < P.COVERAGE_TOL
    assert res.net_check.ok
    # every accepted round lowered its own true energy
    for h in res.history:
        assert np.isfinite(h["energy"]) and h["energy"] <= h["energy0"]


@pytest.mark.slow
@pytest.mark.parametrize("name,mode", [("saddle-04", "cnc"), ("dome-05", "phlw"),
                                       ("pseudosphere-03", "aa")])
def test_early_stop_leaves_every_figure_holding(name, mode):
    res, ref = run(name, mode, (12, 12))
    assert_figures_hold(res, ref)
    stopped = [h for h in res.history if "stop condition" in h["message"]]
    if stopped:
        # the in-round stop asks for a margin on the figures the iterations drive
        assert res.report_after["relation_max_rel"] < P.RELATION_TOL / P.STOP_MARGIN
        assert res.report_after["angle_max_deg"] < P.ANGLE_TOL_DEG / P.STOP_MARGIN
    # stopped once the figures held: no round after that
    assert not res.history[-1].get("figures_failing")
    assert all(h.get("figures_failing") for h in res.history[:-1] if h["accepted"])


@pytest.mark.slow
def test_early_stop_is_no_worse_than_running_the_rounds_out():
    """On a saddle: the rounds run out give the same verdict, and the early-stopped surface's
    relation and angle are within the in-round margin of the tolerances."""
    early, ref = run("saddle-00", "phlw", (12, 12))
    full, _ = run("saddle-00", "phlw", (12, 12), early_stop=False)
    assert_figures_hold(early, ref)
    assert full.converged
    assert sum(h["iterations"] for h in early.history) \
        <= sum(h["iterations"] for h in full.history)
    for key, tol in (("relation_max_rel", P.RELATION_TOL), ("angle_max_deg", P.ANGLE_TOL_DEG)):
        assert early.report_after[key] < tol / P.STOP_MARGIN or \
            early.report_after[key] <= 2 * full.report_after[key]


def test_sample_levels():
    assert O.sample_levels((18, 18)) == [(18, 18)]
    assert O.sample_levels((12, 10)) == [(12, 10)]
    assert O.sample_levels((36, 36)) == [(18, 18), (36, 36)]
    assert O.sample_levels((24, 48)) == [(18, 24), (24, 48)]


def test_coarse_level_figures_are_judged_at_the_asked_sampling():
    """Asked for 24 x 24 samples on a 60 m saddle: the rounds may run on 18 x 18 first, but
    the figures (and the result's rows) are those of the 24 x 24 sampling, and hold densely."""
    res, ref = run("saddle-06", "phlw", (24, 24))
    assert len(res.u_rows) == 24 and len(res.v_samples) == 24 and res.abc.shape == (24, 3)
    assert res.history[0]["samples"] == [18, 18]
    assert_figures_hold(res, ref)
    # the rows' own relation at the asked rows, densely along each row
    assert np.max(P.row_relation_residual(res.surface, res.u_rows, DENSE, res.n_rows,
                                          res.t_rows, mode="phlw")) < P.RELATION_TOL
