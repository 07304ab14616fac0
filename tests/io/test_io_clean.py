"""Cleaning through pymeshlab (gridshell.io.clean): welds, duplicates, orientation; polygons
kept; exact coordinates."""
from __future__ import annotations

import numpy as np
from tests.helpers.io_cases import hill, soup

from gridshell.geometry.grid import grid_quads
from gridshell.io.clean import clean_mesh, coincident_vertices
from gridshell.geometry.meshfile import orientation_problem
from gridshell.geometry.quadmesh import _as_padded


def _faces_by_coordinates(V, F):
    """Faces as sorted tuples of their corner coordinates (order- and numbering-free)."""
    return sorted(tuple(sorted(map(tuple, np.round(V[f[f >= 0]], 12)))) for f in F)


def _signed(V, F):
    """Sum of face vector areas: the side the mesh faces."""
    tri = F[:, :3]
    return np.cross(V[tri[:, 1]] - V[tri[:, 0]], V[tri[:, 2]] - V[tri[:, 0]]).sum(axis=0)


def test_a_triangle_soup_is_welded_back_exactly():
    V, T = hill(12, 9)
    S, ST = soup(V, T)
    P, sz = _as_padded(ST)
    V2, P2, s2, rep = clean_mesh(S, P, sz, name="soup")
    assert rep.summary().startswith(f"welded {len(S)} -> {len(V)} vertices")
    assert len(V2) == len(V) and len(P2) == len(T) and np.all(s2 == 3)
    assert _faces_by_coordinates(V2, P2) == _faces_by_coordinates(V, T)
    # coordinates are the input's, bit for bit
    assert {tuple(r) for r in V2.tolist()} == {tuple(r) for r in V.tolist()}
    assert orientation_problem(P2, len(V2)) is None


def test_quads_stay_quads_and_get_a_consistent_orientation():
    R, C = 9, 7
    rng = np.random.default_rng(1)
    u, v = np.meshgrid(np.linspace(0, 3, R), np.linspace(0, 2, C), indexing="ij")
    V = np.stack([u, v, 0.2 * np.sin(u) * np.cos(v)], -1).reshape(-1, 3)
    Q = grid_quads(R, C)
    S, SQ = soup(V, Q)
    flip = rng.random(len(SQ)) < 0.3
    SQ[flip] = SQ[flip, ::-1]
    P, sz = _as_padded(SQ)
    V2, P2, s2, rep = clean_mesh(S, P, sz)
    assert np.all(s2 == 4) and P2.shape == (len(Q), 4)
    assert _faces_by_coordinates(V2, P2) == _faces_by_coordinates(V, Q)
    assert orientation_problem(P2, len(V2)) is None
    assert rep.flipped == int(flip.sum())          # the minority was flipped back
    assert _signed(V2, P2) @ _signed(V, Q) > 0     # the input's side kept


def test_duplicate_faces_and_unreferenced_vertices_go():
    V, T = hill(8, 6)
    V = np.vstack([V, [[100.0, 0, 0]]])            # unreferenced
    T2 = np.vstack([T, T[:5]])                     # five duplicates
    P, sz = _as_padded(T2)
    V2, P2, _, rep = clean_mesh(V, P, sz)
    assert len(P2) == len(T) and len(V2) == len(V) - 1
    assert rep.duplicate_faces == 5 and rep.unreferenced == 1
    assert "dropped 5 duplicate faces" in rep.summary()


def test_a_clean_mesh_is_untouched():
    V, T = hill(8, 6)
    P, sz = _as_padded(T)
    V2, P2, _, rep = clean_mesh(V, P, sz)
    assert V2 is V and P2 is P and rep.summary() == "nothing to clean"


def test_welding_tolerance_is_relative_to_the_edge_length():
    V, T = hill(8, 6, scale=1000.0)                # millimetres: edges ~ 1700 mm
    S, ST = soup(V, T)
    S = S + np.random.default_rng(2).uniform(-0.05, 0.05, S.shape)  # 0.05 mm of noise
    P, sz = _as_padded(ST)
    V2, _, _, rep = clean_mesh(S, P, sz)
    assert len(V2) == len(V) and rep.welded == len(S) - len(V)


def test_coincident_vertices_of_an_edge_are_a_degenerate_face_not_a_seam():
    V, T = hill(6, 5)
    assert coincident_vertices(V, 1e-6, _as_padded(T)[0]) == 0
    V = V.copy()
    a, b = T[0][:2]
    V[b] = V[a]                                    # an edge of zero length
    assert coincident_vertices(V, 1e-6) == 1
    assert coincident_vertices(V, 1e-6, _as_padded(T)[0]) == 0


def test_a_quad_grid_exported_face_by_face_welds_back_to_the_same_grid():
    from gridshell.geometry.grid import grid_from_quads

    R, C = 7, 5
    u, v = np.meshgrid(np.linspace(0, 3, R), np.linspace(0, 2, C), indexing="ij")
    V = np.stack([u, v, 0.2 * np.sin(u)], -1).reshape(-1, 3)
    S, SQ = soup(V, grid_quads(R, C))
    P, sz = _as_padded(SQ)
    V2, P2, _, _ = clean_mesh(S, P, sz)
    G = grid_from_quads(P2, len(V2))      # the gg target grid: same corner, same direction
    np.testing.assert_array_equal(V2[G].reshape(-1, 3), V)
