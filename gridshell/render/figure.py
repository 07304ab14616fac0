"""Matplotlib set-up shared by the headless pictures: the Agg backend, cube axes, PNG bytes
cropped to their content."""
from __future__ import annotations

import io
from typing import Any, Sequence

import numpy as np

__all__ = ["pyplot", "cube_limits", "png_bytes", "content_box"]


def pyplot() -> Any:
    """``matplotlib.pyplot`` on the Agg backend (no display needed)."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


def cube_limits(ax: Any, P: np.ndarray) -> None:
    """Equal-scale 3D axes around the points ``P (n, 3)`` (metres), axes hidden."""
    P = np.asarray(P, float).reshape(-1, 3)
    lo, hi = P.min(axis=0), P.max(axis=0)
    c, h = 0.5 * (lo + hi), 0.5 * float(np.max(hi - lo)) or 1.0
    ax.set_xlim(c[0] - h, c[0] + h)
    ax.set_ylim(c[1] - h, c[1] + h)
    ax.set_zlim(c[2] - h, c[2] + h)
    ax.set_box_aspect((1, 1, 1))
    ax.set_axis_off()


def png_bytes(fig: Any, pad: int = 8) -> bytes:
    """The figure as PNG bytes, cropped to its content (every pixel that is not the white
    background, plus ``pad`` pixels); the figure is closed. One draw, where
    ``savefig(bbox_inches="tight")`` draws twice (once to measure the bounding box)."""
    from PIL import Image

    try:
        fig.canvas.draw()
        img = np.asarray(fig.canvas.buffer_rgba())[..., :3]
    finally:
        pyplot().close(fig)
    y0, y1, x0, x1 = content_box([img], pad)
    buf = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(img[y0:y1, x0:x1])).save(buf, format="PNG")
    return buf.getvalue()


#: pictures of states and frames are at least this wide (pixels) after cropping: drawn again
#: at a higher resolution when the content of the first drawing is narrower (issue 30)
MIN_FRAME_PX = 800


def dpi_for_width(dpi: float, width: int, target: int = MIN_FRAME_PX) -> int | None:
    """The resolution at which content ``width`` pixels wide at ``dpi`` becomes ``target``
    pixels wide (8 % to spare: the crop's margins do not scale), or None when it already is."""
    if width >= target or width <= 0:
        return None
    return int(np.ceil(dpi * target / width * 1.08))


def content_box(images: Sequence[np.ndarray], pad: int = 8) -> tuple[int, int, int, int]:
    """``(y0, y1, x0, x1)``: the smallest box holding every non-white pixel of all the
    ``(h, w, 3)`` uint8 images (one size), widened by ``pad`` pixels; the whole image when all
    are white."""
    ink = np.zeros(images[0].shape[:2], bool)
    for a in images:
        ink |= (a < 250).any(axis=2)
    ys, xs = np.nonzero(ink.any(axis=1))[0], np.nonzero(ink.any(axis=0))[0]
    h, w = ink.shape
    if not len(ys):
        return 0, h, 0, w
    return (max(int(ys[0]) - pad, 0), min(int(ys[-1]) + 1 + pad, h),
            max(int(xs[0]) - pad, 0), min(int(xs[-1]) + 1 + pad, w))
