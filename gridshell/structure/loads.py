"""Loads on a deployed gridshell beyond its self-weight, and what they do to its joints.

- :func:`plan_areas` / :func:`snow_forces`: a uniform snow load ``q`` (kN per m2 of plan
  area, the horizontal projection, as codes give it) on the net: each net loop's plan area
  (shoelace formula in ``x, y``) is split equally among its corner joints, ``-z``; the forces
  sum to ``q`` times the plan area the loops cover.
- :func:`rod_node_forces` / :func:`bolt_forces`: the force each lamella's own energy
  (stretching, bending, twisting) puts on a node it shares with another lamella; at a joint of
  lamellae A and B in equilibrium the bolt carries ``|F_A - F_B| / 2`` (the joint split into
  A's and B's copies: each takes half of the load and of the joint-axis coupling, the bolt the
  rest) - the shear on the bolt, newtons.
- :func:`span` and :func:`deflection_figures`: the span (largest plan distance between two
  supports) and the largest deflection, with span / deflection.

Units: metres and newtons of the simulated structure (the model at its scale: 1:1 for a
pavilion); ``q`` in kN/m2.
"""
from __future__ import annotations

import numpy as np

from gridshell.core.errors import InputError
from gridshell.structure import rod
from gridshell.structure.jet import Jet

__all__ = ["bolt_forces", "deflection_figures", "plan_areas", "rod_node_forces",
           "snow_forces", "span"]


def plan_areas(J: np.ndarray, loops: np.ndarray) -> np.ndarray:
    """Plan area (m2) of each loop ``loops (m, k)`` (corner joint indices, ``-1`` padding)
    of the joints ``J (n, 3)``: the shoelace formula on ``x, y``, unsigned."""
    L = np.asarray(loops, np.int64)
    if L.size == 0:
        return np.zeros(0)
    valid = L >= 0
    out = np.zeros(len(L))
    for k in np.unique(valid.sum(1)):
        rows = valid.sum(1) == k
        idx = np.where(valid[rows], L[rows], 0)
        # the valid corners come first (padding at the end)
        P = J[idx[:, :k]][..., :2]
        x, y = P[..., 0], P[..., 1]
        out[rows] = 0.5 * np.abs(np.sum(x * np.roll(y, -1, 1) - np.roll(x, -1, 1) * y, 1))
    return out


def snow_forces(J: np.ndarray, loops: np.ndarray, q_kN_m2: float) -> np.ndarray:
    """Nodal forces ``(n, 3)`` (N) of a snow load ``q_kN_m2`` on the plan area of the loops:
    each loop's share equally on its corners, downwards (-z)."""
    q = float(q_kN_m2)
    if not np.isfinite(q) or q < 0:
        raise InputError(f"snow load must be a finite number >= 0 (kN/m2), got {q_kN_m2}")
    F = np.zeros((len(J), 3))
    L = np.asarray(loops, np.int64)
    if L.size == 0:
        return F
    A = plan_areas(J, L) * q * 1e3
    valid = L >= 0
    share = A / np.maximum(valid.sum(1), 1)
    np.add.at(F[:, 2], L[valid], -np.repeat(share, valid.sum(1)))
    return F


def rod_node_forces(net, q: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    """``(R, len(nodes), 3)``: the force (N) the energy of each rod of ``net`` (a
    :class:`~gridshell.structure.rodnet.RodNetwork`) puts on each node of ``nodes`` at the
    unknowns ``q`` (minus its gradient: stretching, bending and twisting stencils of the rod's
    own edges; zero where the rod does not pass)."""
    nodes = np.asarray(nodes, np.int64)
    R, N = len(net.rods), len(net.X)
    where = np.full(N, -1)
    where[nodes] = np.arange(len(nodes))
    edge_rod = np.concatenate([np.full(b - a, i) for i, (a, b) in enumerate(net.rod_edges)])
    out = np.zeros((R, len(nodes), 3))

    def add(grad: np.ndarray, node_idx: np.ndarray, rods: np.ndarray) -> None:
        # grad (B, m, 3) position gradients of m stencil nodes; node_idx (B, m); rods (B,)
        w = where[node_idx]
        sel = w >= 0
        b, m = np.nonzero(sel)
        np.add.at(out, (rods[b], w[b, m]), -grad[b, m])

    from gridshell.structure.rodnet import _bend_plus_twist

    S = rod.stretch_energy(Jet.variables(q[net.stretch_idx], 1),
                           rod.StretchData(net.lbar, net.EA))
    add(S.g.reshape(-1, 2, 3), net.edge_nodes, edge_rod)
    if len(net.bend_idx):
        B = _bend_plus_twist(Jet.variables(q[net.bend_idx], 1), net.bend_data())
        add(B.g[:, :9].reshape(-1, 3, 3), net.vert_nodes, edge_rod[net.vert_edges[:, 0]])
    return out


def bolt_forces(net, q: np.ndarray, joint_nodes: np.ndarray) -> np.ndarray:
    """``(len(joint_nodes),)`` the shear on the bolt (N) of each joint node: ``|F_A - F_B| / 2``
    of the two lamellae through it (:func:`rod_node_forces`; a node on one lamella only: 0)."""
    F = rod_node_forces(net, q, joint_nodes)             # (R, n, 3)
    mag = np.linalg.norm(F, axis=2)
    out = np.zeros(len(joint_nodes))
    for j in range(len(joint_nodes)):
        on = np.flatnonzero(mag[:, j] > 0)
        if len(on) >= 2:
            a, b = on[np.argsort(-mag[on, j])[:2]]
            out[j] = 0.5 * float(np.linalg.norm(F[a, j] - F[b, j]))
    return out


def span(X: np.ndarray) -> float:
    """Largest plan (x, y) distance between two of the points ``X (k, 3)``, metres."""
    P = np.asarray(X, float)[:, :2]
    if len(P) < 2:
        return 0.0
    from scipy.spatial import ConvexHull, QhullError

    try:
        P = P[ConvexHull(P).vertices]
    except (QhullError, ValueError):
        pass
    d = np.linalg.norm(P[:, None] - P[None], axis=2)
    return float(d.max())


def deflection_figures(X0: np.ndarray, X1: np.ndarray, supports_xyz: np.ndarray
                       ) -> dict[str, float]:
    """The largest displacement between ``X0`` and ``X1 (n, 3)`` (m of the structure): total
    and vertical, in mm, the span of the supports (m) and span / deflection."""
    d = np.asarray(X1, float) - np.asarray(X0, float)
    tot = float(np.max(np.linalg.norm(d, axis=1), initial=0.0))
    vert = float(np.max(-d[:, 2], initial=0.0))
    s = span(supports_xyz)
    return {"deflection_max_mm": 1e3 * tot, "deflection_vertical_max_mm": 1e3 * vert,
            "span_m": s, "span_over_deflection": s / tot if tot > 0 else float("inf")}
