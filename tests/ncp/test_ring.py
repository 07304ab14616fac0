"""The ring around the umbilic (gridshell.ncp.ring, issue 29 item 2) on a paraboloid dome of
revolution z = h (1 - rho^2 / R^2), against closed forms: the patch's rows are its parallels
(the height along each is the profile's), its area share the annulus sector's, a row of
constant H gets n = H (the net angle pi/4); and the NCP design on the ring meets every figure
where the regular patch does not exist."""
from __future__ import annotations

import numpy as np
import pytest

from gridshell.ncp.phlw.checks import fit_rows
from gridshell.ncp.ring import GAP, ring_patch

R, H = 5.0, 2.0


def _dome(nt: int = 72, nr: int = 30) -> tuple[np.ndarray, np.ndarray]:
    """The paraboloid over the disc of radius R, a polar triangle mesh (apex at the top)."""
    th = np.linspace(0, 2 * np.pi, nt, endpoint=False)
    T, P = np.meshgrid(th, np.linspace(0, R, nr)[1:], indexing="ij")
    X, Y = P * np.cos(T), P * np.sin(T)
    V = np.vstack([[0.0, 0.0, H], np.stack([X.ravel(), Y.ravel(),
                                              (H * (1 - (X * X + Y * Y) / R ** 2)).ravel()], 1)])
    idx = 1 + np.arange(nt * (nr - 1)).reshape(nt, nr - 1)
    F = []
    for i in range(nt):
        j = (i + 1) % nt
        F.append([0, idx[i, 0], idx[j, 0]])
        for k in range(nr - 2):
            F += [[idx[i, k], idx[j, k], idx[j, k + 1]], [idx[i, k], idx[j, k + 1], idx[i, k + 1]]]
    return V, np.array(F)


def test_the_ring_patch_is_the_dome_in_polar_loops():
    V, F = _dome()
    p = ring_patch(V, F, np.array([0.0, 0.0, H]), np.array([0.0, 0.0, 1.0]), inner=1.5)
    assert abs(p.aspect - 1.0) < 1e-3 and abs(p.outer - 0.97 * R) < 0.02 * R
    u = np.linspace(0, 1, 9)
    S = p.surface.evaluate(np.repeat(u, 9), np.tile(u, 9)).reshape(9, 9, 3)
    rho = np.hypot(S[..., 0], S[..., 1])
    # each row u = const is one parallel: one radius, the profile's height
    assert np.ptp(rho, axis=1).max() < 0.005 * R
    np.testing.assert_allclose(S[..., 2], H * (1 - rho ** 2 / R ** 2), atol=0.002 * R)
    np.testing.assert_allclose(rho[:, 0], np.linspace(1.5, p.outer, 9), atol=0.005 * R)
    # the share of the target's area: the annulus sector's on the paraboloid (closed form of
    # the area of a paraboloid's zone, 2 pi int rho sqrt(1 + (2 h rho / R^2)^2) drho)
    zone = lambda a: (np.pi / 6) * (R ** 4 / H ** 2) * (  # noqa: E731
        (1 + (2 * H * a / R ** 2) ** 2) ** 1.5 - 1)
    expected = 100 * (1 - GAP) * (zone(p.outer) - zone(1.5)) / zone(R)
    assert abs(p.share - expected) < 2.0, (p.share, expected)


def test_a_row_of_constant_curvature_gets_the_net_angle_pi_over_4():
    """On a parallel K and H are constant: the line of eq. 4.8 has no slope; n = H (beta =
    pi/4), t^2 = H^2 - K. A wiggle of 0.1 % of H (a B-spline's) does not change it."""
    K = np.full((3, 40), 0.02)
    Hm = np.full((3, 40), 0.15) * (1 + 1e-3 * np.sin(np.arange(40)))[None, :]
    fit = fit_rows(K, Hm, "phlw")
    np.testing.assert_allclose(fit.n, Hm.mean(axis=1), rtol=1e-12)
    np.testing.assert_allclose(fit.t ** 2, Hm.mean(axis=1) ** 2 - 0.02, rtol=1e-2)
    H2 = np.full((3, 40), 0.15) * (1 + 0.1 * np.sin(np.arange(40)))[None, :]
    slope = fit_rows(2 * 0.2 * H2 - 0.05, H2, "phlw")     # a real line K = 2 n H - c, n = 0.2
    np.testing.assert_allclose(slope.n, 0.2, rtol=1e-9)


def test_the_ring_refuses_what_is_not_a_height_field():
    from gridshell.core.errors import InputError

    V, F = _dome()
    with pytest.raises(InputError, match="empty"):
        ring_patch(V, F, V[-1], np.array([0.0, 0.0, 1.0]), inner=1.0)     # top on the rim
    Vs = np.vstack([V, V * [1, 1, -1]])                # a closed-ish shell: folds over
    Fs = np.vstack([F, F[:, ::-1] + len(V)])
    with pytest.raises(InputError, match="height field"):
        ring_patch(Vs, Fs, np.array([0.0, 0.0, H]), np.array([0.0, 0.0, 1.0]), inner=1.5)


@pytest.mark.slow
def test_ncp_on_the_dome_designs_on_the_ring(tmp_path):
    """The regular patch fails (an umbilic at the top); the ring's design meets every figure,
    sits on the target and covers most of it."""
    from gridshell.analysis.admissible import design_ncp_explained
    from tests.helpers.io_cases import write_obj_text

    V, F = _dome()
    path = write_obj_text(tmp_path / "dome.obj", V, F)
    d = design_ncp_explained(str(path), mode="phlw", frames=4)
    m = d.bundle.metrics
    assert m["quality"]["ok"] and m["region"]["kind"] == "ring around the umbilic"
    f = m["fidelity"]
    assert f["target"] == "the reference mesh" and f["deviation_mean"] < 2.0
    assert f["coverage"] >= 60.0
    # the joints on the paraboloid (closed form), off it by < 0.5 % of the diagonal
    J = d.bundle.net.joints
    off = np.abs(J[:, 2] - H * (1 - (J[:, 0] ** 2 + J[:, 1] ** 2) / R ** 2))
    assert off.max() < 0.005 * f["diagonal"]
