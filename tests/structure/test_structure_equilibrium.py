"""The deployed gridshell as elastic rods: the paper's geometric limit, statics, rest states
and ``gridshell simulate``."""
import json

import numpy as np
import pytest

from tests.helpers.fab_cases import make_bundle
from gridshell.core import manifest
from gridshell.design.bundle import write_bundle
from gridshell.cli.main import main
from gridshell.core.errors import InputError
from gridshell.structure import Section, get_material
from gridshell.structure.deployed import GRAVITY, Stiffness, build_model
from gridshell.structure.equilibrium import simulate

PP = get_material("pp")


@pytest.fixture(scope="module")
def demo_gg():
    """The demo's GG design (dome.obj, grid 16 x 16, 18 + 18 lamellae: 172 joints), in memory."""
    from gridshell import data
    from gridshell.gg.pipeline import design_gg

    bundle, _ = design_gg(data.path("dome.obj"), grid=(16, 16), n_lamellae=18, frames=2)
    return bundle


def test_without_wide_and_torsional_stiffness_the_equilibrium_is_the_geometric_design(demo_gg):
    """The paper's model: lamellae as curves through the joints (one rod element per net
    edge) with no resistance in the wide direction and none in torsion, boundary joints held:
    every joint stays within 0.1 % of the diagonal of its designed position (1:10, 1 mm pp;
    measured 0.015 %)."""
    eq = simulate(demo_gg, PP, Section(20, 1, 0.1), per_bay=1,
                  stiffness=Stiffness(strong=0.0, torsion=0.0))
    assert eq.result.converged
    assert eq.figures["deviation_max_pct"] < 0.1
    assert eq.energy["twist"] == 0.0
    assert eq.energy["bend"] > 0  # the strips are bent: a stressed state that holds


def test_reactions_carry_the_self_weight():
    """A small GG saddle held at its boundary under self-weight: the vertical reactions sum to
    the weight (density x area x length x g) within 1e-6, the horizontal ones to zero (the
    design's own prestress is self-equilibrated)."""
    b = make_bundle("GG", nr=4, nc=5)
    for t in (2.0, 0.5):
        eq = simulate(b, PP, Section(20, t, 1.0), gravity=True, per_bay=2)
        net = eq.model.network
        length = sum(r.lbar.sum() for r in net.rods)
        weight = PP.density * 0.02 * t * 1e-3 * length * GRAVITY
        assert eq.figures["weight_N"] == pytest.approx(weight, rel=1e-12)
        R = eq.reactions.sum(0)
        assert R[2] == pytest.approx(weight, rel=1e-6)
        assert np.abs(R[:2]).max() < 1e-6 * weight
        assert eq.figures["deviation_max_pct"] > 0


def test_cnc_strips_rest_on_the_collapse_circle():
    """CNC lamellae are cut along the collapse circle of radius R: their rest curvature is
    about the strong axis only, 1/(R scale) on the model (0.5 %: the discrete curvature
    2 tan(phi/2) over the Voronoi length), and none about the weak one."""
    R = 1.3
    b = make_bundle("CNC", R=R)
    m = build_model(b, PP, Section(20, 1, 0.5))
    net = m.network
    d = net.bend_data()
    k_strong = net.wbar[:, 0] / (0.5 * d.lbar)
    assert np.allclose(np.abs(k_strong), 1.0 / (R * 0.5), rtol=5e-3)
    assert np.abs(net.wbar[:, 1]).max() < 1e-12
    assert m.rest.startswith("arcs of the collapse circle")


def test_ncp_strips_rest_on_their_stretch_of_the_collapse_curve():
    """A general NCP bundle collapses onto the parabola y = a x^2; lamella i lies on it from
    arc length offset + step i. The rest strong-axis curvature at every interior node is the
    parabola's, 2a / (1 + 4a^2 x^2)^(3/2), at the node's place on it (1.5 %: a vertex curvature averages over two chords of a
    curvature that grows 5-fold along the strip)."""
    from tests.helpers.fab_cases import PARABOLA_A, parabola_at

    b = make_bundle("NCP")
    m = build_model(b, PP, Section(20, 1, 1.0))
    net = m.network
    d = net.bend_data()
    k_rest = np.abs(net.wbar[:, 0] / (0.5 * d.lbar))
    start = 0
    for lid, nodes in zip(m.lamella_ids, m.lamella_nodes):
        lam = next(lm for lm in b.net.lamellae if lm.id == lid)
        P = net.X[nodes]
        s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(P, axis=0), axis=1))])
        c = np.interp(s, lam.joint_s, b.collapse_s[lid])
        # a vertex's curvature belongs between its edges' midpoints
        x = parabola_at(0.25 * (c[:-2] + 2 * c[1:-1] + c[2:]))[:, 0]
        expect = 2 * PARABOLA_A / (1 + 4 * PARABOLA_A ** 2 * x ** 2) ** 1.5
        got = k_rest[start:start + len(nodes) - 2]
        assert np.allclose(got, expect, rtol=1.5e-2), lid
        start += len(nodes) - 2
    assert m.rest == "pieces of the collapse curve"


def test_supports_must_hold_the_structure():
    b = make_bundle("GG", nr=4, nc=5)
    with pytest.raises(InputError, match="at least 3"):
        build_model(b, PP, Section(20, 1, 1.0), supports=[0, 1])
    flat = make_bundle("GG", nr=4, nc=5, c=0.0, twist=0.0)
    with pytest.raises(InputError, match="one line"):
        build_model(flat, PP, Section(20, 1, 1.0), supports=[0, 1, 2, 3])
    with pytest.raises(InputError, match="joint indices"):
        build_model(b, PP, Section(20, 1, 1.0), supports=[0, 5, 999])


@pytest.mark.slow
def test_simulate_from_the_cli(tmp_path, capsys):
    d = tmp_path / "cnc"
    write_bundle(d, make_bundle("CNC", R=1.3))
    code = main(["simulate", str(d), "--material", "pp", "--width", "20", "--thickness", "1",
                 "--scale", "1:2", "--gravity", "-q", "--json"])
    assert code == 0
    out = json.loads(capsys.readouterr().out)
    assert out["ok"] and out["figures"]["converged"]
    eqdir = d / "equilibrium"
    for f in ("equilibrium.obj", "axes.obj", "equilibrium.json", "equilibrium.png"):
        assert (eqdir / f).stat().st_size > 0, f
    rec = json.loads((eqdir / "equilibrium.json").read_text())
    assert len(rec["reactions_N"]) == len(rec["supports"]) >= 3
    assert rec["figures"]["weight_N"] == pytest.approx(sum(r[2] for r in rec["reactions_N"]),
                                                        rel=1e-6)
    assert "equilibrium" in manifest.read(d)["outputs"]
    # again: its own output is replaced; user joints as supports
    assert main(["simulate", str(d), "--supports", "0,4,15,19", "-q"]) == 0
    rec = json.loads((eqdir / "equilibrium.json").read_text())
    assert rec["supports"] == [0, 4, 15, 19]


@pytest.mark.parametrize("args, message", [
    (["--supports", "0,x"], "joint indices"),
    (["--supports", "0,1"], "at least 3"),
    (["--material", "unobtainium"], "unknown material"),
    (["--thickness", "-1"], "thickness"),
    (["--scale", "ten"], "scale"),
])
def test_bad_input_is_one_line_and_writes_nothing(tmp_path, capsys, args, message):
    d = tmp_path / "gg"
    write_bundle(d, make_bundle("GG", nr=3, nc=3))
    assert main(["simulate", str(d), *args, "-q"]) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err
    assert not (d / "equilibrium").exists()
