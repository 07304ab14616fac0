"""The viewer's scene built for all lamellae and states at once (gridshell.render.viewer.scene)
is the scene built lamella by lamella and state by state, bit for bit; and each vectorized part
gives the numbers of the one-at-a-time computation it replaces: ``np.interp`` row by row, the
axes of ``move_joints_states``, per-state extremes, ``np.add.at`` vertex normals, the faces of
``strip_solid`` and the surface lookup kept between calls."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from tests.helpers.render_cases import make_bundle, paraboloid, sequence_extra, write_case  # noqa: E402

from gridshell.design.bundle import read_bundle, write_bundle  # noqa: E402
from gridshell.geometry.net import Lamella, Net, polyline_arclength  # noqa: E402
from gridshell.render.viewer import scene as sc  # noqa: E402


def _bits(a) -> np.ndarray:
    return np.ascontiguousarray(np.asarray(a, float)).view(np.int64)


# ---- the former scene: lamella by lamella, state by state -------------------------------------

def _former_unit(X):
    n = np.linalg.norm(X, axis=-1, keepdims=True)
    return np.divide(X, n, out=np.zeros_like(X), where=n > 0)


def _former_arc(P):
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(P, axis=0), axis=1))])


def _sample(P, frac):
    s = _former_arc(P)
    if s[-1] <= 0:
        return np.repeat(P[:1], len(frac), axis=0)
    return np.stack([np.interp(frac * s[-1], s, P[:, c]) for c in range(3)], axis=1)


def _interp_along(frac, joint_frac, values):
    values = np.asarray(values, float)
    if len(joint_frac) == 0:
        return np.zeros((len(frac),) + values.shape[1:])
    if len(joint_frac) == 1:
        return np.repeat(values[:1], len(frac), axis=0)
    if values.ndim == 1:
        return np.interp(frac, joint_frac, values)
    return np.stack([np.interp(frac, joint_frac, values[:, c]) for c in range(values.shape[1])],
                    axis=1)


def _former_loop_area_vectors(J, loops):
    L = np.asarray(loops, np.int64).reshape(-1, 4)
    A = 0.5 * np.cross(J[L[:, 2]] - J[L[:, 0]], J[L[:, 3]] - J[L[:, 1]])
    out = np.zeros_like(J)
    for c in range(4):
        np.add.at(out, L[:, c], A)
    return out


def _former_joint_normals(states, loops, n0):
    out = [_former_unit(np.asarray(n0, float))]
    if not len(loops):
        return out * len(states)
    A0 = np.linalg.norm(_former_loop_area_vectors(states[0], loops), axis=1)
    for J in states[1:]:
        A = _former_loop_area_vectors(J, loops)
        prev = out[-1]
        n = _former_unit(A)
        n = np.where(np.sum(n * prev, axis=1, keepdims=True) < 0, -n, n)
        ok = np.linalg.norm(A, axis=1) > sc._COLLAPSED * np.maximum(A0, 1e-300)
        out.append(np.where(ok[:, None], n, prev))
    return out


def _former_strips(d: Path) -> dict:
    """The strips, Delta_a samples and centres of build_scene as computed before 2026-12-02:
    move_joints_states' nets, one _sample / np.interp / strip_solid per lamella and state."""
    from gridshell.geometry.net import move_joints_states
    from gridshell.design.section import resolve_section
    from gridshell.geometry.strips3d import is_tangent, nearest_vertex_normals, strip_solid

    b = read_bundle(d)
    section = resolve_section(d)
    w, t = section.width_m, section.thickness_m
    tangent = is_tangent(b.kind)
    net = b.net
    lams = [lam for lam in net.lamellae if len(lam.axis) >= 2]
    states, _ = sc._states(d, b)
    V, F = np.asarray(b.surface_V, float), np.asarray(b.surface_F, np.int64)
    allP = np.concatenate([lam.axis for lam in lams] + [V])
    diag = float(np.linalg.norm(allP.max(axis=0) - allP.min(axis=0))) or 1.0
    fracs, joint_fracs = [], []
    for lam in lams:
        L = float(_former_arc(lam.axis)[-1])
        m = int(np.clip(np.ceil(L / (sc._STEP * diag)) + 1, 8, sc.MAX_SAMPLES))
        fracs.append(np.linspace(0.0, 1.0, m))
        joint_fracs.append(np.clip(lam.joint_s / L, 0.0, 1.0) if L > 0 else lam.joint_s * 0)
    normals = _former_joint_normals(states, net.loops, nearest_vertex_normals(states[0], V, F))
    strip_V, strip_F, offsets = [], None, []
    carried = [net] + move_joints_states(net, list(states[1:]))
    for k in range(len(states)):
        by_id = {lam.id: lam for lam in carried[k].lamellae}
        Pk, Nk, Fk, nv = [], [], [], 0
        for lam, frac, jf in zip(lams, fracs, joint_fracs):
            P = _sample(by_id[lam.id].axis, frac)
            if len(lam.joints) >= 2:
                N = _former_unit(_interp_along(frac, jf, normals[k][lam.joints]))
            else:
                N = nearest_vertex_normals(P, V, F) if k == 0 else \
                    np.repeat(normals[k][lam.joints[:1]], len(P), axis=0)
            if tangent:
                P = P + (0.5 * t if lam.family == 1 else -0.5 * t) * N
            if k == 0:
                SV, SF = strip_solid(P, N, w, t, tangent)
                offsets.append((nv, len(SV), sum(len(f) for f in Fk), len(SF)))
                Fk.append(SF + nv)
                nv += len(SV)
            Pk.append(P)
            Nk.append(N)
        strip_V.append(np.concatenate([strip_solid(P, N, w, t, tangent)[0]
                                       for P, N in zip(Pk, Nk)]))
        if k == 0:
            strip_F = np.concatenate(Fk)
    _, jda = sc.joint_delta_a(states[0], net.loops)
    da = np.concatenate([_interp_along(f, jf, jda[lam.joints])
                         for lam, f, jf in zip(lams, fracs, joint_fracs)])
    return {"V": strip_V, "F": strip_F, "offsets": offsets, "delta_a": da,
            "centres": [(0.5 * (X.min(axis=0) + X.max(axis=0))).tolist() for X in strip_V]}


def _edge_bundle(path: Path, frames: int) -> Path:
    """The small NCP case with three more lamellae: one joint only, two joints and a repeated
    axis vertex, three joints inside a longer axis."""
    b = make_bundle("NCP")
    d = np.linspace(-0.9, 0.9, 15)
    t = np.linspace(-1, 1, 4)
    lams = list(b.net.lamellae)
    ax = paraboloid(np.full_like(d, t[1]) + 0.01, d)
    lams.append(Lamella(id=100, family=1, joints=[5], joint_s=[polyline_arclength(ax)[7]],
                        axis=ax))
    ax = paraboloid(np.full_like(d, t[1]) - 0.01, d)
    ax = np.insert(ax, 4, ax[4], axis=0)
    s = polyline_arclength(ax)
    lams.append(Lamella(id=101, family=3, joints=[6, 7], joint_s=[s[3], s[11]], axis=ax))
    ax = paraboloid(d, np.full_like(d, t[2]) + 0.02)
    s = polyline_arclength(ax)
    lams.append(Lamella(id=102, family=3, joints=[2, 6, 10], joint_s=s[[2, 7, 12]], axis=ax))
    b.net = Net(joints=b.net.joints, loops=b.net.loops, lamellae=lams)
    return write_bundle(path, b, extra=sequence_extra(b, frames=frames) if frames else {})


@pytest.mark.parametrize("case", ["GG", "NCP", "GG-no-sequence", "edge", "edge-no-sequence"])
def test_scene_equals_the_one_built_lamella_by_lamella(tmp_path, case):
    if case.startswith("edge"):
        d = _edge_bundle(tmp_path / "b", 0 if case.endswith("no-sequence") else 5)
    else:
        d = write_case(tmp_path / "b", case[:case.find("-")] if "-" in case else case,
                       sequence="no-sequence" not in case)
    ref = _former_strips(d)
    S = sc.build_scene(d)
    assert len(S["strips"]["V"]) == len(ref["V"])
    q = S["strips"]["quant"]
    step = (np.asarray(q["hi"]) - np.asarray(q["lo"])) / q["steps"]
    for k, want in enumerate(ref["V"]):
        got = sc.strip_vertices(S, k)
        assert np.all(np.abs(got - want.reshape(-1, 3)) <= 0.5 * step + 1e-7 * np.abs(want).max())
    assert sc.decode(S["strips"]["F"], "u4").tobytes() == ref["F"].astype("<u4").tobytes()
    assert [(r["v0"], r["nv"], r["f0"], r["nf"]) for r in S["lamellae"]] == ref["offsets"]
    assert sc.decode(S["scalars"]["delta_a"], "f4").tobytes() == \
        ref["delta_a"].astype("<f4").tobytes()
    assert json.dumps(S["centres"]) == json.dumps(ref["centres"])   # -0.0 and all


# ---- the parts ---------------------------------------------------------------------------------

def test_interp_rows_is_np_interp_row_by_row():
    rng = np.random.default_rng(11)
    for trial in range(60):
        rows = int(rng.integers(1, 12))
        n_knots = rng.integers(0, 30, rows)          # rows without knots give 0
        xp = [np.sort(rng.uniform(0, 5, k)) for k in n_knots]
        for a in xp:                                  # repeated knots
            if len(a) > 3 and trial % 2:
                a[1] = a[2]
        fp = [rng.normal(size=(len(a), 3)) * 10.0 ** rng.uniform(-3, 3) for a in xp]
        x, rx = [], []
        for r, a in enumerate(xp):
            here = [rng.uniform(-1, 6, 20), a, a[:1], a[-1:]] if len(a) else [rng.uniform(0, 5, 3)]
            x += here
            rx += [np.full(sum(len(h) for h in here), r)]
        x, rx = np.concatenate(x), np.concatenate(rx)
        order = rng.permutation(len(x))              # the x need no order
        x, rx = x[order], rx[order]
        look = sc._interp_rows(x, rx, np.concatenate(xp),
                               np.repeat(np.arange(rows), n_knots))
        states = rng.normal(size=(2, sum(n_knots), 3))
        states[0] = np.concatenate(fp)
        got = look(states)
        start = np.concatenate([[0], np.cumsum(n_knots)])
        for r in range(rows):
            here = rx == r
            for k in range(2):
                for c in range(3):
                    want = np.interp(x[here], xp[r], states[k, start[r]:start[r + 1], c]) \
                        if len(xp[r]) else np.zeros(here.sum())
                    assert np.array_equal(_bits(got[k, here, c]), _bits(want))


def test_carried_axes_are_the_moved_nets_axes():
    from gridshell.geometry.net import carried_axes, move_joints_states

    b = _edge_net()
    rng = np.random.default_rng(2)
    states = [b.joints + 0.05 * rng.normal(size=b.joints.shape) for _ in range(3)]
    nets = move_joints_states(b, states)
    arrays = carried_axes(b, states)
    for i, (X, S) in enumerate(arrays):
        for k, net in enumerate(nets):
            axis = net.lamellae[i].axis
            assert np.array_equal(_bits(X[k]), _bits(axis))
            assert np.array_equal(_bits(S[k]), _bits(polyline_arclength(axis)))
    assert [X.shape[0] for X, _ in carried_axes(b, [])] == [0] * len(b.lamellae)


def _edge_net() -> Net:
    from tests.helpers.render_cases import make_net

    net = make_net()
    d = np.linspace(-0.9, 0.9, 15)
    ax = paraboloid(d, np.full_like(d, 0.3))
    s = polyline_arclength(ax)
    lams = list(net.lamellae) + [
        Lamella(id=50, family=1, joints=[5], joint_s=[s[7]], axis=ax),
        Lamella(id=51, family=1, joints=[], joint_s=[], axis=ax),
        Lamella(id=52, family=3, joints=[2, 6], joint_s=s[[3, 11]], axis=ax)]
    return Net(joints=net.joints, loops=net.loops, lamellae=lams)


def test_extremes_are_each_states_min_and_max_with_the_sign_of_zero():
    rng = np.random.default_rng(4)
    for trial in range(400):
        X = rng.normal(size=(int(rng.integers(1, 5)), int(rng.integers(1, 90)), 3))
        if trial % 2:                                  # ties of +0.0 and -0.0 at the extremes
            X = np.abs(X) if trial % 4 == 1 else -np.abs(X)
            m = rng.random(X.shape) < 0.3
            X[m] = rng.choice([0.0, -0.0], size=int(m.sum()))
        want = np.stack([np.stack([x.min(axis=0) for x in X]),
                         np.stack([x.max(axis=0) for x in X])])
        assert np.array_equal(_bits(sc._extremes(X)), _bits(want))


def test_vertex_normals_by_bincount_are_those_of_add_at():
    from gridshell.geometry.quadmesh import _unit, area_weighted_vertex_normals, polygon_vector_areas

    rng = np.random.default_rng(8)
    for trial in range(20):
        V = rng.normal(size=(40, 3))
        F = rng.integers(0, 40, size=(60, 5))
        F[rng.random(60) < 0.4, 4] = -1                # quads padded among pentagons
        F[rng.random(60) < 0.2, 3:] = -1               # and triangles
        A = polygon_vector_areas(V, F)
        want = np.zeros_like(V)
        valid = F >= 0
        rows = np.broadcast_to(np.arange(len(F))[:, None], F.shape)[valid]
        np.add.at(want, F[valid], A[rows])
        assert np.array_equal(_bits(area_weighted_vertex_normals(V, F)), _bits(_unit(want)))


def test_strip_solid_faces_are_strip_solids():
    from gridshell.geometry.strips3d import strip_solid, strip_solid_faces

    for k in (2, 3, 17):
        P = np.column_stack([np.arange(k, dtype=float), np.zeros(k), np.zeros(k)])
        N = np.tile([0.0, 0.0, 1.0], (k, 1))
        assert np.array_equal(strip_solid(P, N, 0.2, 0.01, False)[1], strip_solid_faces(k))


def test_surface_lookup_is_kept_by_content_only():
    from scipy.spatial import cKDTree

    from gridshell.geometry.quadmesh import area_weighted_vertex_normals
    from gridshell.geometry.strips3d import nearest_vertex_normals

    b = make_bundle("GG")
    V, F = b.surface_V.copy(), b.surface_F.copy()
    P = b.net.joints
    first = nearest_vertex_normals(P, V, F)
    again = nearest_vertex_normals(P, V.copy(), F.copy())
    assert np.array_equal(first, again) and again.flags.writeable
    again[:] = 0.0                                     # the caller's own array
    assert np.array_equal(nearest_vertex_normals(P, V, F), first)
    V2 = V.copy()
    V2[:, 2] *= -1.0                                   # another surface: its own normals
    flipped = nearest_vertex_normals(P, V2, F)
    used = np.unique(F[F >= 0])
    want = area_weighted_vertex_normals(V2, F)[used][cKDTree(V2[used]).query(P)[1]]
    assert np.array_equal(flipped, want) and not np.allclose(flipped, first)


def test_smooth_curve_at_its_knots_is_the_vertices():
    """net._smooth_at skips the spline where the joints are axis vertices: CubicSpline at an
    interior knot is 0.0 + y there (+-0 included), bit for bit; elsewhere it is the spline."""
    from scipy.interpolate import CubicSpline

    from gridshell.geometry.net import _smooth_at

    rng = np.random.default_rng(6)
    for trial in range(300):
        n = int(rng.integers(3, 120))
        s = np.concatenate([[0.0], np.cumsum(rng.uniform(1e-4, 1, n - 1))])
        X = rng.normal(size=(n, 3)) * 10.0 ** rng.uniform(-3, 3)
        X[rng.random((n, 3)) < 0.1] = rng.choice([0.0, -0.0])
        at = s[np.sort(rng.choice(n - 1, size=min(n - 1, 5), replace=False))]
        want = CubicSpline(s, X, axis=0)(at)
        assert np.array_equal(_bits(_smooth_at(s, X, at)), _bits(want))
        off = at + 0.25 * (s[1] - s[0])                 # not at knots: the spline itself
        assert np.array_equal(_bits(_smooth_at(s, X, off)),
                              _bits(CubicSpline(s, X, axis=0)(off)))
    ends = np.array([0.0, s[-1]])                       # the last knot: the spline too
    assert np.array_equal(_bits(_smooth_at(s, X, ends)), _bits(CubicSpline(s, X, axis=0)(ends)))


def test_joint_normals_of_all_states_at_once_are_state_by_state():
    rng = np.random.default_rng(9)
    net = _edge_net()
    states = [net.joints + 0.1 * rng.normal(size=net.joints.shape) for _ in range(5)]
    states[3][net.loops[0]] = states[3][net.loops[0, 0]]     # a collapsed loop keeps the normal
    n0 = rng.normal(size=net.joints.shape)
    for got, want in zip(sc.joint_normals(states, net.loops, n0),
                         _former_joint_normals(states, net.loops, n0)):
        assert np.array_equal(_bits(got), _bits(want))
    loops = rng.integers(0, len(net.joints), size=(40, 4))  # joints at one corner of many loops
    for got, want in zip(sc._loop_area_vectors(np.stack(states), loops),
                         [_former_loop_area_vectors(J, loops) for J in states]):
        assert np.array_equal(_bits(got), _bits(want))


def test_row_norms_are_numpys_norms():
    from gridshell.geometry.vectors import row_norms

    rng = np.random.default_rng(12)
    for trial in range(200):
        X = rng.normal(size=(int(rng.integers(1, 400)), 3)) * 10.0 ** rng.uniform(-150, 150)
        X[rng.random(X.shape) < 0.1] = rng.choice([0.0, -0.0, 1e-310, np.nan, np.inf])
        with np.errstate(all="ignore"):
            want = np.linalg.norm(X, axis=-1)
            got = row_norms(X)
        assert np.array_equal(_bits(got), _bits(want))
    Y = rng.normal(size=(4, 50, 3))
    assert np.array_equal(_bits(row_norms(Y)), _bits(np.linalg.norm(Y, axis=-1)))
