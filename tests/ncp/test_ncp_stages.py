"""The NCP pipeline as named stages (gridshell.ncp.pipeline.NCP_STAGES): their order, the
needs/gives chain from the initial state, and a run stopped after the tracing."""
import dataclasses
import inspect

import numpy as np
import pytest

from gridshell.core.errors import InputError
from gridshell.design.stages import run_stages, stage_names
from gridshell.ncp.pipeline import NCP_STAGES, NCPOptions, design_ncp, ncp_state
from tests.helpers.ncp_cases import torus

ORDER = ["surface", "directions", "tracing", "collapse", "postopt", "simulation", "metrics",
         "gate", "bundle", "strips"]


def test_stages_are_named_in_pipeline_order():
    assert stage_names(NCP_STAGES) == ORDER
    assert all(s.doc for s in NCP_STAGES)


def test_every_need_is_given_by_an_earlier_stage_or_the_initial_state():
    have = set(ncp_state(torus(), NCPOptions(mode="cnc")))
    for s in NCP_STAGES:
        missing = set(s.needs) - have
        assert not missing, f"stage {s.name} needs {missing}, given by no earlier stage"
        have |= set(s.gives)
    assert NCP_STAGES[-1].gives == ("design",)


def test_options_have_the_defaults_of_design_ncp():
    sig = inspect.signature(design_ncp).parameters
    fields = {f.name: f.default for f in dataclasses.fields(NCPOptions)}
    assert fields == {k: p.default for k, p in sig.items() if k != "source"}
    with pytest.raises(InputError, match="unknown mode 'xx'"):
        NCPOptions(mode="xx")
    with pytest.raises(InputError, match="finite"):
        NCPOptions(n=float("nan"))


def test_run_until_the_tracing_stops_there():
    """A CNC run on the torus zone (R = 3, r = 1, |theta| <= 0.6) stopped after the tracing:
    the stages up to it ran and were timed, none after; the fitted n lies in the closed-form
    range of constant normal curvatures of its parallels' nets, [max kappa_II, kappa_I] =
    [cos 0 / (3 + cos 0), 1] = [0.25, 1] 1/m."""
    timings = {}
    state = run_stages(NCP_STAGES, ncp_state(torus(), NCPOptions(mode="cnc", curves=6)),
                       timings, until="tracing")
    assert list(timings) == ORDER[:3]
    assert "traced" in state and not {"collapse", "post", "metrics", "design"} & set(state)
    assert 0.25 <= state["n"] <= 1.0
    net = state["traced"].net
    assert 0 < len(net.family(1)) <= 6 and 0 < len(net.family(3)) <= 6
    # every joint lies where both level functions take their levels (eq. 4.12 tracing)
    ij, uv = state["traced"].joint_ij, state["traced"].joint_uv
    for f, col in ((1, 0), (3, 1)):
        F = state["traced"].fits[f].F
        xi = np.array([F.evaluate(np.array([u]), np.array([v]))[0, 2] for u, v in uv])
        assert np.allclose(xi, state["traced"].levels[f][ij[:, col]], atol=1e-6)
