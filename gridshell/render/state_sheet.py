"""Pictures of the states of an alignment sequence, cropped to what they show (GG bundles).

Every state is drawn with one camera and one set of limits (so all states share a scale), then
the common empty margin of all of them is cropped away - 3D axes otherwise leave most of a
picture white, the more so when the sequence ends in a thin line.

- :func:`state_images`: the cropped pictures (PIL images) of all states;
- :func:`states_png`: a strip of some states side by side, each labelled (``states.png``);
- :func:`sequence_pngs`: one titled PNG per state, for ``sequence/frame_*.png`` and the GIF
  (:func:`gridshell.render.ncp_maps.gif`).

Edges can be coloured by lamella family (:data:`gridshell.render.ribbons.FAMILY_COLOURS`).
"""
from __future__ import annotations

import io
from typing import Any, Sequence

import numpy as np

from gridshell.core.errors import InputError
from gridshell.render.figure import MIN_FRAME_PX, cube_limits, dpi_for_width, png_bytes, pyplot

__all__ = ["state_images", "states_png", "sequence_pngs"]

_PAD = 10  # pixels kept around the cropped content


def _edge_colours(n_edges: int, families: np.ndarray | None) -> Any:
    from gridshell.render.ribbons import FAMILY_COLOURS

    if families is None:
        return (0.1, 0.2, 0.5, 0.9)
    fam = np.asarray(families).reshape(-1)
    if len(fam) != n_edges:
        raise InputError(f"{len(fam)} edge families for {n_edges} edges")
    return [FAMILY_COLOURS.get(int(f), (0.3, 0.3, 0.3)) for f in fam]


def state_images(frames: Sequence[np.ndarray], edges: np.ndarray, *,
                 families: np.ndarray | None = None, dpi: int = 100,
                 view: tuple[float, float] | None = None,
                 min_width: int = MIN_FRAME_PX) -> list[Any]:
    """Pictures of the states ``frames [(n, 3)]`` (metres) of a net with ``edges (E, 2)``.

    One camera (``view = (elev, azim)`` in degrees, default
    :func:`gridshell.render.ribbons.view_angles` of all states together, so that neither the
    deployed net nor a collapsed line is seen edge-on) and limits over all states; the common
    white margin is cropped. Returns PIL RGB images, all of one size, at least ``min_width``
    pixels wide (drawn again at a higher ``dpi`` when the content is narrower).
    """
    imgs = _state_pictures(frames, edges, families, dpi, view)
    for _ in range(3):                      # the crop's margins do not scale: at most 3 tries
        better = dpi_for_width(dpi, imgs[0].size[0], min_width)
        if better is None:
            break
        dpi = better
        imgs = _state_pictures(frames, edges, families, dpi, view)
    return imgs


def _state_pictures(frames, edges, families, dpi: float, view) -> list[Any]:
    """:func:`state_images` at ``dpi``."""
    from mpl_toolkits.mplot3d.art3d import Line3DCollection
    from PIL import Image, ImageOps

    from gridshell.render.ribbons import view_angles

    frames = [np.asarray(V, float).reshape(-1, 3) for V in frames]
    if not frames:
        raise InputError("no states to draw")
    E = np.asarray(edges, np.int64).reshape(-1, 2)
    allP = np.concatenate(frames)
    elev, azim = view if view is not None else view_angles(allP)
    colours = _edge_colours(len(E), families)
    plt = pyplot()
    # one figure for all states, its lines and points moved from state to state and its
    # canvas read directly (a figure, a PNG and its decoding per state took 3x as long)
    fig = plt.figure(figsize=(6.0, 5.0), dpi=dpi)
    ax = fig.add_axes((0, 0, 1, 1), projection="3d")
    lines = Line3DCollection(frames[0][E], colors=colours, linewidths=1.2)
    ax.add_collection3d(lines)
    V = frames[0]
    points = ax.scatter(V[:, 0], V[:, 1], V[:, 2], s=3, color=(0.15, 0.15, 0.15),
                        depthshade=False)
    cube_limits(ax, allP)
    ax.view_init(elev=elev, azim=azim)
    imgs = []
    try:
        for V in frames:
            lines.set_segments(V[E])
            points._offsets3d = (V[:, 0], V[:, 1], V[:, 2])
            fig.canvas.draw()  # the whole canvas: one frame for all states
            rgba = np.asarray(fig.canvas.buffer_rgba())
            imgs.append(Image.fromarray(np.ascontiguousarray(rgba[..., :3])))
    finally:
        plt.close(fig)
    boxes = [ImageOps.invert(im).getbbox() for im in imgs]
    boxes = [b for b in boxes if b]
    if boxes:
        W, H = imgs[0].size
        box = (max(min(b[0] for b in boxes) - _PAD, 0), max(min(b[1] for b in boxes) - _PAD, 0),
               min(max(b[2] for b in boxes) + _PAD, W), min(max(b[3] for b in boxes) + _PAD, H))
        imgs = [im.crop(box) for im in imgs]
    return imgs


def _titled(img: Any, title: str, dpi: int) -> bytes:
    """``img`` under a one-line title, as PNG bytes."""
    plt = pyplot()
    w, h = img.size
    band = int(round(0.32 * dpi)) if title else 0
    fig = plt.figure(figsize=(w / dpi, (h + band) / dpi), dpi=dpi)
    fig.figimage(np.asarray(img), xo=0, yo=0)
    if title:
        fig.text(0.5, 1 - 0.5 * band / (h + band), title, ha="center", va="center", fontsize=9)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    plt.close(fig)
    return buf.getvalue()


def sequence_pngs(frames: Sequence[np.ndarray], edges: np.ndarray, *, title: str = "",
                  families: np.ndarray | None = None, dpi: int = 120,
                  t: Sequence[float] | None = None) -> list[bytes]:
    """One PNG per state, cropped as :func:`state_images`, titled
    ``"<title>: state k/K (t = ...)"``; all of one size (ready for an animated GIF)."""
    imgs = state_images(frames, edges, families=families, dpi=dpi)
    K = len(imgs) - 1
    ts = np.linspace(0, 1, K + 1) if t is None else np.asarray(t, float)
    head = f"{title}: " if title else ""
    return [_titled(im, f"{head}state {k}/{K} (t = {ts[k]:.2f})", dpi)
            for k, im in enumerate(imgs)]


def states_png(frames: Sequence[np.ndarray], edges: np.ndarray, *,
               labels: Sequence[str] | None = None, title: str = "",
               families: np.ndarray | None = None, dpi: int = 100,
               columns: int | None = None) -> bytes:
    """A strip of states side by side (``states.png``), each with its label below it.

    Parameters
    ----------
    frames : list of (n, 3) float
        The states to show, metres, e.g. deployed, some intermediate ones, collapsed.
    edges : (E, 2) int
    labels : list of str, optional
        One per state (default ``"state k"``).
    title : str
        Over the whole strip.
    families : (E,) int, optional
        Lamella family of each edge, for the colours.
    columns : int, optional
        States per row (default 2: each state at least
        :data:`~gridshell.render.figure.MIN_FRAME_PX` wide, the sheet twice that).
    """
    # 10 % more: the sheet's margins and labels take their share of each cell
    imgs = state_images(frames, edges, families=families, dpi=dpi,
                        min_width=int(1.1 * MIN_FRAME_PX))
    n = len(imgs)
    labels = list(labels) if labels is not None else [f"state {k}" for k in range(n)]
    if len(labels) != n:
        raise InputError(f"{len(labels)} labels for {n} states")
    cols = columns or (n if n <= 2 else 2)
    rows = int(np.ceil(n / cols))
    w, h = imgs[0].size
    plt = pyplot()
    fig, axes = plt.subplots(rows, cols, figsize=(cols * w / dpi, rows * (h / dpi + 0.3) + 0.35),
                             dpi=dpi, squeeze=False)
    for k, ax in enumerate(axes.ravel()):
        ax.set_axis_off()
        if k < n:
            ax.imshow(np.asarray(imgs[k]))
            ax.set_title(labels[k], fontsize=9, y=-0.08, va="top")
    if title:
        fig.suptitle(title, fontsize=10)
    fig.subplots_adjust(left=0.01, right=0.99, bottom=0.06, top=0.9 if title else 0.99,
                        wspace=0.04, hspace=0.15)
    return png_bytes(fig)
