"""Named pipeline stages: order, timings, the needs/gives contract, skip and until."""
import pytest

from gridshell.design.stages import Stage, run_stages, stage, stage_names


@stage("double", needs=("x",), gives=("y",))
def _double(state):
    """y = 2 x."""
    return {"y": 2 * state["x"]}


@stage("add", needs=("x", "y"), gives=("z",), skip=lambda s: s.get("no_add", False))
def _add(state):
    return {"z": state["x"] + state["y"]}


def test_stages_run_in_order_and_are_timed():
    timings = {}
    state = run_stages((_double, _add), {"x": 3}, timings)
    assert state == {"x": 3, "y": 6, "z": 9}
    assert list(timings) == ["double", "add"] and all(t >= 0 for t in timings.values())
    assert stage_names((_double, _add)) == ["double", "add"]
    assert _double.doc == "y = 2 x."


def test_until_and_skip():
    assert "z" not in run_stages((_double, _add), {"x": 1}, until="double")
    timings = {}
    state = run_stages((_double, _add), {"x": 1, "no_add": True}, timings)
    assert "z" not in state and "add" not in timings
    with pytest.raises(KeyError, match="no stage 'trace'"):
        run_stages((_double,), {"x": 1}, until="trace")


def test_contract_is_checked():
    with pytest.raises(KeyError, match="needs x"):
        _double({})
    broken = Stage("broken", lambda s: {}, gives=("w",))
    with pytest.raises(KeyError, match="did not give w"):
        broken({})
