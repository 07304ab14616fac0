"""The assembly plan (gridshell.design.assembly) on a 2 x 2 net drawn by hand: every joint
closed once, the family-3 strips in id order each from its start, lengths in mm of the model."""
from __future__ import annotations

from gridshell.design.assembly import assembly_plan, deploy_steps

#   joints 0 1 / 2 3: lamellae 0, 1 of family 1 run along the rows, 2, 3 of family 3 along
#   the columns (3 runs backwards: its start is joint 3)
DESIGN = {"lamellae": [
    {"id": 0, "family": 1, "joints": [0, 1], "joint_s": [0.1, 0.3], "length": 0.4},
    {"id": 1, "family": 1, "joints": [2, 3], "joint_s": [0.1, 0.3], "length": 0.4},
    {"id": 2, "family": 3, "joints": [0, 2], "joint_s": [0.05, 0.25], "length": 0.3},
    {"id": 3, "family": 3, "joints": [3, 1], "joint_s": [0.05, 0.25], "length": 0.3}]}
FAB = {"params": {"scale": 0.1}, "pieces": [
    {"lamella": 0, "piece": 1, "sheet": 1}, {"lamella": 2, "piece": 2, "sheet": 2},
    {"lamella": 2, "piece": 1, "sheet": 1}]}


def test_every_joint_closed_once_in_strip_order():
    plan = assembly_plan(DESIGN, FAB)
    steps = plan["steps"]
    assert [s["joint"] for s in steps] == [0, 2, 3, 1]
    assert [s["strip"] for s in steps] == [2, 2, 3, 3]
    assert [s["across"] for s in steps] == [0, 1, 1, 0]
    assert [s["step"] for s in steps] == [1, 2, 3, 4]
    # mm of the model at 1:10: 0.05 m -> 5 mm along lamella 2, 0.1 m -> 10 mm along 0
    assert abs(steps[0]["at_mm"] - 5.0) < 1e-9 and abs(steps[0]["across_mm"] - 10.0) < 1e-9
    assert abs(steps[3]["across_mm"] - 30.0) < 1e-9


def test_strips_say_where_they_go():
    plan = assembly_plan(DESIGN, FAB)
    by_id = {s["id"]: s for s in plan["strips"]}
    assert [s["id"] for s in plan["strips"]] == [0, 1, 2, 3]          # family 1 first
    assert by_id[2]["pieces"] == [(1, 1), (2, 2)]
    assert abs(by_id[0]["length_mm"] - 40.0) < 1e-9
    assert [(j, o) for j, o, _ in by_id[3]["crossings"]] == [(3, 1), (1, 0)]
    assert assembly_plan(DESIGN, None)["scale"] == 1.0


def test_deploy_steps_name_the_collapsed_curve_and_supports():
    cnc = deploy_steps("CNC", 13, supports=8)
    assert "circular arc" in cnc[1] and "13 states" in cnc[3] and "8 support joints" in cnc[4]
    assert "straight strip" in deploy_steps("GG", 5)[1]
