"""The GG pipeline as named stages: their order, the needs/gives contract over the pipeline,
a run stopped after an early stage, and the timing of every stage of a design."""
from __future__ import annotations

import inspect

import numpy as np
from tests.helpers.gg_cases import catenoid, revolution_grid

from gridshell.design.stages import run_stages, stage_names
from gridshell.geometry.grid import grid_quads
from gridshell.gg import pipeline
from gridshell.gg.pipeline import GG_STAGES, design_gg

NAMES = ["read", "grid", "surface", "net", "collapse", "metrics", "sequence", "fairness", "gate",
         "bundle"]


def _catenoid_target(n: int = 12):
    """A catenoid zone r = cosh(z) (neck radius 1 m) as an n x n quad mesh, metres."""
    P = revolution_grid(catenoid(1.0), np.linspace(-0.8, 0.8, n), np.linspace(0.0, 1.5, n))
    return P.reshape(-1, 3), grid_quads(n, n)


def _initial_state(**options):
    """The state design_gg starts its stages with: its parameters (defaults unless given)."""
    state = {k: p.default for k, p in inspect.signature(design_gg).parameters.items()}
    state.update(options)
    return state


def test_stage_names_in_pipeline_order():
    assert stage_names(GG_STAGES) == NAMES
    assert "GG_STAGES" in pipeline.__all__
    assert all(s.doc for s in GG_STAGES)  # one line each for progress and listings


def test_every_need_is_given_by_an_earlier_stage_or_the_parameters():
    given = set(inspect.signature(design_gg).parameters)
    for s in GG_STAGES:
        missing = set(s.needs) - given
        assert not missing, f"stage {s.name!r} needs {sorted(missing)}, given by no earlier stage"
        assert s.gives, f"stage {s.name!r} gives nothing"
        given |= set(s.gives)
    assert {"bundle", "report"} <= given


def test_run_until_grid_stops_before_the_surface_optimization():
    V, F = _catenoid_target()
    timings = {}
    state = run_stages(GG_STAGES, _initial_state(target=(V, F), grid=(9, 7)), timings,
                       until="grid")
    assert list(timings) == ["read", "grid"] and all(t >= 0 for t in timings.values())
    assert "surface" not in state and "net" not in state
    P0 = state["P0"]
    assert P0.shape == (9, 7, 3)
    # the initial grid lies on the target: r = cosh(z) to the chord error of the 12 x 12 mesh
    r = np.hypot(P0[..., 0], P0[..., 1])
    assert np.max(np.abs(r - np.cosh(P0[..., 2]))) < 1e-2


def test_design_times_every_stage_and_keeps_its_figures():
    V, F = _catenoid_target()
    bundle, report = design_gg((V, F), grid=(12, 12), n_lamellae=6, frames=2)
    assert list(report["timings"]) == NAMES
    assert all(t >= 0 for t in report["timings"].values())
    # the same stages run by hand give the same design
    state = run_stages(GG_STAGES, _initial_state(target=(V, F), grid=(12, 12), n_lamellae=6,
                                                 frames=2))
    assert state["bundle"].metrics["alignability"] == bundle.metrics["alignability"]
    assert bundle.metrics["alignability"]["max"] < 3.0 and bundle.metrics["delta_l"]["max"] < 1.0
    assert len(report["sequence"].V) == 3
