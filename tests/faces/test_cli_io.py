"""What users bring, through the commands (issue 18, items 1-3): units, unwelded meshes, Rhino
.3dm input. Inputs are built in the tests (rhino3dm writes the .3dm files); every comparison
is against the same design from a metre OBJ."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from tests.helpers.io_cases import (hill, hill_ctrl, rhino_mesh, rhino_nurbs, soup, write_3dm, write_obj_text,
                      write_ply_soup)

from gridshell.design.bundle import read_bundle
from gridshell.cli.main import main
from gridshell.geometry.grid import grid_quads
from gridshell.geometry.meshfile import write_mesh
from gridshell.geometry.quadmesh import bbox_diagonal

rhino3dm = pytest.importorskip("rhino3dm")

# the default rounds and polish: a design stopped at an iteration limit carries an ulp of its
# input into ~1e-5 of the diagonal, one whose figures stopped it into < 1e-6 (measured 5e-7)
GG = ["--grid", "10", "8", "--lamellae", "4", "--frames", "0", "--no-preview",
      "--allow-unconverged", "-q"]


def gg(capsys, *argv) -> tuple[int, dict | None, str]:
    code = main(["gg", *map(str, argv), *GG, "--json"])
    cap = capsys.readouterr()
    return code, (json.loads(cap.out) if cap.out.strip() else None), cap.err


def lengths(bundle: Path) -> np.ndarray:
    d = json.loads((bundle / "design.json").read_text())
    return np.array([r["length"] for r in d["lamellae"]])


@pytest.fixture(scope="module")
def metre_design(tmp_path_factory):
    """The hill as a welded metre OBJ and its GG design (the reference of every comparison)."""
    root = tmp_path_factory.mktemp("metre")
    V, T = hill()
    target = write_mesh(root / "hill_m.obj", V, T) or root / "hill_m.obj"
    assert main(["gg", str(target), "-o", str(root / "gg"), *GG]) == 0
    return {"V": V, "T": T, "bundle": root / "gg", "diag": bbox_diagonal(V)}


def test_millimetre_obj_refused_without_units_then_the_same_design(tmp_path, capsys,
                                                                    metre_design):
    V, T = metre_design["V"], metre_design["T"]
    mm = write_obj_text(tmp_path / "hill_mm.obj", V * 1000.0, T)
    # without --units: exit 2, both readings named, nothing written
    code, payload, err = gg(capsys, mm, "-o", tmp_path / "no")
    assert code == 2 and payload["error"] in ("InputError", "MeshError")
    line = err.strip().splitlines()[-1]
    assert "km as metres" in line and "m as millimetres" in line and "--units" in line
    assert not (tmp_path / "no").exists()
    # with --units mm: the metre design, joints within 1e-6 of the diagonal
    code, payload, err = gg(capsys, mm, "-o", tmp_path / "mm", "--units", "mm")
    assert code == 0, err
    ref, got = read_bundle(metre_design["bundle"]), read_bundle(tmp_path / "mm")
    assert np.abs(got.net.joints - ref.net.joints).max() < 1e-6 * metre_design["diag"]
    assert got.units.name == "mm" and got.units.metres_per_unit == 0.001
    d = json.loads((tmp_path / "mm" / "design.json").read_text())
    assert d["units"] == {"name": "mm", "metres_per_unit": 0.001}
    assert "units mm" in payload["input"]
    # verify reads the target in its unit: the same deviation as the metre design's
    assert main(["verify", str(tmp_path / "mm")]) == 0
    mm_dev = json.loads(capsys.readouterr().out)["deviation"]
    assert main(["verify", str(metre_design["bundle"])]) == 0
    m_dev = json.loads(capsys.readouterr().out)["deviation"]
    assert abs(mm_dev["max"] - m_dev["max"]) < 1e-4  # % of the diagonal: 1e-6 of it


def test_metre_bundles_record_metres(metre_design):
    d = json.loads((metre_design["bundle"] / "design.json").read_text())
    assert d["units"] == {"name": "m", "metres_per_unit": 1.0}
    assert d["params"]["input"]["units_source"] == "default"


def test_3dm_mesh_in_millimetres(tmp_path, capsys, metre_design):
    V, T = metre_design["V"], metre_design["T"]
    f = write_3dm(tmp_path / "hill_mm.3dm", [(rhino_mesh(V * 1000.0, T), "hill", "Shell")],
                  units="mm")
    code, payload, err = gg(capsys, f, "-o", tmp_path / "gg")
    assert code == 0, err
    ref, got = lengths(metre_design["bundle"]), lengths(tmp_path / "gg")
    assert got.shape == ref.shape
    assert np.abs(got / ref - 1).max() < 1e-3            # within 0.1 %
    assert read_bundle(tmp_path / "gg").units.name == "mm"
    assert "units mm (the file's)" in payload["input"]


def test_3dm_nurbs_in_metres_is_sampled_for_gg(tmp_path, capsys):
    ns = rhino_nurbs(hill_ctrl(6, 5))
    f = write_3dm(tmp_path / "roof.3dm", [(ns, "roof", "Shell")], units="m")
    # the same surface as a metre OBJ, sampled by rhino3dm itself on the grid gg samples
    from gridshell.io.read import read_input, surface_grid

    R, C = surface_grid(read_input(f).surface)
    g = rhino3dm.File3dm.Read(str(f)).Objects[0].Geometry
    (u0, u1), (v0, v1) = (g.Domain(0).T0, g.Domain(0).T1), (g.Domain(1).T0, g.Domain(1).T1)
    P = np.array([[[g.PointAt(u, v).X, g.PointAt(u, v).Y, g.PointAt(u, v).Z]
                   for v in np.linspace(v0, v1, C)] for u in np.linspace(u0, u1, R)])
    write_mesh(tmp_path / "roof.obj", P.reshape(-1, 3), grid_quads(R, C))
    code, _, err = gg(capsys, tmp_path / "roof.obj", "-o", tmp_path / "obj")
    assert code == 0, err
    code, payload, err = gg(capsys, f, "-o", tmp_path / "3dm")
    assert code == 0, err
    ref, got = lengths(tmp_path / "obj"), lengths(tmp_path / "3dm")
    assert got.shape == ref.shape and np.abs(got / ref - 1).max() < 1e-3
    assert "NURBS surface" in payload["input"]


def test_3dm_nurbs_is_the_initial_bspline_of_phlw(tmp_path, capsys):
    ns = rhino_nurbs(hill_ctrl(7, 6, scale=100.0))   # centimetres
    f = write_3dm(tmp_path / "roof_cm.3dm", [(ns, "roof", "Shell")], units="cm")
    code = main(["phlw", str(f), "-o", str(tmp_path / "p"), "--samples", "7", "7", "--outer",
                 "1", "--max-iter", "2", "--check-samples", "10", "10", "--allow-unconverged",
                 "-q"])
    capsys.readouterr()
    assert code == 0
    report = json.loads((tmp_path / "p" / "report.json").read_text())
    assert report["units"] == {"name": "cm", "metres_per_unit": 0.01}
    assert report["control_points"] == [7, 6] and report["degree"] == [3, 3]
    surf = json.loads((tmp_path / "p" / "surface.json").read_text())
    C = np.asarray(surf["ctrl"] if "ctrl" in surf else surf["control_points"], float)
    assert np.abs(np.ptp(C.reshape(-1, 3)[:, 0]) - 12.0) < 0.5  # metres, near the input


def test_three_objects_listed_then_picked(tmp_path, capsys, metre_design):
    V, T = metre_design["V"], metre_design["T"]
    objs = [(rhino_mesh(V, T), "roof mesh", "Meshes"),
            (rhino_nurbs(hill_ctrl()), "roof nurbs", "Surfaces"),
            (rhino3dm.Brep.CreateFromSurface(rhino_nurbs(hill_ctrl(5, 4))), "roof brep",
             "Breps")]
    f = write_3dm(tmp_path / "three.3dm", objs, units="m")
    code, payload, err = gg(capsys, f, "-o", tmp_path / "none")
    assert code == 2 and len(err.strip().splitlines()) == 1
    for name in ("roof mesh", "roof nurbs", "roof brep", "--object"):
        assert name in err
    code, payload, err = gg(capsys, f, "-o", tmp_path / "picked", "--object", "roof mesh")
    assert code == 0, err
    ref, got = lengths(metre_design["bundle"]), lengths(tmp_path / "picked")
    assert np.abs(got / ref - 1).max() < 1e-3


@pytest.mark.parametrize("fmt", ["obj", "ply"])
def test_a_triangle_soup_gives_the_welded_design(tmp_path, capsys, metre_design, fmt):
    V, T = metre_design["V"], metre_design["T"]
    if fmt == "obj":   # a modeller's OBJ: six decimals, every triangle its own vertices
        f = write_obj_text(tmp_path / "soup.obj", *soup(V, T), fmt="%.6f")
    else:              # an STL converted to PLY: float32, unwelded
        f = write_ply_soup(tmp_path / "soup.ply", V, T)
    code, payload, err = gg(capsys, f, "-o", tmp_path / "gg")
    assert code == 0, err
    assert f"welded {3 * len(T)} -> {len(V)} vertices" in payload["input"]
    ref, got = read_bundle(metre_design["bundle"]), read_bundle(tmp_path / "gg")
    assert np.abs(got.net.joints - ref.net.joints).max() < 1e-4 * metre_design["diag"]
    assert np.abs(lengths(tmp_path / "gg") / lengths(metre_design["bundle"]) - 1).max() < 1e-3


def test_the_hill_as_a_soup_without_cleaning_says_weld(tmp_path, capsys, metre_design):
    f = write_obj_text(tmp_path / "soup.obj", *soup(metre_design["V"], metre_design["T"]))
    code, payload, err = gg(capsys, f, "-o", tmp_path / "gg", "--no-clean")
    line = err.strip().splitlines()[-1]
    assert code == 2 and "not a disk" in line and "unwelded" in line and "--no-clean" in line
    assert not (tmp_path / "gg").exists()


def test_a_non_disk_that_is_welded_says_it_is_not_a_soup(tmp_path, capsys):
    V = np.random.default_rng(0).normal(size=(30, 3))
    F = np.arange(30).reshape(10, 3)
    f = write_obj_text(tmp_path / "pieces.obj", V, F)
    code, payload, err = gg(capsys, f, "-o", tmp_path / "gg")
    assert code == 2 and "10 connected components" in err and "not an unwelded mesh" in err
