"""The physical GG alignment path (gridshell.gg.path) against closed forms.

Cylinder: every closing state is the same cylinder, the lamellae helices at the angle
``sin psi = lambda c / R`` to the generators: ``kn = sin^2 psi / R``, ``tau_g = sin psi cos psi
/ R``, ``kg = 0``. Sphere cap: the deployed state has ``kn = 1/R``, ``tau_g = 0``; every
state is the surface of revolution ``(r(s), Z_lambda(s))`` of the module's closed form, whose
meridian and parallel curvatures give, by Euler and Clairaut, ``kn = k_m cos^2 psi + k_p
sin^2 psi`` and ``|tau_g| = |k_p - k_m| sin psi cos psi`` - here evaluated independently of the
path's code (finite differences of the closed-form profile), against the strips measured by
:func:`gridshell.structure.frames.darboux_curvatures`.
"""
import numpy as np
from gridshell.gg.path import gg_path
from gridshell.gg.pipeline import collapse_gg, gg_net_from_mesh
from gridshell.structure.frames import darboux_curvatures


def _grid(r, z, s_range, half, R=41, C=31):
    t = np.linspace(*s_range, R)
    ph = np.linspace(-half, half, C)
    rr, zz = r(t), z(t)
    return np.stack([rr[:, None] * np.cos(ph)[None, :], rr[:, None] * np.sin(ph)[None, :],
                     np.broadcast_to(zz[:, None], (R, C))], -1)


def _path(P, frames=12, **kw):
    g = gg_net_from_mesh(P, **kw)
    aligned, _ = collapse_gg(g["net"])
    return g, gg_path(g["inet"], g["rev"], g["net"], aligned, P, frames=frames)


def _curvatures(strips, f):
    """Per sample: measured kn, kg, tau_g of state f (lamella by lamella, ends dropped)."""
    out, keep = [], []
    for lid in np.unique(strips.lamella):
        m = np.flatnonzero(strips.lamella == lid)
        dc = darboux_curvatures(strips.X[f][m], strips.N[f][m])
        out.append(np.stack([dc.kn, dc.kg, dc.tau_g], 1))
        k = np.zeros(len(m), bool)
        k[3:-3] = True
        keep.append(k)
    return np.concatenate(out), np.concatenate(keep)


def test_cylinder_states_are_helices_of_the_closing_angle():
    Rc = 1.5
    P = _grid(lambda t: Rc + 0 * t, lambda t: t, (0.0, 2.0), 0.7)
    g, path = _path(P)
    assert path is not None
    s, c = path.strips, g["inet"].c
    closing = [f for f in range(len(s.t)) if s.phase[f] == "close"]
    assert len(closing) >= 6
    for f in closing:
        lam = s.lam[f]
        sp = lam * c / Rc
        cp = np.sqrt(1 - sp * sp)
        k, keep = _curvatures(s, f)
        kn, kg, tg = k[keep].T
        ref_n, ref_t = sp * sp / Rc, sp * cp / Rc
        scale = max(ref_n, ref_t, 0.05 / Rc)
        assert np.max(np.abs(np.abs(kn) - ref_n)) <= 0.02 * scale, (f, lam)
        assert np.max(np.abs(np.abs(tg) - ref_t)) <= 0.02 * scale, (f, lam)
        assert np.max(np.abs(kg)) <= 0.02 * scale
    for f in np.flatnonzero(s.phase == "unbend"):       # the generator is straight already
        k, keep = _curvatures(s, f)
        assert np.max(np.abs(k[keep])) <= 1e-3 / Rc
    assert np.max(s.bound) < 1e-3                        # arc lengths between joints kept


def _sphere_reference(s_abs, lam, c):
    """kn, |tau_g| of a geodesic of Clairaut constant lambda c on the state surface of the
    unit sphere's profile r = sin s (closed form, finite differences of the profile)."""
    def dZ(x):
        r, dr = np.sin(x), np.cos(x)
        q = 1 - (c / r) ** 2
        return np.sqrt(np.maximum((1 - (lam * c / r) ** 2) - dr * dr * q, 0) / q)
    h = 1e-5
    r, dr, d2r = np.sin(s_abs), np.cos(s_abs), -np.sin(s_abs)
    z1 = dZ(s_abs)
    z2 = (dZ(s_abs + h) - dZ(s_abs - h)) / (2 * h)
    speed = np.hypot(dr, z1)
    k_m = (dr * z2 - d2r * z1) / speed ** 3
    k_p = z1 / (r * speed)
    sp = lam * c / r
    cp2 = 1 - sp * sp
    return k_m * cp2 + k_p * sp * sp, np.abs(k_p - k_m) * sp * np.sqrt(cp2)


def test_sphere_cap_states_match_the_closed_form_family():
    s0, s1 = 0.9, 1.5
    P = _grid(np.sin, lambda t: -np.cos(t), (s0, s1), 0.8)
    g, path = _path(P)
    assert path is not None
    s, c = path.strips, g["inet"].c
    k, keep = _curvatures(s, 0)                             # deployed: the unit sphere
    assert np.max(np.abs(np.abs(k[keep, 0]) - 1.0)) < 0.02
    assert np.max(np.abs(k[keep, 2])) < 0.02
    s_abs = s0 + s.sphi[:, 0]                               # rev.s starts at the first row
    for f in np.flatnonzero(s.phase == "close"):
        k, keep = _curvatures(s, f)
        kn_ref, tg_ref = _sphere_reference(s_abs, s.lam[f], c)
        scale = np.max(np.abs(kn_ref[keep]))
        assert np.max(np.abs(np.abs(k[keep, 0]) - np.abs(kn_ref[keep]))) <= 0.02 * scale, f
        assert np.max(np.abs(np.abs(k[keep, 2]) - tg_ref[keep])) <= 0.02 * scale, f
        assert np.max(np.abs(k[keep, 1])) <= 0.02 * scale, f      # still geodesics
    assert np.max(s.bound) < 1e-3


def test_path_ends_on_the_collapsed_net_and_starts_on_the_deployed():
    P = _grid(lambda t: 1 + 0.2 * np.sin(2.5 * t + 0.5), lambda t: t, (0.0, 1.5), 1.0)
    g, path = _path(P, frames=9)
    aligned, _ = collapse_gg(g["net"])
    np.testing.assert_array_equal(path.V[0], g["net"].joints)
    np.testing.assert_array_equal(path.V[-1], aligned)
    s = path.strips
    last = np.zeros_like(aligned)
    last[s.joint[s.joint >= 0]] = s.X[-1][s.joint >= 0]
    diag = np.linalg.norm(np.ptp(g["net"].joints, axis=0))
    assert np.max(np.linalg.norm(last - aligned, axis=1)) < 1e-3 * diag
    assert len(path.V) == 10 and s.X.shape[0] == 10
    # consecutive closing states are close: a continuous motion (the unbending also moves
    # the bundle rigidly onto the collapsed net's line)
    close = np.flatnonzero(s.phase == "close")
    steps = [np.max(np.linalg.norm(s.X[k] - s.X[k - 1], axis=1)) for k in close]
    assert max(steps) < 0.25 * diag


def test_turning_point_has_no_closed_form_path():
    # a barrel: geodesics from the widest parallel reach r = c towards the narrow ends
    P = _grid(lambda t: 1 - 0.5 * (2 * t / 1.5 - 1) ** 2, lambda t: t, (0.0, 1.5), 1.0)
    g = gg_net_from_mesh(P)
    from gridshell.gg.mapback import net_parameters
    from gridshell.gg.path import exact_path_possible
    why = exact_path_possible(net_parameters(g["inet"]), g["rev"], g["inet"].c)
    aligned, _ = collapse_gg(g["net"])
    path = gg_path(g["inet"], g["rev"], g["net"], aligned, P)
    assert why and "turn" in why
    assert path is None


def test_a_design_only_isometric_to_its_surface_of_revolution_carries_its_difference():
    """The sample dome is only isometric to its surface of revolution: each closing state
    carries the design's difference from it, scaled by lambda - every lamella keeps its arc
    lengths exactly (its turns interpolated, placed by its joints); the joints' disagreement
    is the bound, a state beyond 1 % of a segment is approximate, and the closed state
    (lambda = 0) is the revolution's own, exact."""
    from gridshell.api import design_gg
    from gridshell.geometry.net import polyline_arclength

    seq = design_gg("samples/dome.obj").report["sequence"]
    s = seq.strips
    carried = np.flatnonzero((s.phase == "close") & (s.lam > 0))
    assert len(carried) >= 6
    for lid in np.unique(s.lamella):
        m = np.flatnonzero(s.lamella == lid)
        a0 = polyline_arclength(s.X[0][m])
        for f in carried:
            np.testing.assert_allclose(polyline_arclength(s.X[f][m]), a0, atol=1e-9 * a0[-1])
    assert np.all(s.bound[carried] > 0)
    np.testing.assert_array_equal(s.approximate, s.bound > 0.01)
    closed = int(np.flatnonzero((s.phase == "close") & (s.lam == 0))[0])
    assert not s.approximate[closed] and s.bound[closed] < 1e-3
