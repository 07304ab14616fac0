"""The .3dm export's bulk mesh construction gives the mesh that adding vertices and faces one
by one gives (same double-precision vertices, same faces in the same order)."""
from __future__ import annotations

import numpy as np
import pytest
import rhino3dm

from gridshell.errors import InputError
from gridshell.export import rhino_geometry as geo


def _one_by_one(V, F):
    """The straightforward construction (the code before the bulk path)."""
    m = rhino3dm.Mesh()
    m.Vertices.UseDoublePrecisionVertices = True
    for x, y, z in np.asarray(V, float).tolist():
        m.Vertices.AddPoint3d(x, y, z)
    for f in np.asarray(F, np.int64).tolist():
        f = [i for i in f if i >= 0]
        m.Faces.AddFace(*f)
    m.Normals.ComputeNormals()
    m.Compact()
    return m


def _arrays(m):
    V = np.array([[p.X, p.Y, p.Z] for p in
                  (m.Vertices.Point3dAt(i) for i in range(len(m.Vertices)))])
    F = np.array([list(m.Faces[i]) for i in range(m.Faces.Count)])
    N = np.array([[n.X, n.Y, n.Z] for n in (m.Normals[i] for i in range(len(m.Normals)))])
    return V, F, N


@pytest.mark.parametrize("shape", ["tri", "quad", "mixed"])
def test_bulk_mesh_equals_one_by_one(shape):
    rng = np.random.default_rng(3)
    V = rng.normal(size=(60, 3)) * 1e3 + 1e-7 * rng.normal(size=(60, 3))  # float64 digits
    if shape == "tri":
        F = rng.integers(0, 60, (80, 3))
    elif shape == "quad":
        F = rng.integers(0, 60, (80, 4))
    else:
        F = rng.integers(0, 60, (80, 4))
        F[::3, 3] = -1
        F[1::6, 1] = -1      # a padding index not at the end (rows 1 mod 3)
    fast, slow = geo.mesh(V, F), _one_by_one(V, F)
    (Vf, Ff, Nf), (Vs, Fs, Ns) = _arrays(fast), _arrays(slow)
    assert np.array_equal(Vf, Vs) and np.array_equal(Ff, Fs) and np.array_equal(Nf, Ns)
    # double precision kept: every vertex left after Compact() is one of V, bit for bit
    assert (Vf[:, None, :] == V[None, :, :]).all(axis=2).any(axis=1).all()
    assert fast.Faces.Count == len(F) and fast.Faces.QuadCount == slow.Faces.QuadCount


def test_bulk_mesh_rejects_faces_that_are_not_triangles_or_quads():
    V = np.zeros((5, 3))
    with pytest.raises(InputError, match="2 corners"):
        geo.mesh(V, np.array([[0, 1, -1, -1]]))
    with pytest.raises(InputError, match="5 corners"):
        geo.mesh(V, np.array([[0, 1, 2, 3, 4]]))
