"""A headless picture of a gridshell: every lamella as the strip that is cut, on its surface
(Figs. 1, 10).

A strip is the lamella axis swept by its real section, ``width x thickness`` (the cut strip
divided by the model scale: 20 x 1 mm at 1:10 = 200 x 10 mm, :mod:`.section`), with its width

- along the in-surface direction ``n x t`` for GG (tangent lamellae, paper Fig. 6 centre);
- along the surface normal ``n`` for NCP / CNC / AA (orthogonal lamellae standing on the
  surface, Fig. 6 left),

with ``n`` the vertex normal of the surface vertex closest to each axis point
(:mod:`gridshell.geometry.strips3d`). Strips are coloured by family on an opaque surface; all polygons
are painted far to near in one list (:mod:`.painter`), so no strip shows through the surface
and none vanishes under it. The camera is chosen from the principal axes of the geometry
(orthographic). Plain arrays in, one PNG out; :func:`render_bundle` does the same for a design
bundle. matplotlib's ``Figure`` is used directly (Agg canvas, no pyplot state, no display).
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import Sequence

import numpy as np

from gridshell.core.atomic import atomic_path
from gridshell.core.errors import InputError
from gridshell.geometry.strips3d import TANGENT_KINDS, nearest_vertex_normals, strip_frame
from gridshell.geometry.vectors import row_norms, unit_rows as _unit

__all__ = ["FAMILY_COLOURS", "TANGENT_KINDS", "nearest_vertex_normals",
           "ribbon_polygons", "view_angles", "render_ribbons", "render_bundle"]

#: RGB colour of each lamella family (C^1, C^3)
FAMILY_COLOURS: dict[int, tuple[float, float, float]] = {1: (0.13, 0.42, 0.70),
                                                         3: (0.86, 0.35, 0.12)}
_SURFACE_RGB = (0.80, 0.82, 0.85)


def ribbon_polygons(axis: np.ndarray, normals: np.ndarray, width: float,
                    tangent: bool) -> np.ndarray:
    """Quads ``(k-1, 4, 3)`` of the ribbon of one lamella.

    Parameters
    ----------
    axis : (k,3) float
        Lamella axis polyline, metres.
    normals : (k,3) float
        Unit surface normals at the axis points.
    width : float
        Ribbon width, metres.
    tangent : bool
        True: offset along ``n x t`` (in the surface, GG); False: along ``n`` made
        orthogonal to the axis (standing on the surface, NCP / CNC / AA);
        :func:`gridshell.geometry.strips3d.strip_frame`.
    """
    P = np.asarray(axis, float).reshape(-1, 3)
    n_normals = len(np.asarray(normals).reshape(-1, 3))
    if len(P) != n_normals:
        raise InputError(f"ribbon: {len(P)} axis points but {n_normals} normals")
    if len(P) < 2:
        return np.zeros((0, 4, 3))
    _, D, _ = strip_frame(P, normals, tangent)
    h = 0.5 * float(width) * D
    a, b = P - h, P + h
    return np.stack([a[:-1], a[1:], b[1:], b[:-1]], axis=1)


def view_angles(P: np.ndarray, tilt_deg: float = 55.0, turn_deg: float = 25.0
                ) -> tuple[float, float]:
    """Camera ``(elev, azim)`` in degrees (matplotlib's convention) from the principal axes.

    With ``e1, e2, e3`` the principal axes of the points ``P (k,3)`` by decreasing spread and
    ``e3`` turned to look from above, the camera sits in direction
    ``cos(tilt) e3 + sin(tilt) (cos(turn) e2 + sin(turn) e1)``: mostly facing the broad side,
    tilted to show the relief, the longest extent running across the picture.
    """
    P = np.asarray(P, float).reshape(-1, 3)
    P = P[np.isfinite(P).all(axis=1)]
    if len(P) < 3:
        return 30.0, -60.0
    X = P - P.mean(axis=0)
    _, _, Vt = np.linalg.svd(X, full_matrices=False)
    e1, e2, e3 = Vt[0], Vt[1], Vt[2] if len(Vt) > 2 else np.cross(Vt[0], Vt[1])
    if e3[2] < 0:
        e3 = -e3
    if e2[2] > 0 or (e2[2] == 0 and e2[1] > 0):
        e2 = -e2  # the tilt then lifts the camera further above the surface
    t, r = np.radians(tilt_deg), np.radians(turn_deg)
    c = np.cos(t) * e3 + np.sin(t) * (np.cos(r) * e2 + np.sin(r) * e1)
    c /= np.linalg.norm(c)
    elev = float(np.degrees(np.arcsin(np.clip(c[2], -1.0, 1.0))))
    azim = float(np.degrees(np.arctan2(c[1], c[0])))
    return elev, azim


def _surface_near(V: np.ndarray, F: np.ndarray, P: np.ndarray, max_faces: int) -> np.ndarray:
    """Face corner arrays ``(m, k, 3)`` of the surface faces whose centroid lies in the
    bounding box of the points ``P`` grown by 5 % (the part under the net); the whole of it
    (an opaque surface with holes would show what is behind it) unless it has more than
    ``max_faces`` faces, then thinned to that many."""
    C = V[F].mean(axis=1)
    lo, hi = P.min(axis=0), P.max(axis=0)
    g = 0.05 * float(np.max(hi - lo))
    inside = np.all((C >= lo - g) & (C <= hi + g), axis=1)
    Fd = F[inside]
    return V[Fd[:: max(1, int(np.ceil(len(Fd) / max_faces)))]]


def _resample_index(k: int, max_points: int) -> np.ndarray:
    """Indices of at most ``max_points`` of ``k`` points, evenly spread, ends kept."""
    if k <= max_points:
        return np.arange(k)
    return np.unique(np.linspace(0, k - 1, max_points).round().astype(int))


def render_ribbons(path: str | os.PathLike, axes: Sequence[np.ndarray],
                   families: Sequence[int], V: np.ndarray, F: np.ndarray,
                   joints: np.ndarray | None = None, *, kind: str = "GG",
                   width: float | None = None, thickness: float | None = None,
                   title: str | None = None, size: tuple[int, int] = (1000, 750),
                   dpi: int = 100, view: tuple[float, float] | None = None,
                   max_faces: int = 40000, max_points: int = 200,
                   colours: Sequence[np.ndarray] | None = None,
                   colorbar: tuple[str, str] | None = None) -> Path:
    """Write a PNG of the lamellae as strips on the opaque surface, atomically.

    Every polygon (surface faces, strip faces, joints) is painted far to near in one list
    (:class:`gridshell.render.painter.Painter`), so strips behind the surface are hidden and
    strips on it are seen.

    Parameters
    ----------
    path : path-like
        Output ``.png``.
    axes : list of (k_i,3) float
        Lamella axis polylines, metres.
    families : (len(axes),) int
        Family of each lamella (1 or 3), which sets its colour (:data:`FAMILY_COLOURS`).
    V, F : (n,3) float, (m,3|4) int
        The surface, drawn opaque, giving the normals.
    joints : (p,3) float, optional
        Joint positions, drawn as small dots.
    kind : {"GG", "NCP", "CNC", "AA"}
        GG lamellae lie tangent to the surface, the others stand orthogonal to it.
    width, thickness : float, optional
        The strip's real section in metres (default :data:`gridshell.design.section.DEFAULT_CUT`
        at its scale: 200 x 10 mm).
    title : str, optional
    size : (w, h) int
        Picture size in pixels (exact: no tight bounding box).
    dpi : int
    view : (elev, azim) degrees, optional
        Camera (default :func:`view_angles` of the axes and joints).
    max_faces, max_points : int
        Drawing budget for surface faces and points per axis.
    colours : list of (k_i,3) float, optional
        RGB at every point of each axis (e.g. a utilisation map) instead of the family
        colours; each segment takes the colour of its first point.
    colorbar : (cmap name, label), optional
        A colour bar over ``[0, 1]`` beside the picture (with ``colours``).

    Returns
    -------
    Path
        ``path``.
    """
    from matplotlib.figure import Figure
    from matplotlib.patches import Patch

    from gridshell.render.painter import Camera, Painter, strips_faces
    from gridshell.design.section import resolve_section

    axes = [np.asarray(a, float).reshape(-1, 3) for a in axes]
    fams = [int(f) for f in families]
    if len(fams) != len(axes):
        raise InputError(f"render_ribbons: {len(fams)} families for {len(axes)} axes; give one "
                         "family per lamella")
    if not axes:
        raise InputError("render_ribbons: no lamella axes to draw")
    if kind not in ("GG", "NCP", "CNC", "AA"):
        raise InputError(f"render_ribbons: kind must be GG, NCP, CNC or AA, got {kind!r}")
    V = np.asarray(V, float).reshape(-1, 3)
    F = np.asarray(F, np.int64)
    J = None if joints is None else np.asarray(joints, float).reshape(-1, 3)
    default = resolve_section(None)
    w = default.width_m if width is None else float(width)
    t = default.thickness_m if thickness is None else float(thickness)
    if not (w > 0 and t > 0):
        raise InputError(f"render_ribbons: width and thickness must be positive, got {w}, {t}")
    tangent = kind in TANGENT_KINDS

    pts = np.concatenate(axes + ([J] if J is not None and len(J) else []))
    elev, azim = view if view is not None else view_angles(pts)
    cam = Camera(elev, azim)
    r, u, c = cam.basis()
    light = _unit(0.5 * c + 0.6 * u - 0.4 * r)
    painter = Painter(cam)

    S = _surface_near(V, F, pts, max_faces)
    if len(S):
        n = _unit(np.cross(S[:, 2] - S[:, 0], S[:, -1] - S[:, 1]))
        k = 0.62 + 0.3 * np.abs(n @ light)
        face = np.column_stack([np.outer(k, _SURFACE_RGB), np.ones(len(S))])
        painter.add(S, face, face)  # edges as the faces: no seams, no mesh lines
        size_faces = float(np.median(row_norms(S[:, 2] - S[:, 0])))
    else:
        size_faces = 0.0
    bias = 0.5 * size_faces + 0.5 * t

    if colours is not None and [len(c) for c in colours] != [len(a) for a in axes]:
        raise InputError("render_ribbons: give one RGB per axis point in colours")
    keep = [i for i, a in enumerate(axes) if len(a) >= 2]
    picks = [_resample_index(len(axes[i]), max_points) for i in keep]
    axes_d = [axes[i][p] for i, p in zip(keep, picks)]
    fams_d = [fams[i] for i in keep]
    cols_d = (None if colours is None else
              [np.asarray(colours[i], float).reshape(-1, 3)[p] for i, p in zip(keep, picks)])
    # the normals at the axes' points and, after them, at the joints: one nearest-vertex search
    Jn = J if J is not None and len(J) else np.zeros((0, 3))
    N_all = nearest_vertex_normals(np.concatenate(axes_d + [Jn]), V, F) \
        if axes_d or len(Jn) else np.zeros((0, 3))
    sizes = [len(a) for a in axes_d]
    N = np.split(N_all[:sum(sizes)], np.cumsum(sizes)[:-1])
    # every strip at once, axis by axis: 8 groups of one quad per segment (strips_faces)
    if axes_d:
        Q, side, qn = strips_faces(axes_d, N, w, t, tangent)
        if cols_d is None:
            rgb = np.concatenate([np.broadcast_to(np.asarray(
                FAMILY_COLOURS.get(f, (0.3, 0.3, 0.3)), float), (8 * (k - 1), 3))
                for f, k in zip(fams_d, sizes)])
        else:
            rgb = np.concatenate([np.tile(c[:-1], (8, 1)) for c in cols_d])
        # GG: family C1 lies on the side of the normal where the two layers cross
        layer = np.repeat([(0.5 * w if f == 1 else -0.5 * w) if tangent else 0.0
                           for f in fams_d], [8 * (k - 1) for k in sizes])
        painter.add_strip(Q, side, qn, rgb, light, bias, layer)
    if J is not None and len(J):
        ring = np.linspace(0, 2 * np.pi, 9)[:-1]
        diag = float(np.linalg.norm(pts.max(axis=0) - pts.min(axis=0)))
        rad = min(0.3 * w, 0.007 * diag) if diag > 0 else 0.3 * w
        dots = J[:, None, :] + rad * (np.cos(ring)[None, :, None] * r +
                                      np.sin(ring)[None, :, None] * u)
        Nj = N_all[sum(sizes):]
        lift = np.where(tangent, 0.5 * t, 0.25 * w) * np.sign(Nj @ c)
        painter.add(dots + (lift[:, None] * Nj)[:, None, :], np.array([0.12, 0.12, 0.14, 1.0]),
                    np.array([0.0, 0.0, 0.0, 1.0]), bias + 1.5 * w)

    fig = Figure(figsize=(size[0] / dpi, size[1] / dpi), dpi=dpi)
    rect = (0.01, 0.01, 0.98, 0.91 if title else 0.98)   # the picture's box, figure fraction
    lo, hi = _extent(painter.polys)
    box = np.array([0.98 * size[0], (0.91 if title else 0.98) * size[1]])  # the box, pixels
    scale = 1.06 * float(np.max((hi - lo) / box)) or 1.0  # metres per pixel, equal both ways
    mid = 0.5 * (lo + hi)
    # drawn by the Agg canvas only (_write_png): light paths (Painter.collection)
    coll = painter.collection(_data_to_pixels(fig, rect, mid - 0.5 * scale * box,
                                              mid + 0.5 * scale * box), dpi, linewidth=0.2,
                              agg_only=True)
    if coll is not None:
        coll.set_zorder(0)  # under everything else, as in an axes added first
        fig.add_artist(coll)
    if colorbar is not None:
        from matplotlib import colormaps
        from matplotlib.cm import ScalarMappable
        from matplotlib.colors import Normalize

        cax = fig.add_axes((0.92, 0.15, 0.02, 0.6))
        cb = fig.colorbar(ScalarMappable(norm=Normalize(0.0, 1.0),
                                         cmap=colormaps[colorbar[0]]), cax=cax)
        cb.set_label(colorbar[1], fontsize=8)
    present = sorted(set(fams_d)) if colours is None else []
    fig.legend(handles=[Patch(color=FAMILY_COLOURS.get(f, (0.3, 0.3, 0.3)),
                              label=f"family C{f} ({fams_d.count(f)})") for f in present],
               loc="lower left", fontsize=8, frameon=False)
    if title:
        fig.suptitle(title, fontsize=max(6.0, min(10.0, size[0] / 60.0)))
    _write_png(fig, path, dpi)
    return Path(path)


def _extent(polys: Sequence[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """The smallest and largest ``x`` and ``y`` ``(2,)`` (the picture's plane, metres) of the
    points of the polygon arrays ``polys (m_i, k_i, 2)``: the numbers ``min(axis=0)`` and
    ``max(axis=0)`` of all of them stacked give (a NaN wins as there), by coordinate (a
    reduction over ~140k rows of 2 along the rows takes numpy ~6 ms, over one strided
    coordinate ~0.1 ms; nothing copied)."""
    lo = np.array([np.array([p[..., i].min() for p in polys]).min() for i in range(2)])
    hi = np.array([np.array([p[..., i].max() for p in polys]).max() for i in range(2)])
    return lo, hi


def _data_to_pixels(fig, rect: tuple[float, float, float, float], lo: np.ndarray,
                    hi: np.ndarray):
    """The affine map from data (the picture's plane, metres) to the display pixels of
    ``fig`` that takes the box ``lo``-``hi`` onto ``rect`` (left, bottom, width, height as
    fractions of the figure): an axes' ``transData`` with these limits (the same transforms,
    the same numbers) without making the axes (its ticks, spines and titles are not drawn).
    The picture's polygons lie inside the box with a margin, so nothing needs clipping."""
    from matplotlib.transforms import Bbox, BboxTransformFrom, BboxTransformTo, TransformedBbox

    return (BboxTransformFrom(Bbox([[lo[0], lo[1]], [hi[0], hi[1]]])) +
            BboxTransformTo(TransformedBbox(Bbox.from_bounds(*rect), fig.transSubfigure)))


def _write_png(fig, path: str | os.PathLike, dpi: int) -> None:
    """``fig`` drawn once by Agg and written as PNG at ``dpi``, atomically: RGB when every pixel
    is opaque (the same picture as ``savefig``'s RGBA, a tenth smaller and faster to encode),
    zlib level 1 (the same pixels; for the 1000 x 750 picture of a 20-curve NCP bundle ~28 ms
    and 540 kB against ~34 ms and 521 kB at level 3, ~60 ms at the default 6)."""
    from matplotlib import __version__ as mpl_version
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from PIL import Image, PngImagePlugin

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    rgba = np.asarray(canvas.buffer_rgba())
    img = rgba[..., :3] if int(rgba[..., 3].min()) == 255 else rgba
    info = PngImagePlugin.PngInfo()
    info.add_text("Software", f"Matplotlib version{mpl_version}, https://matplotlib.org/")
    with atomic_path(path) as tmp:
        Image.fromarray(np.ascontiguousarray(img)).save(tmp, format="png", compress_level=1,
                                                        dpi=(dpi, dpi), pnginfo=info)


def render_bundle(bundle, path: str | os.PathLike | None = None, *,
                  width: float | None = None, thickness: float | None = None,
                  **kwargs) -> Path:
    """Render the strips of a design bundle (a directory or a
    :class:`~gridshell.design.bundle.DesignBundle`) to ``path`` (default ``DIR/render.png``).

    ``width`` and ``thickness`` are the strip's real section in metres (default the cut strip
    of the bundle's ``fabrication/fabrication.json`` divided by its scale, else 20 x 1 mm at
    1:10 = 200 x 10 mm: :func:`gridshell.design.section.resolve_section`); the title says it.
    Further keyword arguments go to :func:`render_ribbons`.
    """
    from gridshell.design.bundle import read_bundle
    from gridshell.design.section import resolve_section

    directory = None
    if isinstance(bundle, (str, os.PathLike)):
        directory = Path(bundle)
        b = read_bundle(directory)
        path = directory / "render.png" if path is None else path
    else:
        b = bundle
        if path is None:
            raise InputError("render_bundle: give an output path for an in-memory bundle")
    lams = b.net.lamellae
    section = resolve_section(directory)
    if width is None and thickness is None:
        text = section.text()
    else:
        text = (f"{1000 * (width or section.width_m):.4g} x "
                f"{1000 * (thickness or section.thickness_m):.4g} mm")
    width = section.width_m if width is None else width
    thickness = section.thickness_m if thickness is None else thickness
    n1, n3 = len(b.net.family(1)), len(b.net.family(3))
    orient = "tangent to" if b.kind in TANGENT_KINDS else "standing on"
    kwargs.setdefault("title", f"{b.kind} gridshell: {n1} + {n3} lamellae {orient} the surface, "
                               f"strips {text}")
    return render_ribbons(path, [lam.axis for lam in lams], [lam.family for lam in lams],
                          b.surface_V, b.surface_F, b.net.joints, kind=b.kind, width=width,
                          thickness=thickness, **kwargs)
