"""gridshell.api: one write for both pipelines (same signature, same layout), the public names,
the design check of fabricate, the deprecated writers."""
from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest
from tests.helpers.gg_cases import catenoid, revolution_grid
from tests.helpers.ncp_cases import torus
from tests.helpers.render_cases import make_bundle, write_case

import gridshell
from gridshell import api
from gridshell.design.bundle import Design, read_bundle
from gridshell.core.errors import InputError
from gridshell.geometry.grid import grid_quads

#: what every bundle holds, whatever its kind
COMMON = {"design.json", "net.obj", "aligned.obj", "axes.obj", "surface.obj", "report.json",
          "manifest.json", "sequence"}


def _names(d):
    return {p.name for p in d.iterdir()}


@pytest.fixture(scope="module")
def designs():
    P = revolution_grid(catenoid(1.0), np.linspace(-0.8, 0.8, 12), np.linspace(0.0, 1.5, 12))
    gg = api.design_gg((P.reshape(-1, 3), grid_quads(12, 12)), grid=(12, 12), n_lamellae=5,
                       frames=2)
    cnc = api.design_ncp(torus(), mode="cnc", curves=6, frames=2, samples=(24, 24),
                         collapse_samples=(300, 300), postopt_rounds=2)
    return {"GG": gg, "CNC": cnc}


def test_one_write_same_layout(designs, tmp_path):
    """write(path, design) for both kinds: a Design unpacks like the old pair; the files every
    kind shares are there for both; report.json holds the run's figures, not its arrays."""
    out = {}
    for kind, design in designs.items():
        assert isinstance(design, Design) and design.bundle.kind == kind
        bundle, report = design
        out[kind] = api.write(tmp_path / kind, design, render=False)
        assert COMMON <= _names(out[kind]), kind
        assert read_bundle(out[kind]).kind == kind
        rep = json.loads((out[kind] / "report.json").read_text())
        assert "sequence" not in rep and "state" not in rep
        frames = sorted((out[kind] / "sequence").glob("frame_*.obj"))
        assert len(frames) == 3                       # frames=2: deployed, one state, collapsed
        assert api.verify(out[kind])["ok"]
    assert json.loads((out["GG"] / "report.json").read_text())["revolution"]["method"] == \
        designs["GG"].report["revolution"]["method"]
    assert {"surface.json", "axes_r.npy", "aligned_r.npy"} <= _names(out["CNC"])
    assert "revolution.obj" in _names(out["GG"])
    # the pair, or the bundle with its report as a third argument, write the same
    b, r = designs["CNC"]
    again = api.write(tmp_path / "pair", b, r, render=False)
    assert _names(again) == _names(out["CNC"])
    assert (again / "net.obj").read_bytes() == (out["CNC"] / "net.obj").read_bytes()


def test_deprecated_writers_warn_and_write_the_same(designs, tmp_path):
    from gridshell.gg.pipeline import write_gg
    from gridshell.ncp.pipeline import write_ncp

    b, r = designs["GG"]
    with pytest.warns(DeprecationWarning, match="gridshell.write"):
        old = write_gg(tmp_path / "old", b, preview=False, sequence=r["sequence"])
    new = api.write(tmp_path / "new", (b, {"sequence": r["sequence"]}), render=False)
    assert _names(old) == _names(new)
    b, r = designs["CNC"]
    with pytest.warns(DeprecationWarning):
        old = write_ncp(tmp_path / "oldn", b, r, render=False)
    assert _names(old) == _names(api.write(tmp_path / "newn", designs["CNC"], render=False))


def test_write_errors_and_bare_gg_bundle(designs, tmp_path):
    b = make_bundle("CNC")
    with pytest.raises(InputError, match="report of design_ncp"):
        api.write(tmp_path / "x", b)
    with pytest.raises(InputError, match="expected a design"):
        api.write(tmp_path / "x", "not a design")
    out = api.write(tmp_path / "gg", designs["GG"].bundle, render=False, frames=2)
    assert len(list((out / "sequence").glob("frame_*.obj"))) == 3
    assert "report.json" not in _names(out)        # no run, no report
    assert not (api.write(tmp_path / "g0", designs["GG"].bundle, render=False, frames=0)
                / "sequence").exists()


def test_fabricate_refuses_a_failing_design_unless_forced(tmp_path):
    d = write_case(tmp_path / "gg", "GG")   # made-up figures: the files disagree with them
    with pytest.raises(InputError, match="fails its checks"):
        api.fabricate(d, tmp_path / "cut")
    assert not (tmp_path / "cut").exists()
    rep = api.fabricate(d, tmp_path / "cut", {"sheet": "600x400"}, force=True, plan=False)
    assert rep["n_sheets"] >= 1 and (tmp_path / "cut" / "sheet_01.dxf").is_file()
    bad = make_bundle("GG", metrics={"alignability": {"mean": 5.0, "max": 9.0}})
    with pytest.raises(InputError, match="Delta_a"):
        api.fabricate(bad, tmp_path / "cut2")


def test_public_names_and_lazy_import():
    for name in gridshell.__all__:
        assert getattr(gridshell, name) is getattr(api, name)
    assert gridshell.write is api.write and gridshell.Design is Design
    with pytest.raises(AttributeError):
        gridshell.no_such_thing
    code = "import gridshell, sys; print('gridshell.api' in sys.modules)"
    assert subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          check=True).stdout.strip() == "False"


def test_export_3dm_of_a_design(designs, tmp_path):
    import rhino3dm

    info = api.export_3dm(designs["GG"], tmp_path / "gg.3dm", sheets=False)
    lams = designs["GG"].bundle.net.lamellae
    assert info["strips"] == len(lams)
    model = rhino3dm.File3dm.Read(str(tmp_path / "gg.3dm"))
    assert model.Settings.ModelUnitSystem == rhino3dm.UnitSystem.Meters
    # a designed net's strips are smooth ribbons: a closed box of the lamella's length
    # (a frame that jumps along the axis crinkles the strip and adds area)
    w, t = info["strip_width_m"], info["strip_thickness_m"]
    names = [layer.Name for layer in model.Layers]
    strips = [o for o in model.Objects if names[o.Attributes.LayerIndex].startswith("family")]
    assert len(strips) == len(lams)
    by_id = {lam.id: lam for lam in lams}
    for o in strips:
        m = o.Geometry
        V = np.array([[p.X, p.Y, p.Z] for p in m.Vertices.ToPoint3dArray()])
        F = np.array([m.Faces[i][:3] for i in range(m.Faces.Count)])
        tri = V[F]
        area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]),
                                    axis=1).sum()
        L = by_id[int(o.Attributes.GetUserString("lamella_id"))].length
        assert area == pytest.approx(2 * L * (w + t) + 2 * w * t, rel=0.01)


def test_the_api_shows_the_real_parameters_of_what_it_runs():
    """design_gg, design_ncp and optimize_phlw spell out their pipeline's parameters (names,
    kinds and defaults the same); check_structure, simulate, export_3dm and write_outputs are
    the implementing functions themselves (one name, one result type)."""
    import inspect

    from gridshell.export import rhino
    from gridshell.gg import pipeline as gg
    from gridshell.ncp import phlw, pipeline as ncp
    from gridshell.workflow import outputs, structure

    def params(f):
        return [(p.name, p.kind, p.default) for p in inspect.signature(f).parameters.values()]

    for mine, theirs in ((api.design_gg, gg.design_gg), (api.design_ncp, ncp.design_ncp),
                         (api.optimize_phlw, phlw.optimize_phlw)):
        names = [p[0] for p in params(mine)]
        assert "args" not in names and "kwargs" not in names, mine.__name__
        want = params(theirs)
        if mine is api.design_ncp:      # the coverage gate around the pipeline adds its own
            want.insert(len(want) - 1, ("min_coverage", inspect.Parameter.KEYWORD_ONLY, None))
        assert params(mine) == want, mine.__name__
    assert [p[0] for p in params(api.design_gg)][:3] == ["target", "meridians", "grid"]
    assert api.check_structure is structure.check_structure
    assert api.simulate is structure.simulate
    assert api.export_3dm is rhino.export_3dm and gridshell.export_3dm is rhino.export_3dm
    assert api.write_outputs is outputs.write_outputs
    from gridshell.export import export_3dm

    assert export_3dm is rhino.export_3dm
    for f in (api.check_structure, api.simulate, api.export_3dm, api.write_outputs):
        names = [p[0] for p in params(f)]
        assert "kwargs" not in names and "options" not in names, f.__name__
    assert {"material", "width", "thickness", "scale"} <= set(
        inspect.signature(api.check_structure).parameters)


def test_check_structure_and_simulate_return_data(tmp_path):
    d = write_case(tmp_path / "gg", "GG")
    chk = api.check_structure(d, width=10, states=False, picture=False)
    assert chk.file == d / "structure.json" and chk.picture is None
    assert json.loads(chk.file.read_text())["section"]["width_mm"] == 10.0
    assert chk.ok == (chk.result["verdict"] == "ok") and chk.section.given("width")
    assert chk.material.name == "pp"
    sim = api.simulate(d, tmp_path / "eq", per_bay=1, scale="1:2")
    assert sim.out == tmp_path / "eq" and (sim.out / "equilibrium.json").is_file()
    assert sim.record["section"]["scale"] == 0.5 and sim.figures["supports"] >= 3


def test_export_3dm_and_write_3dm_are_one_function(tmp_path):
    from gridshell.export import rhino

    with pytest.warns(DeprecationWarning, match="export_3dm"):
        old = rhino.write_3dm
    assert old is rhino.export_3dm
    with pytest.raises(InputError, match="expected a design"):
        api.export_3dm(42, tmp_path / "x.3dm")
