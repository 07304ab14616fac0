"""The strip's material frame along a lamella and the curvatures it undergoes (Darboux frame).

Along a curve on a surface with unit tangent ``T``, unit surface normal ``N`` and ``U = N x T``:
``T' = kg U + kn N``, ``U' = -kg T + tau_g N``, ``N' = -kn T - tau_g U`` (do Carmo 3-2), with
``kn`` the normal curvature, ``kg`` the geodesic curvature and ``tau_g`` the geodesic torsion.
A strip whose cross-section stays tied to ``(U, N)`` bends with ``kn`` and ``kg`` about the
two section axes and twists at ``tau_g`` (rad/m). All design units: metres, 1/m.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gridshell.geometry.diffgeo import normal_geodesic_curvature
from gridshell.core.errors import InputError
from gridshell.geometry.net import polyline_arclength


@dataclass
class DarbouxCurvatures:
    """Curvatures along a polyline, one value per point (design units).

    s : (k,) arc length, m;  kn, kg : (k,) normal / geodesic curvature, 1/m (signs of
    :func:`gridshell.geometry.diffgeo.normal_geodesic_curvature`);  tau_g : (k,) geodesic torsion, 1/m.
    """

    s: np.ndarray
    kn: np.ndarray
    kg: np.ndarray
    tau_g: np.ndarray


def _unit_rows(X: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(X, axis=1)
    return X / np.where(n > 0, n, 1.0)[:, None]


def _fill_ends(x: np.ndarray) -> np.ndarray:
    """Non-finite values (the two ends of an open polyline) take the nearest finite one; all
    zero when none is finite."""
    x = np.asarray(x, float).copy()
    ok = np.isfinite(x)
    if not ok.any():
        return np.zeros_like(x)
    idx = np.arange(len(x))
    return np.interp(idx, idx[ok], x[ok])


def geodesic_torsion(P: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """Geodesic torsion ``tau_g = -<dN/ds, N x T>`` (1/m) at the points of a polyline ``P (k,3)``
    with unit surface normals ``normals (k,3)``.

    ``dN/ds`` by central differences in arc length (one-sided at the ends), ``T`` the central
    difference tangent. Second-order accurate for uniform sampling. Positive when the normal
    turns like the surface of a right-handed helix about ``T``: on a cylinder of radius R, a
    helix at angle ``a`` to the generators has ``tau_g = sin(a) cos(a) / R`` (outward ``N``).
    """
    P = np.asarray(P, float)
    N = _unit_rows(np.asarray(normals, float))
    if len(P) < 2:
        return np.zeros(len(P))
    s = polyline_arclength(P)
    dN = np.gradient(N, s, axis=0, edge_order=1)
    T = _unit_rows(np.gradient(P, s, axis=0, edge_order=1))
    U = np.cross(N, T)
    return -np.einsum("ij,ij->i", dN, U)


def darboux_curvatures(P: np.ndarray, normals: np.ndarray) -> DarbouxCurvatures:
    """``kn``, ``kg`` (:func:`gridshell.geometry.diffgeo.normal_geodesic_curvature`) and ``tau_g``
    (:func:`geodesic_torsion`) at every point of the polyline ``P (k,3)``, metres, with unit
    surface normals ``normals (k,3)``; the end values repeat their neighbours'.

    Repeated consecutive points are measured once and given the value of their twin.
    """
    P = np.asarray(P, float).reshape(-1, 3)
    N = np.asarray(normals, float).reshape(-1, 3)
    if P.shape != N.shape:
        raise InputError(f"normals {N.shape} must match the polyline {P.shape}")
    k = len(P)
    if k == 0:
        z = np.zeros(0)
        return DarbouxCurvatures(z, z, z, z)
    keep = np.concatenate([[True], np.linalg.norm(np.diff(P, axis=0), axis=1) > 0])
    where = np.cumsum(keep) - 1                      # point -> its kept twin
    Q, M = P[keep], N[keep]
    s = polyline_arclength(P)
    if len(Q) < 3:
        z = np.zeros(k)
        return DarbouxCurvatures(s, z, z.copy(), z.copy())
    kn, kg = normal_geodesic_curvature(Q, M)
    tg = geodesic_torsion(Q, M)
    kn, kg, tg = (_fill_ends(x)[where] for x in (kn, kg, tg))
    return DarbouxCurvatures(s, kn, kg, tg)


def surface_normals(P: np.ndarray, V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """Unit surface normals ``(k,3)`` at points ``P (k,3)`` on or near the mesh ``(V, F)``.

    On a structured quad grid (the surfaces of design bundles) the normals of the smooth
    bicubic surface through the grid (:func:`gridshell.measure.metrics.smooth_grid_normals`, second
    order); otherwise the per-vertex normals of the mesh interpolated at the closest point
    (first order in the mesh size). Oriented like the mesh's faces.
    """
    from gridshell.geometry.igl_adapter import closest_points_with_normals
    from gridshell.measure.metrics import smooth_grid_normals

    P = np.asarray(P, float).reshape(-1, 3)
    if not len(P):
        return np.zeros((0, 3))
    N = smooth_grid_normals(P, V, F)
    if N is None or not np.all(np.isfinite(N)):
        _, N = closest_points_with_normals(P, V, F)
    return N


def joint_normals(V: np.ndarray, loops: np.ndarray) -> np.ndarray:
    """Unit normals ``(n,3)`` of a joint mesh ``V (n,3)`` with quad ``loops (m,4)``: the sum of
    the vector areas of the loops around each joint; zero rows where they vanish (a collapsed
    net whose loops have no area)."""
    from gridshell.geometry.quadmesh import polygon_vector_areas

    V = np.asarray(V, float)
    L = np.asarray(loops, np.int64).reshape(-1, 4)
    A = polygon_vector_areas(V, L) if len(L) else np.zeros((0, 3))
    N = np.zeros_like(V)
    for c in range(4):
        np.add.at(N, L[:, c], A)
    norm = np.linalg.norm(N, axis=1)
    scale = np.linalg.norm(V.max(0) - V.min(0)) if len(V) else 1.0
    ok = norm > 1e-9 * max(scale, 1e-300) ** 2
    N[ok] /= norm[ok, None]
    N[~ok] = 0.0
    return N


def _spline_curvature(X: np.ndarray, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit tangents and curvature vectors ``(j,3)`` (1/m) at the joints ``X (j,3)`` of the
    cubic spline (not-a-knot) ``X(s)`` through them at increasing arc lengths ``s (j,)``."""
    from scipy.interpolate import CubicSpline

    sp = CubicSpline(s, X, axis=0)   # not-a-knot: no artificial straight ends
    d1, d2 = sp(s, 1), sp(s, 2)
    sp1 = np.linalg.norm(d1, axis=1)
    t = _unit_rows(d1)
    kvec = (d2 - np.einsum("ij,ij->i", d2, t)[:, None] * t) / np.maximum(sp1 ** 2, 1e-300)[:, None]
    return t, kvec


def joint_curvatures(X: np.ndarray, s: np.ndarray, normals: np.ndarray) -> DarbouxCurvatures:
    """Curvatures of a lamella known by its joints only (a state of an alignment sequence).

    ``X (j,3)`` joint positions at design arc lengths ``s (j,)`` (kept by the alignment: the
    lamellae do not stretch), ``normals (j,3)`` the strip's section normal at each joint (zero
    rows: unknown). A cubic spline ``X(s)`` (not-a-knot) gives the curvature vector
    ``k = (X'' - <X'', t> t) / |X'|^2``; ``kn = <k, N>``, ``kg = <k, N x t>``, and ``tau_g``
    from the normals as in :func:`geodesic_torsion`. Where the normal is unknown the whole
    curvature is counted as ``kn`` and the twist as zero. Resolution: the joint spacing;
    NaN everywhere for fewer than 3 joints (not measurable).
    """
    X = np.asarray(X, float).reshape(-1, 3)
    s = np.asarray(s, float).reshape(-1)
    j = len(X)
    ok_s = np.concatenate([[True], np.diff(s) > 0]) if j else np.zeros(0, bool)
    if j < 3 or ok_s.sum() < 3:     # two joints tell nothing of the curvature
        z = np.full(j, np.nan)
        return DarbouxCurvatures(s, z, z.copy(), z.copy())
    where = np.cumsum(ok_s) - 1
    Xs, ss = X[ok_s], s[ok_s]
    t, kvec = _spline_curvature(Xs, ss)
    N = np.asarray(normals, float).reshape(-1, 3)[ok_s]
    N = N - np.einsum("ij,ij->i", N, t)[:, None] * t
    known = np.linalg.norm(N, axis=1) > 1e-6
    N = _unit_rows(N)
    for i in range(1, len(N)):  # a line's direction: keep the sign of the previous joint's
        if known[i] and known[i - 1] and N[i] @ N[i - 1] < 0:
            N[i] = -N[i]
    U = np.cross(N, t)
    kn = np.where(known, np.einsum("ij,ij->i", kvec, N), np.linalg.norm(kvec, axis=1))
    kg = np.where(known, np.einsum("ij,ij->i", kvec, U), 0.0)
    dN = np.gradient(N, ss, axis=0, edge_order=1)
    both = known & np.roll(known, 1) & np.roll(known, -1)
    both[0], both[-1] = known[0] & known[1], known[-1] & known[-2]
    tg = np.where(both, -np.einsum("ij,ij->i", dN, U), 0.0)
    return DarbouxCurvatures(s, kn[where], kg[where], tg[where])


#: lamella orientations (paper 3): tangent (GG, thickness along the surface normal) and
#: orthogonal (AA, CNC, NCP, width along the surface normal)
ORIENTATIONS = ("tangent", "orthogonal")


@dataclass
class AxisCurvatures:
    """Curvatures of a strip about its section axes, one value per point (design units).

    weak, strong : (k,) bending curvature about the weak / strong axis, 1/m, signed (an
    orthogonal strip's ``strong`` is measured from its cut shape ``k_cut``);
    twist : (k,) twist rate, rad/m.
    """

    weak: np.ndarray
    strong: np.ndarray
    twist: np.ndarray


def axis_curvatures(dc: DarbouxCurvatures, orientation: str,
                    k_cut: np.ndarray | float = 0.0) -> AxisCurvatures:
    """The section-axis curvatures of a strip of ``orientation`` from the Darboux curvatures
    ``dc`` of its axis (1/m): tangent: weak ``kn``, strong ``kg``, twist ``tau_g``; orthogonal:
    weak ``kg``, strong ``kn - k_cut`` (``k_cut``: the in-plane curvature of the strip as cut,
    1/m), twist ``tau_g`` (paper 3; table of :mod:`gridshell.structure.stresses`)."""
    if orientation not in ORIENTATIONS:
        raise InputError(f"orientation must be one of {', '.join(ORIENTATIONS)}, "
                         f"got {orientation!r}")
    if orientation == "tangent":
        return AxisCurvatures(dc.kn, dc.kg, dc.tau_g)
    return AxisCurvatures(dc.kg, dc.kn - np.asarray(k_cut, float), dc.tau_g)


def strip_frame_curvatures(P: np.ndarray, normals: np.ndarray, orientation: str,
                           k_cut: np.ndarray | float = 0.0) -> AxisCurvatures:
    """Weak-axis, strong-axis curvature and twist (1/m, rad/m) of a strip whose axis is the
    dense polyline ``P (k,3)`` (metres) with unit surface normals ``normals (k,3)``, from its
    Darboux frame (:func:`darboux_curvatures`: ``kn``, ``kg``, ``tau_g = -<dN/ds, N x T>``,
    do Carmo 3-2) assigned to the section axes by :func:`axis_curvatures`."""
    return axis_curvatures(darboux_curvatures(P, normals), orientation, k_cut)
