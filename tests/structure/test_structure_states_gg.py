"""GG states: each lamella a geodesic of the state's surface, so the spline through its joints
bends the strip about its weak axis only, whatever normals the joint mesh implies; the
residual geodesic curvature of the joint mesh is reported as the error bound."""
from types import SimpleNamespace

import numpy as np
import pytest

from gridshell.structure.states import _lamella_curvatures


def _helix_lamella(R, alpha, phi_tilt, n=25, L=2.0):
    """Joints of a helix geodesic on the cylinder of radius R, and its inward normals tilted by
    ``phi_tilt`` about the tangent (a joint mesh that is not the geodesic's surface)."""
    s = np.linspace(0.0, L, n)
    phi = s * np.sin(alpha) / R
    X = np.stack([R * np.cos(phi), R * np.sin(phi), s * np.cos(alpha)], axis=1)
    N = -np.stack([np.cos(phi), np.sin(phi), 0 * phi], axis=1)
    T = np.stack([-np.sin(alpha) * np.sin(phi), np.sin(alpha) * np.cos(phi),
                  np.full_like(phi, np.cos(alpha))], axis=1)
    U = np.cross(N, T)
    M = np.cos(phi_tilt) * N + np.sin(phi_tilt) * U
    return X, s, M


@pytest.mark.parametrize("tilt", [0.0, 0.3])
def test_gg_state_strip_is_a_geodesic(tilt):
    """kn = sin^2(alpha)/R = |k| of the helix, kg = 0 (strong axis) within 1 % at any tilt of
    the joint normals; residual |kg| = |k| sin(tilt); orthogonal strips keep the tilt's kg."""
    R, alpha = 0.9, 0.7
    X, s, M = _helix_lamella(R, alpha, tilt)
    lam = SimpleNamespace(joints=np.arange(len(X)), joint_s=s)
    k = np.sin(alpha) ** 2 / R
    (dc,), resid = _lamella_curvatures([lam], X, M, "tangent")
    inner = slice(2, -2)
    assert np.allclose(np.abs(dc.kn[inner]), k, rtol=1e-2)
    assert np.all(dc.kg == 0.0)
    assert resid == pytest.approx(k * np.sin(tilt), rel=2e-2, abs=1e-2 * k)
    (do,), r0 = _lamella_curvatures([lam], X, M, "orthogonal")
    assert r0 == 0.0
    assert np.allclose(np.abs(do.kg[inner]), k * np.sin(tilt), rtol=2e-2, atol=1e-2 * k)
