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
