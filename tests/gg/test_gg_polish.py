"""The final projection of the GG surface design (gridshell.gg.design._polish) and the
coarse-to-fine start: the regularisation shrinks with the constraint energy, so the polish
ends in Gauss-Newton steps (superlinear) and reaches the design's figures; a fine grid starts
from the coarse design interpolated."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from tests.helpers.gg_cases import helicoid_grid

from gridshell.corpus import registry
from gridshell.gg import design as gd
from gridshell.gg.design import design_gg_surface, geodesic_residual, length_residual_rel
from gridshell.gg.initial import initial_grid
from gridshell.gg.pipeline import gg_score
from gridshell.geometry.grid import grid_quads


def _bumped_helicoid(n=40):
    """A 40 x 40 helicoid grid (isometric to the catenoid r = sqrt(0.25 + s^2), an exact GG
    mesh) and the same grid lifted by a smooth bump of 1 % of the diagonal."""
    P = helicoid_grid(n, n, c=0.5)
    u, v = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n), indexing="ij")
    bump = np.sin(np.pi * u) * np.sin(np.pi * v) * np.cos(3 * u + 2 * v)
    diag = float(np.linalg.norm(np.ptp(P.reshape(-1, 3), axis=0)))
    P0 = P.copy()
    P0[..., 2] += 0.01 * diag * bump
    return P, P0


def _polish_energies(d):
    return np.array([h["constraint_energy"] for h in d.history if h["round"] == "polish"])


@pytest.mark.slow
def test_polish_reaches_round_off_superlinearly_on_a_surface_isometric_to_a_catenoid():
    P, P0 = _bumped_helicoid()
    assert np.abs(geodesic_residual(P)).max() < 1e-10  # the target is an exact GG mesh
    assert np.abs(geodesic_residual(P0)).max() > 1e-3
    d = design_gg_surface(P.reshape(-1, 3), grid_quads(*P.shape[:2]), P0)
    # the design's figures: residuals at the round-off tolerances, the net traced on it far
    # inside the paper's thresholds, back on the helicoid
    assert d.converged and d.stop == "tolerance", (d.stop, d.geodesic_residual_max)
    assert np.abs(geodesic_residual(d.P)).max() <= 1e-9
    assert max(length_residual_rel(d.P).values()) <= 1e-9
    assert gg_score(d.P) < 0.01
    assert d.deviation["max"] < 0.1
    # superlinear: the constraint energy (squared residuals) falls every step, by 10x or
    # more per step on average over the whole polish, and by 100x or more in the last two
    # steps above the round-off floor (energy 1e-15: residuals ~3e-8), in a handful of steps
    # (measured: 1.6e-10, then 38x, 8x, 60x, 34x, then 1.5x and 18x at round-off)
    e = _polish_energies(d)
    e_start = d.history[-len(e) - 1]["energy"]  # the last round's energy bounds the start
    assert 3 <= len(e) <= 8, e
    assert np.all(e[1:] < e[:-1])
    assert (e[0] / e[-1]) ** (1.0 / (len(e) - 1)) >= 10.0, e
    above = e[e > 1e-15]
    assert len(above) >= 3 and above[-3] / above[-1] >= 100.0, e
    assert e_start > 1e6 * e[-1]
    # the regularisation shrank with the energy: the last steps are Gauss-Newton steps
    reg = [h["regularisation"] for h in d.history if h["round"] == "polish"]
    assert reg[-1] < 1e-6 and all(b <= a for a, b in zip(reg, reg[1:]))


@pytest.mark.slow
def test_a_fixed_regularisation_converges_only_linearly(monkeypatch):
    # the former schedule (metric terms of fixed size): the same polish, 6 steps, falls by a
    # constant factor per step and stays far above round-off - what the schedule is for
    monkeypatch.setattr(gd, "POLISH_EREF", 1e-300)  # full size at every energy
    P, P0 = _bumped_helicoid()
    d = design_gg_surface(P.reshape(-1, 3), grid_quads(*P.shape[:2]), P0,
                          weights={"polish_decay": 1.0}, polish_iter=6)
    e = _polish_energies(d)
    assert not d.converged and d.stop in ("iteration limit", "stagnation")
    assert e[-1] > 1e-12, e  # the shrinking schedule: ~1e-17 in 6 steps
    assert (e[0] / e[-1]) ** (1.0 / (len(e) - 1)) < 3.0, e


def _height_field(name, n):
    ref = dataclasses.replace(registry.get(name), rows=n, cols=n)
    V, F = ref.mesh_arrays()
    return V, F, initial_grid(V, F, meridians="cols", grid=(n, n))


@pytest.mark.slow
def test_random_height_field_reaches_its_figures_coarse_to_fine():
    # a random freeform height field of the corpus (a 12 m hill), at 48 x 48: above
    # COARSE_ABOVE, so designed at 24 x 24 first and refined
    assert 48 > gd.COARSE_ABOVE
    V, F, P0 = _height_field("hill-02", 48)
    msgs = []
    d = design_gg_surface(V, F, P0, evaluate=gg_score, progress=msgs.append)
    assert any("designing at 24 x 24 first" in m for m in msgs)
    rounds = [h for h in d.history if h["round"] not in ("polish", "coarse")]
    assert len(rounds) == gd.FINE_ROUNDS and d.history[0]["round"] == "coarse"
    # the design's figures hold on the traced net, and the polish ended on them (or on the
    # round-off tolerance), not on its iteration limit
    assert d.score is not None and d.score < 0.5 and gg_score(d.P) == pytest.approx(d.score)
    assert d.stop in ("figures", "tolerance"), d.stop
    # (the constraints are slightly inconsistent on a freeform field: the residuals stop at a
    # floor, here ~1e-3, far below what the figures need)
    assert d.geodesic_residual_max < 3e-3 and d.length_residual_rel_max < 3e-3
    e = _polish_energies(d)
    assert len(e) and np.all(e[1:] < e[:-1])
    assert d.deviation["mean"] < 1.0


def test_resample_is_exact_on_bicubic_grids_and_keeps_the_corners():
    u, v = np.meshgrid(np.arange(7.0), np.arange(5.0), indexing="ij")
    P = np.stack([u, v, 0.1 * u ** 3 - 0.2 * u * v ** 2 + v ** 3 / 7], axis=-1)
    Q = gd._resample(P, 13, 9)
    uu, vv = np.meshgrid(np.linspace(0, 6, 13), np.linspace(0, 4, 9), indexing="ij")
    ref = np.stack([uu, vv, 0.1 * uu ** 3 - 0.2 * uu * vv ** 2 + vv ** 3 / 7], axis=-1)
    np.testing.assert_allclose(Q, ref, atol=1e-12)
    np.testing.assert_allclose(gd._resample(Q, 7, 5), P, atol=1e-12)
