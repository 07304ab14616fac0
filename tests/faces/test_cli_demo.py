"""``gridshell demo`` (the product on the bundled meshes), through main([...]) with --quick."""
from __future__ import annotations

import contextlib
import fnmatch
import io
import json
import re
from pathlib import Path

import pytest

from gridshell.core import manifest
from gridshell.cli import demo
from gridshell.cli.main import main
from gridshell.core.errors import ConvergenceError

GG_FILES = ("design.json", "net.obj", "aligned.obj", "render.png", "preview.png", "states.png",
            "alignment.gif", "sequence/frame_000.obj", "sequence/frame_000.png",
            "report.html", "gg.3dm", "fabrication/sheet_01.dxf", "fabrication/sheet_01.svg",
            "fabrication/cutlist.csv", "fabrication/plan.png")
NCP_FILES = ("design.json", "surface.json", "axes_r.npy", "aligned_r.npy", "render.png",
             "alignment.gif", "sequence/frame_000.obj", "sequence/frame_000.png",
             "delta_a_after.png", "delta_l.png", "delta_n.png", "collapse.png", "curvature_diagram.png", "report.html",
             "ncp.3dm", "fabrication/sheet_01.dxf", "fabrication/sheet_01.svg")


@pytest.fixture(scope="module")
def quick_demo(tmp_path_factory):
    out = tmp_path_factory.mktemp("demo") / "demo"
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = main(["demo", "--quick", "-o", str(out), "-q", "--json"])
    return code, out, json.loads(buf.getvalue())


@pytest.mark.slow
def test_quick_demo_writes_everything(quick_demo):
    code, out, _ = quick_demo
    assert code == 0
    for f in GG_FILES:
        assert (out / "gg" / f).stat().st_size > 0, f
    for f in NCP_FILES:
        assert (out / "ncp" / f).stat().st_size > 0, f
    assert (out / "phlw" / "surface.json").is_file()
    assert (out / "ncp" / "alignment.gif").read_bytes()[:6] in (b"GIF89a", b"GIF87a")
    assert (out / "gg" / "fabrication" / "sheet_01.dxf").read_text().startswith("  0\nSECTION")
    html = (out / "ncp" / "report.html").read_text()
    assert "data:image/gif;base64," in html and "<svg" in html   # GIF and cut sheets inline
    assert "data:image/gif;base64," in (out / "gg" / "report.html").read_text()
    for k in ("gg", "ncp"):          # issue 30: the report under 2 MB (full demo: 1.66 MB)
        assert (out / k / "report.html").stat().st_size < 2_000_000
    assert not [p for p in out.parent.iterdir() if p.name.startswith(".")]  # no temporaries


def test_quick_demo_gg_alignment_sequence(quick_demo):
    # deployed net -> collapsed net (aligned.obj), lamella edges kept within 1 % in every state
    import numpy as np

    from gridshell.design.bundle import read_bundle
    from gridshell.render.sequence import read_sequence

    # (the physical path: every lamella's joint-to-joint arc lengths kept in every state; a
    # state whose joints disagree beyond 1 % of a segment is marked approximate)
    from gridshell.gg.path import segment_length_error

    _, out, s = quick_demo
    b = read_bundle(out / "gg")
    frames, loops = read_sequence(out / "gg")
    assert len(frames) == 5 and "5 states" in s["GG alignment"]
    np.testing.assert_array_equal(frames[0], b.net.joints)
    np.testing.assert_array_equal(frames[-1], b.aligned)
    z = np.load(out / "gg" / "sequence" / "strips.npz")
    assert len(z["t"]) == 5
    E = b.net.edges()
    ell0 = np.linalg.norm(b.net.joints[E[:, 1]] - b.net.joints[E[:, 0]], axis=1)
    for k, V in enumerate(frames):
        assert segment_length_error(z["X"][k], z["X"][0], z["lamella"], z["joint"]) < 1e-3
        ell = np.linalg.norm(V[E[:, 1]] - V[E[:, 0]], axis=1)
        if not z["approximate"][k]:
            assert np.max(np.abs(ell - ell0) / ell0) < 0.01, k
        else:
            assert z["bound"][k] > 0.01
    saved = json.loads((out / "demo.json").read_text())["gg"]
    assert saved["coverage"] > 95 and saved["frames"] == 5


def test_quick_demo_ncp_alignment_sequence(quick_demo):
    # the CNC sequence read back from the files: frame 0 is the deployed net, the last one the
    # aligned state, and the largest edge-length change over the states is the one reported
    import numpy as np

    from gridshell.design.bundle import read_bundle
    from gridshell.render.sequence import read_sequence

    _, out, s = quick_demo
    b = read_bundle(out / "ncp")
    frames, _ = read_sequence(out / "ncp")
    saved = json.loads((out / "demo.json").read_text())["ncp"]
    assert len(frames) == saved["frames"] == 5 and "5 states" in s["CNC alignment"]
    np.testing.assert_allclose(frames[0], b.net.joints, atol=1e-9)
    np.testing.assert_allclose(frames[-1], b.aligned, atol=1e-9)
    E = b.net.edges()
    ell0 = np.linalg.norm(frames[0][E[:, 1]] - frames[0][E[:, 0]], axis=1)
    worst = max(100 * np.max(np.abs(np.linalg.norm(V[E[:, 1]] - V[E[:, 0]], axis=1) - ell0)
                             / ell0) for V in frames)
    assert worst == pytest.approx(saved["sequence_length_error"], rel=1e-4, abs=1e-6)
    assert worst < 2
    # the strips of every state (issue 28): through the sequence's joints, at equilibrium
    # from the cut arcs; the check judges every state on them
    from gridshell.structure.states import read_strips

    strips = read_strips(out / "ncp", len(b.net.joints), len(b.net.lamellae))
    assert strips is not None and len(strips["t"]) == len(frames)
    on = strips["joint"] >= 0
    for f, V in enumerate(frames):
        np.testing.assert_allclose(strips["X"][f][on], V[strips["joint"][on]], atol=1e-9)
    st = json.loads((out / "ncp" / "structure.json").read_text())
    states = st["states"]
    assert states["physical_path"] and states["approximate"] == []
    weak = max(f["max_weak_curvature_per_m"] for f in states["frames"])
    u = [f["max_utilisation"] for f in states["frames"]]
    for f in states["frames"]:
        assert f["max_strong_curvature_per_m"] < 0.05 * weak, f
    assert u[-1] < 0.05 * u[0]                       # collapsed: flat, as cut
    assert u[0] == pytest.approx(st["max_utilisation_deployed"], rel=0.1)


def test_quick_demo_figures_meet_the_paper_bounds(quick_demo):
    _, out, s = quick_demo
    assert s["ok"] and s["output"] == str(out)
    for key in ("GG Delta_a [%]", "GG Delta_a arc length [%]", "CNC Delta_a post-optimized [%]",
                "CNC Delta_a traced [%]"):
        assert s[key]["mean"] < 1 and s[key]["max"] < 3, key
    assert s["CNC Delta_a post-optimized [%]"]["mean"] < s["CNC Delta_a traced [%]"]["mean"] / 8
    assert s["CNC Delta_l [%]"]["max"] < 1 and s["CNC Delta_n [%]"]["max"] < 1
    assert s["GG paper thresholds"].startswith("pass")
    assert s["CNC paper thresholds"].startswith("pass")
    assert s["verified from the files"] == "yes"
    assert s["GG cut files"].startswith("1 x 600 x 400 mm")
    saved = json.loads((out / "demo.json").read_text())
    assert saved["summary"]["GG Delta_a [%]"] == s["GG Delta_a [%]"]
    assert saved["ncp"]["fabrication"]["shape"] == "arc"
    assert saved["gg"]["fabrication"]["shape"] == "line"
    for part, key in (("gg", "GG cut files"), ("ncp", "CNC cut files")):   # sheets and use
        f = saved[part]["fabrication"]
        used = ", ".join(f"{100 * u:.1f}" for u in f["material_used_per_sheet"])
        assert s[key].startswith(f"{f['n_sheets']} x 600 x 400 mm ({used} % of the sheet area")
    # the 1 mm polypropylene strips are checked: structure.json, a line per design
    for part, key in (("gg", "GG strips 1 mm pp"), ("ncp", "CNC strips 1 mm pp")):
        r = json.loads((out / part / "structure.json").read_text())
        assert s[key].startswith(r["verdict"]) and r["section"]["thickness_mm"] == 1
        assert saved[part]["fabrication"]["structure"]["verdict"] == r["verdict"]


def test_demo_prints_a_one_screen_summary(tmp_path, capsys):
    assert main(["demo", "--quick", "--only", "gg", "-o", str(tmp_path / "d")]) == 0
    cap = capsys.readouterr()
    lines = cap.out.strip().splitlines()
    assert lines[0].startswith("gridshell demo (--quick)") and len(lines) <= 24
    assert any(ln.strip().startswith("GG Delta_a [%]") and "mean=" in ln for ln in lines)
    assert not any("CNC" in ln for ln in lines)
    assert "GG: designing" in cap.err and "writing report.html" in cap.err
    assert not (tmp_path / "d" / "ncp").exists()


def test_demo_refuses_a_directory_it_did_not_write(tmp_path, capsys):
    # as gg / phlw / ncp: an output problem (exit 5), found before any work
    (tmp_path / "keep.txt").write_text("mine")
    assert main(["demo", "--quick", "-o", str(tmp_path)]) == 5
    err = capsys.readouterr().err
    assert "not the output of an earlier run" in err and "manifest.json" in err
    assert "GG: designing" not in err
    assert [p.name for p in tmp_path.iterdir()] == ["keep.txt"]
    assert main(["demo", "--quick", "-o", str(tmp_path / "keep.txt")]) == 5
    assert "not a directory" in capsys.readouterr().err
    assert (tmp_path / "keep.txt").read_text() == "mine"


def test_a_failing_demo_leaves_the_previous_output(tmp_path, monkeypatch, capsys):
    out = tmp_path / "demo"
    out.mkdir()
    (out / demo.MARKER).write_text("{}")
    manifest.write(out, manifest.build(out, "demo"))  # an earlier demo's output

    def fail(*args, **kwargs):
        raise ConvergenceError("no convergence (test)")

    monkeypatch.setattr(demo, "_gg", fail)
    assert main(["demo", "--quick", "--only", "gg", "-o", str(out)]) == 4
    assert sorted(p.name for p in out.iterdir()) == [demo.MARKER, manifest.MANIFEST]
    assert [p.name for p in tmp_path.iterdir()] == ["demo"]          # no temporary left


@pytest.mark.slow
def test_quick_demo_reports_the_full_scale_snow_case(quick_demo):
    """The GG demo at 1:1 in spruce C24 under 1 kN/m2 (issue 28): deflection and the bolts'
    shear in the summary and, with their units, in report.html's equilibrium section."""
    code, out, summary = quick_demo
    eq = json.loads((out / "gg" / "equilibrium" / "equilibrium.json").read_text())["figures"]
    html = (out / "gg" / "report.html").read_text()
    section = html[html.index('<section id="equilibrium">'):]
    section = section[:section.index("</section>")]
    for label in ("largest deflection [mm]", "span / deflection",
                  "largest bolt shear (joint force) [N]", "snow load, total [kN]"):
        assert label in section, label
    assert f"{eq['deflection_max_mm']:.4g}"[:3] in section
    assert eq["snow_total_kN"] > 0 and eq["bolt_shear_max_N"] > 0
    assert "GG at 1:1 under snow" in json.dumps(summary) or "full_scale" in json.dumps(summary)


@pytest.mark.slow
def test_quick_demo_pictures_are_readable(quick_demo):
    """Issue 30: the states and frames at least 800 px wide (the GIF from the same frames)."""
    from PIL import Image

    from gridshell.render.figure import MIN_FRAME_PX

    _, out, _ = quick_demo
    for k in ("gg", "ncp"):
        for name in ("sequence/frame_000.png", "alignment.gif"):
            with Image.open(out / k / name) as im:
                assert im.width >= MIN_FRAME_PX, (k, name, im.size)
    with Image.open(out / "gg" / "states.png") as im:
        assert im.width >= 1.75 * MIN_FRAME_PX


# --- the README's output tables against a real run (issue 30: every file written, nothing else)
README = Path(__file__).resolve().parents[2] / "README.md"
_TICK = re.compile(r"`([^`\s]+)`")


def _table(heading: str) -> dict[str, str]:
    """``first cell -> row`` of the first table after the README line ``heading``."""
    text = README.read_text(encoding="utf-8")
    rows: dict[str, str] = {}
    header = True
    for line in text[text.index(heading):].splitlines()[1:]:
        if line.startswith("|---"):
            header = False
        elif line.startswith("|") and not header:
            first, rest = line.strip("|").split("|", 1)
            rows[first.strip()] = rest
        elif rows:
            break
    return rows


def _patterns(cell: str) -> list[str]:
    """The file names (``a.png``, ``sheet_NN.png``, ``delta_*.png``) and folders (``dir/``)
    a table cell names in backticks."""
    return [t.replace("NN", "[0-9][0-9]") for t in _TICK.findall(cell)
            if "." in t or t.endswith("/") or "*" in t]


def _files(folder: Path) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*") if p.is_file())


def _matches(pattern: str, rel: str) -> bool:
    if pattern.endswith("/"):
        return rel.startswith(pattern)
    return fnmatch.fnmatch(rel, pattern) or fnmatch.fnmatch(Path(rel).name, pattern)


def _check_row(patterns: list[str], files: list[str], where: str) -> None:
    unlisted = [f for f in files if not any(_matches(p, f) for p in patterns)]
    assert not unlisted, f"README {where}: written but not listed: {unlisted}"
    absent = [p for p in patterns if not any(_matches(p, f) for f in files)]
    assert not absent, f"README {where}: listed but not written: {absent}"


@pytest.mark.slow
def test_readme_output_tables_list_what_the_demo_writes(quick_demo):
    """The README's table of the demo's output and its table of the design bundle list every
    file the (quick) demo writes and nothing else; a pattern (``sequence/frame_*``,
    ``sheet_NN.png``, ``fabrication/``) stands for the files it matches."""
    _, out, _ = quick_demo
    demo_rows = _table("replaces `out/demo/` only when everything succeeded")
    bundle = [p for cell in _table("## The design bundle") for p in _patterns(cell)]
    assert {"`gg/`", "`phlw/`", "`ncp/`", "`demo.json`"} <= set(demo_rows)
    top = [p.name + "/" * p.is_dir() for p in out.iterdir()]
    _check_row([*(_patterns(k)[0] for k in demo_rows), "manifest.json"], top, "demo table")
    seen_bundle: set[str] = set()
    for key, cell in demo_rows.items():
        name = _patterns(key)[0]
        if not name.endswith("/"):
            continue
        files = _files(out / name)
        own = [*_patterns(cell), "manifest.json"]
        if "design bundle" in cell:        # the bundle's files: the design bundle's table
            own += bundle
            seen_bundle |= {p for p in bundle if any(_matches(p, f) for f in files)}
        else:
            _check_row(own, files, f"demo table, {name}")
            continue
        unlisted = [f for f in files if not any(_matches(p, f) for p in own)]
        assert not unlisted, f"README demo table, {name}: written but not listed: {unlisted}"
        absent = [p for p in _patterns(cell) if not any(_matches(p, f) for f in files)]
        assert not absent, f"README demo table, {name}: listed but not written: {absent}"
    never = [p for p in bundle if p not in seen_bundle]
    assert not never, f"README design bundle table: no bundle of the demo has {never}"
    with pytest.raises(AssertionError, match="not listed"):      # the check can fail
        _check_row(["a.png"], ["a.png", "b.png"], "x")
