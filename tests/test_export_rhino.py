"""Round trip of gridshell.export.rhino: write a .3dm, read it back with rhino3dm."""
from __future__ import annotations

import numpy as np
import pytest
import rhino3dm
from render_cases import N, make_bundle, write_case

from gridshell.errors import InputError
from gridshell.export import export_3dm


def _by_layer(model):
    names = [layer.Name for layer in model.Layers]
    out = {n: [] for n in names}
    for obj in model.Objects:
        out[names[obj.Attributes.LayerIndex]].append(obj)
    return names, out


def test_3dm_round_trip(tmp_path):
    d = write_case(tmp_path / "gg", "GG")  # aligned.obj is degenerate (collapsed)
    out = export_3dm(d, tmp_path / "gg.3dm")
    model = rhino3dm.File3dm.Read(str(out))
    assert model.Settings.ModelUnitSystem == rhino3dm.UnitSystem.Meters
    names, objs = _by_layer(model)
    assert names == ["surface", "family 1", "family 3", "joints", "aligned"]
    assert {n: len(o) for n, o in objs.items()} == {
        "surface": 1, "family 1": N, "family 3": N, "joints": N * N, "aligned": 2 * N}

    b = make_bundle("GG")
    mesh = objs["surface"][0].Geometry
    assert isinstance(mesh, rhino3dm.Mesh)
    assert len(mesh.Vertices) == len(b.surface_V) and mesh.Faces.QuadCount == len(b.surface_F)
    assert objs["surface"][0].Attributes.GetUserString("kind") == "GG"

    for fam in (1, 3):
        for obj, lam in zip(objs[f"family {fam}"], b.net.family(fam)):
            a = obj.Attributes
            assert a.GetUserString("lamella_id") == str(lam.id)
            assert a.GetUserString("family") == str(fam)
            assert float(a.GetUserString("length_m")) == pytest.approx(lam.length, rel=1e-6)
            assert a.GetUserString("joints").split() == [str(j) for j in lam.joints]
            crv = obj.Geometry
            assert crv.PointCount == len(lam.axis)
            pts = [crv.Point(i) for i in range(crv.PointCount)]
            P = np.array([[q.X, q.Y, q.Z] for q in pts])
            np.testing.assert_allclose(P, lam.axis, atol=1e-12)

    ids = [int(o.Attributes.GetUserString("joint_id")) for o in objs["joints"]]
    assert ids == list(range(N * N))
    loc = objs["joints"][5].Geometry.Location
    np.testing.assert_allclose([loc.X, loc.Y, loc.Z], b.net.joints[5])
    al = objs["aligned"][0]
    assert al.Attributes.GetUserString("state") == "aligned"
    assert al.Geometry.PointCount == N
    assert not list(tmp_path.glob(".gg.3dm*"))  # atomic


def test_3dm_with_revolution_and_errors(tmp_path):
    b = make_bundle("GG")
    b.revolution_V, b.revolution_F = b.surface_V + [0, 0, 1], b.surface_F
    out = export_3dm(b, tmp_path / "rev.3dm")
    names, objs = _by_layer(rhino3dm.File3dm.Read(str(out)))
    assert names[-1] == "revolution" and len(objs["revolution"]) == 1
    with pytest.raises(InputError, match=".3dm"):
        export_3dm(b, tmp_path / "model.obj")
    with pytest.raises(InputError, match="not a design bundle"):
        export_3dm(tmp_path, tmp_path / "x.3dm")
