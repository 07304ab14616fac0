"""A network of discrete elastic rods joined at shared nodes: the assembly of the energies of
:mod:`gridshell.structure.rod` over one vector of unknowns.

Unknowns ``q``: node positions ``(N, 3)`` (metres) then one material-frame angle per edge
(radians). Rods are chains of node indices; rods that cross at a joint share the node (same
position) and a :func:`~gridshell.structure.rod.joint_energy` term keeps their joint axes
together. Loads: dead forces per node (self-weight, point loads, N) and follower end moments.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from gridshell.core.errors import InputError
from gridshell.structure import rod
from gridshell.structure.jet import Jet


@dataclass
class RodSpec:
    """One rod: ``nodes (k,)`` global node indices; per edge ``(k-1,)`` rest length ``lbar`` (m),
    ``EA`` (N), ``B1`` strong / ``B2`` weak bending stiffness (N m^2), ``GJ`` (N m^2) and
    ``mass`` per length (kg/m); per interior vertex ``wbar (k-2, 2)`` rest material
    curvatures and ``mbar (k-2,)`` rest twist (radians); ``width``/``thickness`` of the section
    (m, for stresses; 0 when not a strip)."""

    nodes: np.ndarray
    lbar: np.ndarray
    EA: np.ndarray
    B1: np.ndarray
    B2: np.ndarray
    GJ: np.ndarray
    wbar: np.ndarray
    mbar: np.ndarray
    mass: np.ndarray
    width: float = 0.0
    thickness: float = 0.0


@dataclass
class JointSpec:
    """A joint: ``edges (4,)`` global edge indices (two per lamella, an end joint repeating its
    edge), ``c (4, 3)`` joint-axis coordinates in the edge frames (see
    :class:`~gridshell.structure.rod.JointData`),
    ``k`` rotational stiffness N m/rad."""

    edges: np.ndarray
    c: np.ndarray
    k: float


@dataclass
class RodNetwork:
    """Rods, joints and loads over the nodes ``X (N, 3)``; see the module docstring.

    ``theta (E,)`` initial frame angles and ``a1 (E, 3)`` reference directors of the edges (in
    the order of the rods' edges), ``fixed (N*3 + E,)`` the unknowns held at their values,
    ``forces (N, 3)`` dead loads (N), ``moments``: ``(edge, M, axis, ref)`` follower moments.
    """

    X: np.ndarray
    rods: list[RodSpec]
    theta: np.ndarray
    a1: np.ndarray
    joints: list[JointSpec] = field(default_factory=list)
    forces: np.ndarray | None = None
    moments: list[tuple[int, float, np.ndarray, np.ndarray]] = field(default_factory=list)
    fixed: np.ndarray | None = None

    def __post_init__(self) -> None:
        self.X = np.asarray(self.X, float).reshape(-1, 3)
        N = len(self.X)
        ends, e0 = [], 0
        for r in self.rods:
            r.nodes = np.asarray(r.nodes, np.int64)
            k = len(r.nodes)
            if k < 2 or r.nodes.min() < 0 or r.nodes.max() >= N:
                raise InputError("a rod needs at least 2 nodes, each an index into X")
            ends.append((e0, e0 + k - 1))
            e0 += k - 1
        self.n_edges = e0
        self.rod_edges = ends
        self.edge_nodes = np.concatenate([np.stack([r.nodes[:-1], r.nodes[1:]], 1)
                                          for r in self.rods])
        self.theta = np.asarray(self.theta, float).reshape(-1)
        if len(self.theta) != e0:
            raise InputError(f"theta: {len(self.theta)} angles for {e0} edges")
        self.a1 = np.asarray(self.a1, float).reshape(-1, 3).copy()
        self.tref = rod.unit(self.X[self.edge_nodes[:, 1]] - self.X[self.edge_nodes[:, 0]])
        self.n = 3 * N + e0
        if self.forces is None:
            self.forces = np.zeros((N, 3))
        if self.fixed is None:
            self.fixed = np.zeros(self.n, bool)
        cat = (lambda name: np.concatenate([np.asarray(getattr(r, name), float).reshape(-1)
                                            for r in self.rods]))
        self.lbar, self.EA = cat("lbar"), cat("EA")
        self.B1, self.B2, self.GJ = cat("B1"), cat("B2"), cat("GJ")
        # interior vertices: (rod node i) with edges (e-1, e)
        vi, ve = [], []
        for r, (a, b) in zip(self.rods, ends):
            k = len(r.nodes)
            if k >= 3:
                vi.append(np.stack([r.nodes[:-2], r.nodes[1:-1], r.nodes[2:]], 1))
                ve.append(np.stack([np.arange(a, b - 1), np.arange(a + 1, b)], 1))
        self.vert_nodes = np.concatenate(vi) if vi else np.zeros((0, 3), np.int64)
        self.vert_edges = np.concatenate(ve) if ve else np.zeros((0, 2), np.int64)
        self.wbar = np.concatenate([np.asarray(r.wbar, float).reshape(-1, 2)
                                    for r in self.rods])
        self.mbar = np.concatenate([np.asarray(r.mbar, float).reshape(-1) for r in self.rods])
        if len(self.wbar) != len(self.vert_nodes) or len(self.mbar) != len(self.vert_nodes):
            raise InputError("wbar / mbar: one entry per interior vertex of every rod")
        self._index()

    # -- dof bookkeeping ----------------------------------------------------------------------
    def pos_dofs(self, nodes: np.ndarray) -> np.ndarray:
        """Dof indices ``(..., 3)`` of node positions."""
        return 3 * np.asarray(nodes)[..., None] + np.arange(3)

    def theta_dofs(self, edges: np.ndarray) -> np.ndarray:
        return 3 * len(self.X) + np.asarray(edges)

    def _edge_dofs(self, edges: np.ndarray) -> np.ndarray:
        en = self.edge_nodes[edges]
        return np.concatenate([self.pos_dofs(en).reshape(len(edges), 6),
                               self.theta_dofs(edges)[:, None]], 1)

    def _index(self) -> None:
        self.stretch_idx = self.pos_dofs(self.edge_nodes).reshape(-1, 6)
        self.bend_idx = np.concatenate([self.pos_dofs(self.vert_nodes).reshape(-1, 9),
                                        self.theta_dofs(self.vert_edges)], 1)
        if self.joints:
            je = np.stack([j.edges for j in self.joints]).astype(np.int64)
            en = self.edge_nodes[je]  # (J, 4, 2)
            self.joint_idx = np.concatenate([self.pos_dofs(en).reshape(len(je), 24),
                                             self.theta_dofs(je)], 1)
            self.joint_edges = je
            self.joint_c = np.stack([np.asarray(j.c, float) for j in self.joints])
            self.joint_k = np.array([j.k for j in self.joints], float)
        if self.moments:
            me = np.array([m[0] for m in self.moments], np.int64)
            self.moment_idx = self.pos_dofs(self.edge_nodes[me]).reshape(-1, 6)

    def q0(self) -> np.ndarray:
        """The unknowns of the initial state."""
        return np.concatenate([self.X.reshape(-1), self.theta])

    def positions(self, q: np.ndarray) -> np.ndarray:
        return q[:3 * len(self.X)].reshape(-1, 3)

    # -- stencil data -------------------------------------------------------------------------
    def bend_data(self) -> rod.BendTwistData:
        ve = self.vert_edges
        return rod.BendTwistData(self.a1[ve], self.tref[ve], self.wbar, self.B1[ve].mean(1),
                                 self.B2[ve].mean(1),
                                 0.5 * self.GJ[ve].sum(1), self.mbar, self.lbar[ve].sum(1))

    def joint_data(self) -> rod.JointData:
        je = self.joint_edges
        return rod.JointData(self.a1[je], self.tref[je], self.joint_c, self.joint_k)

    def moment_data(self) -> rod.MomentData:
        return rod.MomentData(np.array([m[1] for m in self.moments], float),
                              np.array([m[2] for m in self.moments], float).reshape(-1, 3),
                              np.array([m[3] for m in self.moments], float).reshape(-1, 3))

    def accept(self, q: np.ndarray) -> None:
        """Re-base the reference frames on the tangents of ``q`` (time-parallel transport)."""
        P = self.positions(q)
        t = rod.unit(P[self.edge_nodes[:, 1]] - P[self.edge_nodes[:, 0]])
        self.a1 = rod.unit(rod.transport(self.a1, self.tref, t))
        self.tref = t

    # -- energy -------------------------------------------------------------------------------
    def groups(self):
        """``(name, function, dof index (B, n), data)`` of every stencil group."""
        out = [("stretch", rod.stretch_energy, self.stretch_idx,
                rod.StretchData(self.lbar, self.EA))]
        if len(self.bend_idx):
            out.append(("bend+twist", _bend_plus_twist, self.bend_idx, self.bend_data()))
        if self.joints:
            out.append(("joints", rod.joint_energy, self.joint_idx, self.joint_data()))
        if self.moments:
            out.append(("moments", rod.moment_energy, self.moment_idx, self.moment_data()))
        return out

    def energy(self, q: np.ndarray, order: int = 2, parts: bool = False):
        """Total energy (J) at ``q``, its gradient (order >= 1) and sparse Hessian (order 2);
        with ``parts`` also a dict of each group's energy (J)."""
        q = np.asarray(q, float)
        f = np.concatenate([self.forces.reshape(-1), np.zeros(self.n_edges)])
        E = -float(f @ q)
        grad = -f.copy() if order >= 1 else None
        rows, cols, vals = [], [], []
        each = {"loads": E}
        for name, fn, idx, data in self.groups():
            J = fn(Jet.variables(q[idx], order), data)
            e = float(J.v.sum())
            each[name] = e
            E += e
            if order >= 1:
                grad += np.bincount(idx.reshape(-1), weights=J.g.reshape(-1), minlength=self.n)
            if order >= 2:
                n = idx.shape[1]
                rows.append(np.repeat(idx, n, axis=1).reshape(-1))
                cols.append(np.tile(idx, (1, n)).reshape(-1))
                vals.append(J.h.reshape(-1))
        if parts and len(self.bend_idx):
            V = Jet.variables(q[self.bend_idx], 0)
            b, t = rod.bend_twist(V, self.bend_data())
            each.pop("bend+twist")
            each["bend"], each["twist"] = float(b.v.sum()), float(t.v.sum())
        H = None
        if order >= 2:
            H = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows),
                                                     np.concatenate(cols))),
                              shape=(self.n, self.n))
        if parts:
            return E, grad, H, each
        return E, grad, H

    def __call__(self, q: np.ndarray, order: int = 2):
        return self.energy(q, order)


def _bend_plus_twist(V, d: rod.BendTwistData) -> Jet:
    b, t = rod.bend_twist(V, d)
    return b + t
