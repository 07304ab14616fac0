"""AA on a dome with a little K < 0: where K < 0 on fewer than MAX_DROPPED (5 %) of the samples
(the fraction a net may lack its directions on anyway) there is no AA net, said before any
PHLW work (NoNetError, exit 3); with more the reference goes on to the PHLW step.

The reference is the height field z = -x^2 / 2a - y^2 / 2b + d x^2 y^2 on [-5, 5]^2 (a = b =
10 m), whose Gaussian curvature has the sign of f_xx f_yy - f_xy^2 = (-1/a + 2 d y^2)
(-1/b + 2 d x^2) - 16 d^2 x^2 y^2: negative near the four corners only, on a share that grows
with d. The count of samples with K < 0 the message gives is checked against this closed form
at the same samples.
"""
from __future__ import annotations

import re

import numpy as np
import pytest

from gridshell.cli.main import main
from gridshell.core.errors import NoNetError
from gridshell.geometry.bspline import fit_grid, uniform_params
from gridshell.geometry.grid import grid_quads
from gridshell.geometry.meshfile import write_mesh
from gridshell.ncp import phlw
from gridshell.ncp.directions import MAX_DROPPED, reference_net_check

A = B = 10.0
L = 5.0


def _heights(x, y, d):
    return -x ** 2 / (2 * A) - y ** 2 / (2 * B) + d * x ** 2 * y ** 2


def _k_sign(x, y, d):
    """f_xx f_yy - f_xy^2 (the sign of K) of :func:`_heights`."""
    return (-1 / A + 2 * d * y ** 2) * (-1 / B + 2 * d * x ** 2) - (4 * d * x * y) ** 2


def _grid(d, n=40):
    x, y = np.meshgrid(np.linspace(-L, L, n), np.linspace(-L, L, n), indexing="ij")
    return np.stack([x, y, _heights(x, y, d)], -1)


def _closed_count(srf, d, samples=(24, 24)):
    """Samples of ``reference_net_check`` with K < 0 by the closed form (a grid fit maps the
    parameters linearly onto x and y)."""
    u, v = uniform_params(srf, samples)
    X, Y = np.meshgrid(-L + 2 * L * np.asarray(u), -L + 2 * L * np.asarray(v), indexing="ij")
    return int((_k_sign(X, Y, d) < 0).sum())


@pytest.mark.parametrize("d", [7e-4, 8e-4])
def test_k_negative_on_less_than_five_percent_is_no_net(d):
    srf = fit_grid(_grid(d), 12, 12, 4, 4)[0]
    expected = _closed_count(srf, d)
    assert 0 < expected < MAX_DROPPED * 576
    with pytest.raises(NoNetError) as exc:
        reference_net_check(srf, "aa")
    msg = str(exc.value)
    got = int(re.search(r"K < 0 at only (\d+) of 576 samples", msg).group(1))
    assert got == expected, msg
    assert "no AA net" in msg and "5 %" in msg


def test_k_negative_on_more_goes_on_to_the_phlw_step():
    d = 1e-3
    srf = fit_grid(_grid(d), 12, 12, 4, 4)[0]
    assert _closed_count(srf, d) > MAX_DROPPED * 576
    reference_net_check(srf, "aa")            # no error: a net may exist near it
    reference_net_check(fit_grid(_grid(8e-4), 12, 12, 4, 4)[0], "cnc")  # other modes: K free


def test_ncp_aa_exits_3_before_any_phlw_work(tmp_path, capsys, monkeypatch):
    def no_work(*a, **k):
        raise AssertionError("the PHLW step ran")

    monkeypatch.setattr(phlw, "optimize_phlw", no_work)   # imported from there when it runs
    P = _grid(8e-4, 30)
    write_mesh(tmp_path / "dome.obj", P.reshape(-1, 3), grid_quads(30, 30))
    code = main(["ncp", str(tmp_path / "dome.obj"), "--mode", "aa", "-o", str(tmp_path / "o"),
                 "-q"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 3 and len(err) == 1 and "K < 0 at only" in err[0], err
    assert not (tmp_path / "o").exists()
