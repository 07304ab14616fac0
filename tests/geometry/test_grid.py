"""Tests of gridshell.geometry.grid: grid faces, grid recovery from any vertex order, polylines."""
from __future__ import annotations

import numpy as np
import pytest

from gridshell.core.errors import MeshError
from gridshell.geometry.grid import grid_from_quads, grid_polylines, grid_quads
from gridshell.geometry.quadmesh import QuadMesh


def planar_grid(R: int, C: int) -> tuple[np.ndarray, np.ndarray]:
    """Grid in the xy-plane, j along x, i along y."""
    i, j = np.meshgrid(np.arange(R), np.arange(C), indexing="ij")
    V = np.stack([j.ravel() * 1.0, i.ravel() * 1.0, np.zeros(R * C)], axis=1)
    return V, grid_quads(R, C)


def test_grid_quads_shape_and_orientation():
    V, F = planar_grid(3, 5)
    assert F.shape == (8, 4) and F.dtype == np.int64
    assert F[0].tolist() == [0, 1, 6, 5]
    np.testing.assert_allclose(QuadMesh(V, F).face_normals, [[0, 0, 1]] * 8)


def test_grid_quads_rejects_tiny():
    with pytest.raises(MeshError, match="at least 2 x 2"):
        grid_quads(1, 4)


@pytest.mark.parametrize("R,C", [(2, 2), (3, 7), (6, 4)])
def test_identity_recovery(R, C):
    np.testing.assert_array_equal(grid_from_quads(grid_quads(R, C), R * C),
                                  np.arange(R * C).reshape(R, C))


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_recovery_permuted(seed):
    rng = np.random.default_rng(seed)
    R, C = 5, 8
    F = grid_quads(R, C)
    perm = rng.permutation(R * C)  # new index of old vertex
    Fp = perm[F]
    Fp = Fp[rng.permutation(len(Fp))]
    Fp = np.stack([np.roll(f, rng.integers(4)) for f in Fp])  # rotate face starts
    G = grid_from_quads(Fp, R * C)
    assert sorted(G.shape) == [R, C]
    assert np.array_equal(np.sort(G.ravel()), np.arange(R * C))
    # neighbours in G are neighbours in the original grid
    inv = np.argsort(perm)
    orig = inv[G]
    oi, oj = np.divmod(orig, C)
    steps = np.abs(np.diff(oi, axis=1)) + np.abs(np.diff(oj, axis=1))
    assert np.all(steps == 1)
    # the faces are those of G
    Q = G.ravel()[grid_quads(*G.shape)]
    canon = lambda A: {tuple(np.roll(f, -int(np.argmin(f)))) for f in A}
    assert canon(Q) == canon(Fp)


def test_quadmesh_grid_cached():
    V, F = planar_grid(3, 4)
    M = QuadMesh(V, F)
    assert M.grid() is M.grid()
    assert M.grid().shape == (3, 4)


def test_cylinder_is_not_grid():
    R, C = 4, 6
    G = np.arange(R * C).reshape(R, C)
    Gc = np.concatenate([G, G[:, :1]], axis=1)
    F = np.stack([Gc[:-1, :-1], Gc[:-1, 1:], Gc[1:, 1:], Gc[1:, :-1]], axis=-1).reshape(-1, 4)
    with pytest.raises(MeshError, match="not a structured quad grid"):
        grid_from_quads(F, R * C)


def test_l_shape_is_not_grid():
    F = grid_quads(4, 4)
    F = np.delete(F, [8], axis=0)  # remove the corner face (i=2, j=2)
    with pytest.raises(MeshError, match="not a structured quad grid"):
        grid_from_quads(F, 16)


def test_extraordinary_vertex_is_not_grid():
    # a 3-valent interior vertex: three quads around a centre (hexagon split in 3)
    F = np.array([[0, 1, 2, 3], [0, 3, 4, 5], [0, 5, 6, 1]])
    with pytest.raises(MeshError, match="remesh it as a grid"):
        grid_from_quads(F, 7)


def test_grid_polylines():
    G = np.arange(12).reshape(3, 4)
    rows, cols = grid_polylines(G)
    assert len(rows) == 3 and len(cols) == 4
    assert rows[1].tolist() == [4, 5, 6, 7]
    assert cols[2].tolist() == [2, 6, 10]
