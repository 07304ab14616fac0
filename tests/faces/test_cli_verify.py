"""Round trip through the CLI on real GG designs of surfaces the samples do not hold: ``gg``
writes a bundle, ``verify`` passes it, ``fabricate`` (the 1:10 polypropylene defaults, no
``--force``) cuts it, ``render`` adds to it, ``gg`` replaces its own output; a moved joint
makes ``verify`` fail."""
from __future__ import annotations

import json

import numpy as np
import pytest

from gridshell.core import manifest
from gridshell.cli.main import main
from gridshell.geometry.grid import grid_quads
from gridshell.geometry.meshfile import read_configuration, write_mesh

GG = ["--no-preview", "--frames", "0", "-q"]


def _grid(f, R, C):
    s, t = np.meshgrid(np.linspace(-1, 1, R), np.linspace(-1, 1, C), indexing="ij")
    return np.stack(f(s, t), -1).reshape(-1, 3), grid_quads(R, C)


SURFACES = {  # a catenoid patch (a surface of revolution) and a 0.5 m model of a shallow dome
    "catenoid": lambda: _grid(lambda s, t: (np.cosh(0.6 * s) * np.cos(1.2 * t),
                                            np.cosh(0.6 * s) * np.sin(1.2 * t), 0.6 * s), 12, 12),
    "dome": lambda: _grid(lambda s, t: (0.25 * s, 0.25 * t, -0.05 * (s ** 2 + t ** 2)), 12, 12),
}


@pytest.mark.parametrize("name", list(SURFACES))
def test_gg_bundle_passes_its_own_tools(tmp_path, capsys, name):
    target, b = tmp_path / f"{name}.obj", tmp_path / "design"
    write_mesh(target, *SURFACES[name]())
    assert main(["gg", str(target), "-o", str(b), *GG]) == 0
    capsys.readouterr()
    assert main(["verify", str(b)]) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["ok"] and res["mismatch"] == [] and res["problems"] == []
    assert all(g["ok"] for g in res["gates"]) and len(res["gates"]) == 4
    assert main(["fabricate", str(b), "-q", "--no-plan"]) == 0
    assert (b / "fabrication" / "cutlist.csv").is_file()
    assert main(["render", str(b), "--no-sequence", "--size", "100", "100", "-q"]) == 0
    m = manifest.read(b)
    assert "render.png" in m["files"] and m["outputs"] == ["fabrication"]
    capsys.readouterr()
    # a new design would delete what was made from this one: refused before any work
    before = (b / "design.json").read_bytes()
    assert main(["gg", str(target), "-o", str(b), *GG]) == 5
    err = capsys.readouterr().err
    assert "fabrication" in err and "render.png" in err and "another -o" in err
    assert (b / "fabrication" / "cutlist.csv").is_file() and (b / "render.png").is_file()
    assert (b / "design.json").read_bytes() == before
    # a joint moved by 5 % of the span: the recomputed figures fail or disagree
    text = (b / "net.obj").read_text().splitlines()
    V = read_configuration(b / "net.obj")[0]
    i = next(k for k, ln in enumerate(text) if ln.startswith("v "))
    x, y, z = (V[len(V) // 2] + 0.05 * np.ptp(V, axis=0).max()).tolist()
    j = i + len(V) // 2
    text[j] = f"v {x!r} {y!r} {z!r}"
    (b / "net.obj").write_text("\n".join(text) + "\n")
    code = main(["verify", str(b)])
    cap = capsys.readouterr()
    assert code in (2, 4), cap.err
    res = json.loads(cap.out)
    assert not res["ok"] and "alignability" in res["mismatch"]
    assert main(["fabricate", str(b), "-o", str(tmp_path / "fab"), "-q", "--no-plan"]) == 2
    assert not (tmp_path / "fab").exists()


def test_verify_recomputes_the_nets_fidelity_from_the_target_file(tmp_path, capsys):
    """The dome's net sits on the dome: verify measures it again from dome.obj as design.json
    has it; the dome raised by 1 % of its diagonal moves every joint ~1 % away (the dome is
    shallow: its normal is nearly z) and verify says the files disagree."""
    target, b = tmp_path / "dome.obj", tmp_path / "design"
    V, F = SURFACES["dome"]()
    write_mesh(target, V, F)
    assert main(["gg", str(target), "-o", str(b), *GG]) == 0
    capsys.readouterr()
    stored = json.loads((b / "design.json").read_text())["metrics"]["fidelity"]
    assert main(["verify", str(b)]) == 0
    f = json.loads(capsys.readouterr().out)["fidelity"]
    assert f["deviation_mean"] == pytest.approx(stored["deviation_mean"], rel=1e-3)
    assert f["coverage"] == pytest.approx(stored["coverage"], abs=0.5) and f["coverage"] > 60
    diag = float(np.linalg.norm(np.ptp(V, axis=0)))
    write_mesh(target, V + [0.0, 0.0, 0.01 * diag], F)
    assert main(["verify", str(b)]) in (2, 4)
    res = json.loads(capsys.readouterr().out)
    assert "fidelity" in res["mismatch"]
    assert res["fidelity"]["deviation_mean"] == pytest.approx(1.0, abs=0.1)

