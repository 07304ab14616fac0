"""Section-axis curvatures of a strip from its dense axis and surface normals
(:func:`gridshell.structure.frames.strip_frame_curvatures`) against closed forms (a helix
geodesic on a cylinder, a circle of latitude on a sphere) and against finite differences of
an analytic curve on a torus."""
import numpy as np
import pytest

from gridshell.core.errors import InputError
from gridshell.structure.frames import strip_frame_curvatures

INNER = slice(3, -3)


def cylinder_helix(R, alpha, L=2.0, n=401):
    """Helix at angle ``alpha`` to the rulings of the cylinder of radius R (a geodesic), with
    inward unit normals (towards the axis)."""
    s = np.linspace(0.0, L, n)
    phi = s * np.sin(alpha) / R
    P = np.stack([R * np.cos(phi), R * np.sin(phi), s * np.cos(alpha)], axis=1)
    N = -np.stack([np.cos(phi), np.sin(phi), 0 * phi], axis=1)
    return P, N


@pytest.mark.parametrize("alpha", [0.3, np.pi / 4, 1.2])
def test_helix_geodesic_tangent_and_orthogonal(alpha):
    """kn = sin^2(alpha)/R, kg = 0, tau_g = sin(alpha) cos(alpha)/R within 1 %; the tangent
    strip bends about its weak axis with kn, the orthogonal one about its strong axis."""
    R = 0.8
    P, N = cylinder_helix(R, alpha)
    kn, tg = np.sin(alpha) ** 2 / R, np.sin(alpha) * np.cos(alpha) / R
    t = strip_frame_curvatures(P, N, "tangent")
    assert np.allclose(t.weak[INNER], kn, rtol=1e-2)
    assert np.all(np.abs(t.strong[INNER]) < 1e-2 * kn)
    assert np.allclose(np.abs(t.twist[INNER]), tg, rtol=1e-2)
    o = strip_frame_curvatures(P, N, "orthogonal")
    assert np.allclose(o.strong[INNER], kn, rtol=1e-2)
    assert np.all(np.abs(o.weak[INNER]) < 1e-2 * kn)
    assert np.allclose(o.twist, t.twist)
    c = strip_frame_curvatures(P, N, "orthogonal", k_cut=kn)      # cut to its own curvature
    assert np.all(np.abs(c.strong[INNER]) < 1e-2 * kn)


@pytest.mark.parametrize("theta", [0.4, 1.0, np.pi / 2])
def test_sphere_latitude_circle(theta):
    """Circle of colatitude theta on the sphere of radius R (inward normals): kn = 1/R,
    |kg| = cot(theta)/R, no geodesic torsion (every curve on a sphere is a line of
    curvature)."""
    R = 1.3
    phi = np.linspace(0.0, 1.5 * np.pi, 501)
    P = R * np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi),
                      np.full_like(phi, np.cos(theta))], axis=1)
    N = -P / R
    t = strip_frame_curvatures(P, N, "tangent")
    assert np.allclose(t.weak[INNER], 1.0 / R, rtol=1e-2)
    assert np.allclose(np.abs(t.strong[INNER]), np.cos(theta) / np.sin(theta) / R,
                       rtol=1e-2, atol=1e-3 / R)
    assert np.all(np.abs(t.twist[INNER]) < 1e-3 / R)
    o = strip_frame_curvatures(P, N, "orthogonal")
    assert np.allclose(o.weak, t.strong) and np.allclose(o.strong, t.weak)


def _torus(u, v, a=1.0, b=0.35):
    """Point and outward unit normal of the torus (tube radius b about a circle of radius a)."""
    c = np.stack([np.cos(u) * np.cos(v), np.sin(u) * np.cos(v), np.sin(v)], axis=-1)
    ring = np.stack([np.cos(u), np.sin(u), 0 * u], axis=-1)
    return a * ring + b * c, c


def test_torus_curve_against_finite_differences():
    """A generic curve on a torus: the three curvatures against the Darboux frame computed by
    central differences (step 1e-5) of the analytic parametrization and normal."""
    def curve(t):
        return _torus(t, 0.7 * np.sin(2 * t) + 0.3 * t)

    t = np.linspace(0.0, 2.0, 2001)
    P, N = curve(t)
    h = 1e-5
    (Pp, Np), (Pm, Nm) = curve(t + h), curve(t - h)
    d1, d2 = (Pp - Pm) / (2 * h), (Pp - 2 * P + Pm) / h ** 2
    speed = np.linalg.norm(d1, axis=1)
    T = d1 / speed[:, None]
    kvec = (d2 - np.einsum("ij,ij->i", d2, T)[:, None] * T) / speed[:, None] ** 2
    U = np.cross(N, T)
    dNds = (Np - Nm) / (2 * h) / speed[:, None]
    kn, kg = np.einsum("ij,ij->i", kvec, N), np.einsum("ij,ij->i", kvec, U)
    tg = -np.einsum("ij,ij->i", dNds, U)
    r = strip_frame_curvatures(P, N, "tangent")
    scale = np.abs(np.concatenate([kn, kg, tg])).max()
    for got, ref in ((r.weak, kn), (r.strong, kg), (r.twist, tg)):
        assert np.abs(got - ref)[INNER].max() < 1e-3 * scale


def test_unknown_orientation_is_refused():
    P, N = cylinder_helix(1.0, 0.5, n=11)
    with pytest.raises(InputError, match="orientation"):
        strip_frame_curvatures(P, N, "diagonal")
