"""A headless picture of a gridshell: every lamella as a thin ribbon on its surface (Figs. 1, 10).

A ribbon is the lamella axis offset by ``+- width/2``:

- along the in-surface direction ``n x t`` for GG (tangent lamellae, paper Fig. 6 centre);
- along the surface normal ``n`` for NCP / CNC / AA (orthogonal lamellae standing on the
  surface, Fig. 6 left),

with ``n`` the vertex normal of the surface vertex closest to each axis point. Ribbons are
coloured by family, the surface is drawn faintly, the camera is chosen from the principal axes
of the geometry and the three axes are scaled equally. Plain arrays in, one PNG out;
:func:`render_bundle` does the same for a design bundle. matplotlib's ``Figure`` is used
directly (Agg canvas, no pyplot state, no display).
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import Sequence

import numpy as np

from ..atomic import atomic_path
from ..errors import InputError
from ..strips3d import TANGENT_KINDS, nearest_vertex_normals, strip_frame

__all__ = ["FAMILY_COLOURS", "TANGENT_KINDS", "default_width", "nearest_vertex_normals",
           "ribbon_polygons", "view_angles", "render_ribbons", "render_bundle"]

#: RGB colour of each lamella family (C^1, C^3)
FAMILY_COLOURS: dict[int, tuple[float, float, float]] = {1: (0.13, 0.42, 0.70),
                                                         3: (0.86, 0.35, 0.12)}
_SURFACE_RGBA = (0.62, 0.64, 0.68, 0.18)


def _unit(X: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(X, axis=-1, keepdims=True)
    return np.divide(X, n, out=np.zeros_like(X), where=n > 0)


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
        :func:`gridshell.strips3d.strip_frame`.
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


def default_width(axes: Sequence[np.ndarray], joint_spacing: float | None = None) -> float:
    """A ribbon width that reads well: a quarter of the joint spacing when known, else 1.5 %
    of the bounding-box diagonal of the axes (metres)."""
    if joint_spacing is not None and joint_spacing > 0:
        return 0.25 * float(joint_spacing)
    P = np.concatenate([np.asarray(a, float).reshape(-1, 3) for a in axes]) if len(axes) \
        else np.zeros((1, 3))
    diag = float(np.linalg.norm(P.max(axis=0) - P.min(axis=0)))
    return 0.015 * diag if diag > 0 else 0.01


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


def _camera_dir(elev: float, azim: float) -> np.ndarray:
    e, a = np.radians(elev), np.radians(azim)
    return np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])


def _shade(polys: np.ndarray, rgb: np.ndarray, light: np.ndarray) -> np.ndarray:
    """Face colours ``rgb (m,3)`` dimmed by ``|n . light|`` (two-sided Lambert + ambient)."""
    if not len(polys):
        return rgb
    n = _unit(np.cross(polys[:, 2] - polys[:, 0], polys[:, 3] - polys[:, 1]))
    k = 0.5 + 0.5 * np.abs(n @ light)
    return np.clip(rgb * k[:, None], 0.0, 1.0)


def _fit_view(fig, ax, P: np.ndarray, fill: float = 0.92) -> None:
    """Equal axis scales around ``P (k,3)`` and the zoom that makes the projected points fill
    ``fill`` of the axes rectangle (3D axes otherwise draw into a centred square)."""
    from mpl_toolkits.mplot3d import proj3d

    _set_equal_limits(ax, P, zoom=1.0)
    ax.apply_aspect()  # the centred square that draw() would use, so transData is final
    x, y, _ = proj3d.proj_transform(P[:, 0], P[:, 1], P[:, 2], ax.get_proj())
    xy = ax.transData.transform(np.column_stack([x, y]))
    box = ax.get_position(original=True).transformed(fig.transFigure)
    cx, cy = 0.5 * (box.x0 + box.x1), 0.5 * (box.y0 + box.y1)
    dx = float(np.max(np.abs(xy[:, 0] - cx))) or 1.0
    dy = float(np.max(np.abs(xy[:, 1] - cy))) or 1.0
    zoom = fill * min(0.5 * box.width / dx, 0.5 * box.height / dy)
    _set_equal_limits(ax, P, zoom=float(np.clip(zoom, 0.2, 5.0)))


def _set_equal_limits(ax, P: np.ndarray, pad: float = 0.0, zoom: float = 1.0) -> None:
    lo, hi = P.min(axis=0), P.max(axis=0)
    span = hi - lo
    m = float(span.max()) or 1.0
    span = np.maximum(span, 0.05 * m)
    c = 0.5 * (lo + hi)
    half = 0.5 * span * (1 + 2 * pad)
    ax.set_xlim(c[0] - half[0], c[0] + half[0])
    ax.set_ylim(c[1] - half[1], c[1] + half[1])
    ax.set_zlim(c[2] - half[2], c[2] + half[2])
    ax.set_box_aspect(tuple(2 * half), zoom=zoom)


def _surface_near(V: np.ndarray, F: np.ndarray, P: np.ndarray, max_faces: int) -> np.ndarray:
    """Face corner arrays of the surface faces whose centroid lies in the bounding box of the
    points ``P`` grown by 5 % (the part under the net), thinned to ``max_faces``."""
    C = V[F].mean(axis=1)
    lo, hi = P.min(axis=0), P.max(axis=0)
    g = 0.05 * float(np.max(hi - lo))
    inside = np.all((C >= lo - g) & (C <= hi + g), axis=1)
    Fd = F[inside]
    return V[Fd[:: max(1, int(np.ceil(len(Fd) / max_faces)))]]


def _resample(P: np.ndarray, max_points: int) -> np.ndarray:
    if len(P) <= max_points:
        return P
    idx = np.unique(np.linspace(0, len(P) - 1, max_points).round().astype(int))
    return P[idx]


def render_ribbons(path: str | os.PathLike, axes: Sequence[np.ndarray],
                   families: Sequence[int], V: np.ndarray, F: np.ndarray,
                   joints: np.ndarray | None = None, *, kind: str = "GG",
                   width: float | None = None, title: str | None = None,
                   size: tuple[int, int] = (1000, 750), dpi: int = 100,
                   view: tuple[float, float] | None = None, max_faces: int = 12000,
                   max_points: int = 200) -> Path:
    """Write a PNG of the lamellae as ribbons on the surface, atomically.

    Parameters
    ----------
    path : path-like
        Output ``.png``.
    axes : list of (k_i,3) float
        Lamella axis polylines, metres.
    families : (len(axes),) int
        Family of each lamella (1 or 3), which sets its colour (:data:`FAMILY_COLOURS`).
    V, F : (n,3) float, (m,3|4) int
        The surface, drawn faintly (thinned to ``max_faces``) and giving the normals.
    joints : (p,3) float, optional
        Joint positions, drawn as small dots.
    kind : {"GG", "NCP", "CNC", "AA"}
        GG lamellae lie tangent to the surface, the others stand orthogonal to it.
    width : float, optional
        Ribbon width in metres (default :func:`default_width`).
    title : str, optional
    size : (w, h) int
        Picture size in pixels (exact: no tight bounding box).
    dpi : int
    view : (elev, azim) degrees, optional
        Camera (default :func:`view_angles` of the axes and joints).
    max_faces, max_points : int
        Drawing budget for surface faces and points per axis.

    Returns
    -------
    Path
        ``path``.
    """
    from matplotlib.figure import Figure
    from matplotlib.patches import Patch
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

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
    w = default_width(axes) if width is None else float(width)
    if not w > 0:
        raise InputError(f"render_ribbons: width must be positive, got {width}")
    tangent = kind in TANGENT_KINDS

    pts = np.concatenate(axes + ([J] if J is not None and len(J) else []))
    elev, azim = view if view is not None else view_angles(pts)
    light = _unit(_camera_dir(elev + 25.0, azim - 30.0))

    axes_d = [_resample(a, max_points) for a in axes if len(a) >= 2]
    fams_d = [f for a, f in zip(axes, fams) if len(a) >= 2]
    N = nearest_vertex_normals(np.concatenate(axes_d), V, F)
    polys, cols = [], []
    start = 0
    for a, f in zip(axes_d, fams_d):
        q = ribbon_polygons(a, N[start:start + len(a)], w, tangent)
        start += len(a)
        polys.append(q)
        cols.append(np.broadcast_to(FAMILY_COLOURS.get(f, (0.3, 0.3, 0.3)), (len(q), 3)))
    R = np.concatenate(polys)
    rgb = _shade(R, np.concatenate(cols), light)
    S = _surface_near(V, F, pts, max_faces)
    if S.shape[1] == 3:  # triangles: repeat a corner so one collection holds everything
        S = np.concatenate([S, S[:, 2:3]], axis=1)
    face_rgba = np.concatenate([np.tile(_SURFACE_RGBA, (len(S), 1)),
                                np.column_stack([rgb, np.ones(len(R))])])
    edge_rgba = np.concatenate([np.zeros((len(S), 4)),
                                np.column_stack([0.6 * rgb, np.full(len(R), 0.9)])])

    fig = Figure(figsize=(size[0] / dpi, size[1] / dpi), dpi=dpi)
    ax = fig.add_axes((0.0, 0.0, 1.0, 0.93 if title else 1.0), projection="3d")
    ax.computed_zorder = False
    coll = Poly3DCollection(np.concatenate([S, R]), facecolors=face_rgba,
                            edgecolors=edge_rgba, linewidths=0.25)
    ax.add_collection3d(coll)
    if J is not None and len(J):
        ax.scatter(J[:, 0], J[:, 1], J[:, 2], s=4, color=(0.1, 0.1, 0.1), depthshade=False,
                   zorder=5)
    allP = np.concatenate([pts, R.reshape(-1, 3)])
    ax.view_init(elev=elev, azim=azim)
    ax.set_axis_off()
    _fit_view(fig, ax, allP)
    coll.set_clip_on(False)
    present = sorted(set(fams_d))
    fig.legend(handles=[Patch(color=FAMILY_COLOURS.get(f, (0.3, 0.3, 0.3)),
                              label=f"family C{f} ({fams_d.count(f)})") for f in present],
               loc="lower left", fontsize=8, frameon=False)
    if title:
        fig.suptitle(title, fontsize=max(6.0, min(10.0, size[0] / 60.0)))
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=dpi)
    return Path(path)


def render_bundle(bundle, path: str | os.PathLike | None = None, *,
                  width: float | None = None, **kwargs) -> Path:
    """Render the ribbons of a design bundle (a directory or a
    :class:`~gridshell.bundle.DesignBundle`) to ``path`` (default ``DIR/render.png``).

    ``width`` is in metres (default a quarter of the median joint spacing); further keyword
    arguments go to :func:`render_ribbons`.
    """
    from ..bundle import read_bundle

    if isinstance(bundle, (str, os.PathLike)):
        directory = Path(bundle)
        b = read_bundle(directory)
        path = directory / "render.png" if path is None else path
    else:
        b = bundle
        if path is None:
            raise InputError("render_bundle: give an output path for an in-memory bundle")
    lams = b.net.lamellae
    if width is None:
        gaps = np.concatenate([np.diff(lam.joint_s) for lam in lams] or [np.zeros(0)])
        gaps = gaps[gaps > 0]
        width = default_width([lam.axis for lam in lams],
                              float(np.median(gaps)) if len(gaps) else None)
    n1, n3 = len(b.net.family(1)), len(b.net.family(3))
    orient = "tangent to" if b.kind in TANGENT_KINDS else "standing on"
    kwargs.setdefault("title", f"{b.kind} gridshell: {n1} + {n3} lamellae {orient} the surface, "
                               f"width {1000 * width:.0f} mm")
    return render_ribbons(path, [lam.axis for lam in lams], [lam.family for lam in lams],
                          b.surface_V, b.surface_F, b.net.joints, kind=b.kind, width=width,
                          **kwargs)
