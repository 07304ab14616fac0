"""Matplotlib set-up shared by the headless pictures: the Agg backend, cube axes, PNG bytes."""
from __future__ import annotations

import io
from typing import Any

import numpy as np

__all__ = ["pyplot", "cube_limits", "png_bytes"]


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


def png_bytes(fig: Any) -> bytes:
    """The figure as PNG bytes (tight bounding box); the figure is closed."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", bbox_inches="tight")
    pyplot().close(fig)
    return buf.getvalue()
