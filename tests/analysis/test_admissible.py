"""An NCP design whose PHLW step fails: exit 3 with the analysis's finding where no regular
patch of the mode exists (a sphere cap: umbilic everywhere), the optimizer's failure (exit 4)
where one does (the demo dome: an 86 % patch). The pipeline is replaced by one that fails as
the PHLW step does; the analysis is the real one on the real meshes."""
from __future__ import annotations

import pytest
from tests.analysis.test_analysis import sphere_cap

from gridshell.analysis import admissible
from gridshell.core.errors import ConvergenceError, NoNetError
from gridshell.data import path as data_path


def _fails_like_phlw(source, **kw):
    err = ConvergenceError("the PHLW step left a surface without the cnc net ... the "
                           "optimizer's failure")
    err.phlw_failure = True
    raise err


@pytest.fixture
def failing(monkeypatch):
    from gridshell.ncp import pipeline

    monkeypatch.setattr(pipeline, "design_ncp", _fails_like_phlw)


def test_no_regular_patch_is_exit_3_with_the_finding(failing):
    V, F = sphere_cap()
    with pytest.raises(NoNetError, match="no regular patch of the cnc net") as e:
        admissible.design_ncp_explained((V, F), mode="cnc", units="m")
    assert e.value.exit_code == 3
    assert "near-umbilic regions cover" in str(e.value) and "covers 0 %" in str(e.value)
    assert "optimizer" not in str(e.value)


def test_an_admissible_patch_keeps_the_optimizers_failure(failing):
    with pytest.raises(ConvergenceError, match="optimizer's failure"):
        admissible.design_ncp_explained(str(data_path("dome.obj")), mode="cnc")


def test_other_failures_pass_through(monkeypatch):
    from gridshell.ncp import pipeline

    def bad(source, **kw):
        raise ConvergenceError("the post-optimization missed its figures")

    monkeypatch.setattr(pipeline, "design_ncp", bad)
    V, F = sphere_cap()
    with pytest.raises(ConvergenceError, match="post-optimization"):
        admissible.design_ncp_explained((V, F), mode="cnc", units="m")


class _Design:
    """A design whose net covers ``coverage`` % of the target (only what the gate reads)."""

    def __init__(self, coverage):
        self.bundle = type("B", (), {"metrics": {"fidelity": {"coverage": coverage}}})()


@pytest.fixture
def covering(monkeypatch, tmp_path):
    """``run(target, coverage, **kw)``: design_ncp_explained on the mesh ``target`` (written to
    an OBJ) where the regular design's net covers ``coverage`` % (with DENSE_CURVES curves
    ``dense`` %, if given) and the ring's design fails (covers 50 %) unless ``ring`` is given;
    the ring's calls are counted."""
    from gridshell.geometry.meshfile import write_mesh
    from gridshell.ncp import pipeline

    calls = []

    def run(mesh, coverage, ring=None, dense=None, **kw):
        monkeypatch.setattr(pipeline, "design_ncp", lambda source, **k: _Design(
            dense if dense is not None and k.get("curves") == admissible.DENSE_CURVES
            else coverage))
        monkeypatch.setattr(admissible, "ring_design", lambda *a, **k: calls.append(k) or (
            (ring, "") if ring is not None else (None, "the ring's net covers 50 %")))
        path = tmp_path / "target.obj"
        write_mesh(path, *mesh)
        return admissible.design_ncp_explained(str(path), mode="phlw", units="m", **kw)
    run.calls = calls
    return run


def test_a_dome_net_under_60_percent_is_exit_3_naming_coverage_and_umbilic(covering):
    from tests.analysis.test_analysis import paraboloid

    with pytest.raises(NoNetError) as e:
        covering(paraboloid(), 55.0)
    msg = str(e.value)
    assert "covers 55 % of the target, less than 60 %" in msg and "near-umbilic" in msg
    assert "the ring's net covers 50 %" in msg and "--min-coverage 0" in msg
    assert covering.calls[-1]["min_coverage"] == pytest.approx(60.0)
    kept = covering(paraboloid(), 55.0, min_coverage=0)       # no gate: as it is
    assert kept.bundle.metrics["fidelity"]["coverage"] == 55.0
    ring = _Design(75.0)
    assert covering(paraboloid(), 55.0, ring=ring) is ring      # the ring covers more


def test_a_regular_patch_keeps_its_net_unless_the_user_gates_it(covering):
    from tests.analysis.test_analysis import saddle

    n = len(covering.calls)
    assert covering(saddle(), 44.0).bundle.metrics["fidelity"]["coverage"] == 44.0
    assert len(covering.calls) == n + 1                # the ring was tried (it covers less)
    assert covering(saddle(), 70.0).bundle.metrics["fidelity"]["coverage"] == 70.0
    with pytest.raises(NoNetError, match="less than --min-coverage 80 %"):
        covering(saddle(), 70.0, min_coverage=80.0)


def test_a_denser_net_is_tried_first_where_the_default_covers_too_little(covering):
    from tests.analysis.test_analysis import paraboloid

    n = len(covering.calls)
    got = covering(paraboloid(), 55.0, dense=64.0)
    assert got.bundle.metrics["fidelity"]["coverage"] == 64.0 and len(covering.calls) == n
    with pytest.raises(NoNetError, match="covers 57 % of the target"):   # the better of two
        covering(paraboloid(), 55.0, dense=57.0)
    with pytest.raises(NoNetError, match="covers 55 %"):       # the user's own curves: kept
        covering(paraboloid(), 55.0, dense=64.0, curves=8)

