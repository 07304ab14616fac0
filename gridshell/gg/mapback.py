"""Map a geodesic net from the surface of revolution back onto the designed GG surface (4.1.2).

The designed mesh ``P (R, C, 3)`` and the surface of revolution share the grid parameters
``(s_i, phi_j)``: vertex ``P[i, j]`` corresponds to the point at arc length ``s_i`` on meridian
``phi_j``. A net given in ``(s, phi)`` (:class:`gridshell.gg.clairaut.IntrinsicNet`) is mapped
to 3D through a smooth interpolant of ``P`` over that grid (a bicubic interpolating spline per
coordinate), or onto the surface of revolution itself, where the net is exactly alignable.

Joints are the intersections of C1 and C3 curves, computed in ``(s, phi)`` on the dense
polylines; net-loops are the quads ``A, B, C, D`` with ``A -> B`` forwards along a C1 curve,
``B -> C`` forwards along a C3 curve, ``D -> C`` forwards along the next C1 curve and
``A -> D`` forwards along the C3 curve through ``A`` (Definition 4: alignable iff
``l_AB + l_BC = l_AD + l_DC``), consistently oriented (neighbours run a shared edge in opposite
directions) and counter-clockwise in ``(phi, s)`` overall, like the mesh's faces.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy.interpolate import RectBivariateSpline

from gridshell.core.errors import InputError, NoNetError
from gridshell.geometry.net import Lamella, Net, polyline_arclength
from gridshell.gg.clairaut import IntrinsicNet
from gridshell.gg.revolution import Revolution

__all__ = ["NetParameters", "SurfaceMap", "map_net", "net_parameters", "map_to_revolution", "net_loops", "orient_loops",
           "segment_intersections"]


class SurfaceMap:
    """Smooth map ``(s, phi) -> 3D`` through the grid ``P[i, j] <-> (s_i, phi_j)``.

    One ``RectBivariateSpline`` per coordinate, interpolating (``s=0``), bicubic where the grid
    has at least 4 rows / columns (lower degree otherwise).

    Parameters
    ----------
    P : (R, C, 3) float
        The designed GG mesh, metres.
    s : (R,) float
        Arc length of the parallels, increasing.
    phi : (C,) float
        Angles of the meridians, increasing.
    """

    def __init__(self, P: np.ndarray, s: np.ndarray, phi: np.ndarray) -> None:
        P = np.asarray(P, float)
        s, phi = np.asarray(s, float), np.asarray(phi, float)
        if P.ndim != 3 or P.shape[2] != 3 or P.shape[:2] != (len(s), len(phi)):
            raise InputError(f"P must have shape (len(s), len(phi), 3) = ({len(s)}, {len(phi)}, 3)"
                             f", got {P.shape}")
        kx, ky = min(3, len(s) - 1), min(3, len(phi) - 1)
        self.s_range = (float(s[0]), float(s[-1]))
        self.phi_range = (float(phi[0]), float(phi[-1]))
        self._splines = [RectBivariateSpline(s, phi, P[:, :, k], kx=kx, ky=ky, s=0)
                         for k in range(3)]

    def __call__(self, s: np.ndarray, phi: np.ndarray) -> np.ndarray:
        """Points ``(k, 3)`` at paired parameters ``s (k,)``, ``phi (k,)``."""
        s = np.clip(np.asarray(s, float).ravel(), *self.s_range)
        phi = np.clip(np.asarray(phi, float).ravel(), *self.phi_range)
        return np.stack([sp(s, phi, grid=False) for sp in self._splines], axis=1)

    def normals(self, s: np.ndarray, phi: np.ndarray) -> np.ndarray:
        """Unit normals ``(k, 3)`` of the smooth surface, ``P_s x P_phi`` at paired
        parameters (zero rows where the map is singular)."""
        s = np.clip(np.asarray(s, float).ravel(), *self.s_range)
        phi = np.clip(np.asarray(phi, float).ravel(), *self.phi_range)
        Ps = np.stack([sp(s, phi, dx=1, grid=False) for sp in self._splines], axis=1)
        Pp = np.stack([sp(s, phi, dy=1, grid=False) for sp in self._splines], axis=1)
        n = np.cross(Ps, Pp)
        ln = np.linalg.norm(n, axis=1)
        return n / np.where(ln > 0, ln, 1.0)[:, None]


# ----------------------------------------------------------------------------- intersections


def segment_intersections(A: np.ndarray, B: np.ndarray,
                          tol: float = 1e-12) -> tuple[np.ndarray, ...]:
    """All intersections between two sets of 2D segments, vectorized.

    Segments are binned into a uniform grid of cells at least as large as the longest
    segment; only pairs sharing a cell are tested exactly (``P + t r = Q + u q``).

    Parameters
    ----------
    A : (na, 2, 2) float
        Segments ``[start, end]`` of the first set.
    B : (nb, 2, 2) float
        Segments of the second set.
    tol : float
        Relative tolerance on the segment parameters (hits at ``t`` in ``[-tol, 1 + tol]``).

    Returns
    -------
    ia, ib : (h,) int
        Indices of the intersecting segments in ``A`` and ``B``.
    t, u : (h,) float
        Parameters of the hit along ``A[ia]`` and ``B[ib]``.
    X : (h, 2) float
        Intersection points.
    """
    A, B = np.asarray(A, float), np.asarray(B, float)
    empty = (np.zeros(0, np.int64),) * 2 + (np.zeros(0),) * 2 + (np.zeros((0, 2)),)
    if len(A) == 0 or len(B) == 0:
        return empty
    lo_a, hi_a = A.min(axis=1), A.max(axis=1)
    lo_b, hi_b = B.min(axis=1), B.max(axis=1)
    ext = np.concatenate([hi_a - lo_a, hi_b - lo_b]).max(axis=0)
    lo = np.minimum(lo_a.min(axis=0), lo_b.min(axis=0))
    span = np.maximum(np.maximum(hi_a.max(axis=0), hi_b.max(axis=0)) - lo, 1e-300)
    cell = np.maximum(ext * (1 + 1e-9), span / 4096)
    ncell = np.floor(span / cell).astype(np.int64) + 2

    def cells(lo_, hi_):
        c0 = np.floor((lo_ - lo) / cell).astype(np.int64)
        c1 = np.floor((hi_ - lo) / cell).astype(np.int64)
        keys, segs = [], []
        for dx in (0, 1):
            for dy in (0, 1):
                cx, cy = c0[:, 0] + dx, c0[:, 1] + dy
                ok = (cx <= c1[:, 0]) & (cy <= c1[:, 1])
                keys.append((cx * ncell[1] + cy)[ok])
                segs.append(np.flatnonzero(ok))
        return np.concatenate(keys), np.concatenate(segs)

    ka, sa = cells(lo_a, hi_a)
    kb, sb = cells(lo_b, hi_b)
    ob = np.argsort(kb, kind="stable")
    kb, sb = kb[ob], sb[ob]
    left = np.searchsorted(kb, ka, "left")
    right = np.searchsorted(kb, ka, "right")
    cnt = right - left
    rep_a = np.repeat(sa, cnt)
    starts = np.repeat(left, cnt)
    offs = np.arange(cnt.sum()) - np.repeat(np.cumsum(cnt) - cnt, cnt)
    rep_b = sb[starts + offs]
    if len(rep_a) == 0:
        return empty
    pair = np.unique(rep_a * np.int64(len(B)) + rep_b)
    ia, ib = pair // len(B), pair % len(B)
    # bounding-box rejection, then the exact test
    ok = np.all((lo_a[ia] <= hi_b[ib]) & (lo_b[ib] <= hi_a[ia]), axis=1)
    ia, ib = ia[ok], ib[ok]
    P, r = A[ia, 0], A[ia, 1] - A[ia, 0]
    Q, q = B[ib, 0], B[ib, 1] - B[ib, 0]
    den = r[:, 0] * q[:, 1] - r[:, 1] * q[:, 0]
    d = Q - P
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (d[:, 0] * q[:, 1] - d[:, 1] * q[:, 0]) / den
        u = (d[:, 0] * r[:, 1] - d[:, 1] * r[:, 0]) / den
    hit = (den != 0) & (t >= -tol) & (t <= 1 + tol) & (u >= -tol) & (u <= 1 + tol)
    ia, ib, t, u = ia[hit], ib[hit], np.clip(t[hit], 0, 1), np.clip(u[hit], 0, 1)
    return ia, ib, t, u, P[hit] + t[:, None] * r[hit]


def _segments(curves: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Segments ``(n, 2, 2)`` of polylines in ``(phi, s)`` order, their curve and local index."""
    segs, cid, loc = [], [], []
    for k, cv in enumerate(curves):
        xy = cv[:, ::-1]  # (phi, s)
        segs.append(np.stack([xy[:-1], xy[1:]], axis=1))
        cid.append(np.full(len(cv) - 1, k))
        loc.append(np.arange(len(cv) - 1))
    return np.concatenate(segs), np.concatenate(cid), np.concatenate(loc)


def _joints(inet: IntrinsicNet) -> dict[str, np.ndarray]:
    """Intersections of the two families: per joint its ``(s, phi)``, curves and ``sigma``s.

    Found on the dense polylines (:func:`segment_intersections`), then refined by Newton on
    the smooth base geodesic: ``s(sigma1) = s(sigma3)``, ``g(sigma1) + o_k = -g(sigma3) + o_l``.
    """
    S1, c1, l1 = _segments(inet.curves1)
    S3, c3, l3 = _segments(inet.curves3)
    ia, ib, t, u, X = segment_intersections(S1, S3)
    k1, k3 = c1[ia], c3[ib]
    sig1 = np.array([inet.sigma1[k][j] + t_ * (inet.sigma1[k][j + 1] - inet.sigma1[k][j])
                     for k, j, t_ in zip(k1, l1[ia], t)], float)
    sig3 = np.array([inet.sigma3[k][j] + u_ * (inet.sigma3[k][j + 1] - inet.sigma3[k][j])
                     for k, j, u_ in zip(k3, l3[ib], u)], float)
    if len(k1):
        o1, o3 = inet.offsets1[k1], inet.offsets3[k3]
        lo1 = np.array([inet.sigma1[k][0] for k in k1])
        hi1 = np.array([inet.sigma1[k][-1] for k in k1])
        lo3 = np.array([inet.sigma3[k][0] for k in k3])
        hi3 = np.array([inet.sigma3[k][-1] for k in k3])
        for _ in range(6):
            b1, b3 = inet.base(sig1), inet.base(sig3)
            d1, d3 = inet.base(sig1, 1), inet.base(sig3, 1)
            f1 = b1[:, 0] - b3[:, 0]
            f2 = b1[:, 1] + b3[:, 1] + o1 - o3
            a11, a12, a21, a22 = d1[:, 0], -d3[:, 0], d1[:, 1], d3[:, 1]
            det = a11 * a22 - a12 * a21
            ok = np.abs(det) > 0
            det = np.where(ok, det, 1.0)
            x1 = np.where(ok, (a22 * f1 - a12 * f2) / det, 0.0)
            x3 = np.where(ok, (-a21 * f1 + a11 * f2) / det, 0.0)
            sig1 = np.clip(sig1 - x1, lo1, hi1)
            sig3 = np.clip(sig3 - x3, lo3, hi3)
        X = inet.base(sig1)
        X = np.stack([X[:, 0], X[:, 1] + o1], axis=1)[:, ::-1]  # (phi, s)
    # a hit on a shared vertex is found twice (end of one segment, start of the next): merge
    scale = max(inet.s_range[1] - inet.s_range[0], inet.phi_range[1] - inet.phi_range[0])
    order = np.lexsort((sig1, k3, k1))
    k1, k3, sig1, sig3, X = k1[order], k3[order], sig1[order], sig3[order], X[order]
    dup = np.zeros(len(k1), bool)
    if len(k1) > 1:
        same = (k1[1:] == k1[:-1]) & (k3[1:] == k3[:-1])
        close = np.linalg.norm(X[1:] - X[:-1], axis=1) <= 1e-9 * scale
        dup[1:] = same & close
    keep = ~dup
    return {"k1": k1[keep], "k3": k3[keep], "p1": sig1[keep], "p3": sig3[keep],
            "sphi": X[keep][:, ::-1]}


def net_loops(k1: np.ndarray, p1: np.ndarray, k3: np.ndarray, p3: np.ndarray,
              sphi: np.ndarray | None = None) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Net-loops of joints lying on one C1 and one C3 curve each.

    Parameters
    ----------
    k1, k3 : (n,) int
        The C1 and C3 curve of each joint.
    p1, p3 : (n,) float
        Position of each joint along its curves (any increasing parameter).
    sphi : (n, 2) float, optional
        ``(s, phi)`` of the joints; if given, loops are ordered counter-clockwise in
        ``(phi, s)``.

    Returns
    -------
    loops : (m, 4) int
        ``A, B, C, D`` with ``B`` next after ``A`` on A's C1 curve, ``C`` next after ``B`` on
        B's C3 curve, ``C`` next after ``D`` on D's C1 curve, ``D`` next after ``A`` on A's C3
        curve (reversed to ``A, D, C, B`` by :func:`orient_loops` where needed: consistently
        oriented, counter-clockwise in ``(phi, s)`` overall).
    order : dict
        ``"c1"``, ``"c3"``: for each curve the joints in order along it (lists of arrays).
    """
    n = len(k1)
    nxt1, prv1, nxt3 = (np.full(n, -1, np.int64) for _ in range(3))
    along1, along3 = [], []
    for ks, ps, nxt, prv, out in ((k1, p1, nxt1, prv1, along1), (k3, p3, nxt3, None, along3)):
        order = np.lexsort((ps, ks))
        same = ks[order][1:] == ks[order][:-1]
        nxt[order[:-1][same]] = order[1:][same]
        if prv is not None:
            prv[order[1:][same]] = order[:-1][same]
        n_curves = int(ks.max()) + 1 if n else 0
        bounds = np.searchsorted(ks[order], np.arange(n_curves + 1))
        out.extend(order[bounds[i]:bounds[i + 1]] for i in range(n_curves))
    A = np.arange(n)
    B = nxt1[A]
    C = np.where(B >= 0, nxt3[np.maximum(B, 0)], -1)
    D = np.where(C >= 0, prv1[np.maximum(C, 0)], -1)
    ok = (B >= 0) & (C >= 0) & (D >= 0) & (nxt3[A] == D) & (D != A)
    loops = np.stack([A[ok], B[ok], C[ok], D[ok]], axis=1)
    if sphi is not None and len(loops):
        loops = orient_loops(loops, sphi)
    return loops, {"c1": along1, "c3": along3}


def _signed_areas(loops: np.ndarray, sphi: np.ndarray) -> np.ndarray:
    """Signed area ``(m,)`` of each loop in ``(phi, s)`` (positive: counter-clockwise)."""
    xy = np.asarray(sphi, float)[:, ::-1][loops]  # (m, 4, 2) in (phi, s)
    return 0.5 * np.sum(xy[:, :, 0] * np.roll(xy[:, :, 1], -1, axis=1)
                        - np.roll(xy[:, :, 0], -1, axis=1) * xy[:, :, 1], axis=1)


def orient_loops(loops: np.ndarray, sphi: np.ndarray) -> np.ndarray:
    """The loops ``(m, 4)`` consistently oriented, counter-clockwise in ``(phi, s)`` overall.

    Orientation is combinatorial: every two loops sharing an edge run it in opposite
    directions (the loops are a consistently oriented quad mesh). Within each edge-connected
    component the orientation is propagated from loop to loop; the component is then turned
    so that its total signed area in ``(phi, s)`` is positive (counter-clockwise, like the
    mesh's faces ``(i,j), (i,j+1), (i+1,j+1), (i+1,j)``).

    Judging each loop by its own signed area instead fails where the net folds in the
    parameter domain: near a Clairaut turning parallel (where the geodesics touch a parallel,
    ``r = c``) the loops are slivers whose corners overlap, their own area has either sign,
    and neighbours ended up running a shared edge in the same direction.
    """
    loops = np.array(loops, np.int64, copy=True)
    m = len(loops)
    if m == 0:
        return loops
    area = _signed_areas(loops, sphi)
    # directed edges (a -> b) of every loop, and the undirected key of each
    a = loops.ravel()
    b = np.roll(loops, -1, axis=1).ravel()
    owner = np.repeat(np.arange(m), 4)
    key = np.minimum(a, b) * (int(loops.max()) + 1) + np.maximum(a, b)
    order = np.argsort(key, kind="stable")
    ks = key[order]
    # pairs of loop-edges on one undirected edge (an edge of a consistent quad mesh has two)
    first = np.flatnonzero(ks[1:] == ks[:-1])
    e0, e1 = order[first], order[first + 1]
    # same: the two loops run the edge in the same direction (they need opposite flips)
    same = a[e0] == a[e1]
    nbr: list[list[tuple[int, bool]]] = [[] for _ in range(m)]
    for p, q, s_ in zip(owner[e0].tolist(), owner[e1].tolist(), same.tolist()):
        if p != q:
            nbr[p].append((q, s_))
            nbr[q].append((p, s_))
    flip = np.zeros(m, bool)
    comp = np.full(m, -1, np.int64)
    n_comp = 0
    # start every component at its largest loop (the most reliable area)
    for start in np.argsort(-np.abs(area), kind="stable").tolist():
        if comp[start] >= 0:
            continue
        comp[start] = n_comp
        stack = [start]
        while stack:
            p = stack.pop()
            for q, s_ in nbr[p]:
                if comp[q] < 0:
                    comp[q] = n_comp
                    flip[q] = flip[p] ^ s_
                    stack.append(q)
        n_comp += 1
    signed = np.where(flip, -area, area)
    total = np.bincount(comp, signed, n_comp)
    flip ^= (total < 0)[comp]
    loops[flip] = loops[flip][:, [0, 3, 2, 1]]
    return loops


def _axis_parameters(inet: IntrinsicNet, family: int, ci: int, pos: np.ndarray,
                     min_gap: float) -> tuple[np.ndarray, np.ndarray]:
    """``(s, phi)`` samples ``(k, 2)`` of curve ``ci`` of ``family`` in order of the base arc
    length, with its joints (at base arc lengths ``pos``) inserted, and which of them are
    the joints ``(k,)`` bool."""
    sig = (inet.sigma1 if family == 1 else inet.sigma3)[ci]
    offset = (inet.offsets1 if family == 1 else inet.offsets3)[ci]
    # samples (not the ends) closer than min_gap to a joint are dropped: no sliver segments
    if len(pos):
        dist = np.min(np.abs(sig[:, None] - pos[None, :]), axis=1)
        keep = dist > min_gap
        # the ends stay unless a joint is on them (a joint on the boundary lies within the
        # tracing's 1e-9 domain margin of the curve's end: no sliver segment to it)
        end_gap = max(1e-9 * abs(sig[-1] - sig[0]), 1e-3 * min_gap)
        keep[[0, -1]] |= dist[[0, -1]] > end_gap
    else:
        keep = np.ones(len(sig), bool)
    t_all = np.concatenate([sig[keep], pos])
    is_joint = np.concatenate([np.zeros(int(keep.sum()), bool), np.ones(len(pos), bool)])
    order = np.argsort(t_all, kind="stable")
    return inet.points(family, offset, t_all[order]), is_joint[order]


@dataclass
class NetParameters:
    """A geodesic net in the parameters ``(s, phi)``, before any map to 3D.

    sphi : (n, 2) joints;  loops : (m, 4) net-loops;  lamellae : per lamella ``(family,
    joints (j,) int, samples (k, 2) (s, phi) in order along it with the joints among them,
    is_joint (k,) bool)``;  extra : as :func:`map_net`'s.
    """

    sphi: np.ndarray
    loops: np.ndarray
    lamellae: list[tuple[int, np.ndarray, np.ndarray, np.ndarray]]
    extra: dict[str, np.ndarray]

    def net(self, to3d: Callable[[np.ndarray, np.ndarray], np.ndarray]) -> Net:
        """The :class:`Net` under the map ``to3d(s, phi) -> (k, 3)`` (metres): joints, loops,
        lamellae with their dense axes and ``joint_s`` measured along them."""
        lamellae = []
        for i, (fam, idx, sp, is_joint) in enumerate(self.lamellae):
            X = to3d(sp[:, 0], sp[:, 1])
            lamellae.append(Lamella(id=i, family=fam, joints=idx.copy(),
                                    joint_s=polyline_arclength(X)[is_joint], axis=X))
        return Net(joints=to3d(self.sphi[:, 0], self.sphi[:, 1]), loops=self.loops.copy(),
                   lamellae=lamellae)

    def samples(self) -> np.ndarray:
        """All lamellae's ``(s, phi)`` samples stacked ``(M, 2)``, lamella after lamella."""
        return np.concatenate([sp for _, _, sp, _ in self.lamellae]) if self.lamellae \
            else np.zeros((0, 2))


def net_parameters(inet: IntrinsicNet, min_joints: int = 2) -> NetParameters:
    """Joints, loops and lamellae of an intrinsic net in ``(s, phi)``: the part of
    :func:`map_net` that does not depend on the map."""
    J = _joints(inet)
    if len(J["k1"]) == 0:
        raise NoNetError("the two families of curves do not intersect on the surface; choose "
                         "a different crossing angle or more lamellae")
    sphi = J["sphi"]
    loops, along = net_loops(J["k1"], J["p1"], J["k3"], J["p3"], sphi)
    lamellae, lam_curve = [], []
    for fam, curves, key, pos in ((1, inet.curves1, "c1", J["p1"]), (3, inet.curves3, "c3", J["p3"])):
        for ci, curve in enumerate(curves):
            idx = along[key][ci] if ci < len(along[key]) else np.zeros(0, np.int64)
            if len(idx) < min_joints:
                continue
            sp, is_joint = _axis_parameters(inet, fam, ci, pos[idx],
                                            min_gap=0.1 * inet.info.get("step", 0.0))
            lamellae.append((fam, idx, sp, is_joint))
            lam_curve.append((fam, ci))
    # joints on no lamella (crossings of two stubs) are left out, indices renumbered
    used = np.zeros(len(sphi), bool)
    for _, idx, _, _ in lamellae:
        used[idx] = True
    used[loops.ravel()] = True
    new = np.cumsum(used) - 1
    lamellae = [(fam, new[idx], sp, isj) for fam, idx, sp, isj in lamellae]
    extra = {"sphi": sphi[used], "curve1": J["k1"][used], "curve3": J["k3"][used],
             "lamella_curve": np.asarray(lam_curve, np.int64).reshape(-1, 2)}
    return NetParameters(sphi=sphi[used], loops=new[loops], lamellae=lamellae, extra=extra)


def map_net(inet: IntrinsicNet, to3d: Callable[[np.ndarray, np.ndarray], np.ndarray],
            min_joints: int = 2) -> tuple[Net, dict[str, np.ndarray]]:
    """Build the :class:`Net` of an intrinsic net mapped to 3D by ``to3d(s, phi) -> (k, 3)``.

    Parameters
    ----------
    inet : IntrinsicNet
    to3d : callable
        Map of paired parameter arrays to points ``(k, 3)``, metres.
    min_joints : int
        Curves with fewer joints are left out of the lamellae (their joints stay in the net).

    Returns
    -------
    net : Net
        Joints (the intersections), loops (:func:`net_loops`) and lamellae (C1 first, ids
        from 0, then C3), each with its dense 3D axis through its joints and ``joint_s`` the
        arc length of each joint along that axis.
    extra : dict
        ``sphi (n, 2)`` joint parameters; ``curve1``, ``curve3 (n,)`` curve index of each joint;
        ``lamella_curve`` (family, curve index) of each lamella.
    """
    par = net_parameters(inet, min_joints)
    return par.net(to3d), par.extra


def map_back(inet: IntrinsicNet, P: np.ndarray, rev: Revolution) -> tuple[Net, dict]:
    """The net on the designed GG surface ``P (R, C, 3)``: :func:`map_net` through
    :class:`SurfaceMap` over the grid ``(rev.s, rev.phi)``."""
    smap = SurfaceMap(P, rev.s, rev.phi)
    return map_net(inet, smap)


def map_to_revolution(inet: IntrinsicNet, rev: Revolution) -> tuple[Net, dict]:
    """The same net on the smooth surface of revolution ``(r(s) cos phi, r(s) sin phi, z(s))``,
    where it is exactly alignable (geodesic arc lengths; chords up to discretization)."""
    return map_net(inet, lambda s, phi: rev.points(s, phi).reshape(-1, 3))
