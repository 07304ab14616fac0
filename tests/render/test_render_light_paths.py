"""The picture's polygons handed to Agg as light objects (:class:`painter._Polygon`: only the
attributes Agg reads of a path) paint the pixels, and write the bytes, of the same polygons
as matplotlib ``Path`` objects: for strips lying on (GG) and standing on (NCP, CNC, AA) the
surface, paper and 4x designs, and the options of :func:`render_ribbons`."""
from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest

from gridshell.render.painter import Camera, Painter, _Polygon, _polygon_type
from gridshell.render.ribbons import render_bundle, render_ribbons

from tests.helpers.render_cases import make_bundle  # noqa: E402

SIZE = (300, 225)


def _pixels(path: Path) -> np.ndarray:
    from PIL import Image

    return np.asarray(Image.open(path))


def _light_and_paths(monkeypatch, tmp_path: Path, render) -> tuple[bytes, bytes]:
    """``render(path)`` as the tool draws (light polygons, checked to be in use), then with
    every polygon a matplotlib ``Path``: the two PNG files' bytes, their pixels equal."""
    original = Painter.collection
    used = []

    def light(self, *args, **kwargs):
        coll = original(self, *args, **kwargs)
        paths = coll.get_paths()
        used.append(any(isinstance(paths[i], _Polygon) for i in range(min(len(paths), 50))))
        return coll

    def matplotlib_paths(self, *args, agg_only=False, **kwargs):
        coll = original(self, *args, **kwargs)
        paths = coll.get_paths()
        assert not any(isinstance(paths[i], _Polygon) for i in range(len(paths)))
        return coll

    monkeypatch.setattr(Painter, "collection", light)
    a = render(tmp_path / "light.png")
    monkeypatch.setattr(Painter, "collection", matplotlib_paths)
    b = render(tmp_path / "paths.png")
    monkeypatch.setattr(Painter, "collection", original)
    assert used == [True]
    pa, pb = _pixels(a), _pixels(b)
    assert pa.std() > 10                                # something was drawn
    assert pa.shape == pb.shape and np.array_equal(pa, pb)
    return a.read_bytes(), b.read_bytes()


def _axes_of(b):
    return [lam.axis for lam in b.net.lamellae], [lam.family for lam in b.net.lamellae]


OPTIONS = {
    "default": {},
    "from above, no title": {"view": (89.0, -90.0), "title": None},
    "no joints": {"joints": None},
    "thinned": {"max_points": 9, "max_faces": 20, "dpi": 50},
    "section": {"width": 0.3, "thickness": 0.05},
    "colours": {"colours": True, "colorbar": ("viridis", "utilisation")},
}


@pytest.mark.parametrize("kind", ["GG", "NCP"])   # strips lying on, standing on the surface
@pytest.mark.parametrize("option", list(OPTIONS))
def test_light_polygons_paint_the_pixels_of_paths(monkeypatch, tmp_path, kind, option):
    b = make_bundle(kind)
    axes, fams = _axes_of(b)
    kw = dict(OPTIONS[option])
    joints = kw.pop("joints", b.net.joints)
    if kw.pop("colours", False):
        rng = np.random.default_rng(3)
        kw["colours"] = [rng.uniform(0.0, 1.0, (len(a), 3)) for a in axes]
    kw.setdefault("title", f"{kind} {option}")

    def render(path):
        return render_ribbons(path, axes, fams, b.surface_V, b.surface_F, joints, kind=kind,
                              size=SIZE, **kw)

    light, paths = _light_and_paths(monkeypatch, tmp_path, render)
    assert light == paths


@pytest.fixture(scope="module")
def designed():
    """The benchmark's NCP (AA) pseudosphere bundle at paper size (10 curves per family) and
    4x (20), and a GG bundle of a hill."""
    from tests.helpers.gg_cases import hill_grid
    from tests.helpers.ncp_cases import pseudosphere

    from gridshell.api import design_gg, design_ncp
    from gridshell.geometry.grid import grid_quads

    out = {f"NCP {c}": design_ncp(pseudosphere(), mode="aa", curves=c).bundle for c in (10, 20)}
    P = hill_grid(24, 16)
    out["GG hill"] = design_gg((P.reshape(-1, 3), grid_quads(24, 16)), frames=0).bundle
    return out


@pytest.mark.slow
@pytest.mark.parametrize("name", ["NCP 10", "NCP 20", "GG hill"])
def test_light_polygons_paint_the_pixels_of_paths_designed(monkeypatch, tmp_path, designed,
                                                           name):
    light, paths = _light_and_paths(monkeypatch, tmp_path,
                                    lambda path: render_bundle(designed[name], path))
    assert light == paths


def test_one_polygon_is_a_path():
    """A collection of one path is measured by matplotlib (its single-path shortcut calls
    ``Path.get_extents``): it is made of a matplotlib Path even when ``agg_only``; drawn, the
    same pixels as without."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.path import Path as MplPath

    def draw(agg_only):
        painter = Painter(Camera(90.0, -90.0))
        quad = np.array([[[-0.5, -0.4, 0.0], [0.6, -0.5, 0.0], [0.4, 0.5, 0.0],
                          [-0.6, 0.3, 0.0]]])
        grey = np.array([0.4, 0.5, 0.6, 1.0])
        painter.add(quad, grey, grey)
        fig = Figure(figsize=(2, 2), dpi=100)
        ax = fig.add_axes((0, 0, 1, 1))
        ax.set_xlim(-1, 1)
        ax.set_ylim(-1, 1)
        ax.set_axis_off()
        coll = painter.collection(ax.transData, fig.dpi, agg_only=agg_only)
        assert len(coll.get_paths()) == 1 and isinstance(coll.get_paths()[0], MplPath)
        ax.add_collection(coll, autolim=False)
        canvas = FigureCanvasAgg(fig)
        canvas.draw()
        return np.asarray(canvas.buffer_rgba()).copy()

    a, b = draw(True), draw(False)
    assert a.std() > 10 and np.array_equal(a, b)


@pytest.mark.parametrize("rc", [{}, {"path.simplify_threshold": 0.5},
                                {"path.simplify": False}, {"path.simplify_threshold": 0.0}])
@pytest.mark.parametrize("n", [4, 7, 9, 200])
def test_polygon_type_is_what_a_path_says(rc, n):
    """A light polygon's codes and simplification settings are those of the matplotlib Path
    of its vertices, whatever the rcParams (a polygon of 128 or more corners too: its
    CLOSEPOLY code keeps it from being simplified)."""
    import matplotlib as mpl
    from matplotlib.path import Path as MplPath

    V = np.random.default_rng(n).normal(size=(n, 2))
    with mpl.rc_context(rc):
        path = MplPath(V, closed=True)
        kind = _polygon_type(len(path.codes), path.should_simplify, path.simplify_threshold)
        light = kind()
        light.vertices = V
        assert np.array_equal(light.codes, path.codes) and light.codes.dtype == path.codes.dtype
        assert light.should_simplify is bool(path.should_simplify)   # (numpy's bool there)
        assert light.simplify_threshold == path.simplify_threshold
        assert light.vertices is V and not light.codes.flags.writeable
        with pytest.raises(AttributeError):
            light.extents = 1.0                       # nothing else can be set on it


def test_light_polygons_draw_to_a_png_buffer_too():
    """The collection drawn by Agg through ``savefig`` (PNG) paints what the Path one does."""
    from matplotlib.figure import Figure
    from PIL import Image

    rng = np.random.default_rng(7)

    def draw(agg_only):
        painter = Painter(Camera(35.0, -50.0))
        tri = rng.uniform(-1, 1, (60, 3, 3))
        painter.add(tri, np.column_stack([np.full((60, 3), 0.5), np.ones(60)]),
                    np.array([0.0, 0.0, 0.0, 1.0]))
        fig = Figure(figsize=(3, 3), dpi=100)
        ax = fig.add_axes((0, 0, 1, 1))
        ax.set_xlim(-1.5, 1.5)
        ax.set_ylim(-1.5, 1.5)
        ax.set_axis_off()
        ax.add_collection(painter.collection(ax.transData, fig.dpi, agg_only=agg_only),
                          autolim=False)
        buf = io.BytesIO()
        fig.savefig(buf, format="png")
        return np.asarray(Image.open(buf))

    state = rng.bit_generator.state
    a = draw(True)
    rng.bit_generator.state = state
    b = draw(False)
    assert a.std() > 10 and np.array_equal(a, b)


def test_light_paths_index_as_the_paths():
    """The light sequence gives, index for index (negative ones and slices too), the vertices
    and codes of the Path sequence, and the outlines themselves."""
    from matplotlib.path import Path as MplPath

    from gridshell.render.painter import _LightPolygonPaths, _PolygonPaths

    rng = np.random.default_rng(1)
    sources = [(rng.normal(size=(5, 5, 2)), _polygon_type(5, False, 1 / 9)),
               (rng.normal(size=(3, 9, 2)), _polygon_type(9, False, 1 / 9))]
    chunk = np.array([1, 0, -1, 0, 1, 0, 0, -1, 1, 0])
    local = np.array([0, 0, 0, 1, 1, 2, 3, 1, 2, 4])
    special = [MplPath(rng.normal(size=(6, 2))), MplPath(rng.normal(size=(7, 2)))]
    light = _LightPolygonPaths(sources, chunk, local, special)
    paths = _PolygonPaths(sources, chunk, local, special)
    assert len(light) == len(paths) == 10
    for i in list(range(-10, 10)):
        a, b = light[i], paths[i]
        assert isinstance(a, _Polygon) == (chunk[i] >= 0) and isinstance(b, MplPath)
        assert np.array_equal(a.vertices, b.vertices) and np.array_equal(a.codes, b.codes)
        assert (a is b) == (chunk[i] < 0)
    for a, b in zip(light[1:9:3], paths[1:9:3]):
        assert np.array_equal(a.vertices, b.vertices)
    with pytest.raises(IndexError):
        light[10]
