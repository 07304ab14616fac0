"""The GG design traces the net of each checked mesh once (issue 18, big inputs): the net of
the checkpoint the surface design returns is the one its check traced, not a second trace,
and the design is the same as with every net traced anew."""
from __future__ import annotations

import numpy as np
from tests.helpers.io_cases import hill

import gridshell.gg.pipeline as pipeline
from gridshell.gg.pipeline import TracedNets, design_gg, gg_net_from_mesh, gg_score
from gridshell.measure.metrics import alignability_error, summary

OPTIONS = dict(grid=(10, 8), n_lamellae=4, frames=0, polish_iter=8, allow_unconverged=True)


def _design(monkeypatch, *, cache: bool):
    """The design of the hill, the number of nets traced and the progress messages."""
    calls = []
    trace = pipeline.gg_net_from_mesh

    def counted(P, **kw):
        assert kw["revolution_net"] is False  # a score needs no net on the revolution
        calls.append(np.array(P, copy=True))
        return trace(P, **kw)

    with monkeypatch.context() as m:
        m.setattr(pipeline, "gg_net_from_mesh", counted)
        if not cache:  # every key new: every net traced again
            m.setattr(TracedNets, "_key", staticmethod(lambda P: object()))
        msgs: list[str] = []
        design = design_gg(hill(), progress=msgs.append, **OPTIONS)
    return design, calls, msgs


def test_the_returned_checkpoint_is_not_traced_again(monkeypatch):
    (bundle, report), calls, msgs = _design(monkeypatch, cache=True)
    checks = [m for m in msgs if ": score " in m]
    assert len(checks) >= 2  # checkpoints of the polish (and the rounds) were scored
    # one trace per check, none after the design
    assert len(calls) == len(checks)
    P = bundle.surface_V.reshape(*bundle.params["grid"], 3)
    assert any(np.array_equal(P, c) for c in calls)  # the checkpoint was traced by its check
    assert any("tracing geodesics: the net traced when the design checked" in m for m in msgs)
    # and that net is the one a new trace gives
    fresh = gg_net_from_mesh(P, n_lamellae=4)
    assert np.array_equal(fresh["net"].joints, bundle.net.joints)
    rev = fresh["net_rev"]  # and the net on the revolution, added to the kept one
    assert bundle.metrics["alignability_revolution"] == {
        k: 100.0 * v for k, v in summary(alignability_error(rev.joints, rev.loops)).items()}
    assert report["design"]["score"] == gg_score(P, n_lamellae=4)


def test_the_design_is_the_same_with_and_without_the_kept_nets(monkeypatch):
    (b1, r1), calls1, _ = _design(monkeypatch, cache=True)
    (b0, r0), calls0, _ = _design(monkeypatch, cache=False)
    assert len(calls0) == len(calls1) + 1  # without: the checkpoint traced again
    assert np.array_equal(b1.surface_V, b0.surface_V)
    assert np.array_equal(b1.net.joints, b0.net.joints)
    assert np.array_equal(b1.aligned, b0.aligned)
    assert [lam.joints.tolist() for lam in b1.net.lamellae] == \
        [lam.joints.tolist() for lam in b0.net.lamellae]
    assert b1.metrics == b0.metrics
    assert b1.params["surface"] == b0.params["surface"]
    assert r1["net"] == r0["net"] and r1["revolution"] == r0["revolution"]


def test_a_mesh_with_no_net_scores_inf_and_is_not_kept():
    P = np.zeros((6, 5, 3))  # every vertex at one point: no surface of revolution
    nets = TracedNets(n_lamellae=4)
    assert nets.score(P) == float("inf")
    assert nets._nets == {}
