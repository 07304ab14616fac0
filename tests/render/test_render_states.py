"""The pictures of an alignment sequence are drawn on one reused figure (issue 18: the
pictures took longer than the design of a 200k-triangle target): each state's picture is
the one a figure of its own would show, whatever was drawn before it."""
from __future__ import annotations

import numpy as np
from tests.helpers.render_cases import states_case


def test_a_state_picture_does_not_depend_on_the_states_drawn_before_it():
    from gridshell.render.state_sheet import state_images

    frames, E, fam, _ = states_case()
    view = (25.0, -50.0)  # one camera for both orders (the default one is fitted to all)
    fwd = state_images(frames, E, families=fam, dpi=50, view=view)
    back = state_images(frames[::-1], E, families=fam, dpi=50, view=view)
    again = state_images([frames[0], frames[2], frames[0]], E, families=fam, dpi=50, view=view)
    for a, b in zip(fwd, back[::-1]):
        assert np.array_equal(np.asarray(a), np.asarray(b))
    assert np.array_equal(np.asarray(again[0]), np.asarray(again[2]))
    assert not np.array_equal(np.asarray(fwd[0]), np.asarray(fwd[2]))
    assert all(im.mode == "RGB" for im in fwd)
