"""Every splice holds its two pieces by two fasteners (docs/fabrication.md, ``--overlap``):
a joint splice's pieces share at least two joints, a span splice has two fasteners on both
pieces, no piece is shorter than its overlap; a lamella no such splice can cut is refused
with the reason. Checked on a hand-made strip with a tail (where the farthest joint splice
used to be at the last joint: a 90 mm stub with one hole) and over the synthetic designs of
every kind at scales and sheets that force splices."""
from __future__ import annotations

import numpy as np
import pytest
from tests.helpers.fab_cases import make_bundle

from gridshell.core.errors import InputError
from gridshell.fabrication import FabParams
from gridshell.fabrication.axis import LineAxis
from gridshell.fabrication.splice import split_strip
from gridshell.fabrication.strip import Strip
from gridshell.fabrication.strips import strips_from_bundle


def _check_rule(strip, pieces):
    """The splice rule on consecutive pieces of ``strip`` (independent of the planner: read
    off the pieces' own joints and fasteners)."""
    js = strip.joint_s
    for p, q in zip(pieces[:-1], pieces[1:]):
        note = next(n for n in p.splices if n["with"] == q.piece)
        ov = p.s1 - q.s0
        assert ov > 0
        assert p.length >= ov - 1e-9 and q.length >= ov - 1e-9, (p.name, q.name)
        if note["kind"] == "joint":
            both = [s for s in js if p.s0 - 1e-9 <= s <= p.s1 + 1e-9
                    and q.s0 - 1e-9 <= s <= q.s1 + 1e-9]
            assert len(both) >= 2, (strip.lamella, p.piece, both)
        else:
            f = np.asarray(note["fasteners"], float)
            assert len(f) == 2 and f[1] - f[0] > 0
            for piece in (p, q):
                assert all(np.any(np.isclose(piece.splice_s, s)) for s in f)


def test_a_tail_past_the_last_joint_is_not_a_one_joint_stub():
    js = 100.0 * np.arange(6)
    strip = Strip(lamella=3, family=1, orientation="tangent", axis=LineAxis(),
                  s0=-15.0, s1=js[-1] + 75.0, t_lo=-10.0, t_hi=10.0, joint_s=js,
                  joint_index=np.arange(6), neighbours=[[10 + i] for i in range(6)])
    pieces = split_strip(strip, FabParams(sheet="560x400"))
    assert len(pieces) == 2
    _check_rule(strip, pieces)
    assert list(pieces[1].joint_s) == [400.0, 500.0]     # both last joints on the last piece


def test_an_overlap_too_short_for_two_fasteners_is_refused_with_the_reason():
    strip = Strip(lamella=5, family=1, orientation="tangent", axis=LineAxis(),
                  s0=-15.0, s1=2015.0, t_lo=-10.0, t_hi=10.0, joint_s=np.array([0.0, 2000.0]),
                  joint_index=np.arange(2), neighbours=[[1], [2]])
    with pytest.raises(InputError) as e:
        split_strip(strip, FabParams(overlap=32.0))
    msg = str(e.value)
    assert "\n" not in msg and "lamella 5" in msg and "hinge" in msg and "--overlap" in msg


CASES = [(kind, scale, sheet, net)
         for kind in ("GG", "AA", "CNC", "NCP")
         for scale, sheet in (("1:1", "300x200"), ("1:2", "400x200"), ("1:1", "194x119"))
         for net in ({"nr": 4, "nc": 5}, {"nr": 3, "nc": 7, "stretch": (0.05, 0.4)})]


@pytest.mark.parametrize("kind, scale, sheet, net", CASES)
def test_every_splice_of_the_synthetic_designs_shares_two_fasteners(kind, scale, sheet, net):
    b = make_bundle(kind, **net)
    params = FabParams(scale=scale, sheet=sheet, joints="marks")
    n_split = 0
    for strip in strips_from_bundle(b, params):
        try:
            pieces = split_strip(strip, params)
        except InputError as e:
            assert "\n" not in str(e) and f"lamella {strip.lamella}" in str(e)
            continue
        n_split += len(pieces) > 1
        _check_rule(strip, pieces)
    assert n_split
