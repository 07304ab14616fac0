"""The alignment states of a GG vase (an exact surface of revolution) at the defaults (20 x 1 mm
polypropylene at 1:10): measured on the physical path's dense strips, every state bends the
strips about their weak axis only (strong-axis curvature below 5 % of the weak one), the
sequence's utilisation is at most 1.5 times the deployed one and changes smoothly from state
to state (no step above 20 % of the largest), and the verdict judges every state."""
import numpy as np
import pytest

from gridshell.api import design_gg, write
from gridshell.geometry.meshfile import write_mesh
from gridshell.structure.check import check_bundle
from gridshell.structure.materials import get_material
from gridshell.structure.section import Section


def _vase(path, R=31, C=25):
    z = np.linspace(0, 1.5, R)
    ph = np.linspace(-1.0, 1.0, C)
    r = 1 + 0.2 * np.sin(2.5 * z + 0.5)
    V = np.stack([r[:, None] * np.cos(ph)[None, :], r[:, None] * np.sin(ph)[None, :],
                  np.broadcast_to(z[:, None], (R, C))], -1).reshape(-1, 3)
    F = np.array([[i * C + j, i * C + j + 1, (i + 1) * C + j + 1, (i + 1) * C + j]
                  for i in range(R - 1) for j in range(C - 1)])
    write_mesh(path, V, F)


@pytest.fixture(scope="module")
def vase_check(tmp_path_factory):
    d = tmp_path_factory.mktemp("vase")
    _vase(d / "vase.obj")
    out = write(d / "bundle", design_gg(d / "vase.obj"), render=False)
    res = check_bundle(out, get_material("pp"), Section(20.0, 1.0, 0.1))
    return out, res


def test_vase_states_are_the_physical_path(vase_check):
    out, res = vase_check
    st = res["states"]
    assert st["physical_path"] and (out / "sequence" / "strips.npz").is_file()
    assert st["approximate"] == [] and st["unresolved"] == []
    frames = st["frames"]
    assert len(frames) == 13
    for f in frames:
        if f["max_weak_curvature_per_m"] > 1e-6:       # not the straight bundle (round-off)
            assert f["max_strong_curvature_per_m"] < 0.05 * f["max_weak_curvature_per_m"], f
        assert f["length_error"] < 1e-3


def test_vase_sequence_utilisation_smooth_and_bounded(vase_check):
    _, res = vase_check
    u_dep = res["max_utilisation_deployed"]
    u = np.array([f["max_utilisation"] for f in res["states"]["frames"]])
    assert res["states"]["sequence_max_utilisation"] <= 1.5 * u_dep
    assert np.max(np.abs(np.diff(u))) <= 0.2 * u.max()
    assert res["verdict"] == "ok"
    assert abs(u[0] - u_dep) <= 0.05 * u_dep       # the dense deployed check agrees


def test_an_intermediate_state_is_the_strips_own_equilibrium(vase_check):
    """Issue 28, item 2: state t = 0.5 of the path as rods of the 20 x 1 mm strip as cut
    (straight) with its joints held: the strips stay within 2 % of the diagonal of the state
    (measured 0.18 %). The same check catches a state that is not the strips' own: the strips
    bulged off their path between the joints by 3 % of the diagonal spring back."""
    from gridshell.design.bundle import read_bundle
    from gridshell.structure.pathcheck import state_equilibrium
    from gridshell.structure.states import read_strips

    out, _ = vase_check
    b = read_bundle(out)
    strips = read_strips(out, len(b.net.joints), len(b.net.lamellae))
    f = int(np.argmin(np.abs(strips["t"] - 0.5)))
    pp, section = get_material("pp"), Section(20.0, 1.0, 0.1)
    ok = state_equilibrium(b, strips, f, pp, section)
    assert ok["converged"] and ok["deviation_max_pct"] < 2.0
    assert ok["held_joints"] == len(b.net.joints)
    diag = float(np.linalg.norm(np.ptp(b.net.joints, axis=0)))
    bent = dict(strips, X=strips["X"].copy())
    for lid in np.unique(strips["lamella"]):
        m = np.flatnonzero(strips["lamella"] == lid)
        at = np.flatnonzero(strips["joint"][m] >= 0)
        for a, c in zip(at[:-1], at[1:]):
            k = np.arange(a, c + 1)
            bump = np.sin(np.pi * (k - a) / (c - a))[:, None]
            bent["X"][f, m[k]] += 0.03 * diag * bump * strips["N"][f, m[k]]
    moved = state_equilibrium(b, bent, f, pp, section)
    assert moved["deviation_max_pct"] > 2.0


def test_simulate_state_prints_the_path_check(vase_check, capsys):
    from gridshell.cli.main import main

    out, _ = vase_check
    assert main(["simulate", str(out), "--state", "6", "-o", str(out / "eq6")]) == 0
    text = capsys.readouterr().out
    assert "path check" in text and "frame_006" in text and "joints held" in text
    assert main(["simulate", str(out), "--state", "99", "-o", str(out / "eq99")]) == 2
    assert "the path has states 0 to 12" in capsys.readouterr().err
    assert not (out / "eq99").exists()
