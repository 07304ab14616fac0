"""Tests of the report's WebGL viewer (gridshell.render.viewer): the embedded scene against the
bundle's geometry, the bundled three.js, the page's self-containment, and - in headless
Chromium - no console errors, no network request, a canvas that is not blank and a slider that
changes the picture."""
from __future__ import annotations

import hashlib
import io
import json
import re
from pathlib import Path

import numpy as np
import pytest
from PIL import Image
from tests.helpers.render_cases import write_case

from gridshell.design.bundle import read_bundle
from gridshell.core.errors import InputError
from gridshell.render.report import write_report
from gridshell.design.section import DEFAULT_CUT, resolve_section
from gridshell.render.viewer import assets
from gridshell.render.viewer.scene import (build_scene, decode, strip_solids_vertices,
                                           strip_vertices)
from gridshell.geometry.strips3d import nearest_vertex_normals, strip_solid

VENDOR = Path(assets.__file__).parent / "vendor"


def _scene_of(html: str) -> dict:
    from gridshell.render.viewer.page import unpacked

    m = re.search(r'<script type="application/gzip" id="gridshell-scene">(.*?)</script>', html,
                  re.S)
    assert m, "the scene is embedded"
    return json.loads(unpacked(m.group(1)))


def _tri_areas(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    return 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]),
                                axis=1)


def _structure(d: Path, bundle) -> dict:
    """structure.json as 'gridshell check' writes it: utilisation per axis point."""
    lams = []
    for lam in bundle.net.lamellae:
        s = np.linspace(0.0, 1.0, len(lam.axis))
        u = (0.2 + 0.9 * s) if lam.family == 1 else np.full(len(s), 0.1)  # C1 rises to 1.1
        lams.append({"id": int(lam.id), "family": int(lam.family), "utilisation": u.tolist(),
                     "max_utilisation": float(u.max())})
    rec = {"lamellae": lams, "max_utilisation": 1.1, "verdict": "fail"}
    (d / "structure.json").write_text(json.dumps(rec), encoding="utf-8")
    return rec


@pytest.mark.parametrize("tangent", [True, False])
def test_strip_solids_vertices_equal_one_solid_per_axis(tangent):
    rng = np.random.default_rng(3)
    axes = [np.cumsum(rng.normal(size=(k, 3)), axis=0) for k in (2, 3, 9, 40)]
    normals = [rng.normal(size=(len(a), 3)) for a in axes]
    one = np.concatenate([strip_solid(a, n, 0.2, 0.01, tangent)[0]
                          for a, n in zip(axes, normals)])
    assert np.array_equal(strip_solids_vertices(axes, normals, 0.2, 0.01, tangent), one)
    with pytest.raises(InputError):
        strip_solids_vertices([axes[0][:1]], [normals[0][:1]], 0.2, 0.01, tangent)


@pytest.fixture()
def gg(tmp_path):
    return write_case(tmp_path / "gg", "GG", sequence=True)


def test_vendored_three_is_the_pinned_release():
    """The committed files are three@0.170.0's, unmodified (hashes in vendor/README.md)."""
    readme = (VENDOR / "README.md").read_text(encoding="utf-8")
    for name in ("three.module.min.js", "OrbitControls.js"):
        digest = hashlib.sha256((VENDOR / name).read_bytes()).hexdigest()
        assert f"{digest}  {name}" in readme, name
    assert "MIT License" in (VENDOR / "LICENSE-three.txt").read_text(encoding="utf-8")
    assert 'const t="170"' in (VENDOR / "three.module.min.js").read_text(encoding="utf-8")[:400]


def test_three_script_is_classic_and_complete():
    js = assets.three_script()
    assert not re.search(r"^\s*(import|export)\b", js, re.M)
    assert "export{" not in js and "from 'three'" not in js
    for name in ("WebGLRenderer", "BufferGeometry", "InstancedMesh", "MeshStandardMaterial",
                 "OrbitControls"):
        assert re.search(rf"\b{name}:", js), name
    assert not re.search(r"https?://", js) and not re.search(r"</script", js, re.I)


def test_section_from_fabrication_json_or_defaults(tmp_path, gg):
    from gridshell.fabrication.params import FabParams

    p = FabParams()
    assert (p.width, p.thickness, p.scale) == (DEFAULT_CUT["width"], DEFAULT_CUT["thickness"],
                                               DEFAULT_CUT["scale"])
    s = resolve_section(gg)
    assert s.source == "defaults"
    assert s.width_m == pytest.approx(0.2) and s.thickness_m == pytest.approx(0.01)
    assert s.text() == "200 x 10 mm (20 x 1 mm cut at 1:10)"
    (gg / "fabrication").mkdir()
    (gg / "fabrication" / "fabrication.json").write_text(json.dumps(
        {"params": {"width": 30.0, "thickness": 2.0, "scale": 0.05}}))
    s = resolve_section(gg)
    assert (s.width_m, s.thickness_m) == pytest.approx((0.6, 0.04))
    assert s.source.endswith("fabrication.json") and "1:20" in s.text()
    (gg / "fabrication" / "fabrication.json").write_text("{not json")
    with pytest.raises(InputError, match="fabrication.json is not a readable fabrication report"):
        resolve_section(gg)   # one error policy: a corrupt report is named, never skipped


def test_scene_decodes_to_the_bundle_geometry(gg):
    """Strip solids: wide faces ~ length x width (the real section), axes through the bundle's
    axes, joints and surface as stored, one strip array per state of the sequence."""
    html = write_report(gg).read_text(encoding="utf-8")
    S = _scene_of(html)
    assert "F" not in S["strips"]               # the viewer makes the faces
    S = build_scene(gg)
    assert {k: v for k, v in S.items() if k != "strips"} == \
        {k: v for k, v in _scene_of(html).items() if k != "strips"}
    b = read_bundle(gg)
    w, t = S["section"]["width_m"], S["section"]["thickness_m"]
    assert (w, t) == pytest.approx((0.2, 0.01))
    assert len(S["states"]) == 3 == len(S["strips"]["V"]) == len(S["joints"]["V"])
    F = decode(S["strips"]["F"], "u4").reshape(-1, 3).astype(np.int64)
    assert len(F) == S["strips"]["nf"]
    V0 = strip_vertices(S, 0)
    assert len(V0) == S["strips"]["nv"] and F.max() < len(V0)
    by_id = {lam.id: lam for lam in b.net.lamellae}
    for rec in S["lamellae"]:
        lam = by_id[rec["id"]]
        assert rec["family"] == lam.family
        sv = V0[rec["v0"]:rec["v0"] + rec["nv"]]
        sf = F[rec["f0"]:rec["f0"] + rec["nf"]] - rec["v0"]
        k = rec["samples"]
        assert rec["nv"] == 4 * k and rec["nf"] == 8 * (k - 1) + 4
        area = _tri_areas(sv, sf).sum()
        L = rec["length"]
        assert L == pytest.approx(lam.length, rel=1e-9)
        # two wide faces (2 L w), two edges (2 L t), two end caps (2 w t); chords: within 1 %
        assert area == pytest.approx(2 * L * (w + t) + 2 * w * t, rel=1e-2)
        centre = sv.reshape(k, 4, 3).mean(axis=1)
        # the centre line: the axis at equal steps of arc length, GG strips in two layers half
        # a thickness off it along the surface normal (C1 on its side, C3 on the other)
        seg = np.linalg.norm(np.diff(lam.axis, axis=0), axis=1)
        s = np.concatenate([[0], np.cumsum(seg)])
        want = np.stack([np.interp(np.linspace(0, s[-1], k), s, lam.axis[:, c])
                         for c in range(3)], axis=1)
        off = centre - want
        q = S["strips"]["quant"]                  # uint16 over the strips' box
        step = float(np.max(np.subtract(q["hi"], q["lo"]))) / q["steps"]
        assert np.allclose(np.linalg.norm(off, axis=1), t / 2, rtol=1e-3, atol=step)
        n = nearest_vertex_normals(want, b.surface_V, b.surface_F)
        side = np.sum(off * n, axis=1) / (t / 2)
        assert np.all(side > 0.95) if lam.family == 1 else np.all(side < -0.95)
    J = [decode(x, "f4").reshape(-1, 3) for x in S["joints"]["V"]]
    assert np.allclose(J[0], b.net.joints, atol=1e-6)
    assert np.allclose(J[-1], b.aligned, atol=1e-6)
    Vs = decode(S["surface"]["V"], "f4").reshape(-1, 3)
    Fs = decode(S["surface"]["F"], "u4").reshape(-1, 3)
    assert np.allclose(Vs, b.surface_V, atol=1e-6)
    from gridshell.measure.metrics import surface_area
    assert _tri_areas(Vs.astype(float), Fs.astype(np.int64)).sum() == pytest.approx(
        surface_area(b.surface_V, b.surface_F), rel=1e-6)
    # the last state: every strip near the aligned joints' line (the x axis)
    Vk = strip_vertices(S, -1).reshape(-1, 4, 3).mean(axis=1)
    assert np.abs(Vk[:, 1:]).max() < 1e-2 * L  # between joints: the carried axis (spline)
    # a lamella kept isometric (family 1 of this case: its joints at their arc lengths on the
    # line) keeps its section in the aligned state: the strip neither collapses nor stretches
    Vk = strip_vertices(S, -1)
    for rec in S["lamellae"]:
        if rec["family"] == 1:
            a = _tri_areas(Vk[rec["v0"]:rec["v0"] + rec["nv"]],
                           F[rec["f0"]:rec["f0"] + rec["nf"]] - rec["v0"]).sum()
            assert a == pytest.approx(2 * rec["length"] * (w + t) + 2 * w * t, rel=0.03)


def test_scene_delta_a_matches_the_metrics(gg):
    from gridshell.measure.metrics import alignability_error

    S = build_scene(gg)
    b = read_bundle(gg)
    da = 100 * alignability_error(b.net.joints, b.net.loops)
    assert S["delta_a"]["max"] == pytest.approx(da.max())
    assert np.array_equal(decode(S["loops"]["F"], "u4").reshape(-1, 4), b.net.loops)
    assert np.allclose(decode(S["loops"]["delta_a"], "f4"), da, rtol=1e-6, atol=1e-7)
    jda = decode(S["joints"]["delta_a"], "f4")
    for j in range(len(b.net.joints)):
        near = [da[i] for i, loop in enumerate(b.net.loops) if j in loop]
        assert jda[j] == pytest.approx(max(near), rel=1e-5, abs=1e-6)
    values = decode(S["scalars"]["delta_a"], "f4")
    assert len(values) == sum(r["samples"] for r in S["lamellae"])
    assert values.min() >= 0 and values.max() <= da.max() * (1 + 1e-5)
    assert "utilisation" not in S["scalars"] and not S["has_structure"]


def test_scene_utilisation_from_structure_json(gg):
    b = read_bundle(gg)
    _structure(gg, b)
    S = build_scene(gg)
    assert S["has_structure"]
    u = decode(S["scalars"]["utilisation"], "f4")
    off = 0
    for rec in S["lamellae"]:
        k = rec["samples"]
        seg = u[off:off + k]
        off += k
        if rec["family"] == 1:  # 0.2 + 0.9 s along the axis: ends 0.2 and 1.1, increasing
            assert seg[0] == pytest.approx(0.2, abs=1e-6)
            assert seg[-1] == pytest.approx(1.1, abs=1e-6)
            assert np.all(np.diff(seg) >= -1e-6)
            assert rec["max_utilisation"] == pytest.approx(1.1)
        else:
            assert np.allclose(seg, 0.1)
    html = write_report(gg).read_text(encoding="utf-8")
    assert _scene_of(html)["has_structure"] is True
    (gg / "structure.json").write_text('{"lamellae": 3}')
    with pytest.raises(InputError, match="structure.json"):
        build_scene(gg)


@pytest.mark.parametrize("kind", ["GG", "NCP"])
def test_report_page_is_self_contained_and_bounded(tmp_path, kind):
    d = write_case(tmp_path / kind, kind, sequence=True)
    html = write_report(d).read_text(encoding="utf-8")
    assert not re.search(r"https?://", html, re.I), "no http(s) URL anywhere"
    assert not re.search(r"<(link|iframe|embed|object)\b", html, re.I)
    assert not re.search(r"<script[^>]*\bsrc=", html, re.I)
    # three.js has loaders (fetch) the viewer never calls; the viewer's own script loads nothing
    assert not re.search(r"\b(fetch|XMLHttpRequest|import|Loader|WebSocket)\b",
                         assets.viewer_script())
    assert html.count("<script") == 3  # scene JSON, three.js, viewer
    size = len(html.encode("utf-8"))
    three = (VENDOR / "three.module.min.js").stat().st_size
    assert size < three + 600_000, size  # the small case: the library and little else
    S = _scene_of(html)
    assert S["kind"] == kind and S["tangent"] == (kind == "GG")


def test_scene_without_sequence_has_deployed_and_aligned(tmp_path):
    d = write_case(tmp_path / "gg", "GG")
    S = build_scene(d)
    assert S["states"] == ["deployed", "aligned"]


def test_long_sequence_is_thinned_keeping_both_ends(tmp_path):
    from tests.helpers.render_cases import make_bundle, sequence_extra

    from gridshell.design.bundle import write_bundle
    from gridshell.render.viewer.scene import MAX_STATES

    b = make_bundle("GG")
    d = write_bundle(tmp_path / "gg", b, extra=sequence_extra(b, frames=MAX_STATES + 15))
    S = build_scene(d)
    K = MAX_STATES + 14
    assert len(S["states"]) == MAX_STATES == len(S["strips"]["V"]) == len(S["joints"]["V"])
    assert S["states"][0] == f"state 0/{K} (deployed)"
    assert S["states"][-1] == f"state {K}/{K} (aligned)"
    assert np.allclose(decode(S["joints"]["V"][-1], "f4").reshape(-1, 3), b.aligned, atol=1e-6)


# ---- in a browser ---------------------------------------------------------------------------

def _blank(png: bytes) -> tuple[bool, float]:
    img = np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), float)
    return float(img.std(axis=(0, 1)).max()) < 4.0, float(img.std())


@pytest.mark.browser
def test_report_in_headless_chromium(tmp_path):
    """report.html from file://: no console error, no network request, a canvas that is not
    blank; moving the slider (keyboard End on the focused slider) changes the picture."""
    from tests.helpers.headless import Browser, find_chromium

    exe, reason = find_chromium()
    if exe is None:
        pytest.skip(reason)
    d = write_case(tmp_path / "gg", "GG", sequence=True)
    _structure(d, read_bundle(d))
    page = write_report(d)
    br = Browser(exe, tmp_path / "profile")
    try:
        br.call("Page.navigate", url=page.resolve().as_uri())
        br.wait_event("Page.loadEventFired")
        br.wait_for("document.getElementById('gridshell-viewer').dataset.ready === '1'")
        rect = br.evaluate("(() => {const c = document.querySelector('#gridshell-viewer canvas');"
                           "c.scrollIntoView(); const r = c.getBoundingClientRect();"
                           "return {x: r.x + scrollX, y: r.y + scrollY, width: r.width,"
                           " height: r.height};})()")
        assert rect["width"] > 300 and rect["height"] > 300
        before = br.screenshot(rect)
        blank, spread = _blank(before)
        assert not blank, f"the canvas is blank (pixel spread {spread:.1f})"
        (tmp_path / "before.png").write_bytes(before)
        # the model fills most of its canvas (issue 30): what differs from the background
        # spans most of the width or the height
        img = np.asarray(Image.open(io.BytesIO(before)).convert("RGB"), float)
        ink = np.abs(img - np.array([0xf4, 0xf5, 0xf7], float)).max(axis=2) > 12
        ys = np.nonzero(ink.mean(axis=1) > 0.01)[0]     # rows / columns the model crosses
        xs = np.nonzero(ink.mean(axis=0) > 0.01)[0]
        fx, fy = (xs[-1] - xs[0]) / img.shape[1], (ys[-1] - ys[0]) / img.shape[0]
        assert max(fx, fy) > 0.7 and max(fx, fy) < 0.99, \
            f"the model spans {100 * fx:.0f} % x {100 * fy:.0f} % of the canvas"
        br.evaluate("document.querySelector('[data-control=state]').focus()")
        br.key("End", 35)
        assert br.evaluate("document.querySelector('[data-control=state]').value") == "2"
        assert br.evaluate("document.querySelector('.gv-state').textContent").startswith(
            "state 2/2")
        after = br.screenshot(rect)
        a = np.asarray(Image.open(io.BytesIO(before)).convert("RGB"), float)
        b = np.asarray(Image.open(io.BytesIO(after)).convert("RGB"), float)
        changed = float(np.mean(np.abs(a - b).max(axis=2) > 30))
        assert changed > 0.01, f"the slider changed {100 * changed:.2f} % of the pixels"
        # colour by utilisation: the picture changes again
        br.evaluate("(() => {const s = document.querySelector('[data-control=colour]');"
                    "s.value = 'utilisation'; s.dispatchEvent(new Event('change'));})()")
        util = np.asarray(Image.open(io.BytesIO(br.screenshot(rect))).convert("RGB"), float)
        assert float(np.mean(np.abs(util - b).max(axis=2) > 30)) > 0.005
        # hiding both families and the joints leaves the (aligned, surface-less) view empty
        br.evaluate("document.querySelectorAll('[data-layer]').forEach(b => {"
                    "if (b.checked && b.dataset.layer !== 'surface') b.click();})")
        empty = br.screenshot(rect)
        assert _blank(empty)[0], "toggles hide the strips and the joints"
        problems = br.problems()
        requests = [u for u in br.requests() if not u.startswith(("file:", "data:", "blob:"))]
    finally:
        br.close()
    assert not problems, problems
    assert not requests, requests


def test_strip_faces_follow_from_the_samples_alone(gg):
    """The page leaves the strips' faces out (the viewer makes them from each lamella's
    samples, as strip_solid_faces does): the scene's faces are exactly those."""
    from gridshell.geometry.strips3d import strip_solid_faces

    S = build_scene(gg)
    F = decode(S["strips"]["F"], "u4").reshape(-1, 3).astype(np.int64)
    for rec in S["lamellae"]:
        k = rec["samples"]
        assert rec["nv"] == 4 * k and rec["nf"] == 8 * (k - 1) + 4
        np.testing.assert_array_equal(F[rec["f0"]:rec["f0"] + rec["nf"]],
                                      strip_solid_faces(k) + rec["v0"])
    assert sum(r["nf"] for r in S["lamellae"]) == S["strips"]["nf"] == len(F)
