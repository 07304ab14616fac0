"""The in-plane curvature of each strip as cut (orthogonal lamellae), along its axis.

The shapes :mod:`gridshell.fabrication.strips` cuts (one rule for both:
:func:`gridshell.design.bundle.strip_cut_shape` and :func:`gridshell.design.bundle.collapse_radius`): AA and
GG strips are straight;
CNC strips are arcs of radius ``collapse.radius`` (or ``1 / metrics.n``); NCP strips are pieces
of the planar collapse curve, joint 0 at ``collapse_s[0]`` and the axis following at its own arc
length. Curvatures are signed against the flattened surface normals stored with the collapse
curve (positive: the strip bends towards its normal side), design units (1/m).
"""
from __future__ import annotations

import numpy as np

from gridshell.design.bundle import DesignBundle, collapse_radius
from gridshell.design.bundle import strip_cut_shape as cut_shape
from gridshell.geometry.diffgeo import polyline_curvature
from gridshell.core.errors import InputError
from gridshell.geometry.net import Lamella, polyline_arclength


def collapse_curvature(bundle: DesignBundle) -> tuple[np.ndarray, np.ndarray]:
    """Arc length ``c (k,)`` (m) and signed curvature ``(k,)`` (1/m) along the collapse curve."""
    c = bundle.collapse
    P = np.asarray(c.points, float)
    keep = np.concatenate([[True], np.linalg.norm(np.diff(P, axis=0), axis=1) > 0])
    P = P[keep]
    Nn = np.asarray(c.normals, float)[keep] if len(c.normals) == len(keep) else None
    arc = polyline_arclength(np.pad(P, ((0, 0), (0, 1))))
    if len(P) < 3:
        return arc, np.zeros(len(P))
    kvec, _ = polyline_curvature(np.pad(P, ((0, 0), (0, 1))))
    k2 = kvec[:, :2]
    if Nn is None:   # no normals: the left side of the curve
        T = np.gradient(P, axis=0)
        Nn = np.stack([-T[:, 1], T[:, 0]], axis=1)
    Nn = Nn / np.maximum(np.linalg.norm(Nn, axis=1), 1e-300)[:, None]
    k = np.einsum("ij,ij->i", k2, Nn)
    ok = np.isfinite(k)
    k = np.interp(arc, arc[ok], k[ok]) if ok.any() else np.zeros_like(k)
    return arc, k


def cut_curvature(bundle: DesignBundle, lam: Lamella, s: np.ndarray,
                  curve: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
    """In-plane curvature (1/m, design) of lamella ``lam``'s strip as cut, at axis arc lengths
    ``s``; ``curve`` the output of :func:`collapse_curvature` (computed when needed)."""
    s = np.asarray(s, float)
    shape = cut_shape(bundle)
    if shape == "line":
        return np.zeros_like(s)
    if shape == "arc":
        return np.full_like(s, 1.0 / collapse_radius(bundle))
    arc, k = curve if curve is not None else collapse_curvature(bundle)
    cs = (bundle.collapse_s or {}).get(int(lam.id))
    c0 = float(cs[0]) if cs is not None and len(cs) else 0.0
    js0 = float(lam.joint_s[0]) if len(lam.joint_s) else 0.0
    return np.interp(c0 + s - js0, arc, k)
