"""Quality gates: the paper's thresholds, and a missing figure never passes."""
import math

import pytest

from gridshell.measure.quality import THRESHOLDS, design_gates, failing, gate_summary, passed


def _gg(mean, mx, amean=None, amax=None):
    return {"alignability": {"mean": mean, "max": mx},
            "alignability_arc": {"mean": mean if amean is None else amean,
                                 "max": mx if amax is None else amax}}


def test_gg_passes_below_and_fails_at_the_thresholds():
    assert passed(design_gates("GG", _gg(0.2, 1.5)))
    bad = failing(design_gates("GG", _gg(0.2, 7.05)))
    assert [g.name for g in bad] == ["delta_a_max", "delta_a_arc_max"]
    # the limit itself is not within it
    assert not passed(design_gates("GG", _gg(1.0, 1.5)))
    assert "7.05 % >= 3 %" in gate_summary(design_gates("GG", _gg(0.2, 7.05)))


@pytest.mark.parametrize("value", [None, math.nan, math.inf, "x"])
def test_a_figure_that_was_not_measured_fails(value):
    m = {"delta_a_after": {"mean": 0.1, "max": 0.2}, "delta_l": {"max": 0.1},
         "delta_n": {"max": value}, "aligned_radius_error": 0.01}
    gates = design_gates("CNC", m)
    assert [g.name for g in failing(gates)] == ["delta_n_max"]
    assert "not measured" in failing(gates)[0].line()


def test_ncp_kinds_have_their_collapse_gate():
    base = {"delta_a_after": {"mean": 0.1, "max": 0.2}, "delta_l": {"max": 0.1},
            "delta_n": {"max": 0.1}}
    assert passed(design_gates("NCP", base))
    assert not passed(design_gates("AA", base))  # no line error measured
    assert passed(design_gates("AA", dict(base, aligned_line_error=0.5)))
    assert not passed(design_gates("CNC", dict(base, aligned_radius_error=1.2)))
    with pytest.raises(ValueError):
        design_gates("XX", base)


def test_thresholds_are_the_papers():
    assert THRESHOLDS["delta_a_mean"][1] == 1.0 and THRESHOLDS["delta_a_max"][1] == 3.0
    assert THRESHOLDS["delta_l_max"][1] == 1.0 and THRESHOLDS["delta_n_max"][1] == 1.0


def test_the_phlw_step_gates_are_gates_with_their_records_and_lines():
    """One Gate class: the PHLW step's gates (own rule, no % limit) are quality.Gate, their
    records and printed lines as before, and a record reads back to the same gate."""
    from gridshell.measure.quality import Gate
    from gridshell.ncp.phlw.gates import phlw_gates

    before = {"E_PHLW": {"total": 2000.0}, "relation_max_rel": 0.5, "angle_max_deg": 10.0}
    after = {"E_PHLW": {"total": 120.0}, "relation_max_rel": 0.7, "angle_max_deg": 1.0}
    gates = phlw_gates(before, after, converged=True)
    assert all(type(g) is Gate for g in gates)
    assert [g.ok for g in gates] == [True, True, False, True]
    assert gates[1].line() == "pass  E_PHLW not higher than at the start: 2e+03 -> 120 (<= start 2e+03)"
    assert gates[2].line().startswith("FAIL  relation error (eq. 4.8) not higher than at the start: 0.5 -> 0.7 (> ")
    d = gates[2].as_dict()
    assert list(d) == ["name", "label", "ok", "detail", "line"] and d["line"] == gates[2].line()
    assert Gate.from_dict(d) == gates[2]
    t = design_gates("GG", _gg(0.2, 7.05))[1]
    assert list(t.as_dict()) == ["name", "label", "value", "limit", "ok"]
    assert Gate.from_dict(t.as_dict()) == t
    assert "2 of 4 figures fail" not in gate_summary(gates) and "1 of 4 figures fail: relation" \
        in gate_summary(gates)


def test_the_former_check_class_warns_and_makes_a_gate():
    from gridshell.measure.quality import Gate
    from gridshell.ncp.phlw import gates as phlw

    with pytest.warns(DeprecationWarning, match="Gate"):
        check = phlw.Check
    g = check("converged", "optimizer converged", False, "no")
    assert type(g) is Gate and not g.ok and g.line() == "FAIL  optimizer converged: no"
