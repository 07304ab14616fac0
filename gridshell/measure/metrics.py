"""Verification metrics of a gridshell net (paper 5.1), shared by the GG and NCP pipelines.

Every function is pure: arrays (or a :class:`~gridshell.geometry.net.Net`) in, arrays or a small dict
out. Lengths in metres; errors are dimensionless fractions (multiply by 100 for %), except
:func:`deviation`, which reports percent of a bounding-box diagonal as the paper does.
"""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from gridshell.core.errors import InputError
from gridshell.geometry.net import Net

__all__ = ["alignability_error", "alignability_error_arc", "coverage", "crossing_normal_curvature",
           "crossing_normal_curvature_on_mesh", "delta_l", "delta_n", "deviation",
           "geodesic_turning", "loop_side_lengths", "smooth_grid_normals", "summary",
           "surface_area", "target_deviation"]


def _V(name: str, V: Any) -> np.ndarray:
    V = np.asarray(V, dtype=float)
    if V.ndim != 2 or V.shape[1] != 3:
        raise InputError(f"{name} must have shape (n, 3), got {V.shape}")
    return V


def _loops(loops: Any, n: int) -> np.ndarray:
    L = np.asarray(loops)
    if L.ndim != 2 or L.shape[1] != 4:
        raise InputError(f"loops must have shape (m, 4), got {L.shape}")
    L = L.astype(np.int64)
    if L.size and (L.min() < 0 or L.max() >= n):
        raise InputError(f"loop indices must lie in [0, {n}), got [{L.min()}, {L.max()}]")
    return L


def _delta_a(l1: np.ndarray, l2: np.ndarray, l3: np.ndarray, l4: np.ndarray) -> np.ndarray:
    tot = l1 + l2 + l3 + l4
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(tot > 0, 4.0 * np.abs(l1 + l2 - l3 - l4) / tot, np.nan)


def loop_side_lengths(V: np.ndarray, loops: np.ndarray) -> np.ndarray:
    """Chord lengths ``(m, 4)`` of the sides ``AB, BC, AD, DC`` of net-loops ``A, B, C, D``."""
    V = _V("V", V)
    L = _loops(loops, len(V))
    A, B, C, D = (V[L[:, i]] for i in range(4))
    return np.stack([np.linalg.norm(B - A, axis=1), np.linalg.norm(C - B, axis=1),
                     np.linalg.norm(D - A, axis=1), np.linalg.norm(C - D, axis=1)], axis=1)


def alignability_error(V: np.ndarray, loops: np.ndarray) -> np.ndarray:
    """Alignability error per net-loop with straight edges (paper 5.1).

    ``Delta_a = 4 |l1 + l2 - l3 - l4| / (l1 + l2 + l3 + l4)`` with ``(l1, l2) = (|AB|, |BC|)``
    the way from corner ``A`` to ``C`` through ``B`` and ``(l3, l4) = (|AD|, |DC|)`` the way
    through ``D``: a loop is alignable iff ``l_AB + l_BC = l_AD + l_DC`` (Definition 4), and
    ``Delta_a`` is that difference over the mean edge length.

    Parameters
    ----------
    V : (n, 3) float
        Joint positions, metres.
    loops : (m, 4) int
        Net-loops ``A, B, C, D`` (either orientation: the value is symmetric).

    Returns
    -------
    delta_a : (m,) float
        Dimensionless (0.01 = 1 %); NaN for a loop of zero perimeter.
    """
    ell = loop_side_lengths(V, loops)
    return _delta_a(*ell.T)


def _edge_arcs(net: Net) -> dict[tuple[int, int], float]:
    arcs: dict[tuple[int, int], float] = {}
    for lam in net.lamellae:
        d = np.diff(lam.joint_s)
        for a, b, x in zip(lam.joints[:-1].tolist(), lam.joints[1:].tolist(), d.tolist()):
            arcs[(a, b)] = arcs[(b, a)] = float(x)
    return arcs


def alignability_error_arc(net: Net) -> np.ndarray:
    """Alignability error per net-loop with the lamella arc lengths between joints (paper 5.1).

    As :func:`alignability_error` with ``l_XY = |joint_s(Y) - joint_s(X)|`` along the lamella
    joining consecutive joints ``X`` and ``Y`` (the exact quantity of Definition 4).

    Returns
    -------
    delta_a : (m,) float

    Raises
    ------
    InputError
        If a loop side joins joints that are not consecutive on any lamella.
    """
    arcs = _edge_arcs(net)
    L = net.loops
    out = np.empty((len(L), 4))
    for k, (a, b) in enumerate(((0, 1), (1, 2), (0, 3), (3, 2))):
        for m, (x, y) in enumerate(zip(L[:, a].tolist(), L[:, b].tolist())):
            v = arcs.get((x, y))
            if v is None:
                raise InputError(f"net-loop {m}: joints {x} and {y} are not consecutive on a "
                                 "lamella; the loops do not match the lamellae")
            out[m, k] = v
    return _delta_a(*out.T)


def delta_l(V_star: np.ndarray, V_aligned: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """Relative edge-length change between a mesh and its aligned configuration (paper 5.1).

    ``Delta_l = | |V^a_k - V^a_j| - |V*_k - V*_j| | / |V*_k - V*_j|`` per edge ``(j, k)``.

    Parameters
    ----------
    V_star : (n, 3) float
        Optimized (deployed) vertices, metres.
    V_aligned : (n, 3) float
        The same vertices in the aligned configuration.
    edges : (E, 2) int

    Returns
    -------
    (E,) float
        Dimensionless; NaN for zero-length edges of ``V_star``.
    """
    Vs, Va = _V("V_star", V_star), _V("V_aligned", V_aligned)
    if Vs.shape != Va.shape:
        raise InputError(f"V_star {Vs.shape} and V_aligned {Va.shape} must have the same shape")
    E = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    ls = np.linalg.norm(Vs[E[:, 1]] - Vs[E[:, 0]], axis=1)
    la = np.linalg.norm(Va[E[:, 1]] - Va[E[:, 0]], axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(ls > 0, np.abs(la - ls) / ls, np.nan)


def delta_n(V_star: np.ndarray, r_star: np.ndarray, V_a: np.ndarray, r_a: np.ndarray,
            edges: np.ndarray) -> np.ndarray:
    """Relative change of discrete normal curvature at each vertex upon alignment (paper 5.1).

    ``Delta_n_j = (1/m) sum_k | <V^a_j - V^a_k, r^a_j> - <V*_j - V*_k, r*_j> |
    / |<V*_j - Vbar*_k, r*_j>|`` over the ``m`` neighbours ``k`` of ``j`` along ``edges``,
    with ``Vbar*_k`` the mean of those neighbours and ``r_j`` the rotation axis at ``j``.

    Parameters
    ----------
    V_star, r_star : (n, 3) float
        Optimized vertices (metres) and their unit rotation axes.
    V_a, r_a : (n, 3) float
        Aligned vertices and axes.
    edges : (E, 2) int

    Returns
    -------
    (n,) float
        Dimensionless; NaN at vertices without neighbours or with a zero denominator
        (locally flat along the axis).
    """
    Vs, rs, Va, ra = (_V(n_, a) for n_, a in (("V_star", V_star), ("r_star", r_star),
                                                 ("V_a", V_a), ("r_a", r_a)))
    if not (Vs.shape == rs.shape == Va.shape == ra.shape):
        raise InputError("V_star, r_star, V_a and r_a must all have the same shape (n, 3)")
    n = len(Vs)
    E = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    j = np.concatenate([E[:, 0], E[:, 1]])
    k = np.concatenate([E[:, 1], E[:, 0]])
    m = np.bincount(j, minlength=n).astype(float)
    num = np.abs(np.einsum("ij,ij->i", Va[j] - Va[k], ra[j])
                 - np.einsum("ij,ij->i", Vs[j] - Vs[k], rs[j]))
    Vbar = np.zeros_like(Vs)
    np.add.at(Vbar, j, Vs[k])
    with np.errstate(divide="ignore", invalid="ignore"):
        Vbar /= m[:, None]
        den = np.abs(np.einsum("ij,ij->i", Vs - Vbar, rs))
        tot = np.bincount(j, weights=num, minlength=n)
        out = tot / m / den
    return np.where((m > 0) & (den > 0), out, np.nan)


def deviation(P: np.ndarray, V: np.ndarray, F: np.ndarray,
              reuse: bool = False) -> dict[str, float]:
    """Distance of points from a surface mesh in percent of its bounding-box diagonal (Fig. 17).

    Parameters
    ----------
    P : (k, 3) float
        Points, metres.
    V, F
        The reference surface (triangles or quads; see :mod:`gridshell.geometry.igl_adapter`).

    Returns
    -------
    dict
        ``max``, ``mean``: distances in % of the bounding-box diagonal of the referenced
        vertices of ``(V, F)``; ``diagonal`` in metres.
    """
    return deviations([P], V, F, reuse)[0]


def deviations(Ps: Sequence[np.ndarray], V: np.ndarray, F: np.ndarray,
               reuse: bool = False) -> list[dict[str, float]]:
    """:func:`deviation` of each point set of ``Ps`` from one surface, with one closest-point
    query (igl builds its AABB tree once per query: on a 200k-triangle target ~0.15 s;
    ``reuse``: see :func:`gridshell.geometry.igl_adapter.closest_points`)."""
    from gridshell.geometry.igl_adapter import closest_points

    V = _V("V", V)
    used = np.zeros(len(V), dtype=bool)  # the referenced vertices (a mask: O(n), no sort)
    used[np.asarray(F, dtype=np.int64).ravel()] = True
    used = V[used]
    diag = float(np.linalg.norm(used.max(axis=0) - used.min(axis=0))) if len(used) else 0.0
    if not diag > 0:
        raise InputError("the reference surface has a zero bounding box; give a real surface")
    Ps = [_V("P", P) for P in Ps]
    sq, _, _ = closest_points(np.concatenate(Ps) if Ps else np.zeros((0, 3)), V, F, reuse)
    d = np.sqrt(np.maximum(sq, 0.0)) / diag * 100.0
    out = []
    for part in np.split(d, np.cumsum([len(P) for P in Ps])[:-1]):
        out.append({"max": float(part.max()) if len(part) else 0.0,
                    "mean": float(part.mean()) if len(part) else 0.0, "diagonal": diag})
    return out


def surface_area(V: np.ndarray, F: np.ndarray) -> float:
    """Area of a triangle or quad mesh, m^2 (quads split along their shorter diagonal, as
    :func:`gridshell.geometry.igl_adapter.triangulate` does)."""
    from gridshell.geometry.igl_adapter import triangulate

    V, T, _ = triangulate(_V("V", V), F)
    return float(0.5 * np.linalg.norm(np.cross(V[T[:, 1]] - V[T[:, 0]], V[T[:, 2]] - V[T[:, 0]]),
                                      axis=1).sum())


def coverage(V: np.ndarray, F: np.ndarray, target_V: np.ndarray, target_F: np.ndarray) -> float:
    """How much of a target a designed surface covers: ``area(V, F) / area(target)`` in %.

    With :func:`target_deviation` it exposes a design that shrank away from the target's
    boundary, which the one-way :func:`deviation` (surface -> target) cannot see: a small
    patch in the middle of the target is at distance zero.

    Returns
    -------
    float
        Percent (100 = the same area; above 100 if the surface is larger or wavier).
    """
    At = surface_area(target_V, target_F)
    if not At > 0:
        raise InputError("the target has zero area; give a real surface")
    return 100.0 * surface_area(V, F) / At


def target_deviation(V: np.ndarray, F: np.ndarray, target_V: np.ndarray,
                     target_F: np.ndarray) -> dict[str, float]:
    """Distance of the target from a designed surface, % of the target's bounding-box diagonal.

    The reverse of :func:`deviation` (which measures the surface's points against the target):
    the target is sampled at its vertices and at four points of every triangle (centroid and
    ``(2/3, 1/6, 1/6)`` and its permutations, each carrying a quarter of the triangle's area),
    and each sample's distance to ``(V, F)`` is taken. Large where the surface does not reach a
    part of the target.

    Parameters
    ----------
    V, F
        The designed surface (triangles or quads), metres.
    target_V, target_F
        The target surface.

    Returns
    -------
    dict
        ``max`` (over all samples) and ``mean`` (area-weighted over the triangle samples), in %
        of the bounding-box diagonal of the referenced target vertices; ``diagonal`` in metres.
    """
    from gridshell.geometry.igl_adapter import closest_points, triangulate
    from gridshell.geometry.quadmesh import unique_ints

    tV, T, _ = triangulate(_V("target_V", target_V), target_F)
    used = tV[unique_ints(T)]
    diag = float(np.linalg.norm(used.max(axis=0) - used.min(axis=0)))
    if not diag > 0:
        raise InputError("the target has a zero bounding box; give a real surface")
    A, B, C = tV[T[:, 0]], tV[T[:, 1]], tV[T[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(B - A, C - A), axis=1)
    bary = np.array([[1 / 3, 1 / 3, 1 / 3], [2 / 3, 1 / 6, 1 / 6], [1 / 6, 2 / 3, 1 / 6],
                     [1 / 6, 1 / 6, 2 / 3]])
    S = (bary[None, :, 0, None] * A[:, None] + bary[None, :, 1, None] * B[:, None]
         + bary[None, :, 2, None] * C[:, None]).reshape(-1, 3)
    w = np.repeat(area / 4.0, 4)
    sq, _, _ = closest_points(np.concatenate([S, used]), _V("V", V), F)
    d = np.sqrt(np.maximum(sq, 0.0)) / diag * 100.0
    mean = float(np.sum(d[:len(S)] * w) / np.sum(w)) if np.sum(w) > 0 else float(d.mean())
    return {"max": float(d.max()), "mean": mean, "diagonal": diag}


def smooth_grid_normals(P: np.ndarray, V: np.ndarray, F: np.ndarray) -> np.ndarray | None:
    """Unit normals at the feet of points on the smooth surface through a structured quad grid.

    The grid ``X (R, C, 3)`` of ``(V, F)`` (:func:`gridshell.geometry.grid.grid_from_quads`) is
    interpolated by a bicubic spline per coordinate (``scipy.interpolate.RectBivariateSpline``,
    lower degree below 4 rows / columns) over averaged chord-length parameters: ``u_i`` the
    cumulative mean length of the edges between rows ``i - 1`` and ``i``, ``v_j`` likewise
    across columns. For a GG mesh (equal edges along every parallel, equal meridian edges
    between two parallels) this is exactly the map :class:`gridshell.gg.mapback.SurfaceMap`
    puts the net on (its parameters ``(s, phi)`` are an affine image of ``(u, v)``). Each point
    is projected onto the spline surface (nearest of a 4x refined sampling, then Gauss-Newton
    on ``|S(u, v) - p|^2``) and gets the normal ``S_u x S_v / |S_u x S_v|`` there.

    Parameters
    ----------
    P : (k, 3) float
        Points on or near the surface, metres.
    V, F
        The surface mesh; ``F (m, 4)`` must form a structured grid.

    Returns
    -------
    (k, 3) float or None
        Unit normals (oriented like ``S_u x S_v``), or None if ``(V, F)`` is not a structured
        quad grid with at least 2 x 2 vertices.
    """
    from scipy.interpolate import RectBivariateSpline
    from scipy.spatial import cKDTree

    from gridshell.core.errors import MeshError
    from gridshell.geometry.grid import grid_from_quads

    F = np.asarray(F)
    if F.ndim != 2 or F.shape[1] != 4:
        return None
    try:
        G = grid_from_quads(F, len(V))
    except MeshError:
        return None
    X = _V("V", V)[G]
    R, C = G.shape
    u = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(X, axis=0), axis=2).mean(1))])
    v = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(X, axis=1), axis=2).mean(0))])
    if not (np.all(np.diff(u) > 0) and np.all(np.diff(v) > 0)):
        return None
    kx, ky = min(3, R - 1), min(3, C - 1)
    spl = [RectBivariateSpline(u, v, X[:, :, k], kx=kx, ky=ky, s=0) for k in range(3)]

    def ev(uu: np.ndarray, vv: np.ndarray, du: int = 0, dv: int = 0) -> np.ndarray:
        return np.stack([sp(uu, vv, dx=du, dy=dv, grid=False) for sp in spl], axis=1)

    P = _V("P", P)
    fu = np.interp(np.linspace(0, R - 1, 4 * (R - 1) + 1), np.arange(R), u)
    fv = np.interp(np.linspace(0, C - 1, 4 * (C - 1) + 1), np.arange(C), v)
    Uu, Vv = (a.ravel() for a in np.meshgrid(fu, fv, indexing="ij"))
    _, near = cKDTree(ev(Uu, Vv)).query(P)
    uu, vv = Uu[near], Vv[near]
    for _ in range(8):  # Gauss-Newton on the foot point, clamped to the parameter domain
        Su, Sv = ev(uu, vv, 1, 0), ev(uu, vv, 0, 1)
        r = P - ev(uu, vv)
        a, b, c = (np.einsum("ij,ij->i", x, y) for x, y in ((Su, Su), (Su, Sv), (Sv, Sv)))
        g1, g2 = np.einsum("ij,ij->i", Su, r), np.einsum("ij,ij->i", Sv, r)
        det = a * c - b * b
        ok = det > 1e-300
        det = np.where(ok, det, 1.0)
        uu = np.clip(uu + np.where(ok, (c * g1 - b * g2) / det, 0.0), u[0], u[-1])
        vv = np.clip(vv + np.where(ok, (a * g2 - b * g1) / det, 0.0), v[0], v[-1])
    N = np.cross(ev(uu, vv, 1, 0), ev(uu, vv, 0, 1))
    return N / np.maximum(np.linalg.norm(N, axis=1), 1e-300)[:, None]


def geodesic_turning(net_or_axes: Net | Sequence[np.ndarray], V: np.ndarray,
                     F: np.ndarray, *, normals: str = "auto") -> dict[str, Any]:
    """How far lamella axes are from geodesics of a surface: ``int |kg| ds / int |kappa| ds``.

    ``kappa_vec = kn n + kg (n x t)`` (:func:`gridshell.geometry.diffgeo.normal_geodesic_curvature`)
    with ``n`` the surface normal at the axis point; each interior vertex carries half of its
    two adjacent segments. Zero for geodesics (then the lamella bends about its weak axis
    only), one for a curve in a plane tangent to the surface.

    The normal matters: ``kg`` of a geodesic measured with a normal tilted by ``e`` radians
    about the tangent is ``kn e``, so the ratio is only as good as the normals. On a structured
    quad grid (a GG bundle's ``surface.obj``) they come from the smooth surface through the grid
    (:func:`smooth_grid_normals`, the surface the GG net is mapped onto); otherwise from the
    per-vertex normals of the mesh interpolated at the closest point (first order in the mesh
    size: 1 % on exact geodesics of the catenoid measured on a 13 x 13 grid of it, 0.4 % on a
    25 x 25 grid, against 0.005 % and 0.0006 % with the smooth normals).

    Parameters
    ----------
    net_or_axes : Net or list of (k_i, 3) float
        The axes (dense polylines, metres).
    V, F
        The surface mesh.
    normals : {"auto", "smooth", "mesh"}
        ``"auto"``: smooth normals on a structured quad grid, mesh normals otherwise;
        ``"smooth"``: require a structured quad grid; ``"mesh"``: interpolated mesh normals.

    Returns
    -------
    dict
        ``ratio`` (the quotient above), ``kg_integral``, ``kappa_integral`` (radians),
        ``kg_max`` (1/m), ``normals`` ("smooth" or "mesh": which were used).

    Raises
    ------
    InputError
        No axis with 3 points; an unknown ``normals``; ``normals="smooth"`` on a mesh that is
        not a structured quad grid.
    """
    from gridshell.geometry.diffgeo import normal_geodesic_curvature
    from gridshell.geometry.igl_adapter import closest_points_with_normals

    if normals not in ("auto", "smooth", "mesh"):
        raise InputError(f"normals must be 'auto', 'smooth' or 'mesh', got {normals!r}")
    axes = [lam.axis for lam in net_or_axes.lamellae] if isinstance(net_or_axes, Net) \
        else [np.asarray(a, float) for a in net_or_axes]
    axes = [a for a in axes if len(a) >= 3]
    if not axes:
        raise InputError("no lamella axis with at least 3 points; nothing to measure")
    # drop repeated points (zero-length segments) that the curvature formula cannot handle
    clean = []
    for a in axes:
        keep = np.concatenate([[True], np.linalg.norm(np.diff(a, axis=0), axis=1) > 0])
        if keep.sum() >= 3:
            clean.append(a[keep])
    allP = np.concatenate(clean)
    N = smooth_grid_normals(allP, V, F) if normals != "mesh" else None
    used = "smooth"
    if N is None:
        if normals == "smooth":
            raise InputError("smooth normals need the surface as a structured quad grid (e.g. a "
                             "GG bundle's surface.obj); pass normals='mesh' for other meshes")
        _, N = closest_points_with_normals(allP, V, F)
        used = "mesh"
    kg_int = kappa_int = 0.0
    kg_max = 0.0
    start = 0
    for a in clean:
        n = N[start:start + len(a)]
        start += len(a)
        kn, kg = normal_geodesic_curvature(a, n)
        seg = np.linalg.norm(np.diff(a, axis=0), axis=1)
        w = np.zeros(len(a))
        w[1:-1] = 0.5 * (seg[:-1] + seg[1:])
        inner = slice(1, -1)
        kg_i, kn_i, w_i = kg[inner], kn[inner], w[inner]
        ok = np.isfinite(kg_i) & np.isfinite(kn_i)
        kg_int += float(np.sum(np.abs(kg_i[ok]) * w_i[ok]))
        kappa_int += float(np.sum(np.hypot(kg_i[ok], kn_i[ok]) * w_i[ok]))
        if ok.any():
            kg_max = max(kg_max, float(np.abs(kg_i[ok]).max()))
    ratio = kg_int / kappa_int if kappa_int > 0 else 0.0
    return {"ratio": ratio, "kg_integral": kg_int, "kappa_integral": kappa_int, "kg_max": kg_max,
            "normals": used}


def _kn_at_joints(net: Net, axis_normals: Sequence[np.ndarray],
                  joint_index: Sequence[np.ndarray]) -> dict[int, dict[int, float]] | None:
    """``{joint: {family: kn}}`` (1/m) at the interior joint samples of the lamellae of at
    least 3 samples: :func:`gridshell.geometry.diffgeo.normal_geodesic_curvature`'s ``kn`` there, the
    same arithmetic row by row, for the joint rows of all lamellae at once instead of every
    row of each. None when a lamella's polyline or normals are ones that function refuses
    (not finite, a zero-length segment, a zero normal, shapes): the caller asks it, for its
    error. tests/measure/test_metrics.py compares with it."""
    from gridshell.geometry.diffgeo import _dot

    axes, normals, rows, keys, at = [], [], [], [], 0
    for lam, N, jidx in zip(net.lamellae, axis_normals, joint_index):
        P = np.asarray(lam.axis, dtype=float)
        if len(P) < 3:
            continue
        N = np.asarray(N, dtype=float)
        if P.ndim != 2 or P.shape[1] != 3 or N.shape != P.shape:
            return None
        for jj, vi in zip(np.asarray(lam.joints).tolist(), np.asarray(jidx).tolist()):
            if 0 < vi < len(P) - 1:
                rows.append(at + vi)
                keys.append((jj, lam.family))
        axes.append(P)
        normals.append(N)
        at += len(P)
    if not axes:
        return {}
    P, N = np.concatenate(axes), np.concatenate(normals)
    inner = np.ones(len(P) - 1, dtype=bool)          # segments within one lamella
    inner[np.cumsum([len(a) for a in axes])[:-1] - 1] = False
    seg = np.linalg.norm(np.diff(P, axis=0), axis=1)[inner]
    if not (np.all(np.isfinite(P)) and np.all(seg != 0)
            and np.all(np.linalg.norm(N, axis=1) > 0)):
        return None
    i = np.asarray(rows, dtype=np.int64)
    a, b = P[i - 1] - P[i], P[i + 1] - P[i]
    aa, bb = _dot(a, a), _dot(b, b)
    cc = _dot(a - b, a - b)
    X = np.cross(aa[:, None] * b - bb[:, None] * a, np.cross(a, b))
    kvec = 2.0 * X / (aa * bb * cc)[:, None]
    n = N[i]
    n = n / np.linalg.norm(n, axis=1)[:, None]
    kn_at: dict[int, dict[int, float]] = {}
    for (jj, fam), k in zip(keys, _dot(kvec, n).tolist()):
        kn_at.setdefault(jj, {})[fam] = k
    return kn_at


def kn_at_joints_per_axis(net: Net, axis_normals: Sequence[np.ndarray],
                          joint_index: Sequence[np.ndarray]) -> dict[int, dict[int, float]]:
    """``{joint: {family: kn}}`` (1/m) as :func:`_kn_at_joints`, lamella by lamella through
    :func:`gridshell.geometry.diffgeo.normal_geodesic_curvature` of each whole axis (which raises its
    own error on a polyline or normals it refuses)."""
    from gridshell.geometry.diffgeo import normal_geodesic_curvature

    kn_at: dict[int, dict[int, float]] = {}
    for lam, N, jidx in zip(net.lamellae, axis_normals, joint_index):
        if len(lam.axis) < 3:
            continue
        kn, _ = normal_geodesic_curvature(lam.axis, N)
        for jj, vi in zip(np.asarray(lam.joints).tolist(), np.asarray(jidx).tolist()):
            if 0 < vi < len(lam.axis) - 1:
                kn_at.setdefault(jj, {})[lam.family] = float(kn[vi])
    return kn_at


def crossing_normal_curvature(net: Net, axis_normals: Sequence[np.ndarray],
                              joint_index: Sequence[np.ndarray],
                              scale: np.ndarray) -> dict[str, Any]:
    """Normal curvature of the two lamella axes crossing at each interior joint (NCP, 3.4).

    ``kn`` from :func:`gridshell.geometry.diffgeo.normal_geodesic_curvature` on each dense axis with
    the surface normals at its points; the relative difference at a joint is
    ``|kn_1 - kn_3| / max(|kn_1|, |kn_3|, scale)`` with ``scale`` the radius of Euler's circle
    ``|kappa_II - kappa_I| / 2`` there (keeps it meaningful where ``kn = 0``, AA).

    Parameters
    ----------
    net : Net
        Joints and lamellae with their dense axes (metres).
    axis_normals : list of (k_i, 3) float
        Surface normals at the axis points, one array per lamella.
    joint_index : list of (j_i,) int
        Index of each of the lamella's joints among its axis points.
    scale : (n_joints,) float
        ``|kappa_II - kappa_I| / 2`` at every joint, 1/m.

    Returns
    -------
    dict
        ``rel (m,)`` (fraction), ``joints (m,)``, ``kn1, kn3 (m,)`` 1/m, ``mean``, ``max``.
    """
    kn_at = _kn_at_joints(net, axis_normals, joint_index)
    if kn_at is None:        # a polyline or normals it refuses: its own error
        kn_at = kn_at_joints_per_axis(net, axis_normals, joint_index)
    joints = np.array(sorted(j for j, d in kn_at.items() if len(d) == 2), np.int64)
    if len(joints) == 0:
        return {"rel": np.zeros(0), "joints": joints, "kn1": np.zeros(0), "kn3": np.zeros(0),
                "mean": float("nan"), "max": float("nan")}
    k1 = np.array([kn_at[j][1] for j in joints])
    k3 = np.array([kn_at[j][3] for j in joints])
    sc = np.asarray(scale, float)[joints]
    den = np.maximum.reduce([np.abs(k1), np.abs(k3), np.nan_to_num(sc)])
    # a flat spot (all zero) has equal normal curvatures: difference 0
    rel = np.divide(np.abs(k1 - k3), den, out=np.zeros_like(den), where=den > 0)
    return {"rel": rel, "joints": joints, "kn1": k1, "kn3": k3, "mean": float(rel.mean()),
            "max": float(rel.max())}


def crossing_normal_curvature_on_mesh(net: Net, V: np.ndarray, F: np.ndarray,
                                      reuse: bool = False) -> dict[str, Any]:
    """:func:`crossing_normal_curvature` with normals and principal curvatures of a surface
    mesh ``(V, F)`` (e.g. a bundle's ``surface.obj``): what ``gridshell verify`` measures on
    ``axes.obj``; joints are located on their axes by arc length (``joint_s``). ``reuse``: the
    closest-point queries may answer from earlier ones
    (:func:`gridshell.geometry.igl_adapter.closest_points`)."""
    from gridshell.geometry.igl_adapter import (ask_closest_points, closest_points, closest_points_with_normals,
                              principal_curvature_at)
    from gridshell.geometry.net import polyline_arclength

    axes = [np.asarray(lam.axis, float) for lam in net.lamellae]
    if reuse:       # the axes' and the joints' queries below in one igl query (one tree)
        ask_closest_points([np.concatenate(axes), net.joints], V, F)
    _, N = closest_points_with_normals(np.concatenate(axes), V, F, reuse)
    normals = np.split(N, np.cumsum([len(a) for a in axes])[:-1])
    jidx = []
    for lam, a in zip(net.lamellae, axes):
        s = polyline_arclength(a)
        jidx.append(np.abs(s[None, :] - np.asarray(lam.joint_s, float)[:, None]).argmin(axis=1))
    _, face, C = closest_points(net.joints, V, F, reuse)
    tri = np.asarray(F, np.int64)[face]
    nearest = tri[np.arange(len(tri)), np.linalg.norm(V[tri] - C[:, None], axis=2).argmin(1)]
    # the curvatures of the nearest vertices only (those of the whole mesh, bit for bit)
    _, _, k1, k2 = principal_curvature_at(V, F, nearest, radius=2)
    scale = np.abs(k2 - k1) / 2
    return crossing_normal_curvature(net, normals, jidx, scale)


def summary(values: np.ndarray) -> dict[str, float]:
    """``{"mean", "max"}`` of finite values (NaN when there are none)."""
    v = np.asarray(values, float)
    v = v[np.isfinite(v)]
    if not len(v):
        return {"mean": float("nan"), "max": float("nan")}
    return {"mean": float(v.mean()), "max": float(v.max())}
