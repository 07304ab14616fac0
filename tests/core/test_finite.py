"""Finite or nothing (issue 14 item 2): no code path writes a non-finite number into an output.

A property test over random bundles: NaN / Inf injected field by field (design.json geometry,
every OBJ, the rotation axes); ``fabricate`` and ``render`` either refuse (exit 2, nothing
written) or write files that hold only finite numbers. And the writers' own net
(:mod:`gridshell.core.finite`) refuses a non-finite number in every text format, JSON and NPY.
"""
from __future__ import annotations

import io
import json
import os
import shutil
from pathlib import Path

import numpy as np
import pytest
from tests.helpers.fab_cases import make_bundle

from gridshell.core import finite
from gridshell.core.atomic import atomic_dir, write_text
from gridshell.design.bundle import write_bundle
from gridshell.cli.main import main
from gridshell.core.errors import GridshellError

FIELDS = ["joint_s", "length", "collapse_s", "collapse.points", "collapse.radius", "net.obj",
          "axes.obj", "aligned.obj", "surface.obj", "axes_r.npy"]


def _inject(b: Path, field: str, value: float, rng: np.random.Generator) -> None:
    if field.endswith(".obj"):
        lines = (b / field).read_text().splitlines()
        vs = [i for i, ln in enumerate(lines) if ln.startswith("v ")]
        i = int(rng.choice(vs))
        parts = lines[i].split()
        parts[1 + int(rng.integers(3))] = repr(value)
        lines[i] = " ".join(parts)
        (b / field).write_text("\n".join(lines) + "\n")
        return
    if field.endswith(".npy"):
        a = np.load(b / field)
        a[int(rng.integers(len(a))), int(rng.integers(3))] = value
        buf = io.BytesIO()
        np.save(buf, a)
        (b / field).write_bytes(buf.getvalue())
        return
    d = json.loads((b / "design.json").read_text())
    if field.startswith("collapse."):
        key = field.split(".")[1]
        if key == "radius":
            d["collapse"]["radius"] = value
        else:
            pts = d["collapse"]["points"]
            pts[int(rng.integers(len(pts)))][int(rng.integers(2))] = value
    else:
        lam = d["lamellae"][int(rng.integers(len(d["lamellae"])))]
        if field == "length":
            lam["length"] = value
        else:
            lam[field][int(rng.integers(len(lam[field])))] = value
    (b / "design.json").write_text(json.dumps(d))


def _random_bundle(path: Path, rng: np.random.Generator) -> Path:
    kind = str(rng.choice(["GG", "CNC", "NCP"]))
    b = make_bundle(kind, nr=int(rng.integers(3, 6)), nc=int(rng.integers(3, 6)),
                    c=float(rng.uniform(-0.3, 0.3)), twist=float(rng.uniform(-0.4, 0.4)),
                    a=float(rng.uniform(0.15, 0.35)), R=float(rng.uniform(0.8, 2.0)))
    buf = io.BytesIO()
    np.save(buf, np.tile([0.0, 0.0, 1.0], (len(b.net.joints), 1)))
    return write_bundle(path, b, extra={"axes_r.npy": buf.getvalue(),
                                        "aligned_r.npy": buf.getvalue()})


def _all_finite(root: Path) -> None:
    for dirpath, _, names in os.walk(root):
        for n in names:
            p = Path(dirpath) / n
            assert finite.problem(p) is None, (p, finite.problem(p))


CASES = [(seed, FIELDS[seed % len(FIELDS)], [np.nan, np.inf, -np.inf][seed % 3])
         for seed in range(30)]


@pytest.mark.parametrize("seed, field, value", CASES,
                         ids=[f"{s}-{f}-{v}" for s, f, v in CASES])
def test_injected_non_finite_never_reaches_an_output(tmp_path, capsys, seed, field, value):
    rng = np.random.default_rng(seed)
    b = _random_bundle(tmp_path / "b", rng)
    kind = json.loads((b / "design.json").read_text())["kind"]
    if field.startswith("collapse") and kind == "GG":
        field = "joint_s"
    if field == "collapse.radius" and kind != "CNC":
        field = "collapse.points"
    if field == "collapse_s" and kind != "NCP":  # only NCP bundles store collapse_s here
        field = "joint_s"
    _inject(b, field, value, rng)
    before = sorted(p.name for p in b.iterdir())
    out = tmp_path / "fab"
    code = main(["fabricate", str(b), "-o", str(out), "--no-plan", "--force", "-q"])
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert code == 2 and not out.exists(), err  # refused, even with --force
    assert sorted(p.name for p in b.iterdir()) == before
    tampered = {p: p.read_bytes() for p in b.rglob("*") if p.is_file()}
    code = main(["render", str(b), "--no-sequence", "--size", "80", "80", "-q"])
    err = capsys.readouterr().err
    assert "Traceback" not in err and code in (0, 2), err
    if code == 2:  # refused: nothing written into the bundle
        assert {p: p.read_bytes() for p in b.rglob("*") if p.is_file()} == tampered
    for p in b.rglob("*"):  # what render wrote (the injected files themselves aside)
        if p.is_file() and p.name != "manifest.json" and tampered.get(p) != p.read_bytes():
            assert finite.problem(p) is None, p


@pytest.mark.parametrize("seed", range(6))
def test_random_valid_bundles_give_finite_cut_files(tmp_path, seed):
    from gridshell.fabrication import fabricate

    b = _random_bundle(tmp_path / "b", np.random.default_rng(100 + seed))
    fabricate(b, tmp_path / "fab", plan=seed == 0)
    _all_finite(tmp_path / "fab")
    _all_finite(b)


# ------------------------------------------------------------------------ the writers' net

@pytest.mark.parametrize("name, text", [
    ("a.obj", "v 0 0 nan\n"), ("a.obj", "v 0 0 inf\n"), ("a.csv", "1,-inf,2\n"),
    ("a.svg", '<path d="M nan 0"/>'), ("a.dxf", "10\nNaN\n"), ("a.ply", "0 0 Infinity\n"),
    ("a.off", "OFF\n+inf 0 0\n"), ("a.json", '{"x": NaN}'), ("a.json", '[1, -Infinity]'),
])
def test_the_atomic_writers_refuse_non_finite_numbers(tmp_path, name, text):
    with pytest.raises(GridshellError, match="non-finite|refusing"):
        write_text(tmp_path / name, text)
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(GridshellError, match=name):
        with atomic_dir(tmp_path / "d", owner="x") as t:
            (t / "sub").mkdir()
            (t / "sub" / name).write_text(text)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("name, text", [
    ("a.obj", "# information: nanometres\nv 0 0 1\n"),
    ("a.json", '{"message": "NaN or Inf are refused", "x": 1e308}'),
    ("a.svg", "<text>Info nano</text>"), ("a.csv", "lamella,inflection\n1,2\n"),
    ("a.txt", "nan"), ("a.html", "inf"),
])
def test_words_and_other_formats_are_not_numbers(tmp_path, name, text):
    write_text(tmp_path / name, text)
    assert (tmp_path / name).read_text() == text


def test_npy_with_nan_is_refused(tmp_path):
    buf = io.BytesIO()
    np.save(buf, np.array([[0.0, np.nan, 1.0]]))
    assert finite.problem(tmp_path / "r.npy", buf.getvalue()) == "1 non-finite values"
    b = make_bundle("NCP")
    with pytest.raises(GridshellError, match="axes_r.npy"):
        write_bundle(tmp_path / "b", b, extra={"axes_r.npy": buf.getvalue()})
    assert not (tmp_path / "b").exists()


def test_design_json_geometry_must_be_finite(tmp_path):
    b = make_bundle("GG")
    b.net.lamellae[0].joint_s[1] = np.nan
    with pytest.raises(GridshellError, match="design.json"):
        write_bundle(tmp_path / "b", b)
    assert list(tmp_path.iterdir()) == []
    b = make_bundle("GG")
    b.metrics = {"coverage": float("nan"), "alignability": {"mean": np.inf, "max": 1.0}}
    write_bundle(tmp_path / "b", b)  # an unmeasured figure is stored as null
    m = json.loads((tmp_path / "b" / "design.json").read_text())["metrics"]
    assert m == {"coverage": None, "alignability": {"mean": None, "max": 1.0}}


def test_rhino_export_refuses_non_finite_geometry(tmp_path):
    from gridshell.export.rhino import export_3dm

    b = make_bundle("GG")
    b.net.lamellae[1].axis[2, 0] = np.nan
    with pytest.raises(GridshellError, match="lamella 1 axis"):
        export_3dm(b, tmp_path / "m.3dm")
    assert list(tmp_path.iterdir()) == []
    export_3dm(make_bundle("GG"), tmp_path / "m.3dm")
    assert (tmp_path / "m.3dm").stat().st_size > 0


@pytest.mark.parametrize("text", [
    b"10\n1.5\n20\n2.25\n", b"v 0 0 nan\n", b"v NaN", b"-INF", b"+Infinity 1", b"iNf",
    b"information nanometres", b"\xc3\xa9nan\xff", b"x_nan inf_y", b"", b"N\nA\nN",
])
def test_prefilter_gives_the_token_scan_answer(tmp_path, text):
    """The cheap "nan" / "inf" look-up before the token scan changes no answer."""
    m = finite._TOKEN.search(text)
    nl = b"\n"
    want = None if m is None else \
        f"'{m.group(0).decode(errors='replace')}' at line {text.count(nl, 0, m.start()) + 1}"
    assert finite.problem(tmp_path / "a.dxf", text) == want
