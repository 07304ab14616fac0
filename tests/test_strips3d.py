"""The strip as built (gridshell.strips3d): frames and closed solids against closed forms."""
import numpy as np
import pytest

from gridshell.errors import InputError
from gridshell.strips3d import (is_tangent, real_section_m, strip_frame, strip_solid)


def _circle(R=2.0, k=200, angle=np.pi):
    s = np.linspace(0.0, angle, k)
    return np.c_[R * np.cos(s), R * np.sin(s), np.zeros(k)]


def _volume_area(V, F):
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    vol = np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0
    n = np.cross(b - a, c - a)
    return vol, n


@pytest.mark.parametrize("tangent", [True, False])
def test_frame_orthonormal_and_width_direction(tangent):
    P = _circle()
    N = np.tile([0.0, 0.0, 1.0], (len(P), 1))        # a flat plate: normal +z
    T, W, H = strip_frame(P, 3.0 * N, tangent)
    for X in (T, W, H):
        assert np.allclose(np.linalg.norm(X, axis=1), 1.0)
    assert np.allclose(np.einsum("ij,ij->i", T, W), 0.0, atol=1e-12)
    assert np.allclose(np.einsum("ij,ij->i", T, H), 0.0, atol=1e-12)
    if tangent:      # in the plane, pointing to the centre (n x t for a ccw circle)
        assert np.allclose(W[:, 2], 0.0)
        radial = -P / np.linalg.norm(P, axis=1, keepdims=True)
        assert np.allclose(np.einsum("ij,ij->i", W, radial), 1.0, atol=1e-3)
    else:            # standing on the plate: width along its normal
        assert np.allclose(W, [0.0, 0.0, 1.0])


def test_frame_makes_a_slanted_normal_orthogonal():
    P = np.c_[np.linspace(0, 1, 5), np.zeros(5), np.zeros(5)]
    N = np.tile([1.0, 0.0, 1.0], (5, 1))
    _, W, _ = strip_frame(P, N, tangent=False)
    assert np.allclose(W, [0.0, 0.0, 1.0])


@pytest.mark.parametrize("tangent", [True, False])
def test_solid_closed_volume_and_face_area(tangent):
    """A strip bent along a half circle of radius R: volume w t pi R, wide faces w pi R."""
    R, w, t = 2.0, 0.2, 0.01
    P = _circle(R, k=400)
    N = np.tile([0.0, 0.0, 1.0], (len(P), 1))
    V, F = strip_solid(P, N, w, t, tangent)
    # closed: every edge shared by exactly two faces, in opposite directions
    E = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    assert len({tuple(e) for e in E.tolist()}) == len(E)
    assert {tuple(e) for e in E.tolist()} == {tuple(e) for e in E[:, ::-1].tolist()}
    vol, n = _volume_area(V, F)
    assert vol == pytest.approx(w * t * np.pi * R, rel=1e-3)      # outward: positive volume
    _, _, H = strip_frame(P, N, tangent)
    Hf = H[(F[:, 0] // 4).clip(0, len(P) - 1)]
    wide = np.abs(np.einsum("ij,ij->i", n / np.linalg.norm(n, axis=1, keepdims=True), Hf)) > 0.99
    area = 0.5 * np.linalg.norm(n[wide], axis=1).sum()
    assert area == pytest.approx(2 * w * np.pi * R, rel=1e-3)


def test_bad_sections_are_refused():
    P = _circle(k=5)
    N = np.tile([0.0, 0.0, 1.0], (5, 1))
    with pytest.raises(InputError, match="positive"):
        strip_solid(P, N, 0.0, 0.01, True)
    with pytest.raises(InputError, match="normals"):
        strip_frame(P, N[:3], True)
    with pytest.raises(InputError, match="positive"):
        real_section_m(20, 1, 0)


def test_real_section_and_kinds():
    assert real_section_m(20.0, 1.0, 0.1) == pytest.approx((0.2, 0.01))
    assert is_tangent("GG") and not is_tangent("CNC") and not is_tangent("NCP")


def test_strip_solid_with_the_frame_given_is_the_strip_solid():
    """The .3dm export hands strip_solid the frame it computed: the same solid, bit for bit."""
    import numpy as np

    from gridshell.strips3d import strip_frame, strip_solid

    t = np.linspace(0, 2, 41)
    P = np.column_stack([t, np.sin(t), 0.2 * t * t])
    N = np.column_stack([np.zeros_like(t), -np.cos(t), np.ones_like(t)])
    for tangent in (False, True):
        plain = strip_solid(P, N, 0.2, 0.01, tangent)
        given = strip_solid(P, N, 0.2, 0.01, tangent, frame=strip_frame(P, N, tangent))
        assert all(np.array_equal(a, b) for a, b in zip(plain, given))
