"""Tests of gridshell.render.ribbons and gridshell.render.sequence on small synthetic bundles."""
from __future__ import annotations

import numpy as np
import pytest
from PIL import Image
from tests.helpers.render_cases import make_bundle, states_case, write_case

from gridshell.core.errors import InputError
from gridshell.render.ribbons import (FAMILY_COLOURS, ribbon_polygons, render_bundle,
                                      render_ribbons, view_angles)
from gridshell.render.sequence import read_sequence, render_bundle_sequence, sequence_files

SIZE = (320, 240)


def _image(path) -> np.ndarray:
    with Image.open(path) as im:
        assert im.format == "PNG"
        assert im.size == SIZE
        return np.asarray(im.convert("RGB"), float)


def _has_colour(img: np.ndarray, rgb, tol: float = 60.0) -> bool:
    """Some pixels close to ``rgb`` (0..1) up to shading (same hue, dimmed)."""
    c = np.asarray(rgb) * 255
    # shading scales the colour by k in [0.5, 1]: compare to the best k per pixel
    k = np.clip((img @ c) / (c @ c), 0.4, 1.0)
    d = np.linalg.norm(img - k[..., None] * c, axis=-1)
    return int((d < tol).sum()) > 50


def test_ribbon_offsets_tangent_and_normal():
    x = np.linspace(0, 1, 5)
    axis = np.stack([x, np.zeros_like(x), np.zeros_like(x)], axis=1)
    n = np.tile([0.0, 0.0, 1.0], (5, 1))
    flat = ribbon_polygons(axis, n, 0.2, tangent=True)
    assert flat.shape == (4, 4, 3)
    assert np.allclose(flat[..., 2], 0.0)  # GG: in the surface
    assert np.allclose(np.abs(flat[..., 1]), 0.1)
    up = ribbon_polygons(axis, n, 0.2, tangent=False)
    assert np.allclose(up[..., 1], 0.0)  # NCP: standing on the surface
    assert np.allclose(np.abs(up[..., 2]), 0.1)


def test_view_looks_at_the_broad_side_from_above():
    rng = np.random.default_rng(0)
    P = rng.uniform(-1, 1, (200, 3)) * [3.0, 1.0, 0.05]  # flat, long along x
    elev, azim = view_angles(P)
    assert elev == pytest.approx(35.0, abs=3.0)  # 90 - default tilt 55
    # the camera looks mostly across the long x extent (from -y or +y)
    assert abs(np.cos(np.radians(azim))) < 0.5


@pytest.mark.parametrize("kind", ["GG", "NCP"])
def test_render_ribbons_png(tmp_path, kind):
    b = make_bundle(kind)
    lams = b.net.lamellae
    out = render_ribbons(tmp_path / "r.png", [lam.axis for lam in lams],
                         [lam.family for lam in lams], b.surface_V, b.surface_F, b.net.joints,
                         kind=kind, width=0.12, size=SIZE, title="test")
    img = _image(out)
    assert img.std() > 10  # not blank
    assert _has_colour(img, FAMILY_COLOURS[1]) and _has_colour(img, FAMILY_COLOURS[3])
    assert not list(tmp_path.glob(".*"))  # atomic: no temporary file left


def _square(z: float, n: int = 1, half: float = 1.0):
    """A horizontal square ``[-half, half]^2`` at height ``z`` as an ``n x n`` quad grid."""
    from gridshell.geometry.grid import grid_quads

    t = np.linspace(-half, half, n + 1)
    X, Y = np.meshgrid(t, t, indexing="ij")
    return np.stack([X, Y, np.full_like(X, z)], axis=-1).reshape(-1, 3), grid_quads(n + 1, n + 1)


def _line(y: float, z: float, k: int = 30) -> np.ndarray:
    x = np.linspace(-0.8, 0.8, k)
    return np.stack([x, np.full(k, y), np.full(k, z)], axis=1)


@pytest.mark.parametrize("kind", ["GG", "NCP"])
def test_surface_hides_the_strips_behind_it(tmp_path, kind):
    """Two stacked opaque squares seen from above: the strip on the upper one shows, the strip
    on the lower one is hidden (a transparent surface or a per-collection sort shows both)."""
    V1, F1 = _square(0.0, 4)
    V2, F2 = _square(1.0, 4)
    V, F = np.concatenate([V1, V2]), np.concatenate([F1, F2 + len(V1)])
    corners = np.array([[-0.9, -0.9, 0.0], [0.9, 0.9, 1.0]])  # the drawn part: both squares
    out = render_ribbons(tmp_path / "r.png", [_line(0.0, 0.0), _line(0.3, 1.0)], [1, 3], V, F,
                         corners, kind=kind, width=0.1, thickness=0.01, size=SIZE,
                         view=(89.0, -90.0))
    img = _image(out)
    img[-50:, :130] = 255  # the legend's colour patches
    img[img.max(axis=2) < 80] = 255  # the joint dots (dark grey, close to a dimmed blue)
    assert _has_colour(img, FAMILY_COLOURS[3]), "the strip on the near surface is seen"
    assert not _has_colour(img, FAMILY_COLOURS[1]), "the strip behind the surface is hidden"


def test_strip_on_a_large_face_is_not_painted_over():
    """A strip near the far edge of one big face, seen obliquely: its mean depth is behind the
    face's, yet it lies on it and is seen (matplotlib's mean-depth order paints it over)."""
    import tempfile
    from pathlib import Path

    V, F = _square(0.0, 1)
    with tempfile.TemporaryDirectory() as d:
        out = render_ribbons(Path(d) / "r.png", [_line(0.7, 0.0)], [1], V, F, kind="GG",
                             width=0.1, thickness=0.01, size=SIZE, view=(30.0, -90.0))
        img = _image(out)
        img[-50:, :130] = 255  # the legend's colour patches
        assert _has_colour(img, FAMILY_COLOURS[1])


def test_render_bundle_title_says_the_real_strip_width(tmp_path, monkeypatch):
    import json

    import gridshell.render.ribbons as ribbons

    seen = {}
    monkeypatch.setattr(ribbons, "render_ribbons",
                        lambda path, *a, **kw: seen.update(kw) or Path(path))
    from pathlib import Path
    d = write_case(tmp_path / "b", "GG")
    render_bundle(d)
    assert seen["width"] == pytest.approx(0.2) and seen["thickness"] == pytest.approx(0.01)
    assert seen["title"].endswith("strips 200 x 10 mm (20 x 1 mm cut at 1:10)")
    (d / "fabrication").mkdir()
    (d / "fabrication" / "fabrication.json").write_text(json.dumps(
        {"params": {"width": 15.0, "thickness": 1.5, "scale": 0.05}}))
    render_bundle(d)
    assert seen["width"] == pytest.approx(0.3)
    assert "300 x 30 mm (15 x 1.5 mm cut at 1:20)" in seen["title"]


def test_render_bundle_writes_render_png(tmp_path):
    d = write_case(tmp_path / "b", "GG")
    out = render_bundle(d, size=SIZE)
    assert out == d / "render.png"
    assert _image(out).std() > 10


def test_render_rejects_bad_input(tmp_path):
    b = make_bundle()
    axes = [lam.axis for lam in b.net.lamellae]
    with pytest.raises(InputError, match="one family per lamella"):
        render_ribbons(tmp_path / "x.png", axes, [1], b.surface_V, b.surface_F)
    with pytest.raises(InputError, match="kind"):
        render_ribbons(tmp_path / "x.png", axes, [1] * len(axes), b.surface_V, b.surface_F,
                       kind="XY")
    with pytest.raises(InputError, match="output path"):
        render_bundle(b)
    assert not (tmp_path / "x.png").exists()


def test_sequence_frames_and_gif(tmp_path):
    d = write_case(tmp_path / "b", "NCP", sequence=True)
    assert [p.name for p in sequence_files(d)] == [f"frame_{k:03d}.obj" for k in range(3)]
    frames, F = read_sequence(d)
    assert len(frames) == 3 and F.shape == (9, 4)
    np.testing.assert_allclose(frames[-1], make_bundle("NCP").aligned)
    res = render_bundle_sequence(d, dpi=40)
    assert [p.name for p in res["frames"]] == [f"frame_{k:03d}.png" for k in range(3)]
    with Image.open(res["gif"]) as im:
        assert im.format == "GIF" and im.n_frames == 3 and im.info.get("loop") == 0


def test_png_bytes_crops_to_the_content():
    """One draw, cropped to the ink plus the pad: a black 40 x 20 px rectangle on a white
    200 x 100 px figure gives a (20 + 2 pad) x (40 + 2 pad) picture."""
    import io

    from gridshell.render.figure import png_bytes, pyplot

    fig = pyplot().figure(figsize=(2.0, 1.0), dpi=100)
    fig.patches.append(__import__("matplotlib").patches.Rectangle(
        (50, 30), 40, 20, transform=None, facecolor="k", edgecolor="none"))
    img = np.asarray(Image.open(io.BytesIO(png_bytes(fig, pad=5))).convert("RGB"))
    assert img.shape == (30, 50, 3)
    assert (img[5:-5, 5:-5] < 10).all() and (img[:4] > 245).all() and (img[:, -4:] > 245).all()


def test_sequence_frames_one_crop_and_gif_one_palette():
    """The frames share one size and one crop (content reaches near every side in some
    frame), and the GIF's frames decode to the PNGs' colours."""
    import io

    from gridshell.render.ncp_maps import _PAD, gif, sequence_frames

    frames, E, _, _ = states_case()
    pngs = sequence_frames(frames, E, title="t", dpi=50)
    imgs = [np.asarray(Image.open(io.BytesIO(b)).convert("RGB"), float) for b in pngs]
    assert len(pngs) == 3 and len({a.shape for a in imgs}) == 1
    ink = np.zeros(imgs[0].shape[:2], bool)
    for a in imgs:
        ink |= (a < 250).any(axis=2)
    ys, xs = np.nonzero(ink.any(axis=1))[0], np.nonzero(ink.any(axis=0))[0]
    h, w = ink.shape
    assert ys[0] <= _PAD and xs[0] <= _PAD and ys[-1] >= h - 1 - _PAD and xs[-1] >= w - 1 - _PAD
    assert not np.array_equal(imgs[0], imgs[-1])          # the states differ
    with Image.open(io.BytesIO(gif(pngs))) as im:
        assert im.n_frames == 3 and im.info.get("loop") == 0
        assert len(im.getpalette()) <= 3 * 256
        for k in range(3):
            im.seek(k)
            # 255 colours for antialiased lines: within a few levels of the PNG on average
            assert np.abs(np.asarray(im.convert("RGB"), float) - imgs[k]).mean() < 3.0


def test_sequence_missing(tmp_path):
    d = write_case(tmp_path / "b", "GG")
    assert sequence_files(d) == []
    with pytest.raises(InputError, match="no sequence"):
        read_sequence(d)


# ----------------------------------------------------------------------------- GG states


def test_state_images_share_one_crop_and_scale():
    from gridshell.render.state_sheet import state_images

    frames, E, fam, _ = states_case()
    imgs = state_images(frames, E, families=fam, dpi=60)
    assert len({im.size for im in imgs}) == 1
    a = [np.asarray(im, float) for im in imgs]
    # cropped: content reaches close to every side of the common box in some state
    ink = np.max([np.any(x < 200, axis=2) for x in a], axis=0)
    rows, cols = np.flatnonzero(ink.any(1)), np.flatnonzero(ink.any(0))
    assert rows[0] <= 12 and cols[0] <= 12
    assert rows[-1] >= ink.shape[0] - 13 and cols[-1] >= ink.shape[1] - 13
    # both family colours are drawn in the deployed state
    assert _has_colour(a[0], FAMILY_COLOURS[1]) and _has_colour(a[0], FAMILY_COLOURS[3])


def test_states_png_strip_and_sequence_pngs():
    import io

    from gridshell.render.state_sheet import sequence_pngs, state_images, states_png

    frames, E, fam, _ = states_case()
    with Image.open(io.BytesIO(states_png(frames, E, labels=["deployed", "t = 0.5",
                                                             "collapsed"], title="GG",
                                          families=fam, dpi=60))) as im:
        # two states per row, each at least MIN_FRAME_PX wide (issue 30: readable)
        from gridshell.render.figure import MIN_FRAME_PX

        assert im.width >= 1.75 * MIN_FRAME_PX          # margins and labels aside
        px = np.asarray(im.convert("L"), float)
    ink = px < 200                         # not a white page with small pictures in it
    rows, cols = np.flatnonzero(ink.any(1)), np.flatnonzero(ink.any(0))
    assert (cols[-1] - cols[0]) > 0.9 * px.shape[1] and (rows[-1] - rows[0]) > 0.8 * px.shape[0]
    pngs = sequence_pngs(frames, E, title="GG alignment", dpi=60)
    sizes = {Image.open(io.BytesIO(b)).size for b in pngs}
    assert len(pngs) == 3 and len(sizes) == 1 and min(w for w, _ in sizes) >= MIN_FRAME_PX
    with pytest.raises(InputError, match="labels"):
        states_png(frames, E, labels=["one"])
    with pytest.raises(InputError, match="edge families"):
        state_images(frames, E, families=fam[:3])
