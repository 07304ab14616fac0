"""Headless pictures of the NCP pipeline (paper Figs. 13, 15, 16): plain arrays in, PNG bytes out.

- :func:`edge_map` edges coloured by a value (``Delta_l``), :func:`vertex_map` joints coloured
  by a value (``Delta_n``), :func:`collapse_plot` the collapse curve with its normals,
  :func:`sequence_frames` the alignment sequence with fixed axes, :func:`gif` an animated GIF
  of PNG frames (Pillow). Matplotlib's Agg backend; nothing needs a display.
"""
from __future__ import annotations

import io
from typing import Sequence

import numpy as np

from gridshell.core.errors import InputError
from gridshell.render.figure import (MIN_FRAME_PX, content_box, cube_limits, dpi_for_width,
                                     png_bytes, pyplot)

__all__ = ["edge_map", "vertex_map", "collapse_plot", "sequence_frames", "gif"]

#: pixels kept around the cropped content of the sequence frames
_PAD = 8


def edge_map(V: np.ndarray, edges: np.ndarray, values: np.ndarray, *, title: str = "",
             label: str = "", dpi: int = 110) -> bytes:
    """PNG of the edges ``(E, 2)`` of joints ``V (n, 3)`` coloured by ``values (E,)``."""
    from mpl_toolkits.mplot3d.art3d import Line3DCollection

    import matplotlib

    plt = pyplot()
    V = np.asarray(V, float)
    E = np.asarray(edges, np.int64).reshape(-1, 2)
    vals = np.asarray(values, float).reshape(-1)
    if len(vals) != len(E):
        raise InputError(f"edge_map: {len(vals)} values for {len(E)} edges")
    fig = plt.figure(figsize=(6.4, 5.2), dpi=dpi)
    ax = fig.add_subplot(projection="3d")
    finite = vals[np.isfinite(vals)]
    norm = matplotlib.colors.Normalize(0.0, float(finite.max()) if len(finite) and
                                       finite.max() > 0 else 1.0)
    cmap = plt.get_cmap("viridis")
    ax.add_collection3d(Line3DCollection(V[E], colors=cmap(norm(np.nan_to_num(vals))),
                                         linewidths=2.0))
    fig.colorbar(matplotlib.cm.ScalarMappable(norm=norm, cmap=cmap), ax=ax, shrink=0.6,
                 label=label)
    cube_limits(ax, V)
    if title:
        ax.set_title(title, fontsize=9)
    return png_bytes(fig)


def vertex_map(V: np.ndarray, edges: np.ndarray, values: np.ndarray, *, title: str = "",
               label: str = "", dpi: int = 110) -> bytes:
    """PNG of joints ``V (n, 3)`` coloured by ``values (n,)`` over grey edges ``(E, 2)``."""
    from mpl_toolkits.mplot3d.art3d import Line3DCollection

    plt = pyplot()
    V = np.asarray(V, float)
    E = np.asarray(edges, np.int64).reshape(-1, 2)
    vals = np.asarray(values, float).reshape(-1)
    if len(vals) != len(V):
        raise InputError(f"vertex_map: {len(vals)} values for {len(V)} joints")
    fig = plt.figure(figsize=(6.4, 5.2), dpi=dpi)
    ax = fig.add_subplot(projection="3d")
    ax.add_collection3d(Line3DCollection(V[E], colors=(0.5, 0.5, 0.5, 0.7), linewidths=0.8))
    finite = vals[np.isfinite(vals)]
    vmax = float(finite.max()) if len(finite) and finite.max() > 0 else 1.0
    sc = ax.scatter(V[:, 0], V[:, 1], V[:, 2], c=np.nan_to_num(vals), cmap="viridis", vmin=0,
                    vmax=vmax, s=14, depthshade=False)
    fig.colorbar(sc, ax=ax, shrink=0.6, label=label)
    cube_limits(ax, V)
    if title:
        ax.set_title(title, fontsize=9)
    return png_bytes(fig)


def collapse_plot(points: np.ndarray, normals: np.ndarray, joints: np.ndarray | None = None, *,
                  title: str = "", dpi: int = 110, arrows: int = 24) -> bytes:
    """PNG of the collapse polyline ``points (k, 2)`` with some flattened normals and the
    aligned joints ``(n, 2)`` (Fig. 15)."""
    plt = pyplot()
    P = np.asarray(points, float)
    N = np.asarray(normals, float)
    fig, ax = plt.subplots(figsize=(6.4, 4.0), dpi=dpi)
    ax.plot(P[:, 0], P[:, 1], "-", color="0.2", lw=1.2, label="collapse curve")
    idx = np.unique(np.linspace(0, len(P) - 1, arrows).astype(int))
    L = 0.05 * float(np.ptp(P, axis=0).max() or 1.0)
    ax.quiver(P[idx, 0], P[idx, 1], N[idx, 0], N[idx, 1], angles="xy", scale_units="xy",
              scale=1 / L, color="tab:blue", width=0.003, label="flattened normal")
    if joints is not None:
        J = np.asarray(joints, float)
        ax.plot(J[:, 0], J[:, 1], "o", ms=3, color="tab:red", label="aligned joints")
    # a nearly straight curve would make a sliver of a plot: widen the y range instead
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("m", fontsize=8)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=3, frameon=False)
    if title:
        ax.set_title(title, fontsize=9)
    fig.tight_layout()
    return png_bytes(fig)


def sequence_frames(frames: Sequence[np.ndarray], edges: np.ndarray, *, title: str = "",
                    dpi: int = 80, elev: float = 25.0, azim: float = -60.0,
                    min_width: int = MIN_FRAME_PX) -> list[bytes]:
    """PNG bytes of every state ``(n, 3)`` of the alignment sequence, same axes for all.

    One figure is drawn for all states (the edges and joints are moved, the title changed),
    and every picture is cropped to the one box that holds the content of all of them (plus
    :data:`_PAD` pixels, :func:`~.figure.content_box`): all PNGs have one size, ready for
    :func:`gif`, at least ``min_width`` pixels wide (drawn again at a higher ``dpi`` when the
    content is narrower)."""
    from PIL import Image

    rgb, box = _frame_pixels(frames, edges, title, dpi, elev, azim)
    for _ in range(3):                      # the crop's margins do not scale: at most 3 tries
        better = dpi_for_width(dpi, box[3] - box[2], min_width)
        if better is None:
            break
        dpi = better
        rgb, box = _frame_pixels(frames, edges, title, dpi, elev, azim)
    y0, y1, x0, x1 = box
    out = []
    for a in rgb:
        buf = io.BytesIO()
        Image.fromarray(a[y0:y1, x0:x1]).save(buf, format="PNG")
        out.append(buf.getvalue())
    return out


def _frame_pixels(frames, edges, title: str, dpi: float, elev: float, azim: float):
    """The RGB arrays of :func:`sequence_frames`' drawings at ``dpi`` and their common
    content box."""
    from mpl_toolkits.mplot3d.art3d import Line3DCollection

    plt = pyplot()
    E = np.asarray(edges, np.int64).reshape(-1, 2)
    frames = [np.asarray(f, float).reshape(-1, 3) for f in frames]
    if not frames:
        raise InputError("sequence_frames needs at least one state")
    allP = np.concatenate(frames)
    fig = plt.figure(figsize=(5.0, 4.2), dpi=dpi)
    ax = fig.add_axes((0.0, 0.0, 1.0, 0.93), projection="3d")   # the net fills the picture
    lines = Line3DCollection(frames[0][E], colors=(0.1, 0.2, 0.5, 0.9), linewidths=1.0)
    ax.add_collection3d(lines)
    V = frames[0]
    dots, = ax.plot(V[:, 0], V[:, 1], V[:, 2], "o", ms=2.2, mew=0.4, color="tab:red")
    cube_limits(ax, allP)
    ax.view_init(elev=elev, azim=azim)
    text = ax.set_title("", fontsize=9)
    rgb = []
    try:
        for k, V in enumerate(frames):
            lines.set_segments(V[E])
            dots.set_data_3d(V[:, 0], V[:, 1], V[:, 2])
            text.set_text(f"{title} frame {k}/{len(frames) - 1}".strip())
            fig.canvas.draw()
            rgb.append(np.asarray(fig.canvas.buffer_rgba())[..., :3].copy())
    finally:
        plt.close(fig)
    return rgb, content_box(rgb, _PAD)


def gif(pngs: Sequence[bytes], duration_ms: int = 250) -> bytes:
    """An animated GIF (looping) of PNG frames, via Pillow, with one palette for all frames
    (quantized once from all of them: no colour flicker between frames, one colour table)."""
    from PIL import Image

    if not pngs:
        raise InputError("gif needs at least one frame")
    imgs = [Image.open(io.BytesIO(b)).convert("RGB") for b in pngs]
    size = imgs[0].size
    imgs = [im if im.size == size else im.resize(size) for im in imgs]
    w, h = size
    sheet = Image.new("RGB", (w, h * len(imgs)))
    for k, im in enumerate(imgs):
        sheet.paste(im, (0, k * h))
    sheet = sheet.quantize(colors=255, method=Image.Quantize.MEDIANCUT,
                           dither=Image.Dither.NONE)
    frames = [sheet.crop((0, k * h, w, (k + 1) * h)) for k in range(len(imgs))]
    buf = io.BytesIO()
    frames[0].save(buf, format="GIF", save_all=True, append_images=frames[1:],
                   duration=duration_ms, loop=0)
    return buf.getvalue()
