"""read_bundle reads a bundle once per process and content: a second read of byte-identical
files parses nothing and returns its own copy; any change of a file (even one that keeps its
size and modification time) is read anew."""
from __future__ import annotations

import os

import numpy as np
import pytest
from tests.helpers.render_cases import write_case

import gridshell.geometry.meshfile as meshfile
from gridshell.design.bundle import content_key, read_bundle
from gridshell.core.errors import InputError


def _no_parsing(monkeypatch):
    def refuse(*args, **kwargs):
        raise AssertionError("the bundle was parsed again")
    for name in ("read_mesh", "read_configuration", "read_polylines"):
        monkeypatch.setattr(meshfile, name, refuse)


def test_a_second_read_parses_nothing_and_returns_its_own_copy(tmp_path, monkeypatch):
    d = write_case(tmp_path / "b")
    first = read_bundle(d)
    _no_parsing(monkeypatch)
    second = read_bundle(d)
    assert second is not first and second.net is not first.net
    assert np.array_equal(second.surface_V, first.surface_V)
    assert np.array_equal(second.net.joints, first.net.joints)
    assert all(np.array_equal(a.axis, b.axis) for a, b in zip(first.net.lamellae,
                                                                second.net.lamellae))
    assert second.metrics == first.metrics and second.params == first.params
    # what a caller does to its copy does not reach the next reader
    second.surface_V[:] = 0.0
    second.net.lamellae[0].axis[:] = 0.0
    second.params["nested"]["b"].append(99)
    third = read_bundle(d)
    assert np.array_equal(third.surface_V, first.surface_V)
    assert np.array_equal(third.net.lamellae[0].axis, first.net.lamellae[0].axis)
    assert third.params == first.params


def test_a_changed_file_is_read_anew_even_with_the_same_size_and_time(tmp_path):
    d = write_case(tmp_path / "b")
    before = read_bundle(d)
    f = d / "surface.obj"
    text = f.read_text()
    st = os.stat(f)
    # the first vertex's x coordinate, one digit changed: same size, same mtime
    i = text.index("v ") + 2
    digit = text[i + 1] if text[i] == "-" else text[i]
    j = i + 1 if text[i] == "-" else i
    new = "2" if digit != "2" else "3"
    f.write_text(text[:j] + new + text[j + 1:])
    os.utime(f, ns=(st.st_atime_ns, st.st_mtime_ns))
    assert os.stat(f).st_size == st.st_size and os.stat(f).st_mtime_ns == st.st_mtime_ns
    after = read_bundle(d)
    assert not np.array_equal(after.surface_V, before.surface_V)
    assert np.array_equal(after.surface_V[1:], before.surface_V[1:])


def test_a_broken_bundle_still_fails_after_a_good_read(tmp_path):
    d = write_case(tmp_path / "b")
    read_bundle(d)
    (d / "net.obj").write_text("garbage\n")
    with pytest.raises(InputError):
        read_bundle(d)
    (d / "net.obj").unlink()
    with pytest.raises(InputError, match="net.obj"):
        read_bundle(d)


def test_content_key_names_the_files_by_content():
    from pathlib import Path

    assert content_key(Path("/nonexistent-dir-xyz"))[2] == (None,) * 6


def test_an_added_revolution_file_is_read(tmp_path):
    d = write_case(tmp_path / "b")
    assert read_bundle(d).revolution_V is None
    b = read_bundle(d)
    meshfile.write_mesh(d / "revolution.obj", b.surface_V + 1.0, b.surface_F)
    assert np.array_equal(read_bundle(d).revolution_V, b.surface_V + 1.0)


def test_closest_point_queries_asked_with_reuse_are_answered_once(monkeypatch):
    import gridshell.geometry.igl_adapter as ia

    rng = np.random.default_rng(5)
    t = np.linspace(-1, 1, 12)
    X, Y = np.meshgrid(t, t, indexing="ij")
    V = np.stack([X, Y, 0.2 * X * Y], -1).reshape(-1, 3)
    from gridshell.geometry.grid import grid_quads

    F = grid_quads(12, 12)
    P = rng.uniform(-1, 1, (50, 3))
    plain = ia.closest_points(P, V, F)
    plain_n = ia.closest_points_with_normals(P, V, F)
    first = ia.closest_points(P, V, F, reuse=True)
    first_n = ia.closest_points_with_normals(P + 0.0, V, F, reuse=True)
    monkeypatch.setattr(ia.igl, "point_mesh_squared_distance",
                        lambda *a: (_ for _ in ()).throw(AssertionError("asked igl again")))
    again = ia.closest_points(P.copy(), V.copy(), F.copy(), reuse=True)
    again_n = ia.closest_points_with_normals(P, V, F, reuse=True)
    for a, b, c in zip(plain + plain_n, first + first_n, again + again_n):
        assert np.array_equal(a, b) and np.array_equal(a, c)
    again[2][:] = 0.0                        # the caller's own copy
    assert np.array_equal(ia.closest_points(P, V, F, reuse=True)[2], plain[2])
    with pytest.raises(AssertionError, match="asked igl again"):
        ia.closest_points(P + 1e-9, V, F, reuse=True)       # other points: a new query
    with pytest.raises(AssertionError, match="asked igl again"):
        ia.closest_points(P, V, F)                           # without reuse: always asked


def test_closest_points_asked_ahead_together_equal_their_own_queries(monkeypatch):
    """ask_closest_points answers several point sets with one igl query (one AABB tree):
    afterwards each set's reuse queries (closest points, with normals) give, bit for bit,
    what its own query gives, without asking igl again; a set asked before is not asked."""
    import gridshell.geometry.igl_adapter as ia
    from gridshell.geometry.grid import grid_quads

    rng = np.random.default_rng(11)
    t = np.linspace(-1, 1, 15)
    X, Y = np.meshgrid(t, t, indexing="ij")
    V = np.stack([X, Y, 0.3 * X * X - 0.1 * Y], -1).reshape(-1, 3)
    F = grid_quads(15, 15)
    sets = [rng.uniform(-1.2, 1.2, (k, 3)) for k in (40, 1, 0, 300)]    # 8 results: kept
    own = [ia.closest_points(P, V, F) for P in sets]
    own_n = [ia.closest_points_with_normals(P, V, F) for P in sets]
    asked = []
    real = ia.igl.point_mesh_squared_distance
    monkeypatch.setattr(ia.igl, "point_mesh_squared_distance",
                        lambda P, *a: asked.append(len(P)) or real(P, *a))
    ia.closest_points(sets[3], V, F, reuse=True)             # answered before: not asked again
    ia.ask_closest_points(sets, V, F)
    assert asked == [300, 41]
    monkeypatch.setattr(ia.igl, "point_mesh_squared_distance",
                        lambda *a: (_ for _ in ()).throw(AssertionError("asked igl again")))
    for P, a, a_n in zip(sets, own, own_n):
        b = ia.closest_points(P, V, F, reuse=True)
        b_n = ia.closest_points_with_normals(P, V, F, reuse=True)
        for x, y in zip(a + a_n, b + b_n):
            assert x.dtype == y.dtype and x.shape == y.shape
            assert np.array_equal(x.view(np.uint8), y.view(np.uint8))
    ia.ask_closest_points(sets[:2], V, F)                    # all answered: no query


def test_verification_after_a_read_gives_what_it_gives_alone(tmp_path):
    """verify_bundle on the arrays read_bundle parsed (and on reused closest points) gives
    the result it gives from the files alone, in a new process, pass and fail alike."""
    import json
    import subprocess
    import sys

    from gridshell.design.verification import verify_bundle

    d = write_case(tmp_path / "b", kind="NCP")
    code = ("import json\n"
            "from gridshell.design.verification import verify_bundle\n"
            f"print(json.dumps(verify_bundle({str(d)!r})))")
    alone = json.loads(subprocess.run([sys.executable, "-c", code], capture_output=True,
                                      text=True, check=True, timeout=120).stdout)
    read_bundle(d)
    from gridshell.design.bundle import cached_bundle

    assert cached_bundle(d) is not None
    assert json.loads(json.dumps(verify_bundle(d))) == alone
    assert json.loads(json.dumps(verify_bundle(d))) == alone


def _irregular_mesh(rng, n=5000):
    """A Delaunay triangulation of random points on a wavy height field (irregular
    valences, a ragged boundary)."""
    from scipy.spatial import Delaunay

    xy = rng.uniform(-1, 1, (n, 2))
    T = Delaunay(xy).simplices.astype(np.int64)
    V = np.column_stack([xy, 0.3 * np.sin(2 * xy[:, 0]) * np.cos(3 * xy[:, 1])])
    return V, T


def _noisy_wave(rng, m: int):
    """An m x m quad grid of a wave z = 0.3 sin 2x cos 3y on [-1, 1]^2, points moved by
    noise of 3 mm."""
    from gridshell.geometry.grid import grid_quads

    t = np.linspace(-1, 1, m)
    X, Y = np.meshgrid(t, t, indexing="ij")
    V = np.stack([X, Y, 0.3 * np.sin(2 * X) * np.cos(3 * Y)], -1).reshape(-1, 3)
    return V + rng.normal(0, 0.003, V.shape), grid_quads(m, m)


@pytest.mark.parametrize("case", ["grid", "irregular"])
@pytest.mark.parametrize("radius", [1, 2, 3])
def test_principal_curvature_at_some_vertices_is_that_of_the_whole_mesh(case, radius):
    from gridshell.geometry.igl_adapter import principal_curvature, principal_curvature_at

    rng = np.random.default_rng(11 + radius)
    if case == "grid":
        m = 120
        V, F = _noisy_wave(rng, m)
        corners = [0, m - 1, m * m - 1, m * (m - 1), m, 2 * m + 1]
    else:
        V, F = _irregular_mesh(rng)
        corners = []
    whole = principal_curvature(V, F, radius=radius)
    picks = np.concatenate([rng.choice(len(V), 30, replace=False),
                            np.array(corners + [5, 5], dtype=np.int64)])
    part = principal_curvature_at(V, F, picks, radius=radius)
    for w, p in zip(whole, part):
        assert np.array_equal(w[picks], p, equal_nan=True)


def test_principal_curvature_at_asks_igl_about_a_part_of_the_mesh(monkeypatch):
    """(The test above compares on meshes where only a part is handed to igl.)"""
    import gridshell.geometry.igl_adapter as ia

    V, F = _irregular_mesh(np.random.default_rng(3))
    sizes = []
    real = ia.igl.principal_curvature
    monkeypatch.setattr(ia.igl, "principal_curvature",
                        lambda V, T, r: sizes.append(len(V)) or real(V, T, r))
    ia.principal_curvature_at(V, F, np.arange(0, 5000, 170), radius=3)
    assert sizes and sizes[0] < len(V) // 2


@pytest.mark.parametrize("radius", [1, 2, 3])
def test_principal_curvature_at_one_ring_less_when_the_outer_normals_agree(radius, monkeypatch):
    """On a smooth mesh the outermost ring's normals face the vertex's side: igl gets the
    part one ring smaller, and the figures are still those of the whole mesh, bit for bit;
    on a mesh folded onto itself near a vertex the guard refuses and the full part is used
    (the same figures again)."""
    import gridshell.geometry.igl_adapter as ia

    rng = np.random.default_rng(7 + radius)
    m = 50
    V, F = _noisy_wave(rng, m)
    picks = rng.choice(np.arange(m * m), 25, replace=False)
    Vt, T, _ = ia.triangulate(V, F)
    assert ia._outer_ring_agrees(Vt, T, picks, max(radius, 2))
    sizes = []
    real = ia.igl.principal_curvature
    monkeypatch.setattr(ia.igl, "principal_curvature",
                        lambda V, T, r: sizes.append(len(T)) or real(V, T, r))
    whole = ia.principal_curvature(V, F, radius=radius)
    part = ia.principal_curvature_at(V, F, picks, radius=radius)
    for w, p in zip(whole, part):
        assert np.array_equal(w[picks], p, equal_nan=True)
    near = np.zeros(len(Vt), dtype=bool)
    near[picks] = True
    for _ in range(max(radius, 2) - 1):
        near[T[near[T].any(axis=1)]] = True
    assert sizes[-1] == int(near[T].any(axis=1).sum())       # one ring less
    # a sharp fold next to a picked vertex: its ring's outer triangles face away
    Vf = V.copy()
    c = (m // 2) * m + m // 2
    Vf[c + 2 * m: c + 2 * m + 3, 2] += 5.0
    Vft, Tf, _ = ia.triangulate(Vf, F)
    assert not ia._outer_ring_agrees(Vft, Tf, np.array([c]), max(radius, 2))
    whole = ia.principal_curvature(Vf, F, radius=radius)
    part = ia.principal_curvature_at(Vf, F, np.array([c]), radius=radius)
    for w, p in zip(whole, part):
        assert np.array_equal(w[[c]], p, equal_nan=True)


def test_principal_curvature_at_one_ring_less_on_an_irregular_mesh():
    """The same on a Delaunay mesh of random points (irregular valences, a ragged boundary):
    where the guard lets igl have the smaller part, the figures are the whole mesh's."""
    from scipy.spatial import Delaunay

    import gridshell.geometry.igl_adapter as ia

    rng = np.random.default_rng(3)
    xy = rng.uniform(-1, 1, (3000, 2))
    F = Delaunay(xy).simplices.astype(np.int64)
    V = np.column_stack([xy, 0.05 * np.sin(2 * xy[:, 0]) * np.cos(3 * xy[:, 1])])
    for radius in (1, 2, 3):
        picks = rng.choice(len(V), 20, replace=False)
        assert ia._outer_ring_agrees(V, F, picks, max(radius, 2))
        whole = ia.principal_curvature(V, F, radius=radius)
        part = ia.principal_curvature_at(V, F, picks, radius=radius)
        for w, p in zip(whole, part):
            assert np.array_equal(w[picks], p, equal_nan=True)
