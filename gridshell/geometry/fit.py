"""Least-squares fits of point sets: line, plane, circle (metres in, metres out).

Used by the NCP collapse (:mod:`gridshell.ncp.collapse`) and by the verification of a bundle
(:mod:`gridshell.design.verification`), which must not import a pipeline.
"""
from __future__ import annotations

import numpy as np

from gridshell.core.errors import InputError

__all__ = ["fit_circle", "fit_plane", "line_deviation"]


def _points(P: np.ndarray, dim: int | None, least: int, what: str) -> np.ndarray:
    P = np.asarray(P, float)
    if P.ndim != 2 or (dim is not None and P.shape[1] != dim) or len(P) < least:
        shape = f"(k, {dim})" if dim is not None else "(k, d)"
        raise InputError(f"{what} needs at least {least} points of shape {shape}, got "
                         f"{P.shape}")
    return P


def fit_circle(P: np.ndarray) -> tuple[np.ndarray, float]:
    """Least-squares circle (Kasa fit) through 2D points ``P (k, 2)``, ``k >= 3``: centre,
    radius (exact for points on a circle)."""
    P = _points(P, 2, 3, "a circle fit")
    c0 = P.mean(axis=0)
    Q = P - c0
    A = np.column_stack([2 * Q, np.ones(len(Q))])
    b = np.einsum("ij,ij->i", Q, Q)
    sol = np.linalg.lstsq(A, b, rcond=None)[0]
    centre = sol[:2]
    r = float(np.sqrt(sol[2] + centre @ centre))
    return centre + c0, r


def fit_plane(P: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Least-squares plane of points ``P (k, 3)``, ``k >= 3`` (principal axes).

    Returns
    -------
    centroid : (3,) a point of the plane
    basis : (2, 3) orthonormal in-plane axes, largest spread first; ``(P - centroid) @ basis.T``
        are the points' coordinates in the plane
    distance : (k,) signed distances of the points from the plane along its normal
        ``basis[0] x basis[1]``, metres
    """
    P = _points(P, 3, 3, "a plane fit")
    c = P.mean(axis=0)
    _, _, Vt = np.linalg.svd(P - c, full_matrices=False)
    return c, Vt[:2], (P - c) @ np.cross(Vt[0], Vt[1])


def line_deviation(P: np.ndarray) -> float:
    """Max distance of points ``P (k, d)`` from their best-fit line, divided by their span."""
    P = _points(P, None, 2, "a line fit")
    Q = P - P.mean(axis=0)
    _, _, Vt = np.linalg.svd(Q, full_matrices=False)
    along = Q @ Vt[0]
    off = np.linalg.norm(Q - along[:, None] * Vt[0][None, :], axis=1)
    span = float(np.ptp(along))
    return float(off.max() / span) if span > 0 else float("nan")
