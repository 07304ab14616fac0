"""Bad input through the CLI: every case exits with its documented code (2 bad input, 3 no net,
4 no convergence, 5 output not writable), prints one line on stderr naming the problem, no
traceback, ``{"ok": false, ...}`` with ``--json``, and leaves no partial output behind.

Meshes are tiny and options small so that the whole file runs in seconds.
"""
from __future__ import annotations

import json
import os
import shutil
import struct
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from tests.helpers.gg_cases import helicoid_grid
from tests.helpers.ncp_cases import torus_grid

from gridshell.geometry.bspline import fit_grid
from gridshell.cli.main import main
from gridshell.geometry.grid import grid_quads
from gridshell.geometry.meshfile import write_mesh

# --------------------------------------------------------------------------- small options

GG = ["--grid", "6", "6", "--lamellae", "3", "--no-preview"]
PHLW = ["--ctrl", "5", "5", "--degree", "3", "3", "--samples", "7", "7", "--outer", "1",
        "--max-iter", "3", "--check-samples", "10", "10"]
NCP = ["--curves", "4", "--samples", "12", "12", "--collapse-samples", "100", "100",
       "--frames", "2", "--rounds", "1", "--levelset-ctrl", "6", "6", "--no-render",
       "--phlw-ctrl", "5", "5", "--phlw-samples", "7", "7", "--phlw-outer", "1",
       "--phlw-max-iter", "3"]
MESH_OPTIONS = {"gg": GG, "phlw": PHLW, "ncp": NCP}
CLASSES = {2: ("InputError", "MeshError", "UsageError"), 3: ("NoNetError",), 4: ("ConvergenceError",),
           5: ("OutputError",)}


# --------------------------------------------------------------------------- mesh builders

def _obj(V, F) -> str:
    text = "".join(f"v {x!r} {y!r} {z!r}\n" for x, y, z in np.asarray(V, float).tolist())
    return text + "".join("f " + " ".join(str(i + 1) for i in f) + "\n" for f in F)


def _grid(f, R=6, C=6):
    """Vertices ``f(s, t)`` on an ``R x C`` grid over [0, 1]^2 and its quads."""
    s, t = np.meshgrid(np.linspace(0, 1, R), np.linspace(0, 1, C), indexing="ij")
    return np.stack(f(s, t), -1).reshape(-1, 3), grid_quads(R, C)


def _saddle(scale=1.0):
    return _grid(lambda s, t: (scale * (2 * s - 1), scale * (2 * t - 1),
                               0.3 * scale * ((2 * s - 1) ** 2 - (2 * t - 1) ** 2)))


def _plane():
    return _grid(lambda s, t: (s, t, 0.3 * s + 0.2 * t), 8, 8)


def _sphere_patch():
    th, ph = (lambda s: 0.6 + 0.8 * s), (lambda t: 0.8 * t)
    return _grid(lambda s, t: (np.sin(th(s)) * np.cos(ph(t)), np.sin(th(s)) * np.sin(ph(t)),
                               np.cos(th(s))), 8, 8)


def _outer_torus():
    """Outer side of a torus: K > 0 everywhere, no asymptotic directions."""
    return torus_grid(10, 10).reshape(-1, 3), grid_quads(10, 10)


def _tube():
    n, ang = 8, np.linspace(0, 2 * np.pi, 9)[:-1]
    V = np.array([[np.cos(a), np.sin(a), h] for h in np.linspace(0, 1, 5) for a in ang])
    F = [[i * n + j, i * n + (j + 1) % n, (i + 1) * n + (j + 1) % n, (i + 1) * n + j]
         for i in range(4) for j in range(n)]
    return V, F


def _octahedron():
    """A closed sphere: no boundary."""
    V = [[1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]]
    F = [[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4], [1, 0, 5], [2, 1, 5], [3, 2, 5], [0, 3, 5]]
    return V, F


def _with_hole():
    V, F = _saddle()
    return V, [f for k, f in enumerate(F.tolist()) if k != 12]


def _soup():
    V = np.random.default_rng(0).normal(size=(30, 3))
    return V, [[3 * i, 3 * i + 1, 3 * i + 2] for i in range(10)]


def _l_shape():
    """Quads that are not a structured grid: a 4 x 4 grid of quads missing one corner block."""
    V, F = _grid(lambda s, t: (s, t, 0.2 * s * t), 5, 5)
    keep = [f for k, f in enumerate(F.tolist()) if not (k // 4 >= 2 and k % 4 >= 2)]
    used = sorted({i for f in keep for i in f})
    new = {old: k for k, old in enumerate(used)}
    return V[used], [[new[i] for i in f] for f in keep]


def _edge_of_three():
    """Three quads sharing the edge (0, 1)."""
    V = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [1, -1, 0], [0, -1, 0], [0.5, 0.5, 1],
         [0.5, 0, 1]]
    return V, [[0, 1, 2, 3], [1, 0, 5, 4], [0, 1, 6, 7]]


def _bow_tie():
    """Two quads touching at vertex 0 only."""
    V = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [-1, 0, 0], [-1, -1, 0], [0, -1, 0]]
    return V, [[0, 1, 2, 3], [0, 4, 5, 6]]


def _repeated_vertex():
    """A quad repeating a vertex (face 12 of the saddle becomes ``a b b d``)."""
    V, F = _saddle()
    F = F.tolist()
    a, b, _, d = F[12]
    F[12] = [a, b, b, d]
    return V, F


def _zero_area():
    """A corner quad squashed onto its first edge (``c -> b``, ``d -> a``): zero area, four
    distinct vertex indices, every other face intact."""
    V, F = _saddle()
    a, b, c, d = F[0]
    V = V.copy()
    V[c], V[d] = V[b], V[a]
    return V, F


def _bad_coordinate(value: str) -> str:
    lines = _obj(*_saddle()).splitlines(keepends=True)
    lines[7] = f"v 0.1 {value} 0.2\n"
    return "".join(lines)


def _truncated_obj() -> str:
    text = _obj(*_saddle())
    return text[: len(text) // 2 - 3]  # cut inside a vertex record


def _truncated_ply() -> bytes:
    V, F = _saddle()
    head = ("ply\nformat binary_little_endian 1.0\nelement vertex 36\nproperty double x\n"
            "property double y\nproperty double z\nelement face 25\n"
            "property list uchar int vertex_indices\nend_header\n").encode()
    body = V.astype("<f8").tobytes() + b"".join(struct.pack("<B4i", 4, *f) for f in F.tolist())
    return head + body[: len(body) // 2]


#: file name -> content; "missing.obj" is not written
BAD_FILES = {
    "empty.obj": lambda: "",
    "truncated.obj": _truncated_obj,
    "truncated.ply": _truncated_ply,
    "short.off": lambda: "OFF\n10 1 0\n0 0 0\n1 0 0\n1 1 0\n3 0 1 2\n",
    "garbage.obj": lambda: b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR\xff\xfe",
    "garbage.ply": lambda: b"\x00\x01\x02\x03 not a mesh at all \xff\xfe",
    "garbage.off": lambda: "hello, this is not an OFF file\n",
    "mesh.stl": lambda: _obj(*_saddle()),
    "edge_of_three.obj": lambda: _obj(*_edge_of_three()),
    "bow_tie.obj": lambda: _obj(*_bow_tie()),
    "degenerate_repeat.obj": lambda: _obj(*_repeated_vertex()),
    "degenerate_area.obj": lambda: _obj(*_zero_area()),
    "nan.obj": lambda: _bad_coordinate("nan"),
    "inf.obj": lambda: _bad_coordinate("inf"),
    "huge.obj": lambda: _obj(*_saddle(1e12)),
    "tiny.obj": lambda: _obj(*_saddle(1e-12)),
    "index.obj": lambda: _obj(*_saddle()) + "f 1 2 99 3\n",
    "tube.obj": lambda: _obj(*_tube()),
    "sphere_closed.obj": lambda: _obj(*_octahedron()),
    "hole.obj": lambda: _obj(*_with_hole()),
    "soup.obj": lambda: _obj(*_soup()),
    "l_shape.obj": lambda: _obj(*_l_shape()),
    "plane.obj": lambda: _obj(*_plane()),
    "sphere_patch.obj": lambda: _obj(*_sphere_patch()),
    "outer_torus.obj": lambda: _obj(*_outer_torus()),
    "saddle.obj": lambda: _obj(*_saddle()),
}


def _write(tmp_path: Path, name: str) -> Path:
    path = tmp_path / name
    if name in BAD_FILES:
        data = BAD_FILES[name]()
        (path.write_bytes if isinstance(data, bytes) else path.write_text)(data)
    return path


# --------------------------------------------------------------------------- the checks

def _run(capsys, argv):
    code = main(argv)
    cap = capsys.readouterr()
    return code, cap.out, cap.err


def _leftovers(path: Path) -> list[str]:
    """Temporary files or directories of an atomic write of ``path`` left beside it."""
    parent = path.parent
    if not parent.is_dir():
        return []
    return sorted(p.name for p in parent.iterdir() if p.name.startswith(f".{path.name}."))


def assert_clean_failure(capsys, argv, code, words, outputs=()):
    """Run ``gridshell argv --json -q``; check the exit code, the one stderr line naming the
    problem (``words``, case-insensitive), no traceback, the JSON error and no output."""
    got, out, err = _run(capsys, [*argv, "--json", "-q"])
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert got == code, err
    assert "Traceback" not in err
    assert len(lines) == 1, err
    assert lines[0].startswith(f"gridshell {argv[0]}: error: "), lines[0]
    for w in words:
        assert w.lower() in lines[0].lower(), (w, lines[0])
    payload = json.loads(out)
    assert payload["ok"] is False and payload["error"] in CLASSES[code]
    assert payload["message"] and payload["message"] in lines[0]
    for p in outputs:
        p = Path(p)
        assert not p.exists(), f"partial output {p}"
        assert not _leftovers(p), _leftovers(p)
    return lines[0]


# --------------------------------------------------------------------------- mesh inputs

#: (file, expected code, key words of the message) for every mesh command
FILE_CASES = [
    ("empty.obj", 2, ["empty.obj", "empty"]),
    ("truncated.obj", 2, ["truncated.obj", "truncated"]),
    ("truncated.ply", 2, ["truncated.ply", "cut short"]),
    ("short.off", 2, ["short.off", "announces 10 vertices", "truncated"]),
    ("garbage.obj", 2, ["garbage.obj", "binary", "corrupt"]),
    ("garbage.ply", 2, ["garbage.ply", "PLY header"]),
    ("garbage.off", 2, ["garbage.off", "OFF header"]),
    ("mesh.stl", 2, ["unknown mesh format", ".stl", ".obj"]),
    ("missing.obj", 2, ["missing.obj", "no such file"]),
    ("edge_of_three.obj", 2, ["non-manifold", "edge", "more than two faces"]),
    ("bow_tie.obj", 2, ["non-manifold", "vertices", "split the mesh"]),
    ("degenerate_repeat.obj", 2, ["degenerate_repeat.obj", "degenerate", "repeating a vertex"]),
    ("degenerate_area.obj", 2, ["degenerate_area.obj", "degenerate", "zero area"]),
    ("nan.obj", 2, ["nan.obj", "NaN or infinite"]),
    ("inf.obj", 2, ["inf.obj", "NaN or infinite"]),
    ("huge.obj", 2, ["huge.obj", "spans", "rescale"]),
    ("tiny.obj", 2, ["tiny.obj", "spans", "rescale"]),
    ("index.obj", 2, ["index.obj", "outside", "vertices"]),
    ("tube.obj", 2, ["not a disk"]),
    ("sphere_closed.obj", 2, ["disk"]),  # gg: "not a disk"; phlw, ncp: "closed (no boundary)"
    ("hole.obj", 2, ["not a disk"]),
]


@pytest.mark.parametrize("command", ["gg", "phlw", "ncp"])
@pytest.mark.parametrize("name, code, words", FILE_CASES, ids=[c[0] for c in FILE_CASES])
def test_bad_mesh_file(tmp_path, capsys, command, name, code, words):
    out = tmp_path / "out"
    assert_clean_failure(capsys, [command, str(_write(tmp_path, name)), "-o", str(out),
                                  *MESH_OPTIONS[command]], code, words, [out])


@pytest.mark.parametrize("command, words", [
    ("gg", ["not a disk", "10 boundary loop"]),
    ("phlw", ["10 connected components", "one disk"]),
    ("ncp", ["10 connected components", "one disk"]),
])
def test_triangle_soup(tmp_path, capsys, command, words):
    out = tmp_path / "out"
    assert_clean_failure(capsys, [command, str(_write(tmp_path, "soup.obj")), "-o", str(out),
                                  *MESH_OPTIONS[command]], 2, words, [out])


def test_gg_needs_a_structured_quad_grid(tmp_path, capsys):
    out = tmp_path / "out"
    assert_clean_failure(capsys, ["gg", str(_write(tmp_path, "l_shape.obj")), "-o", str(out),
                                  *GG], 2, ["not a structured quad grid", "triangle"], [out])


# --------------------------------------------------------------------------- no net (exit 3)

@pytest.fixture(scope="module")
def surfaces(tmp_path_factory):
    """B-spline JSON surfaces: a plane, a sphere patch and the outer side of a torus."""
    d = tmp_path_factory.mktemp("surfaces")
    for name, (V, F) in (("plane", _plane()), ("sphere", _sphere_patch()),
                         ("torus", _outer_torus())):
        R = int(np.sqrt(len(V)))
        fit_grid(np.asarray(V).reshape(R, R, 3), 5, 5, 3, 3)[0].save(d / f"{name}.json")
    return d


@pytest.mark.parametrize("command, source, mode, words", [
    ("phlw", "plane.obj", "phlw", ["umbilic", "principal directions", "saddle"]),
    ("phlw", "sphere_patch.obj", "cnc", ["umbilic", "sphere"]),
    ("phlw", "outer_torus.obj", "aa", ["K > 0", "asymptotic", "'phlw' or 'cnc'"]),
    ("ncp", "plane.obj", "phlw", ["umbilic", "principal directions"]),
    ("ncp", "plane.json", "cnc", ["umbilic", "principal directions"]),
    ("ncp", "sphere.json", "phlw", ["no real direction", "nearly umbilic"]),
    ("ncp", "torus.json", "aa", ["K > 0", "asymptotic", "'phlw' or 'cnc'"]),
    ("ncp", "torus.json", "cnc --n 1e12", ["no real direction", "kappa_I, kappa_II"]),
    # (a surface of revolution in mode phlw had nearly parallel families from a row slope set
    # by noise; its flat rows now get n = H, the net at pi/4: tests/ncp/test_ring.py)
])
def test_no_net(tmp_path, capsys, surfaces, command, source, mode, words):
    src = surfaces / source if source.endswith(".json") else _write(tmp_path, source)
    mode, *extra = mode.split()
    out = tmp_path / "out"
    assert_clean_failure(capsys, [command, str(src), "-o", str(out), "--mode", mode, *extra,
                                  *MESH_OPTIONS[command]], 3, words, [out])


# --------------------------------------------------------------------------- absurd parameters

#: options of MESH_OPTIONS taking two values (the others take one, or none: --no-*)
PAIRS = {"--grid", "--ctrl", "--degree", "--samples", "--check-samples", "--collapse-samples",
         "--levelset-ctrl", "--phlw-ctrl", "--phlw-samples"}


def _without(options, *names):
    """``options`` without the given flags and their values."""
    out, skip = [], 0
    for o in options:
        if skip:
            skip -= 1
        elif o in names:
            skip = 2 if o in PAIRS else 0 if o.startswith("--no-") else 1
        else:
            out.append(o)
    return out


PARAMETER_CASES = [
    ("gg", "--grid 100000 100000", ["too fine", "smaller grid"]),
    ("gg", "--grid 0 0", ["--grid", ">= 4"]),
    ("gg", "--grid -3 5", ["--grid", ">= 4"]),
    ("gg", "--lamellae 0", ["--lamellae", ">= 2"]),
    ("gg", "--lamellae -2", ["--lamellae", ">= 2"]),
    ("gg", "--lamellae 100000", ["closer than", "at most"]),
    ("gg", "--spacing 1e-9", ["closer than", "spacing of at least"]),
    ("gg", "--spacing -1", ["--spacing", "> 0"]),
    ("gg", "--spacing nan", ["--spacing", "finite"]),
    ("gg", "--angle 0", ["--angle", "between 0 and 180"]),
    ("gg", "--angle nan", ["--angle", "finite"]),
    ("gg", "--at 2", ["--at", "between 0 and 1"]),
    ("phlw", "--samples 100000 100000", ["100000 x 100000 samples", "coarser"]),
    ("phlw", "--samples 0 0", ["--samples", ">= 4"]),
    ("phlw", "--check-samples 100000 100000", ["samples", "coarser"]),
    ("phlw", "--ctrl 100000 100000", ["control points"]),
    ("phlw", "--ctrl 0 0", ["--ctrl", ">= 2"]),
    ("phlw", "--degree 0 0", ["--degree", ">= 1"]),
    ("phlw", "--outer 0", ["--outer", ">= 1"]),
    ("phlw", "--max-iter -1", ["--max-iter", ">= 1"]),
    ("phlw", "--w-closeness nan", ["--w-closeness", "finite"]),
    ("phlw", "--w-gliding -1", ["--w-gliding", ">= 0"]),
    ("ncp", "--curves 0", ["--curves", ">= 1"]),
    ("ncp", "--curves -3", ["--curves", ">= 1"]),
    ("ncp", "--curves 100000", ["100000 curves", "fewer curves"]),
    ("ncp", "--spacing 1e-12", ["curves per family", "larger spacing"]),
    ("ncp", "--spacing 0", ["--spacing", "> 0"]),
    ("ncp", "--samples 100000 100000", ["samples", "coarser"]),
    ("ncp", "--collapse-samples 100000 100000", ["samples", "coarser"]),
    ("ncp", "--levelset-ctrl 100000 100000", ["control points"]),
    ("ncp", "--omega-f nan", ["--omega-f", "finite"]),
    ("ncp", "--rounds -1", ["--rounds", ">= 0"]),
    ("ncp", "--frames 0", ["--frames", ">= 1"]),
    ("ncp", "--frames 100000", ["--frames", "<= 1000"]),
    ("ncp", "--mode cnc --n nan", ["--n", "finite"]),
]


@pytest.mark.parametrize("command, options, words", PARAMETER_CASES,
                         ids=[f"{c[0]} {c[1]}" for c in PARAMETER_CASES])
def test_absurd_parameters(tmp_path, capsys, surfaces, command, options, words):
    extra = options.split()
    base = MESH_OPTIONS[command] + (["--mode", "cnc"] if command == "ncp" else [])
    base = _without(base, *[o for o in extra if o.startswith("--")])
    if "--spacing" in extra:
        base = _without(base, "--curves", "--lamellae")
    src = {"gg": lambda: _write_helicoid(tmp_path), "phlw": lambda: _write(tmp_path, "saddle.obj"),
           "ncp": lambda: surfaces / "torus.json"}[command]()
    out = tmp_path / "out"
    assert_clean_failure(capsys, [command, str(src), "-o", str(out), *base, *extra], 2, words,
                         [out])


def _write_helicoid(tmp_path: Path, n: int = 8) -> Path:
    path = tmp_path / "helicoid.obj"
    write_mesh(path, helicoid_grid(n, n).reshape(-1, 3), grid_quads(n, n))
    return path


# --------------------------------------------------------------------------- convergence (exit 4)

def test_phlw_strict_fails_when_the_optimizer_stops_early(tmp_path, capsys):
    ref, out = _write(tmp_path, "saddle.obj"), tmp_path / "out"
    opts = _without(PHLW, "--max-iter") + ["--max-iter", "1"]
    # the default now (--strict is a deprecated alias): exit 4, nothing written
    for extra in ([], ["--strict"]):
        assert_clean_failure(capsys, ["phlw", str(ref), "-o", str(out), *opts, *extra], 4,
                             ["did not converge", "--max-iter", "--allow-unconverged"], [out])
    # with --allow-unconverged the design is written, and the summary says it did not converge
    code, stdout, err = _run(capsys, ["phlw", str(ref), "-o", str(out), *opts, "--json",
                                      "--allow-unconverged"])
    assert code == 0, err
    summary = json.loads(stdout)
    assert summary["converged"] is False and summary["quality"]["ok"] is False
    assert "warning: the PHLW optimization did not converge" in err


def test_ncp_strict_fails_at_the_phlw_step(tmp_path, capsys):
    ref, out = _write(tmp_path, "saddle.obj"), tmp_path / "out"
    opts = _without(NCP, "--phlw-max-iter") + ["--phlw-max-iter", "1"]
    assert_clean_failure(capsys, ["ncp", str(ref), "-o", str(out), *opts, "--strict"], 4,
                         ["PHLW step did not converge", "--phlw-max-iter"], [out])


def test_ncp_strict_fails_at_the_level_set_fit(tmp_path, capsys, surfaces, monkeypatch):
    """No CLI option makes the level-set fit miss its tolerances: it is a linear least-squares
    problem that Levenberg-Marquardt solves well within its 20 iterations (measured on this
    torus: converged for 4 x 4 to 60 x 60 control points, omega_f 1e-14 to 1e8, 6 x 6 to
    12 x 12 samples), and its iteration limit is not a parameter of trace() or design_ncp().
    Its default limit is lowered here to one iteration, which the fit cannot converge in."""
    from gridshell.ncp.levelset import fit_level_function

    monkeypatch.setitem(fit_level_function.__kwdefaults__, "max_iter", 1)
    src, out = surfaces / "torus.json", tmp_path / "out"
    opts = [*NCP, "--mode", "cnc"]
    assert_clean_failure(capsys, ["ncp", str(src), "-o", str(out), *opts, "--strict"], 4,
                         ["level-set fit of family 1 did not converge", "--levelset-ctrl",
                          "--omega-f"], [out])
    code, stdout, err = _run(capsys, ["ncp", str(src), "-o", str(out), *opts, "--json"])
    assert code == 0, err
    summary = json.loads(stdout)
    assert summary["converged"] is False
    assert "level-set fit 1" in summary["not converged"]
    assert "level-set fit 3" in summary["not converged"]


def test_ncp_reports_an_unconverged_post_optimization(tmp_path, capsys, surfaces):
    # the polish alone: without a round, the aligned joints are not held on the collapse
    # curve, and holding the constraints is not enough to count as converged
    src, out = surfaces / "torus.json", tmp_path / "out"
    opts = _without(NCP, "--rounds") + ["--rounds", "0", "--mode", "cnc"]
    assert_clean_failure(capsys, ["ncp", str(src), "-o", str(out), *opts, "--strict"], 4,
                         ["post-optimization did not converge", "--rounds"], [out])
    # without a round the figures miss the thresholds (Delta_a, collapse): exit 4, naming
    # them; with --allow-unconverged the design is written, marked as failing
    assert_clean_failure(capsys, ["ncp", str(src), "-o", str(out), *opts], 4,
                         ["misses the paper's figures", "Delta_a", "--rounds",
                          "--allow-unconverged"], [out])
    code, stdout, err = _run(capsys, ["ncp", str(src), "-o", str(out), *opts, "--json",
                                      "--allow-unconverged"])
    assert code == 0, err
    summary = json.loads(stdout)
    assert summary["ok"] and summary["converged"] is False
    assert summary["not converged"] == "post-optimization"
    assert summary["quality"]["ok"] is False
    d = json.loads((out / "design.json").read_text())
    assert d["metrics"]["quality"]["ok"] is False and d["params"]["allow_unconverged"]


def test_gg_unconverged_design_is_an_error_unless_allowed(tmp_path, capsys):
    ref, out = _write(tmp_path, "saddle.obj"), tmp_path / "out"
    opts = [*GG, "--rounds", "1", "--polish", "0"]
    # refused on the paper's figures of the traced net, naming them and the way out
    assert_clean_failure(capsys, ["gg", str(ref), "-o", str(out), *opts], 4,
                         ["misses the paper's figures", "Delta_a mean", "--grid"], [out])
    code, stdout, err = _run(capsys, ["gg", str(ref), "-o", str(out), *opts,
                                      "--allow-unconverged", "--json"])
    assert code == 0, err
    summary = json.loads(stdout)
    assert summary["ok"] is False and summary["verdict"].startswith("FAIL")
    assert any(not g["ok"] for g in summary["gates"])
    assert json.loads((out / "design.json").read_text())["params"]["quality"]["ok"] is False


# --------------------------------------------------------------------------- unwritable output

def _make_read_only(d: Path) -> bool:
    """Make directory ``d`` unwritable: mode 0o500, or, where root ignores the mode, the
    immutable attribute (``chattr +i``). Returns whether ``d`` is now unwritable."""
    d.chmod(0o500)
    if not os.access(d, os.W_OK):
        return True
    if shutil.which("chattr"):
        subprocess.run(["chattr", "+i", str(d)], capture_output=True, check=False)
    return not os.access(d, os.W_OK)


def _make_writable(d: Path) -> None:
    """Undo :func:`_make_read_only` (so that pytest can remove ``d``)."""
    if shutil.which("chattr"):
        subprocess.run(["chattr", "-i", str(d)], capture_output=True, check=False)
    d.chmod(0o700)


@pytest.fixture
def read_only_dir(tmp_path, monkeypatch):
    """``make(path)``: make the directory ``path`` unwritable for the rest of the test. Where
    neither the mode nor the immutable attribute has an effect (root on a file system without
    ``chattr``), the permission check of ``gridshell.core.atomic`` is told what a non-root user's
    would answer: not writable."""
    made: list[Path] = []

    def make(d: Path) -> Path:
        made.append(d)
        if not _make_read_only(d):
            import gridshell.core.atomic as atomic

            real = os.access
            monkeypatch.setattr(atomic.os, "access", lambda p, mode, *a, **k: False
                                if Path(p).resolve() == d.resolve() and mode & os.W_OK
                                else real(p, mode, *a, **k))
        return d

    yield make
    for d in reversed(made):
        _make_writable(d)


@pytest.fixture
def unwritable(tmp_path):
    """A directory that cannot be written (:func:`_make_read_only`), or, where that is not
    possible, a regular file standing where the directory should be."""
    d = tmp_path / "readonly"
    d.mkdir()
    if not _make_read_only(d):
        _make_writable(d)
        d.rmdir()
        d.write_text("a regular file, not a directory\n")
    yield d
    if d.is_dir():
        _make_writable(d)


def _output_location(kind: str, tmp_path: Path, unwritable_dir: Path) -> Path:
    if kind == "under a file":
        f = tmp_path / "file.txt"
        f.write_text("not a directory\n")
        return f / "out"
    return unwritable_dir / "out"


@pytest.fixture(scope="module")
def bundle(tmp_path_factory):
    """A small valid GG design bundle (helicoid; its net-loops touch at a corner)."""
    d = tmp_path_factory.mktemp("bundle")
    target = _write_helicoid(d)
    assert main(["gg", str(target), "-o", str(d / "gg"), "-q", "--lamellae", "3",
                 "--no-preview"]) == 0
    return d / "gg"


@pytest.mark.parametrize("where", ["under a file", "read-only directory"])
@pytest.mark.parametrize("command", ["gg", "phlw", "ncp", "fabricate"])
def test_unwritable_output(tmp_path, capsys, unwritable, bundle, command, where):
    out = _output_location(where, tmp_path, unwritable)
    src = {"gg": lambda: _write_helicoid(tmp_path), "phlw": lambda: _write(tmp_path, "saddle.obj"),
           "ncp": lambda: _write(tmp_path, "saddle.obj"), "fabricate": lambda: bundle}[command]()
    opts = MESH_OPTIONS.get(command, ["--no-plan"])
    assert_clean_failure(capsys, [command, str(src), "-o", str(out), *opts], 5,
                         ["cannot write", "writable output location"], [out])


@pytest.mark.parametrize("where", ["under a file", "read-only directory"])
def test_render_unwritable_rhino_file(tmp_path, capsys, unwritable, bundle, where):
    target = _output_location(where, tmp_path, unwritable).with_suffix(".3dm")
    before = sorted(p.name for p in bundle.iterdir())
    assert_clean_failure(capsys, ["render", str(bundle), "--3dm", str(target), "--no-sequence",
                                  "--size", "100", "100"], 5, ["cannot write", ".3dm"],
                         [target])
    assert sorted(p.name for p in bundle.iterdir()) == before  # nothing rendered either


def test_render_read_only_bundle(tmp_path, capsys, bundle, read_only_dir):
    """render writes into the bundle: a read-only bundle is named before any rendering."""
    b = tmp_path / "bundle"
    shutil.copytree(bundle, b)
    before = sorted(p.name for p in b.iterdir())
    read_only_dir(b)
    assert_clean_failure(capsys, ["render", str(b), "--no-sequence", "--size", "100", "100"],
                         5, ["cannot write", "render.png", "not writable",
                             "writable output location"], [b / "render.png"])
    assert sorted(p.name for p in b.iterdir()) == before


@pytest.mark.parametrize("where", ["under a file", "read-only directory"])
def test_demo_unwritable_output(tmp_path, capsys, unwritable, where):
    """The demo fails at once (it would run for minutes otherwise) and writes nothing."""
    out = _output_location(where, tmp_path, unwritable)
    assert_clean_failure(capsys, ["demo", "-o", str(out), "--quick"], 5,
                         ["cannot", str(out), "writable output location"], [out])
    if unwritable.is_dir():
        assert list(unwritable.iterdir()) == []


@pytest.mark.parametrize("command", ["gg", "phlw", "ncp"])
def test_output_never_replaces_a_file_or_a_foreign_directory(tmp_path, capsys, command):
    src = _write_helicoid(tmp_path) if command == "gg" else _write(tmp_path, "saddle.obj")
    f = tmp_path / "notes.txt"
    f.write_text("precious\n")
    assert_clean_failure(capsys, [command, str(src), "-o", str(f), *MESH_OPTIONS[command]], 5,
                         ["exists and is not a directory"])
    assert f.read_text() == "precious\n"
    d = tmp_path / "home"
    d.mkdir()
    (d / "thesis.tex").write_text("precious\n")
    assert_clean_failure(capsys, [command, str(src), "-o", str(d), *MESH_OPTIONS[command]], 5,
                         ["not the output of an earlier run"])
    assert (d / "thesis.tex").read_text() == "precious\n"


# --------------------------------------------------------------------------- bad bundles

def _design(bundle_dir: Path) -> dict:
    return json.loads((bundle_dir / "design.json").read_text())


#: name -> (file in the bundle, new content or None to delete it, key words)
BUNDLE_CASES = {
    "no design.json": ("design.json", None, ["not a design bundle", "design.json"]),
    "empty design.json": ("design.json", "", ["design.json", "not valid JSON"]),
    "garbage design.json": ("design.json", b"\x00\xff\x13garbage", ["not valid JSON"]),
    "truncated design.json": ("design.json", lambda b: (b / "design.json").read_text()[:150],
                              ["not valid JSON"]),
    "design.json a list": ("design.json", "[1, 2]", ["not a gridshell design file"]),
    "design.json other format": ("design.json", '{"format": "something"}',
                                 ["not a gridshell design file", "something"]),
    "no lamellae": ("design.json", '{"format": "gridshell.design", "kind": "GG"}',
                    ["lacks 'lamellae'"]),
    "unknown kind": ("design.json", lambda b: json.dumps({**_design(b), "kind": "XYZ"}),
                     ["unknown design kind", "XYZ"]),
    "lamellae not records": ("design.json", lambda b: json.dumps({**_design(b), "lamellae": 5}),
                             ["'lamellae' must be a list"]),
    "lamella record lacks joints": (
        "design.json", lambda b: json.dumps({**_design(b), "lamellae": [
            {k: v for k, v in r.items() if k != "joints"} for r in _design(b)["lamellae"]]}),
        ["lamella record 0", "joints"]),
    "lamella joints out of range": (
        "design.json", lambda b: json.dumps({**_design(b), "lamellae": [
            {**r, "joints": [10 ** 6] * len(r["joints"])} for r in _design(b)["lamellae"]]}),
        ["joints outside"]),
    "fewer axes than lamellae": ("axes.obj", "v 0 0 0\nv 1 0 0\nl 1 2\n",
                                 ["axes.obj has 1 polylines"]),
    "no net.obj": ("net.obj", None, ["lacks net.obj"]),
    "empty net.obj": ("net.obj", "", ["net.obj", "empty"]),
    "truncated net.obj": ("net.obj", lambda b: (b / "net.obj").read_text()[:60],
                          ["net.obj", "truncated"]),
    "garbage net.obj": ("net.obj", b"\x00\x01garbage", ["net.obj", "binary"]),
    "non-manifold net.obj": ("net.obj", _obj(*_edge_of_three()), ["net.obj", "non-manifold"]),
    "NaN in net.obj": ("net.obj", lambda b: (b / "net.obj").read_text().replace(
        "\nv ", "\nv nan 0 0 # ", 1), ["net.obj", "NaN"]),
    "no axes.obj": ("axes.obj", None, ["lacks axes.obj"]),
    "no surface.obj": ("surface.obj", None, ["lacks surface.obj"]),
    "bundle missing": (None, "missing", ["is not a directory"]),
    "bundle is a file": (None, "file", ["is not a directory"]),
}


def _broken_bundle(good: Path, tmp_path: Path, case: str) -> Path:
    name, content, _ = BUNDLE_CASES[case]
    b = tmp_path / "bundle"
    if name is None:
        if content == "file":
            b.write_text("not a bundle\n")
        return b
    shutil.copytree(good, b)
    if callable(content):
        content = content(b)
    if content is None:
        (b / name).unlink()
    elif isinstance(content, bytes):
        (b / name).write_bytes(content)
    else:
        (b / name).write_text(content)
    return b


@pytest.mark.parametrize("command", ["verify", "fabricate", "render"])
@pytest.mark.parametrize("case", list(BUNDLE_CASES))
def test_bad_bundle(tmp_path, capsys, bundle, command, case):
    b = _broken_bundle(bundle, tmp_path, case)
    before = sorted(p.name for p in b.iterdir()) if b.is_dir() else None
    out = tmp_path / "fab"
    argv = {"verify": ["verify", str(b)],
            "fabricate": ["fabricate", str(b), "-o", str(out), "--no-plan"],
            "render": ["render", str(b), "--no-sequence", "--size", "100", "100"]}[command]
    assert_clean_failure(capsys, argv, 2, BUNDLE_CASES[case][2], [out])
    if before is not None:  # nothing written into the bundle
        assert sorted(p.name for p in b.iterdir()) == before


def test_the_good_bundle_passes_every_bundle_command(tmp_path, capsys, bundle):
    """The fixture the bad bundles start from is valid (its loops touch at a corner)."""
    assert main(["verify", str(bundle)]) == 0
    assert json.loads(capsys.readouterr().out)["ok"]
    assert main(["fabricate", str(bundle), "-o", str(tmp_path / "fab"), "--no-plan", "-q"]) == 0
    assert (tmp_path / "fab" / "cutlist.csv").is_file()


PARAMETER_BUNDLE_CASES = [
    ("fabricate", "--width 0", ["--width", "> 0"]),
    ("fabricate", "--sheet 0x0", ["sheet size", "positive"]),
    ("fabricate", "--scale abc", ["scale", "not understood"]),
    ("fabricate", "--kerf 1e9", ["kerf"]),
    ("fabricate", "--gap nan", ["--gap"]),
    ("render", "--size 10 10", ["--size", ">= 64 and <= 10000"]),
    ("render", "--size 100000 100000", ["--size", ">= 64 and <= 10000"]),
    ("render", "--width nan", ["--width", "finite"]),
]


@pytest.mark.parametrize("command, options, words", PARAMETER_BUNDLE_CASES,
                         ids=[f"{c[0]} {c[1]}" for c in PARAMETER_BUNDLE_CASES])
def test_absurd_bundle_parameters(tmp_path, capsys, bundle, command, options, words):
    b = tmp_path / "bundle"
    shutil.copytree(bundle, b)
    out = tmp_path / "fab"
    argv = [command, str(b), *(["-o", str(out), "--no-plan"] if command == "fabricate"
                               else ["--no-sequence"]), *options.split()]
    before = sorted(p.name for p in b.iterdir())
    assert_clean_failure(capsys, argv, 2, words, [out])
    assert sorted(p.name for p in b.iterdir()) == before


# --------------------------------------------------------------------------- the parser itself

def test_no_command_prints_help_on_stderr_and_exits_2(capsys):
    code, out, err = _run(capsys, [])
    assert code == 2
    assert out == ""
    assert err.startswith("usage: gridshell")
    for name in ("gg", "phlw", "ncp", "verify", "fabricate", "render", "demo"):
        assert name in err
    assert "error: give a command" in err


def _choices(command: str, option: str) -> tuple:
    from gridshell.cli.main import build_parser

    parser = build_parser([command])
    sub = next(a for a in parser._actions if a.dest == "command").choices[command]
    action = next(a for a in sub._actions if option in a.option_strings)
    return tuple(action.choices), action.default, action.help


def _registries():
    from gridshell.fabrication import params as fp

    from gridshell.ncp import phlw, pipeline

    return [("phlw", "--mode", phlw, "MODES"), ("ncp", "--mode", pipeline, "KIND"),
            ("fabricate", "--joints", fp, "JOINT_STYLES"), ("fabricate", "--axis", fp,
                                                            "AXIS_PLACES"),
            ("fabricate", "--dxf-version", fp, "DXF_VERSIONS")]


@pytest.mark.parametrize("i", range(5), ids=lambda i: " ".join(_registries()[i][:2]))
def test_choices_are_the_registries(i, monkeypatch):
    command, option, module, name = _registries()[i]
    registry = getattr(module, name)
    choices, default, text = _choices(command, option)
    assert choices == tuple(registry)
    # --joints defaults to None: holes, engraved as marks where they would merge at the scale
    assert default in choices or (option == "--joints" and default is None)
    assert all(c in text for c in choices)
    # a choice the registry gains is offered without touching the CLI
    grown = {**registry, "zz": "ZZ"} if isinstance(registry, dict) else (*registry, "zz")
    monkeypatch.setattr(module, name, grown)
    choices, _, text = _choices(command, option)
    assert "zz" in choices and "zz" in text


def test_a_command_builds_only_its_own_options():
    """``gridshell gg`` does not import the fabrication package for fabricate's choices."""
    code = ("import sys; from gridshell.cli.main import main\n"
            "try:\n    main(['gg', '--help'])\nexcept SystemExit:\n    pass\n"
            "print('fabrication' in sys.modules, 'gridshell.ncp.phlw' in sys.modules)")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert res.stdout.split()[-2:] == ["False", "False"]
