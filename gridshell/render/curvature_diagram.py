"""The curvature diagram of paper Fig. 11: samples in the (H, K) plane with each u-row's line.

A PHLW surface has, along each principal line ``u = const``, ``K - 2 n_u H + n_u^2 + t_u^2 = 0``
(eq. 4.8): the samples of one row lie on the line ``K = 2 n_u H - (n_u^2 + t_u^2)``, which
touches or stays below the parabola ``K = H^2`` (``b^2 - 4ac <= 0``). Plain arrays in, a PNG out.
"""
from __future__ import annotations

import os

import numpy as np

from gridshell.core.atomic import atomic_path
from gridshell.core.errors import InputError


def curvature_diagram(path: str | os.PathLike, H: np.ndarray, K: np.ndarray,
                      n_rows: np.ndarray | None = None, t_rows: np.ndarray | None = None, *,
                      u_rows: np.ndarray | None = None, title: str | None = None,
                      parabola: bool = True, dpi: int = 120) -> None:
    """Write the curvature diagram as a PNG, atomically.

    Parameters
    ----------
    path : output file (.png)
    H, K : (rows, cols) mean (1/m) and Gaussian (1/m^2) curvature at the samples; row ``i`` is
        the u-row ``u = u_rows[i]`` and gets its own colour
    n_rows, t_rows : (rows,) coefficients of eq. 4.8 per row (1/m); with them each row's line
        ``K = 2 n H - (n^2 + t^2)`` is drawn over the row's H range
    u_rows : (rows,) u values for the colour bar (default 0 .. rows-1)
    title : plot title
    parabola : also draw ``K = H^2`` (umbilics), which every line touches or stays below
    dpi : resolution
    """
    H = np.atleast_2d(np.asarray(H, dtype=float))
    K = np.atleast_2d(np.asarray(K, dtype=float))
    if H.shape != K.shape:
        raise InputError(f"H and K must have the same (rows, cols) shape, got {H.shape} and {K.shape}")
    R = H.shape[0]
    for name, a in (("n_rows", n_rows), ("t_rows", t_rows), ("u_rows", u_rows)):
        if a is not None and np.size(a) not in (1, R):
            raise InputError(f"{name} needs one value per row ({R}), got {np.size(a)}")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib import cm, colors

    u = np.arange(R, dtype=float) if u_rows is None else np.asarray(u_rows, float).reshape(-1)
    norm = colors.Normalize(vmin=float(u.min()), vmax=float(u.max()) if u.max() > u.min()
                            else float(u.min()) + 1.0)
    cmap = plt.get_cmap("viridis")
    fig, ax = plt.subplots(figsize=(6.4, 5.0))
    try:
        finite = np.isfinite(H) & np.isfinite(K)
        hmin, hmax = (float(H[finite].min()), float(H[finite].max())) if finite.any() else (0, 1)
        pad = 0.05 * max(hmax - hmin, 1e-12)
        if parabola and finite.any():
            hh = np.linspace(hmin - pad, hmax + pad, 200)
            ax.plot(hh, hh * hh, color="0.6", lw=1.0, ls="--", label="K = H$^2$ (umbilic)")
        for i in range(R):
            col = cmap(norm(u[i]))
            ok = finite[i]
            ax.scatter(H[i, ok], K[i, ok], s=9, color=col, zorder=3)
            if n_rows is not None and t_rows is not None and ok.any():
                n = float(np.broadcast_to(np.asarray(n_rows, float).reshape(-1), (R,))[i])
                t = float(np.broadcast_to(np.asarray(t_rows, float).reshape(-1), (R,))[i])
                lo, hi = float(H[i, ok].min()), float(H[i, ok].max())
                ext = 0.15 * max(hi - lo, 2 * pad)
                hh = np.array([lo - ext, hi + ext])
                ax.plot(hh, 2 * n * hh - (n * n + t * t), color=col, lw=1.0, zorder=2)
        fig.colorbar(cm.ScalarMappable(norm=norm, cmap=cmap), ax=ax, label="u (row)")
        ax.set_xlabel("mean curvature H [1/m]")
        ax.set_ylabel("Gaussian curvature K [1/m$^2$]")
        ax.set_title(title or "curvature diagram: aK + bH + c = 0 per principal line u")
        if finite.any():
            kmin, kmax = float(K[finite].min()), float(K[finite].max())
            kp = 0.1 * max(kmax - kmin, 1e-12)
            ax.set_ylim(kmin - kp, kmax + kp)
            ax.set_xlim(hmin - 3 * pad, hmax + 3 * pad)
        if parabola:
            ax.legend(loc="best", fontsize=8)
        ax.grid(True, lw=0.3)
        fig.tight_layout()
        with atomic_path(path) as tmp:
            fig.savefig(tmp, format="png", dpi=dpi)
    finally:
        plt.close(fig)
