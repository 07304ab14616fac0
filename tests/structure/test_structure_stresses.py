"""Stresses from the geometry against closed forms: strips on a cylinder (helices, circles,
generators), on a sphere (geodesic torsion 0), a geodesic (GG lamella) on a surface of
revolution (Clairaut, Euler), bending and torsion of a strip, the thickness that stays elastic,
and the joints-only estimate of the states against the dense one."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from gridshell.structure import Section, get_material
from gridshell.structure.frames import (darboux_curvatures, geodesic_torsion, joint_curvatures,
                                        joint_normals, surface_normals)
from gridshell.structure.stresses import (StripCurvatures, max_elastic_thickness,
                                          strip_curvatures, strip_stresses)

PP = get_material("pp")


def helix(R, a, L=3.0, n=301):
    """Curve on the cylinder of radius R at angle a to the generators, with outward normals."""
    s = np.linspace(0.0, L, n)
    phi = s * np.sin(a) / R
    P = np.stack([R * np.cos(phi), R * np.sin(phi), s * np.cos(a)], axis=1)
    N = np.stack([np.cos(phi), np.sin(phi), 0 * phi], axis=1)
    return P, N


@pytest.mark.parametrize("a", [0.0, 0.3, np.pi / 4, 1.1, np.pi / 2])
def test_cylinder_helix_closed_form(a):
    """Generator (a = 0): straight, untwisted; circle (a = pi/2): kn = -1/R, no twist; helix:
    kn = -sin^2(a)/R, kg = 0, tau_g = sin(a) cos(a)/R (angle a from the generators)."""
    R = 1.7
    P, N = helix(R, a)
    d = darboux_curvatures(P, N)
    assert np.allclose(d.kn, -np.sin(a) ** 2 / R, atol=1e-6)
    assert np.allclose(d.kg, 0.0, atol=1e-6)
    assert np.allclose(d.tau_g, np.sin(a) * np.cos(a) / R, atol=1e-6)
    assert d.s[-1] == pytest.approx(3.0, rel=1e-5)   # chords of the arc


def test_cylinder_helix_on_a_mesh():
    """The same with the normals of a sampled cylinder (bundle surfaces are meshes)."""
    R, a = 1.0, 0.6
    phi = np.linspace(0, 2.2, 60)
    z = np.linspace(-0.2, 2.8, 60)
    Ph, Z = np.meshgrid(phi, z, indexing="ij")
    V = np.stack([R * np.cos(Ph), R * np.sin(Ph), Z], -1).reshape(-1, 3)
    from gridshell.geometry.grid import grid_quads
    F = grid_quads(60, 60)
    P, N_exact = helix(R, a, L=2.4, n=241)
    N = surface_normals(P, V, F)
    N *= np.sign(np.sum(N * N_exact, axis=1))[:, None]
    d = darboux_curvatures(P, N)
    inner = slice(5, -5)
    assert np.allclose(d.tau_g[inner], np.sin(a) * np.cos(a) / R, rtol=2e-3)
    assert np.allclose(d.kn[inner], -np.sin(a) ** 2 / R, rtol=2e-3)


@pytest.mark.parametrize("theta", [np.pi / 2, 1.0, 0.5])
def test_sphere_circles_have_no_geodesic_torsion(theta):
    """Every curve on a sphere is a line of curvature: tau_g = 0; kn = -1/rho; a circle of
    latitude at polar angle theta has kg = cot(theta) / rho (0 for the great circle)."""
    rho = 2.5
    t = np.linspace(0, 2.0, 400)
    P = rho * np.stack([np.sin(theta) * np.cos(t), np.sin(theta) * np.sin(t),
                        np.cos(theta) + 0 * t], axis=1)
    N = P / rho
    d = darboux_curvatures(P, N)
    assert np.allclose(d.tau_g, 0.0, atol=1e-9)
    assert np.allclose(d.kn, -1 / rho, rtol=1e-5)
    assert np.allclose(np.abs(d.kg), abs(np.cos(theta) / np.sin(theta)) / rho, atol=1e-5)


def test_sphere_oblique_great_circle():
    rho = 1.3
    t = np.linspace(0, 2.5, 500)
    e1, e2 = np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.6, 0.8])
    P = rho * (np.cos(t)[:, None] * e1 + np.sin(t)[:, None] * e2)
    d = darboux_curvatures(P, P / rho)
    assert np.allclose(d.tau_g, 0.0, atol=1e-9)
    assert np.allclose(d.kg, 0.0, atol=1e-9)


def _catenoid_geodesic(c=1.0, C=0.6, z0=-0.8, L=2.5, n=600):
    """A geodesic of the catenoid r(z) = c cosh(z/c) by Clairaut (r cos psi = C, psi the angle
    with the parallels), integrated in arc length; returns points, outward normals, psi, z."""
    r = lambda z: c * np.cosh(z / c)
    dr = lambda z: np.sinh(z / c)

    def rhs(s, y):
        z, phi = y
        cos_psi = C / r(z)
        sin_psi = np.sqrt(1 - cos_psi ** 2)
        return [sin_psi / np.sqrt(1 + dr(z) ** 2), cos_psi / r(z)]

    s = np.linspace(0, L, n)
    sol = solve_ivp(rhs, (0, L), [z0, 0.0], t_eval=s, rtol=1e-12, atol=1e-12)
    z, phi = sol.y
    P = np.stack([r(z) * np.cos(phi), r(z) * np.sin(phi), z], axis=1)
    g = np.sqrt(1 + dr(z) ** 2)
    N = np.stack([np.cos(phi) / g, np.sin(phi) / g, -dr(z) / g], axis=1)
    psi = np.arccos(C / r(z))
    return P, N, psi, z


def test_gg_lamella_on_a_surface_of_revolution():
    """A GG lamella (a geodesic) on the catenoid: kg = 0 (no strong-axis bending), Euler's
    kn = k_par cos^2(psi) + k_mer sin^2(psi) and |tau_g| = |k_mer - k_par| sin(psi) cos(psi),
    with k_par = -1/(r sqrt(1 + r'^2)) and k_mer = r''/(1 + r'^2)^(3/2) (outward normal)."""
    c = 1.0
    P, N, psi, z = _catenoid_geodesic(c=c)
    r, dr, ddr = c * np.cosh(z / c), np.sinh(z / c), np.cosh(z / c) / c
    k_par = -1 / (r * np.sqrt(1 + dr ** 2))
    k_mer = ddr / (1 + dr ** 2) ** 1.5
    d = darboux_curvatures(P, N)
    inner = slice(2, -2)
    assert np.allclose(d.kg[inner], 0.0, atol=1e-5)
    kn = k_par * np.cos(psi) ** 2 + k_mer * np.sin(psi) ** 2
    assert np.allclose(d.kn[inner], kn[inner], atol=1e-5)
    tg = np.abs(k_mer - k_par) * np.sin(psi) * np.cos(psi)
    assert np.allclose(np.abs(d.tau_g[inner]), tg[inner], atol=1e-5)
    # the strip as cut (straight, tangent): weak axis kn, strong axis kg, twist tau_g, / scale
    sec = Section(20.0, 1.0, 0.1)
    k = strip_curvatures(d, "tangent", sec)
    assert np.allclose(k.weak, d.kn / 0.1) and np.allclose(k.twist, d.tau_g / 0.1)
    assert np.abs(k.strong[inner]).max() < 1e-4


def test_orthogonal_strip_axes():
    """Orthogonal (NCP) strips: weak axis = geodesic curvature, strong axis = normal curvature
    less the curvature the strip was cut with; a CNC strip on its circle is unstressed."""
    R = 2.0
    P, N = helix(R, np.pi / 2)        # a circle: kn = -1/R, kg = 0
    d = darboux_curvatures(P, N)
    sec = Section(20.0, 1.0, 1.0)
    k = strip_curvatures(d, "orthogonal", sec, k_cut=-1 / R)
    assert np.allclose(k.strong, 0.0, atol=1e-9) and np.allclose(k.weak, 0.0, atol=1e-9)
    k_line = strip_curvatures(d, "orthogonal", sec, k_cut=0.0)
    assert np.allclose(np.abs(k_line.strong), 1 / R, rtol=1e-6)


def test_bending_and_torsion_stresses_closed_form():
    sec = Section(20.0, 1.0, 1.0)
    R = 0.25
    k = StripCurvatures(np.array([1 / R]), np.array([0.0]), np.array([0.0]))
    st = strip_stresses(k, sec, PP)
    assert st.sigma_weak[0] == pytest.approx(PP.E * 0.001 / (2 * R))     # sigma = E t / 2R
    theta = 0.5                                                          # rad/m
    k = StripCurvatures(np.zeros(1), np.zeros(1), np.array([theta]))
    st = strip_stresses(k, sec, PP)
    # tau_max = T / W_t with T = G J theta' (Saint-Venant), ~ G t theta' for a thin strip
    assert st.tau[0] == pytest.approx(PP.G * sec.J * theta / sec.W_torsion)
    assert st.tau[0] == pytest.approx(PP.G * 0.001 * theta, rel=1e-2)
    assert st.utilisation[0] == pytest.approx(np.sqrt(3) * st.tau[0] / PP.allowable)


def test_weak_axis_utilisation_linear_in_thickness():
    k = StripCurvatures(np.linspace(0.5, 3.0, 7), np.zeros(7), np.zeros(7))
    u1 = strip_stresses(k, Section(20.0, 1.0), PP).utilisation
    u2 = strip_stresses(k, Section(20.0, 2.0), PP).utilisation
    u3 = strip_stresses(k, Section(20.0, 3.0), PP).utilisation
    assert np.allclose(u2, 2 * u1) and np.allclose(u3, 3 * u1)


def test_max_elastic_thickness():
    sec = Section(20.0, 1.0)
    kw = np.array([0.5, 2.0, 10.0])
    k = StripCurvatures(kw, np.zeros(3), np.zeros(3))
    t = max_elastic_thickness(k, sec, PP)
    # pure weak-axis bending: E k t / 2 = allowable, capped at the width
    assert np.allclose(t, np.minimum(2 * PP.allowable / (PP.E * kw), sec.width), rtol=1e-9)
    # with strong-axis bending and twist: utilisation exactly 1 at that thickness
    k = StripCurvatures(np.array([2.0, 1.0]), np.array([0.3, 5.0]), np.array([4.0, 0.0]))
    t = max_elastic_thickness(k, sec, PP)
    u = strip_stresses(StripCurvatures(k.weak[:1], k.strong[:1], k.twist[:1]),
                       sec.with_thickness(t[0] * 1e3), PP).utilisation[0]
    assert u == pytest.approx(1.0, rel=1e-6)
    # strong-axis bending alone overstresses the 20 mm width: no thickness helps
    assert PP.E * 5.0 * 0.02 / 2 > PP.allowable and t[1] == 0.0


def test_geodesic_torsion_converges_second_order():
    """The central differences of the normals converge at second order (a finite-difference
    check of the derivative dN/ds)."""
    R, a = 1.0, 0.7
    errs = []
    for n in (51, 101, 201):
        P, N = helix(R, a, L=2.0, n=n)
        tg = geodesic_torsion(P, N)
        errs.append(np.abs(tg[1:-1] - np.sin(a) * np.cos(a) / R).max())
    assert errs[0] / errs[1] > 3.5 and errs[1] / errs[2] > 3.5 and errs[-1] < 1e-5
    # non-uniform sampling: still second order in the largest step
    s = np.linspace(0, 1, 101) ** 1.3 * 2.0
    phi = s * np.sin(a) / R
    P = np.stack([R * np.cos(phi), R * np.sin(phi), s * np.cos(a)], axis=1)
    N = np.stack([np.cos(phi), np.sin(phi), 0 * phi], axis=1)
    assert np.abs(geodesic_torsion(P, N)[1:-1] - np.sin(a) * np.cos(a) / R).max() < 2e-3


def test_joint_estimate_agrees_with_dense():
    """The joints-only estimate (states) against the dense axis on a helix: within 1 % at
    12 joints per 3 m on a cylinder of radius 1.7 m."""
    R, a = 1.7, 0.5
    P, N = helix(R, a, n=13)
    s = np.linspace(0, 3.0, 13)
    d = joint_curvatures(P, s, N)
    assert np.allclose(d.kn[2:-2], -np.sin(a) ** 2 / R, rtol=1e-2)
    assert np.allclose(d.tau_g[2:-2], np.sin(a) * np.cos(a) / R, rtol=1e-2)
    assert np.allclose(d.kg[2:-2], 0.0, atol=1e-3)
    # flipped normals at some joints (a line's direction): the same result
    N2 = N.copy()
    N2[::3] *= -1
    d2 = joint_curvatures(P, s, N2)
    assert np.allclose(np.abs(d2.tau_g), np.abs(d.tau_g)) and np.allclose(
        np.abs(d2.kn), np.abs(d.kn))
    # a straight line of joints (a collapsed GG lamella), normals unknown: nothing
    L = np.stack([s, 0 * s, 0 * s], axis=1)
    d3 = joint_curvatures(L, s, np.zeros_like(L))
    assert np.allclose(d3.kn, 0) and np.allclose(d3.kg, 0) and np.allclose(d3.tau_g, 0)


def test_joint_normals_of_a_grid_and_a_collapsed_net():
    from gridshell.geometry.grid import grid_quads
    X, Y = np.meshgrid(np.linspace(0, 1, 4), np.linspace(0, 1, 4), indexing="ij")
    V = np.stack([X, Y, 0 * X], -1).reshape(-1, 3)
    F = grid_quads(4, 4)
    N = joint_normals(V, F)
    assert np.allclose(np.abs(N[:, 2]), 1.0)
    V[:, 1] = 0.0           # every loop flat on a line: no normal
    assert np.allclose(joint_normals(V, F), 0.0)


def test_slerp_axes():
    from gridshell.structure.states import slerp_axes
    a = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])
    b = np.array([[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]])    # a line: -x is +x
    assert np.allclose(slerp_axes(a, b, 0.0), a)
    assert np.allclose(np.abs(slerp_axes(a, b, 1.0)), np.abs(b))
    m = slerp_axes(a, b, 0.5)
    assert np.allclose(m[0], [np.sqrt(0.5), 0, np.sqrt(0.5)]) and np.allclose(m[1], [1, 0, 0])
