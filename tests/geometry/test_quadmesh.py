"""Tests of gridshell.geometry.quadmesh: geometry, topology, mesh files and input checks."""
from __future__ import annotations

import numpy as np
import pytest

from gridshell.core.errors import MeshError
from gridshell.geometry.grid import grid_quads
from gridshell.geometry.quadmesh import QuadMesh, TriMesh, validate_mesh
from gridshell.geometry.meshfile import read_mesh, read_polylines, write_mesh, write_polylines


def planar_grid(R: int = 4, C: int = 5, h: float = 0.5) -> QuadMesh:
    i, j = np.meshgrid(np.arange(R), np.arange(C), indexing="ij")
    V = np.stack([j.ravel() * h, i.ravel() * h, np.zeros(R * C)], axis=1)
    return QuadMesh(V, grid_quads(R, C))


def sphere_grid(R: int = 12, C: int = 16, r: float = 2.0) -> QuadMesh:
    """Latitude/longitude patch of a sphere away from the poles (u along j, v along i)."""
    th = np.linspace(0.4, np.pi - 0.4, R)  # polar angle grows with i
    ph = np.linspace(0.0, 1.5 * np.pi, C)
    T, P = np.meshgrid(th, ph, indexing="ij")
    V = r * np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], -1).reshape(-1, 3)
    return QuadMesh(V, grid_quads(R, C))


def cylinder_grid(R: int = 4, C: int = 8) -> QuadMesh:
    G = np.arange(R * C).reshape(R, C)
    Gc = np.concatenate([G, G[:, :1]], axis=1)
    F = np.stack([Gc[:-1, :-1], Gc[:-1, 1:], Gc[1:, 1:], Gc[1:, :-1]], axis=-1).reshape(-1, 4)
    a = 2 * np.pi * np.arange(C) / C
    z = np.arange(R, dtype=float)
    V = np.stack([np.tile(np.cos(a), R), np.tile(np.sin(a), R), np.repeat(z, C)], axis=1)
    return QuadMesh(V, F)


# ------------------------------------------------------------------ geometry and topology

def test_planar_normals_are_z():
    M = planar_grid()
    np.testing.assert_allclose(M.face_normals, np.tile([0, 0, 1.0], (M.n_faces, 1)), atol=1e-15)
    np.testing.assert_allclose(M.vertex_normals, np.tile([0, 0, 1.0], (M.n_vertices, 1)),
                               atol=1e-15)
    flipped = QuadMesh(M.V, M.F[:, ::-1])
    np.testing.assert_allclose(flipped.face_normals[:, 2], -1.0)
    np.testing.assert_allclose(M.face_areas, 0.25)


def test_sphere_face_normals_radial():
    M = sphere_grid()
    centroids = M.V[M.F].mean(axis=1)
    radial = centroids / np.linalg.norm(centroids, axis=1, keepdims=True)
    cosang = np.sum(M.face_normals * radial, axis=1)
    # j runs along longitude (east), i along colatitude (south): e_phi x e_theta = -e_r
    assert cosang.max() < -0.99
    vn = np.sum(M.vertex_normals * M.V / 2.0, axis=1)
    assert vn.max() < -0.98  # one-sided at the boundary
    np.testing.assert_allclose(np.linalg.norm(M.vertex_normals, axis=1), 1.0)


def test_bbox_edges_and_lengths():
    M = planar_grid(3, 4, h=1.0)
    assert M.bbox_diagonal == pytest.approx(np.hypot(3.0, 2.0))
    E = M.edges
    assert len(E) == 3 * 3 + 2 * 4 and np.all(E[:, 0] < E[:, 1])
    assert len(np.unique(E, axis=0)) == len(E)
    np.testing.assert_allclose(M.edge_lengths, 1.0)
    assert M.euler_characteristic == 1


def test_boundary_loop_of_grid():
    R, C = 5, 7
    M = planar_grid(R, C)
    loops = M.boundary_loops
    assert len(loops) == 1 and len(loops[0]) == 2 * (R + C) - 4
    assert set(loops[0].tolist()) == set(M.boundary_vertices.tolist())
    # consecutive loop vertices are joined by edges
    E = {tuple(e) for e in M.edges.tolist()}
    ring = np.r_[loops[0], loops[0][:1]]
    assert all(tuple(sorted(p)) in E for p in zip(ring[:-1].tolist(), ring[1:].tolist()))
    assert M.is_manifold and M.is_disk


def test_cylinder_is_not_disk():
    M = cylinder_grid()
    assert len(M.boundary_loops) == 2
    assert M.euler_characteristic == 0
    assert M.is_manifold and not M.is_disk


def test_triangulate_shorter_diagonal():
    M = sphere_grid(5, 6)
    V, T = M.triangulate()
    assert T.shape == (2 * M.n_faces, 3)
    Tm = M.to_trimesh()
    assert isinstance(Tm, TriMesh) and Tm.is_disk
    # same orientation: triangle normals agree with their quad's normal
    qn = np.repeat(M.face_normals, 2, axis=0)
    assert np.all(np.sum(Tm.face_normals * qn, axis=1) > 0.9)
    # shorter diagonal on a skewed quad
    V = np.array([[0, 0, 0], [1, 0, 0], [3, 1, 0], [2, 1, 0.0]])
    _, T = QuadMesh(V, [[0, 1, 2, 3]]).triangulate()
    assert T.tolist() == [[0, 1, 3], [1, 2, 3]]


def test_copy_and_with_vertices():
    M = planar_grid()
    N = M.with_vertices(M.V + [0, 0, 1.0])
    assert np.array_equal(N.F, M.F) and N.V[0, 2] == 1.0 and M.V[0, 2] == 0.0
    assert M.copy() is not M and np.array_equal(M.copy().V, M.V)
    with pytest.raises(MeshError, match="expected V of shape"):
        M.with_vertices(M.V[:-1])
    with pytest.raises(ValueError):
        M.V[0, 0] = 3.0  # read-only


# ------------------------------------------------------------------ files

@pytest.mark.parametrize("ext", [".obj", ".ply", ".off"])
def test_round_trip_exact(tmp_path, ext):
    rng = np.random.default_rng(7)
    M = sphere_grid(4, 5)
    V = M.V * 1e5 + 123456.789012345 + rng.normal(size=M.V.shape) * 1e-9
    perm = rng.permutation(M.n_faces)
    F = np.roll(M.F[perm], 1, axis=1)  # unusual face order and start vertex
    path = tmp_path / f"m{ext}"
    write_mesh(path, V, F)
    R = read_mesh(path, kind="quad")
    assert isinstance(R, QuadMesh)
    assert np.max(np.abs(R.V - V) / np.abs(V).max()) <= 1e-12
    np.testing.assert_array_equal(R.F, F)
    assert not list(tmp_path.glob(".*tmp*"))  # no temp file left behind


def test_written_files_readable_by_openmesh(tmp_path):
    import openmesh as om
    M = planar_grid(3, 3)
    for ext in (".obj", ".ply", ".off"):
        write_mesh(tmp_path / f"g{ext}", M.V, M.F)
        m = om.read_polymesh(str(tmp_path / f"g{ext}"))
        np.testing.assert_array_equal(m.face_vertex_indices(), M.F)


def test_read_kinds(tmp_path):
    M = planar_grid(3, 3)
    write_mesh(tmp_path / "q.obj", M.V, M.F)
    assert isinstance(read_mesh(tmp_path / "q.obj"), QuadMesh)
    T = read_mesh(tmp_path / "q.obj", kind="tri")
    assert isinstance(T, TriMesh) and T.n_faces == 2 * M.n_faces
    write_mesh(tmp_path / "t.off", *M.triangulate())
    assert isinstance(read_mesh(tmp_path / "t.off"), TriMesh)


def test_obj_extras_and_negative_indices(tmp_path):
    p = tmp_path / "x.obj"
    p.write_text("# c\nmtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n"
                 "g grp\nf 1/1/1 2/1/1 3//1 -1\n")
    M = read_mesh(p, kind="quad")
    assert M.F.tolist() == [[0, 1, 2, 3]]


def test_binary_ply(tmp_path):
    M = planar_grid(3, 4)
    hdr = ("ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty double x\n"
           "property double y\nproperty double z\nelement face %d\n"
           "property list uchar int vertex_indices\nend_header\n" % (M.n_vertices, M.n_faces))
    rec = np.zeros(M.n_faces, dtype=[("n", "u1"), ("i", "<i4", (4,))])
    rec["n"], rec["i"] = 4, M.F
    (tmp_path / "b.ply").write_bytes(hdr.encode() + M.V.astype("<f8").tobytes() + rec.tobytes())
    R = read_mesh(tmp_path / "b.ply")
    np.testing.assert_array_equal(R.F, M.F)
    np.testing.assert_array_equal(R.V, M.V)


def test_mixed_mesh_any_is_triangulated(tmp_path):
    p = tmp_path / "mixed.obj"
    p.write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nf 1 2 3 4\nf 2 5 3\n")
    T = read_mesh(p)
    assert isinstance(T, TriMesh) and T.n_faces == 3
    with pytest.raises(MeshError, match="1 faces are not quads"):
        read_mesh(p, kind="quad")


def test_polylines_round_trip(tmp_path):
    rng = np.random.default_rng(3)
    pls = [rng.normal(size=(k, 3)) * 1e4 for k in (2, 5, 3)]
    write_polylines(tmp_path / "p.obj", pls)
    back = read_polylines(tmp_path / "p.obj")
    assert len(back) == 3
    for a, b in zip(pls, back):
        np.testing.assert_array_equal(a, b)


# ------------------------------------------------------------------ bad input

QUAD = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"

BAD_FILES = [
    ("empty.obj", b"", "empty"),
    ("trunc.obj", (QUAD + "v 2 0").encode(), "truncated"),
    ("trunc.off", b"OFF\n4 1 0\n0 0 0\n1 0 0\n", "truncated"),
    ("trunc.ply", b"ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\n", "truncated"),
    ("garbage.obj", bytes(range(256)) * 4, "corrupt"),
    ("garbage.ply", b"\x89PNG\r\n\x1a\n" + bytes(64), "corrupt"),
    ("mesh.stl", QUAD.encode(), "unknown mesh format"),
    ("nan.obj", ("v 0 0 nan\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n").encode(), "NaN"),
    ("oor.obj", (QUAD + "f 1 2 3 9\n").encode(), "outside"),
    ("nm.obj", (QUAD + "v 0 -1 0\nv 1 -1 0\nv 0 0 1\nv 1 0 1\n"
                "f 1 2 3 4\nf 2 1 5 6\nf 1 2 8 7\n").encode(), "non-manifold"),
    ("deg.obj", (QUAD + "f 1 2 2 3\n").encode(), "degenerate"),
    # zero area: all four corners on one line
    ("flat.obj", b"v 0 0 0\nv 1 0 0\nv 2 0 0\nv 3 0 0\nv 0 1 0\nf 1 2 3 4\n", "degenerate"),
    ("pent.off", b"OFF\n5 1 0\n0 0 0\n1 0 0\n1 1 0\n0.5 2 0\n0 1 0\n5 0 1 2 3 4\n", "not quads"),
    ("noface.obj", QUAD.encode(), "empty"),
]


@pytest.mark.parametrize("name,data,word", BAD_FILES, ids=[b[0] for b in BAD_FILES])
def test_bad_files(tmp_path, name, data, word):
    p = tmp_path / name
    p.write_bytes(data)
    with pytest.raises(MeshError, match=word) as err:
        read_mesh(p, kind="quad")
    assert name in str(err.value)


def test_missing_file(tmp_path):
    with pytest.raises(MeshError, match="no such file"):
        read_mesh(tmp_path / "nope.obj")


def test_validate_messages():
    V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.0]])
    with pytest.raises(MeshError, match="empty"):
        validate_mesh(np.zeros((0, 3)), np.zeros((0, 4), int))
    with pytest.raises(MeshError, match="shape"):
        validate_mesh(V[:, :2], [[0, 1, 2, 3]])
    with pytest.raises(MeshError, match="infinite"):
        validate_mesh(np.where(V == 1, np.inf, V), [[0, 1, 2, 3]])
    with pytest.raises(MeshError, match=r"face 0 is degenerate|faces are degenerate"):
        validate_mesh(V * [1, 0, 0], [[0, 1, 2, 3]])
    with pytest.raises(MeshError, match="a face of 3 vertices is face 1"):
        validate_mesh(V, [[0, 1, 2, 3], [0, 1, 2]], require_quads=True)
    # two faces running the same edge the same way
    V2 = np.vstack([V, [[0, -1, 0], [1, -1, 0]]])
    with pytest.raises(MeshError, match="inconsistently oriented"):
        validate_mesh(V2, [[0, 1, 2, 3], [0, 1, 5, 4]])
    validate_mesh(V2, [[0, 1, 2, 3], [1, 0, 4, 5]], require_quads=True)


def test_non_manifold_vertex():
    # two quads touching at vertex 0 only (bow tie)
    V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                  [-1, 0, 0], [-1, -1, 0], [0, -1, 0.0]])
    with pytest.raises(MeshError, match="non-manifold.*vertex 0"):
        validate_mesh(V, [[0, 1, 2, 3], [0, 4, 5, 6]])


def test_too_large(monkeypatch):
    import gridshell.geometry.quadmesh as qm
    M = planar_grid(3, 3)
    monkeypatch.setattr(qm, "MAX_ELEMENTS", 3)
    with pytest.raises(MeshError, match="too large"):
        validate_mesh(M.V, M.F)


def test_quadmesh_checks_input():
    with pytest.raises(MeshError):
        QuadMesh(np.zeros((3, 3)), [[0, 1, 2]])


def test_read_configuration_accepts_a_collapsed_net_but_not_garbage(tmp_path):
    from gridshell.geometry.meshfile import read_configuration
    # a collapsed net: every loop's joints on the x axis, zero area by design
    V = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0], [1.5, 0, 0]])
    F = np.array([[0, 1, 2, 3]])
    write_mesh(tmp_path / "aligned.obj", V, F)
    with pytest.raises(MeshError, match="degenerate"):
        read_mesh(tmp_path / "aligned.obj", kind="quad")
    V2, P, sizes = read_configuration(tmp_path / "aligned.obj")
    np.testing.assert_array_equal(V2, V)
    np.testing.assert_array_equal(P[:, :4], F)
    assert sizes.tolist() == [4]
    (tmp_path / "bad.obj").write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 9\n")
    with pytest.raises(MeshError, match="vertex"):
        read_configuration(tmp_path / "bad.obj")
    (tmp_path / "nan.obj").write_text("v 0 0 nan\nv 1 0 0\nv 1 1 0\nf 1 2 3\n")
    with pytest.raises(MeshError, match="NaN"):
        read_configuration(tmp_path / "nan.obj")


def test_orientation_message_counts_and_names_as_numpys_unique():
    """The directed edges run twice found by sorting: the count and first edge of the message
    are those of np.unique's counts (a grid with several faces flipped)."""
    from gridshell.geometry.quadmesh import _face_edges, _topology_problem

    n = 7
    F = np.array([[i * n + j, (i + 1) * n + j, (i + 1) * n + j + 1, i * n + j + 1]
                  for i in range(n - 1) for j in range(n - 1)])
    F[[3, 10, 11, 20]] = F[[3, 10, 11, 20], ::-1]
    src, dst, _ = _face_edges(F)
    directed = src * np.int64(n * n) + dst
    u, c = np.unique(directed, return_counts=True)
    d = u[c > 1]
    msg = _topology_problem(F, n * n)
    assert msg.startswith(f"{len(d)} edges are run in the same direction")
    assert f"joins vertices {d[0] // (n * n)} and {d[0] % (n * n)})" in msg
