"""The strip as built (gridshell.geometry.strips3d): frames and closed solids against closed forms."""
import numpy as np
import pytest

from gridshell.core.errors import InputError
from gridshell.geometry.strips3d import (is_tangent, real_section_m, strip_frame, strip_solid)


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

    from gridshell.geometry.strips3d import strip_frame, strip_solid

    t = np.linspace(0, 2, 41)
    P = np.column_stack([t, np.sin(t), 0.2 * t * t])
    N = np.column_stack([np.zeros_like(t), -np.cos(t), np.ones_like(t)])
    for tangent in (False, True):
        plain = strip_solid(P, N, 0.2, 0.01, tangent)
        given = strip_solid(P, N, 0.2, 0.01, tangent, frame=strip_frame(P, N, tangent))
        assert all(np.array_equal(a, b) for a, b in zip(plain, given))


# ------------------------------------------------------------------ solids with fewer rings

def _corners(P, W, H, w, t):
    hw, ht = 0.5 * w * W, 0.5 * t * H
    return np.stack([P - hw - ht, P + hw - ht, P + hw + ht, P - hw + ht], axis=1)


def _to_polyline(X, Q):
    """Distance of each point of ``X (n,3)`` to the polyline ``Q (m,3)`` (brute force)."""
    A, B = Q[:-1][None], Q[1:][None]
    D = B - A
    u = np.clip(np.einsum("nmi,nmi->nm", X[:, None] - A, D) / np.einsum("nmi,nmi->nm", D, D),
                0.0, 1.0)
    return np.linalg.norm(X[:, None] - A - u[..., None] * D, axis=-1).min(axis=1)


def _check_rings(P, N, w, t, tangent):
    """solid_rings keeps the ends, its solid's corner edges within ring_tolerance of the full
    ones (each full-resolution corner point to the simplified corner polyline), and the
    solid through the kept rings is closed and consistently oriented like strip_solid's."""
    from gridshell.geometry.strips3d import ring_tolerance, solid_rings

    T, W, H = strip_frame(P, N, tangent)
    r = solid_rings(P, W, H, w, t)
    assert r[0] == 0 and r[-1] == len(P) - 1 and np.all(np.diff(r) > 0)
    full = _corners(P, W, H, w, t)
    V, F = strip_solid(P[r], N[r], w, t, tangent, frame=(T[r], W[r], H[r]))
    np.testing.assert_array_equal(V.reshape(-1, 4, 3), full[r])    # the same corners
    tol = ring_tolerance(t)
    worst = max(_to_polyline(full[:, c], full[r, c]).max() for c in range(4))
    assert worst <= tol
    edges = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    _, counts = np.unique(np.sort(edges, axis=1), axis=0, return_counts=True)
    assert np.all(counts == 2)                              # closed: every edge twice
    assert len(np.unique(edges, axis=0)) == len(edges)      # consistently oriented
    return r, worst, tol


@pytest.mark.parametrize("tangent", [True, False])
def test_solid_rings_of_a_helix_strip(tangent):
    """A helix strip (bent and twisted: the normal of its cylinder turns round the axis),
    2000 samples over two turns of radius 0.5 m: far fewer rings, every corner edge within
    ring_tolerance (0.05 mm here: 1 % of 10 mm is 0.1 mm) of the full-resolution one."""
    from gridshell.geometry.strips3d import ring_tolerance

    k, R, pitch = 2000, 0.5, 0.3
    a = np.linspace(0.0, 4 * np.pi, k)
    P = np.c_[R * np.cos(a), R * np.sin(a), pitch * a / (2 * np.pi)]
    N = -np.c_[np.cos(a), np.sin(a), np.zeros(k)]           # the cylinder's inner normal
    assert ring_tolerance(0.01) == pytest.approx(5e-5)
    assert ring_tolerance(0.001) == pytest.approx(1e-5)
    r, worst, tol = _check_rings(P, N, 0.2, 0.01, tangent)
    assert len(r) < k / 2                # ~1/3 (14 mm spans where the samples are 3 mm)
    assert worst > 0.2 * tol             # not more rings than the tolerance asks for


def test_solid_rings_keep_what_a_finer_tolerance_needs():
    """A tolerance of 0 keeps every sample of a curved axis; a straight axis needs its ends."""
    from gridshell.geometry.strips3d import solid_rings

    P = _circle(k=50)
    N = np.tile([0.0, 0.0, 1.0], (len(P), 1))
    _, W, H = strip_frame(P, N, True)
    np.testing.assert_array_equal(solid_rings(P, W, H, 0.2, 0.01, tol=0.0), np.arange(50))
    L = np.c_[np.linspace(0, 1, 30), np.zeros(30), np.zeros(30)]
    _, W, H = strip_frame(L, np.tile([0.0, 0.0, 1.0], (30, 1)), True)
    np.testing.assert_array_equal(solid_rings(L, W, H, 0.2, 0.01), [0, 29])
    np.testing.assert_array_equal(solid_rings(L[:2], W[:2], H[:2], 0.2, 0.01), [0, 1])


def test_solid_rings_of_an_ncp_bundle():
    """The lamellae of an NCP design (pseudosphere, AA, 10 curves; strips 0.2 x 0.01 m as
    the .3dm export builds them): within the tolerance, and at most half the rings."""
    from tests.helpers.ncp_cases import pseudosphere

    from gridshell.geometry.igl_adapter import closest_points_with_normals
    from gridshell.ncp.pipeline import design_ncp

    bundle, _ = design_ncp(pseudosphere(), mode="aa", curves=10)
    total = kept = 0
    for lam in bundle.net.lamellae:
        P = lam.axis[np.r_[True, np.linalg.norm(np.diff(lam.axis, axis=0), axis=1) > 0]]
        N = closest_points_with_normals(P, bundle.surface_V, bundle.surface_F)[1]
        r, _, _ = _check_rings(P, N, 0.2, 0.01, False)
        total, kept = total + len(P), kept + len(r)
    assert kept < 0.5 * total


def _unit_rows(X):
    return X / np.linalg.norm(X, axis=1, keepdims=True)


def _rings_one_by_one(P, W, H, w, t, tol):
    """The straightforward Ramer-Douglas-Peucker of solid_rings: each span split at its first
    farthest sample (the largest of the four corners' distances to their chords) while that
    exceeds ``tol``, span by span (recursion), one axis at a time."""
    from gridshell.geometry.strips3d import _segment_distance

    X = _corners(P, W, H, w, t)
    keep = {0, len(P) - 1}
    todo = [(0, len(P) - 1)] if len(P) > 2 else []
    while todo:
        a, b = todo.pop()
        if b - a < 2:
            continue
        d = _segment_distance(X[a + 1:b], X[a][None], X[b][None]).max(axis=1)
        i = int(np.argmax(d))
        if d[i] > tol:
            keep.add(a + 1 + i)
            todo += [(a, a + 1 + i), (a + 1 + i, b)]
    return np.array(sorted(keep), np.int64)


def test_solid_rings_many_equal_one_axis_at_a_time():
    """solid_rings_many (all axes in one vectorized pass, as the .3dm export asks) gives every
    axis the indices solid_rings gives it alone, and both those of the straightforward
    recursive simplification: wiggly axes of many lengths (1, 2, 3 samples too), tangent and
    standing frames, several tolerances."""
    from gridshell.geometry.strips3d import ring_tolerance, solid_rings, solid_rings_many

    rng = np.random.default_rng(7)
    axes = []
    for k in [1, 2, 3, 5, 40, 200, 2, 731, 17]:
        s = np.linspace(0.0, 3.0, k)
        P = np.c_[s, 0.3 * np.sin(2 * s) + 1e-3 * rng.standard_normal(k),
                  0.2 * np.cos(3 * s) + 1e-3 * rng.standard_normal(k)]
        N = _unit_rows(np.c_[0.1 * rng.standard_normal((k, 2)), np.ones(k)])
        axes.append((P, N))
    for tangent in (True, False):
        frames = [strip_frame(P, N, tangent) if len(P) >= 2 else
                  (np.zeros((1, 3)), np.array([[0.0, 1, 0]]), np.array([[0.0, 0, 1]]))
                  for P, N in axes]
        for w, t, tol in ((0.2, 0.01, None), (0.05, 0.002, None), (0.2, 0.01, 1e-3),
                          (0.2, 0.01, 0.0)):
            many = solid_rings_many([P for P, _ in axes], [f[1] for f in frames],
                                    [f[2] for f in frames], w, t, tol)
            assert len(many) == len(axes)
            for (P, _), (_, W, H), r in zip(axes, frames, many):
                assert r.dtype == np.int64
                np.testing.assert_array_equal(r, solid_rings(P, W, H, w, t, tol))
                ref = _rings_one_by_one(P, W, H, w, t, ring_tolerance(t) if tol is None else tol)
                np.testing.assert_array_equal(r, ref)
    assert solid_rings_many([], [], [], 0.2, 0.01) == []
    empty = solid_rings_many([np.zeros((0, 3)), axes[4][0]], [np.zeros((0, 3)), frames[4][1]],
                             [np.zeros((0, 3)), frames[4][2]], 0.2, 0.01)
    assert len(empty[0]) == 0
    np.testing.assert_array_equal(empty[1], solid_rings(axes[4][0], frames[4][1],
                                                        frames[4][2], 0.2, 0.01))
