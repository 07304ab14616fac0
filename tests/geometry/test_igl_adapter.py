"""libigl adapter: closest points, curvature and disk parameterization vs closed forms."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import ConvexHull, Delaunay

from gridshell.geometry import igl_adapter as ia
from gridshell.core.errors import InputError, MeshError


def fibonacci_sphere(n: int, R: float) -> tuple[np.ndarray, np.ndarray]:
    """Near-uniform triangulated sphere, faces oriented outward."""
    i = np.arange(n) + 0.5
    phi, th = np.arccos(1 - 2 * i / n), np.pi * (1 + 5 ** 0.5) * i
    V = R * np.c_[np.cos(th) * np.sin(phi), np.sin(th) * np.sin(phi), np.cos(phi)]
    F = ConvexHull(V).simplices.astype(np.int64)
    fn = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    inward = np.einsum("ij,ij->i", fn, V[F].mean(axis=1)) < 0
    F[inward] = F[inward][:, ::-1]
    return V, F


def quad_grid(rows: int, cols: int, size: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Flat square grid in z = 0; quad (i, j) is face i * (cols - 1) + j, normal +z."""
    x, y = np.meshgrid(np.linspace(0, size, rows), np.linspace(0, size, cols), indexing="ij")
    V = np.c_[x.ravel(), y.ravel(), np.zeros(x.size)]
    i, j = np.meshgrid(np.arange(rows - 1), np.arange(cols - 1), indexing="ij")
    a = (i * cols + j).ravel()
    return V, np.c_[a, a + cols, a + cols + 1, a + 1]


def paraboloid_disk(n: int = 400, seed: int = 1) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    r, t = np.sqrt(rng.random(n)) * 0.97, 2 * np.pi * rng.random(n)
    c = np.linspace(0, 2 * np.pi, 64, endpoint=False)
    xy = np.r_[np.c_[r * np.cos(t), r * np.sin(t)], np.c_[np.cos(c), np.sin(c)]]
    F = Delaunay(xy).simplices.astype(np.int64)
    fn = np.cross(np.c_[xy[F[:, 1]] - xy[F[:, 0]], np.zeros(len(F))],
                  np.c_[xy[F[:, 2]] - xy[F[:, 0]], np.zeros(len(F))])[:, 2]
    F[fn < 0] = F[fn < 0][:, ::-1]
    return np.c_[xy, 0.6 * (xy ** 2).sum(axis=1)], F


# ----------------------------------------------------------------------------- triangulation


def test_quads_split_along_shorter_diagonal():
    V = np.array([[0, 0, 0], [2, 0, 0], [2.5, 1, 0], [0, 1, 0.0]])   # a-c longer than b-d
    _, T, face_of = ia.triangulate(V, np.array([[0, 1, 2, 3]]))
    np.testing.assert_array_equal(T, [[0, 1, 3], [1, 2, 3]])
    np.testing.assert_array_equal(face_of, [0, 0])
    V[2] = [1.5, 1, 0]                                               # now a-c is shorter
    _, T, _ = ia.triangulate(V, np.array([[0, 1, 2, 3]]))
    np.testing.assert_array_equal(T, [[0, 1, 2], [0, 2, 3]])


def test_bad_meshes_are_rejected_before_igl():
    V, F = quad_grid(3, 3)
    with pytest.raises(MeshError, match="face indices must lie in"):
        ia.closest_points(np.zeros((1, 3)), V, F + 100)
    with pytest.raises(MeshError, match="shape \\(m, 3\\) or \\(m, 4\\)"):
        ia.per_vertex_normals(V, F[:, :2])
    with pytest.raises(InputError, match="query points"):
        ia.closest_points(np.zeros((1, 2)), V, F)


# ----------------------------------------------------------------------------- queries


def test_closest_points_on_flat_grid_are_projections():
    V, F = quad_grid(6, 6)
    rng = np.random.default_rng(0)
    P = np.c_[rng.uniform(0.01, 0.99, (50, 2)), rng.normal(size=50)]
    sqr, face, C = ia.closest_points(P, V, F)
    np.testing.assert_allclose(C, np.c_[P[:, :2], np.zeros(50)], atol=1e-12)
    np.testing.assert_allclose(sqr, P[:, 2] ** 2, atol=1e-12)
    cell = np.floor(P[:, :2] * 5).astype(int)
    np.testing.assert_array_equal(face, cell[:, 0] * 5 + cell[:, 1])   # index into the quads
    C2, N = ia.closest_points_with_normals(P, V, F)
    np.testing.assert_allclose(C2, C, atol=1e-12)
    np.testing.assert_allclose(N, np.tile([0, 0, 1.0], (50, 1)), atol=1e-12)


def test_closest_points_with_normals_on_sphere_are_radial():
    R = 2.0
    V, F = fibonacci_sphere(2000, R)
    rng = np.random.default_rng(2)
    d = rng.normal(size=(100, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    P = d * rng.uniform(0.5 * R, 1.5 * R, (100, 1))
    C, N = ia.closest_points_with_normals(P, V, F)
    np.testing.assert_allclose(np.linalg.norm(C, axis=1), R, rtol=5e-3)   # chord sagitta
    np.testing.assert_allclose(np.linalg.norm(N, axis=1), 1, atol=1e-12)
    assert np.einsum("ij,ij->i", N, d).min() > np.cos(np.radians(2))
    Nv = ia.per_vertex_normals(V, F)
    assert np.einsum("ij,ij->i", Nv, V / R).min() > np.cos(np.radians(2))


def test_principal_curvature_of_sphere():
    R = 2.0
    V, F = fibonacci_sphere(2000, R)
    d1, d2, k1, k2 = ia.principal_curvature(V, F, radius=2)
    # Outward normals: the sphere bends away from them, k = -1/R (igl's sign is flipped).
    assert np.all(k1 <= k2)
    np.testing.assert_allclose(k1 * R, -1, atol=2e-2)
    np.testing.assert_allclose(k2 * R, -1, atol=2e-2)
    # igl's default neighbourhood (radius 5) over-estimates by a few percent on this mesh.
    _, _, k1_5, _ = ia.principal_curvature(V, F)
    np.testing.assert_allclose(k1_5 * R, -1, atol=6e-2)
    n = V / R
    assert np.abs(np.einsum("ij,ij->i", d1, n)).max() < 0.05          # tangent directions


def test_principal_curvature_of_cylinder_quads():
    """A quad-meshed cylinder: k1 = -1/r around it (outward normal), k2 = 0 along the axis."""
    r, rows, cols = 0.5, 120, 41
    ang = np.linspace(0, 2 * np.pi, rows, endpoint=False)
    z = np.linspace(0, 2.0, cols)
    A, Z = np.meshgrid(ang, z, indexing="ij")
    V = np.c_[r * np.cos(A).ravel(), r * np.sin(A).ravel(), Z.ravel()]
    i, j = np.meshgrid(np.arange(rows), np.arange(cols - 1), indexing="ij")
    a = (i * cols + j).ravel()
    b = (((i + 1) % rows) * cols + j).ravel()
    F = np.c_[a, b, b + 1, a + 1]                  # counter-clockwise seen from outside
    Nv = ia.per_vertex_normals(V, F)
    inner = (Z.ravel() > 0.5) & (Z.ravel() < 1.5)
    radial = np.c_[np.cos(A).ravel(), np.sin(A).ravel(), np.zeros(A.size)]
    assert np.einsum("ij,ij->i", Nv, radial)[inner].min() > 0.999
    d1, d2, k1, k2 = ia.principal_curvature(V, F, radius=2)
    np.testing.assert_allclose(k1[inner] * r, -1, atol=2e-2)
    np.testing.assert_allclose(k2[inner] * r, 0, atol=2e-2)
    assert np.abs(d2[inner, 2]).min() > 0.99                          # axis direction


# ----------------------------------------------------------------------------- parameterization


@pytest.mark.parametrize("method", ["lscm", "harmonic"])
def test_disk_parameterization_is_bijective(method):
    V, F = paraboloid_disk()
    UV = ia.parameterize_disk(V, F, method=method)
    assert UV.shape == (len(V), 2)
    np.testing.assert_allclose(UV.min(axis=0), 0, atol=1e-12)
    np.testing.assert_allclose(UV.max(axis=0), 1, atol=1e-12)
    assert len(ia.flipped_triangles(UV, V, F)) == 0


def test_lscm_of_planar_mesh_is_a_similarity():
    V, F = paraboloid_disk()
    V[:, 2] = 0.0
    UV = ia.parameterize_disk(V, F, normalize=False)
    i, j = F[:, 0], F[:, 1]
    ratio = np.linalg.norm(UV[i] - UV[j], axis=1) / np.linalg.norm(V[i, :2] - V[j, :2], axis=1)
    np.testing.assert_allclose(ratio, ratio.mean(), rtol=1e-6)


def test_lscm_unrolls_a_developable_quad_grid_isometrically():
    """A grid bent about one axis has planar triangles and an exact flat unfolding."""
    V, F = quad_grid(8, 5, size=1.0)
    V[:, 2] = 0.2 * V[:, 0] ** 2
    UV = ia.parameterize_disk(V, F, normalize=False)
    _, T, _ = ia.triangulate(V, F)
    for i, j in ((0, 1), (1, 2), (2, 0)):
        a, b = T[:, i], T[:, j]
        ratio = np.linalg.norm(UV[a] - UV[b], axis=1) / np.linalg.norm(V[a] - V[b], axis=1)
        np.testing.assert_allclose(ratio, ratio.mean(), rtol=1e-9)
    assert len(ia.flipped_triangles(ia.parameterize_disk(V, F), V, F)) == 0


def test_non_disks_are_rejected():
    Vs, Fs = fibonacci_sphere(200, 1.0)
    with pytest.raises(MeshError, match="closed"):
        ia.parameterize_disk(Vs, Fs)
    V, F = paraboloid_disk()
    centre = np.linalg.norm(V[F].mean(axis=1)[:, :2], axis=1)
    ring = F[centre > 0.3]
    used = np.unique(ring)
    remap = np.full(len(V), -1)
    remap[used] = np.arange(len(used))
    with pytest.raises(MeshError, match="not a disk"):
        ia.parameterize_disk(V[used], remap[ring])
    with pytest.raises(MeshError, match="belong to no face"):
        ia.parameterize_disk(V, ring)
    two = np.r_[F, F + len(V)]
    with pytest.raises(MeshError, match="2 connected components"):
        ia.parameterize_disk(np.r_[V, V + 5.0], two)


def test_cotangent_laplacian_integrates_the_gradient_of_linear_functions():
    # on a planar mesh a linear x = a . p is reproduced exactly: x^T L x = |a|^2 * area, and
    # constants are in the kernel (the adapter flips igl's negative semi-definite sign)
    from gridshell.geometry.grid import grid_quads
    from gridshell.geometry.igl_adapter import cotangent_laplacian

    s, t = np.meshgrid(np.linspace(0, 2, 7), np.linspace(0, 1.5, 5), indexing="ij")
    rng = np.random.default_rng(3)
    V = np.stack([s + 0.05 * rng.normal(size=s.shape), t, 0 * s], -1).reshape(-1, 3)
    L = cotangent_laplacian(V, grid_quads(7, 5))
    a = np.array([0.7, -1.3])
    x = V[:, :2] @ a
    np.testing.assert_allclose(x @ (L @ x), (a @ a) * _area(V, grid_quads(7, 5)), rtol=1e-10)
    np.testing.assert_allclose(L @ np.ones(len(V)), 0.0, atol=1e-12)
    assert np.all(np.linalg.eigvalsh(L.toarray()) > -1e-10)


def _area(V, Q):
    """Area of planar quads (half the cross product of the diagonals)."""
    P = V[Q]
    return 0.5 * np.linalg.norm(np.cross(P[:, 2] - P[:, 0], P[:, 3] - P[:, 1]), axis=1).sum()
