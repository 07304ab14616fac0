"""The fast paths of the fabrication stage (issue 17) against the straightforward ones they
replace: the nesting's per-run profile look-ups against the sliding windows over every
column (bit for bit, on the drop passes of straight and curved parts), the layout of a whole
nesting with the fast look-ups switched off, and the Hershey stroke joining against
np.allclose."""
from __future__ import annotations

import numpy as np
import pytest
from tests.helpers.fab_cases import make_bundle

from gridshell.fabrication import FabParams
from gridshell.fabrication import nesting
from gridshell.fabrication.labels import _font
from gridshell.fabrication.part import build_part
from gridshell.fabrication.strips import strips_from_bundle


def _parts(kind, nr, nc, **kw):
    params = FabParams(**kw)
    return [build_part(s, params) for s in strips_from_bundle(make_bundle(kind, nr=nr, nc=nc), params)
            ], params


def _slow(sheet, s, off):
    view = np.lib.stride_tricks.sliding_window_view
    nb = len(s.low)
    hi = (view(sheet.top, nb, axis=1)[:, off] - s.low).max(axis=2)
    lo = (view(sheet.bot, nb, axis=1)[:, off] - s.up).min(axis=2)
    return hi, lo


@pytest.mark.parametrize("kind", ["GG", "CNC"])
def test_profile_lookups_equal_the_sliding_windows(kind, monkeypatch):
    parts, params = _parts(kind, 5, 5)
    calls = []
    fast = nesting._Sheet._profiles

    def both(self, s, off):
        got = fast(self, s, off)
        want = _slow(self, s, off)
        calls.append(len(s.runs_low) + len(s.runs_up) <= len(s.low) // 4)
        for g, w in zip(got, want):
            np.testing.assert_array_equal(g, w)
        return got

    monkeypatch.setattr(nesting._Sheet, "_profiles", both)
    monkeypatch.setattr(nesting, "_rows_best", lambda *a, **k: None)   # drop passes only
    monkeypatch.setattr(nesting, "RASTER", [])
    nesting.nest(parts, params)
    assert calls and any(calls) == (kind == "GG")   # straight strips: the run look-ups


def test_layout_unchanged_without_the_fast_lookups(monkeypatch):
    parts, params = _parts("GG", 6, 6)
    monkeypatch.setattr(nesting, "_rows_best", lambda *a, **k: None)   # drop passes only
    a = nesting.nest(parts, params)
    monkeypatch.setattr(nesting._Sheet, "_profiles",
                        lambda self, s, off: _slow(self, s, off))
    b = nesting.nest(parts, params)
    assert a.n_sheets == b.n_sheets and a.sheet_of == b.sheet_of
    for p, q in zip(a.parts, b.parts):
        np.testing.assert_array_equal(p.outline.V, q.outline.V)


def test_stroke_joining_matches_allclose():
    f, _, _ = _font()
    from gridshell.fabrication.labels import _unit_strokes
    for text in ["L12", "3,17", "L40-S2", "0123456789"]:
        lines, _ = _unit_strokes(text)
        segs = np.array(list(f.lines_for_text(text)), float).reshape(-1, 2, 2)
        # consecutive segments joined exactly where np.allclose says their ends meet
        joins = sum(np.allclose(a, b) for a, b in zip(segs[1:, 0], segs[:-1, 1]))
        assert len(lines) == len(segs) - joins
        assert sum(len(L) for L in lines) == len(segs) + len(lines)


def _entities_text(doc) -> str:
    import io
    buf = io.StringIO()
    doc.write(buf)
    text = buf.getvalue()
    return text[text.index("ENTITIES"):text.index("OBJECTS")]


@pytest.mark.parametrize("kind", ["GG", "CNC"])
def test_dxf_entities_equal_point_by_point_polylines(kind):
    """The sheet document's ENTITIES section equals the one written through
    ``add_lwpolyline(points.tolist())`` point by point, byte for byte."""
    import ezdxf

    from gridshell.fabrication import dxf

    parts, params = _parts(kind, 4, 5)
    layout = nesting.nest(parts, params)
    sp = layout.on_sheet(0)
    assert any(len(p.engrave) for p in sp)
    fast = dxf.sheet_document(sp, layout.sheet, params)

    def slow(msp, pts, dxfattribs, closed=False):
        pts = np.asarray(pts, float)
        fmt = "xyb" if pts.shape[1] == 3 else "xy"
        return msp.add_lwpolyline(pts.tolist(), format=fmt, close=closed,
                                  dxfattribs=dxfattribs)

    orig = dxf.add_polyline
    try:
        dxf.add_polyline = slow
        ref = dxf.sheet_document(sp, layout.sheet, params)
    finally:
        dxf.add_polyline = orig
    assert _entities_text(fast) == _entities_text(ref)
    assert ezdxf.__version__    # (the comparison holds for the installed ezdxf)


def test_svg_polylines_equal_numpy_formatting():
    """Engraved polylines formatted from Python floats equal those formatted from the
    numpy rows (the straightforward loop), character for character."""
    from gridshell.fabrication import svg

    parts, params = _parts("GG", 4, 5)
    layout = nesting.nest(parts, params)
    sp = layout.on_sheet(0)
    text = svg.sheet_svg(sp, layout.sheet, params)
    H = layout.sheet[1]
    for p in sp:
        for L in p.engrave:
            pts = " ".join(f"{svg._f(x)},{svg._f(H - y)}" for x, y in L)
            assert f'points="{pts}"' in text


@pytest.mark.parametrize("kind", ["GG", "CNC"])
def test_drop_passes_stopped_early_give_the_same_layout(kind, monkeypatch):
    """The last pass of each drop strategy stops once it cannot win: same layout as running
    every pass to its end."""
    parts, params = _parts(kind, 6, 6)
    monkeypatch.setattr(nesting, "_rows_best", lambda *a, **k: None)   # drop passes only
    monkeypatch.setattr(nesting, "RASTER", [])
    a = nesting.nest(parts, params)
    full = nesting._nest_once
    stopped = []

    def never_stop(*args, beat=None, **kw):
        stopped.append(beat is not None and full(*args, beat=beat, **kw) is None)
        return full(*args, **kw)

    monkeypatch.setattr(nesting, "_nest_once",
                        lambda *args: never_stop(*args[:7], beat=args[7] if len(args) > 7
                                                 else None))
    b = nesting.nest(parts, params)
    assert a.n_sheets == b.n_sheets and a.sheet_of == b.sheet_of
    for p, q in zip(a.parts, b.parts):
        np.testing.assert_array_equal(p.outline.V, q.outline.V)
    assert any(stopped) == (kind == "CNC")   # (the GG case: one pass reaches the floor)


def test_png_level_keeps_the_pixels(tmp_path, monkeypatch):
    """The sheet previews and the plan at zlib level 3: the same pixels (and metadata) as
    at PIL's default level 6."""
    from PIL import Image

    from gridshell.fabrication import plan, preview

    parts, params = _parts("GG", 4, 5)
    layout = nesting.nest(parts, params)
    net = make_bundle("GG", nr=4, nc=5).net
    files = {}
    for level in (preview.PNG_LEVEL, 6):
        monkeypatch.setattr(preview, "PNG_LEVEL", level)
        d = tmp_path / str(level)
        preview.write_sheet_png(d / "s.png", layout.on_sheet(0), layout.sheet, params, "t")
        plan.write_plan(d / "p.png", d / "p.svg", net, "t")
        files[level] = [d / "s.png", d / "p.png"]
    for a, b in zip(files[3], files[6]):
        assert a.read_bytes() != b.read_bytes()           # the level was applied
        ia, ib = Image.open(a), Image.open(b)
        assert ia.info == ib.info
        np.testing.assert_array_equal(np.asarray(ia), np.asarray(ib))


def test_line_axis_one_point_equals_the_array_path():
    from gridshell.fabrication.axis import LineAxis

    ax = LineAxis()
    for s, t in [(0.0, 0.0), (12.25, -3.5), (np.float64(7.1), 2.0), (-0.0, 1e-300)]:
        got, want = ax.point(s, t), ax.point(np.array(s), np.array(t))
        assert got.dtype == want.dtype and got.shape == want.shape == (2,)
        np.testing.assert_array_equal(got, want)
        np.testing.assert_array_equal(ax.tangent(s), ax.tangent(np.array(s)))


def test_rows_plan_placed_as_the_sheets_would_place_it():
    """A rows-and-columns plan is placed without building sheet profiles: the same parts and
    moves (turned parts included) as adding each shape to its sheet, and no shape's drop
    profiles are made for it."""
    parts, params = _parts("GG", 6, 6)
    W, H = params.sheet
    Lx, Ly, g = max(W, H), min(W, H), params.gap
    shapes = [nesting._shapes(p, False) for p in parts]
    best = nesting._rows_best(parts, shapes, Lx, Ly, g)
    assert best is not None
    plan = best[2]
    assert all("_profile" not in s[0].__dict__ for s in shapes)    # sizes only so far
    n, placed = nesting._place_plan(shapes, plan)
    sheets = [nesting._Sheet(Lx, Ly, g) for _ in range(n)]
    assert n == max(k for k, *_ in plan) + 1
    for i, (k, x, y, turned) in enumerate(plan):
        s = nesting._shape(shapes[i][0].part, np.pi / 2, False) if turned else shapes[i][0]
        part, motion = sheets[k].add(s, float(x), float(y))
        got_k, (got_part, got_motion) = placed[i]
        assert got_k == k and got_motion == motion
        np.testing.assert_array_equal(got_part.outline.V, part.outline.V)
        np.testing.assert_array_equal(nesting._moved(placed[i][1]).outline.V,
                                      part.moved(motion).outline.V)


def test_hole_circles_buffered_at_once_equal_one_by_one():
    """The material of a part (outline less its holes) from the circles buffered at once is
    the one of Point(c).buffer(r, 32) one by one, bit for bit."""
    import shapely
    from shapely.geometry import Point
    from shapely.ops import unary_union

    parts, params = _parts("GG", 5, 5)
    assert any(len(p.holes) for p in parts)
    for p in parts:
        if not len(p.holes):
            continue
        one = unary_union([Point(c).buffer(params.hole / 2, 32) for c in p.holes])
        once = shapely.union_all(shapely.buffer(shapely.points(np.asarray(p.holes, float)),
                                                params.hole / 2, quad_segs=32))
        assert one.wkb == once.wkb


def test_sheet_preview_description_names_the_colours_drawn(tmp_path):
    """The preview's PNG ``Description`` names each layer's colour, and that colour (the
    layer table's RGB, read as a colour name by matplotlib's CSS table) is in the picture:
    it once said ENGRAVE black while engraving was drawn green."""
    from matplotlib.colors import to_rgb
    from PIL import Image

    from gridshell.fabrication import preview
    from gridshell.fabrication.layers import LAYERS

    parts, params = _parts("GG", 4, 5)
    layout = nesting.nest(parts, params)
    preview.write_sheet_png(tmp_path / "s.png", layout.on_sheet(0), layout.sheet, params, "t")
    img = Image.open(tmp_path / "s.png")
    said = dict(item.split() for item in
                img.info["Description"].split(": ", 1)[1].split(";")[0].split(", "))
    assert set(said) == set(LAYERS)
    css = {"green": "lime"}          # CSS "green" is (0, 128, 0); ACI 3 is (0, 255, 0)
    pixels = {tuple(p) for p in np.asarray(img.convert("RGB")).reshape(-1, 3)}
    for layer, name in said.items():
        rgb = LAYERS[layer][1]
        assert tuple(round(255 * c) for c in to_rgb(css.get(name, name))) == rgb, (layer, name)
        if layer != "SCORE":         # a GG strip has no score lines; cuts and labels it has
            assert rgb in pixels, layer


def _unit_strokes_by_lines(text):
    """The stroke polylines of ``text`` the straightforward way: every segment of the
    library's ``lines_for_text``, consecutive ones joined where ``np.allclose`` says they
    meet (the code before the glyphs were composed)."""
    f, y0, cap = _font()
    segs = np.array(list(f.lines_for_text(text)), float).reshape(-1, 2, 2)
    if len(segs) == 0:
        return (), 0.0
    segs[..., 1] -= y0
    segs /= cap
    x0, x1 = segs[..., 0].min(), segs[..., 0].max()
    segs[..., 0] -= x0
    lines, cur = [], segs[0].tolist()
    for a, b in segs[1:].tolist():
        if np.allclose(a, cur[-1]):
            cur.append(b)
        else:
            lines.append(np.array(cur))
            cur = [a, b]
    lines.append(np.array(cur))
    return tuple(lines), float(x1 - x0)


def _label_texts():
    """Texts as the labels write them (names, pieces, splices, neighbour lists) and
    every printable character, alone, in pairs and in random strings (and characters the
    font lacks)."""
    rng = np.random.default_rng(7)
    chars = [chr(c) for c in range(32, 128)]
    texts = ["", " ", "L", "S", "-", "/", ",", "0123456789", "L0", "L12", "L12-1/2",
             "L40-S2", "L7-S13", "3,17", "12,40,7", "1,2,3,4", "L1-2/3", "L99-10/12",
             "é", "L1é2", "\n", "L 1", "  L1  "]
    texts += [f"L{i}" for i in range(120)] + [f"L{i}-{j}/{k}" for i in range(0, 60, 7)
                                              for k in (2, 3) for j in range(1, k + 1)]
    texts += [f"L{i}-S{j}" for i in range(0, 60, 9) for j in range(1, 4)]
    texts += [",".join(str(v) for v in rng.integers(0, 200, n)) for n in range(1, 8)
              for _ in range(8)]
    texts += chars + [a + b for a in "L0S,-/1" for b in chars]
    texts += ["".join(rng.choice(chars, n)) for n in range(1, 20) for _ in range(5)]
    return texts


def test_glyph_composed_strokes_equal_the_library_lines():
    """The labels' stroke polylines composed from cached glyphs equal, bit for bit (same
    arrays, same line breaks), those from the library's ``lines_for_text`` joined
    segment by segment with np.allclose."""
    from gridshell.fabrication.labels import _unit_strokes

    for text in _label_texts():
        lines, length = _unit_strokes(text)
        want, want_length = _unit_strokes_by_lines(text)
        assert length == want_length and np.float64(length).tobytes() == \
            np.float64(want_length).tobytes(), text
        assert len(lines) == len(want), text
        for L, W in zip(lines, want):
            assert L.dtype == W.dtype and L.shape == W.shape, text
            assert L.tobytes() == W.tobytes(), text


def _fullest_by_arrays(lengths, cap):
    """:func:`gridshell.fabrication.rows.fullest` the straightforward way: the reachable sums as a
    boolean array per item (the code before the bit sets)."""
    from gridshell.fabrication.rows import ROW_UNIT

    units = np.ceil(lengths / ROW_UNIT - 1e-9).astype(int)
    c = int(np.floor(cap / ROW_UNIT + 1e-9)) - units[0]
    if c < 0:
        return []
    reach = np.zeros(c + 1, bool)
    reach[0] = True
    history = []
    for u in units[1:]:
        history.append(reach.copy())
        if u <= c:
            reach[u:] |= history[-1][:c + 1 - u]
    total = int(np.flatnonzero(reach).max())
    chosen = [0]
    for k in range(len(units) - 1, 0, -1):
        if not history[k - 1][total]:
            chosen.append(k)
            total -= units[k]
    return sorted(chosen)


def test_fullest_bit_sets_choose_as_the_boolean_arrays():
    """The row filling's subset sum over int bit sets picks the same items as over boolean
    arrays (random strip lengths, caps from below the first to above the sum, ties)."""
    from gridshell.fabrication.rows import fullest

    rng = np.random.default_rng(3)
    cases = 0
    for n in (1, 2, 3, 5, 8, 13, 30, 45):
        for _ in range(12):
            L = np.round(rng.uniform(5.0, 300.0, n), rng.integers(0, 4))
            if rng.random() < 0.3:
                L[rng.integers(0, n, n // 2 + 1)] = L[0]          # equal lengths
            for cap in (L[0] - 1.0, L[0], L[0] + 0.05, 0.5 * L.sum(), L.sum(),
                        L.sum() + 7.0, rng.uniform(L[0], 600.0)):
                got = fullest(L, float(cap))
                assert got == _fullest_by_arrays(L, float(cap)), (L, cap)
                cases += bool(got)
    assert cases > 300


@pytest.mark.parametrize("kind,kw", [("GG", {}), ("CNC", {"kerf": 0.2}),
                                     ("NCP", {"joints": "slots"}),
                                     ("CNC", {"joints": "marks", "scale": 0.2})])
def test_parts_built_at_once_equal_part_by_part(kind, kw, monkeypatch):
    """build_parts' material polygons, areas and labels' safe regions, made for all parts
    at once by shapely's vectorized functions, equal those of the part-by-part code (outline
    polygon less the union of its hole circles, its area, ``buffer(-0.5)``) bit for bit."""
    import shapely
    from shapely.geometry import Polygon

    from gridshell.fabrication import part as part_mod

    params = FabParams(**kw)
    strips = strips_from_bundle(make_bundle(kind, nr=5, nc=6), params)
    seen = []
    label = part_mod.strip_labels

    def spy(strip, params, material, safe=None):
        seen.append((material, safe))
        return label(strip, params, material, safe)

    monkeypatch.setattr(part_mod, "strip_labels", spy)
    parts = part_mod.build_parts(strips, params)
    assert len(seen) == len(parts) == len(strips)
    for p, (mat, safe) in zip(parts, seen):
        ref = Polygon(p.nominal.flatten(params.tolerance))
        if len(p.holes):
            circles = shapely.buffer(shapely.points(np.asarray(p.holes, float)),
                                     params.hole / 2, quad_segs=32)
            ref = ref.difference(shapely.union_all(circles))
        assert mat.wkb == ref.wkb
        assert p.area == float(ref.area)
        assert safe is not None and safe.wkb == ref.buffer(-0.5).wkb
    assert any(len(p.holes) for p in parts) == (params.joints == "hole")
