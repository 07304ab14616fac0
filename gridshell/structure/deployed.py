"""The deployed gridshell of a design bundle as a network of discrete elastic rods.

Every lamella becomes one rod through its joints (``per_bay`` elements between consecutive
joints, the axis's tails beyond the end joints kept), on the model (the design times the
scale) with the real strip's section. Its material frame at the design: width direction ``m1``
in the surface (``n x t``) for GG's tangent strips, along the surface normal ``n`` for the
orthogonal strips of NCP / CNC / AA; ``n`` is the joints' net normal (sum of the loops' vector
areas), interpolated along the lamella by arc length.

Rest state, the strip as cut (so the design is a stressed state):

- GG: straight and untwisted;
- NCP / CNC / AA: the planar collapse curve of the bundle (circle for CNC, line for AA),
  strong-axis curvature only; the lamella's joints sit at their ``collapse_s`` along it.

Crossing lamellae share the joint's node and keep a common joint axis (the net normal at the
joint) while turning freely about it (:func:`~gridshell.structure.rod.joint_energy`). Supports
hold joints at their design positions (pinned: rotations free). Self-weight: density times
area times length, lumped at the nodes, -z.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from ..net import polyline_arclength
from . import rod
from .materials import Material
from .rodnet import JointSpec, RodNetwork, RodSpec
from .section import Section

#: standard gravity, m/s^2
GRAVITY = 9.81
#: design kinds whose strips lie tangent to the surface (thickness along the normal)
TANGENT_KINDS = ("GG",)


@dataclass
class Stiffness:
    """Factors on the strip's stiffnesses (1 = the real strip); 0 drops a resistance (the
    paper's geometric model has no wide-direction and no torsional resistance)."""

    strong: float = 1.0
    weak: float = 1.0
    torsion: float = 1.0


@dataclass
class DeployedModel:
    """A bundle's rod network and how it maps back to the design.

    network : the rods (model metres)
    joint_node : (n_joints,) node index of each net joint (-1: on no lamella)
    supports : (k,) joint indices held at their design positions
    lamella_nodes : per lamella (bundle order), its node indices
    lamella_ids : the lamellae's ids
    scale : model / design length ratio
    rest : how the rest state was obtained
    """

    network: RodNetwork
    joint_node: np.ndarray
    supports: np.ndarray
    lamella_nodes: list[np.ndarray]
    lamella_ids: list[int]
    scale: float
    kind: str
    rest: str
    section: Section
    material: Material
    gravity: bool
    loops: np.ndarray = field(default_factory=lambda: np.zeros((0, 4), np.int64))


def joint_normals(V: np.ndarray, loops: np.ndarray) -> np.ndarray:
    """Unit normals ``(n,3)`` at net joints ``V (n,3)``: sum of the vector areas of the quad
    ``loops (m,4)`` around each joint (zero where none)."""
    from ..quadmesh import polygon_vector_areas

    N = np.zeros_like(np.asarray(V, float))
    L = np.asarray(loops, np.int64).reshape(-1, 4)
    if len(L):
        A = polygon_vector_areas(V, L)
        for c in range(4):
            np.add.at(N, L[:, c], A)
    return rod.unit(N)


def boundary_joints(net) -> np.ndarray:
    """Joints on the boundary of the net's loops (an edge of one loop only); the lamellae's end
    joints when the net has no loops."""
    from ..quadmesh import boundary_vertices_of

    if len(net.loops):
        return boundary_vertices_of(net.loops, len(net.joints))
    ends = [lam.joints[[0, -1]] for lam in net.lamellae if len(lam.joints)]
    return np.unique(np.concatenate(ends)) if ends else np.zeros(0, np.int64)


def _node_arclengths(s_axis: float, js: np.ndarray, per_bay: int) -> tuple[np.ndarray, np.ndarray]:
    """Arc lengths of a lamella's rod nodes and, for each, the position of its joint in
    ``js`` (-1 for an in-between node)."""
    keep = np.concatenate([[True], np.diff(js) > 1e-9 * max(s_axis, 1e-300)])
    jpos = np.flatnonzero(keep)
    js = js[keep]
    s, which = [], []
    gaps = np.diff(js)
    h = float(np.median(gaps)) / per_bay if len(gaps) else s_axis / max(per_bay, 1)
    if js[0] > 0.25 * h:  # tail before the first joint
        k = max(1, int(round(js[0] / h)))
        s += list(np.linspace(0.0, js[0], k + 1)[:-1])
        which += [-1] * k
    for a in range(len(js)):
        s.append(js[a])
        which.append(int(jpos[a]))
        if a + 1 < len(js):
            s += list(np.linspace(js[a], js[a + 1], per_bay + 1)[1:-1])
            which += [-1] * (per_bay - 1)
    tail = s_axis - js[-1]
    if tail > 0.25 * h:
        k = max(1, int(round(tail / h)))
        s += list(np.linspace(js[-1], s_axis, k + 1)[1:])
        which += [-1] * k
    return np.asarray(s), np.asarray(which, np.int64)


def _interp_rows(s: np.ndarray, xs: np.ndarray, Y: np.ndarray) -> np.ndarray:
    return np.stack([np.interp(s, xs, Y[:, c]) for c in range(Y.shape[1])], axis=1)


def _rest_from_collapse(bundle, lam, s_nodes: np.ndarray
                        ) -> tuple[np.ndarray, np.ndarray] | None:
    """The lamella's rest polyline ``(k,3)`` on the collapse curve and the width direction of
    each edge ``(k-1,3)`` (the flattened surface normal), or None if the bundle has none."""
    cc, cs = bundle.collapse, (bundle.collapse_s or {}).get(lam.id)
    if cc is None or cs is None or len(cc.points) < 2 or len(cs) != len(lam.joint_s):
        return None
    cs = np.asarray(cs, float)
    keep = np.concatenate([[True], np.diff(lam.joint_s) > 1e-12])
    jsd, csd = lam.joint_s[keep], cs[keep]
    if len(jsd) >= 2:
        slope = np.sign(csd[-1] - csd[0]) or 1.0
    else:
        slope = 1.0
    c = np.interp(s_nodes, jsd, csd) if len(jsd) >= 2 else csd[0] + (s_nodes - jsd[0])
    c = np.where(s_nodes < jsd[0], csd[0] + slope * (s_nodes - jsd[0]), c)
    c = np.where(s_nodes > jsd[-1], csd[-1] + slope * (s_nodes - jsd[-1]), c)
    P2 = np.asarray(cc.points, float)
    sc = polyline_arclength(np.column_stack([P2, np.zeros(len(P2))]))
    # extend the curve linearly past its ends (tails of the strip beyond the collapse curve)
    def at(x, Y):
        out = _interp_rows(np.clip(x, sc[0], sc[-1]), sc, Y)
        lo, hi = x < sc[0], x > sc[-1]
        d0 = rod.unit(Y[1] - Y[0]) if Y is P2 else 0 * Y[0]
        d1 = rod.unit(Y[-1] - Y[-2]) if Y is P2 else 0 * Y[0]
        out[lo] += (x[lo] - sc[0])[:, None] * d0
        out[hi] += (x[hi] - sc[-1])[:, None] * d1
        return out
    R = at(c, P2)
    Nn = at(c, np.asarray(cc.normals, float))
    R3 = np.column_stack([R, np.zeros(len(R))])
    N3 = np.column_stack([Nn, np.zeros(len(Nn))])
    D = rod.unit(0.5 * (N3[1:] + N3[:-1]))
    return R3, D


def build_model(bundle, material: Material, section: Section, *,
                supports: str | np.ndarray = "boundary", gravity: bool = False,
                per_bay: int = 3, stiffness: Stiffness | None = None,
                joint_factor: float = 100.0) -> DeployedModel:
    """The rod network of a design bundle (:class:`~gridshell.bundle.DesignBundle`) built as
    ``section`` of ``material`` (module docstring). ``supports``: "boundary" or joint indices;
    ``joint_factor``: joint stiffness relative to the strips' stiffest rotation (a penalty)."""
    net = bundle.net
    st = stiffness or Stiffness()
    if per_bay < 1:
        raise InputError(f"per_bay must be >= 1, got {per_bay}")
    scale = float(section.scale)
    J = net.joints * scale
    NJ = joint_normals(net.joints, net.loops)
    tangent = bundle.kind in TANGENT_KINDS
    E, G = material.E, material.G
    EA, B1 = E * section.area, st.strong * E * section.I_strong
    B2, GJ = st.weak * E * section.I_weak, st.torsion * G * section.J
    mass = material.density * section.area
    X = [J]
    n_nodes = len(J)
    rods, theta, a1, lam_nodes, lam_ids = [], [], [], [], []
    joint_at: dict[int, list[tuple[int, int, int]]] = {}  # joint -> (rod, node pos, edges)
    rests = set()
    edge0 = 0
    for li, lam in enumerate(net.lamellae):
        if len(lam.joints) == 0 or len(lam.axis) < 2:
            continue
        A = lam.axis * scale
        sA = polyline_arclength(A)
        js = np.clip(lam.joint_s * scale, 0.0, sA[-1])
        s_nodes, which = _node_arclengths(sA[-1], js, per_bay)
        P = _interp_rows(s_nodes, sA, A)
        jidx = lam.joints[which[which >= 0]]
        P[which >= 0] = J[jidx]
        nodes = np.empty(len(P), np.int64)
        nodes[which >= 0] = jidx
        free = which < 0
        nodes[free] = n_nodes + np.arange(int(free.sum()))
        n_nodes += int(free.sum())
        X.append(P[free])
        seg = np.linalg.norm(np.diff(P, axis=0), axis=1)
        if np.any(seg <= 1e-9 * max(sA[-1], 1e-300)):
            raise InputError(f"lamella {lam.id}: two of its joints coincide; re-run the design")
        # design frame: normals interpolated between the joints
        jn = NJ[jidx]
        Nn = rod.unit(_interp_rows(s_nodes, s_nodes[which >= 0], jn)) if len(jidx) > 1 \
            else np.broadcast_to(jn[0], P.shape).copy()
        T = rod.unit(np.diff(P, axis=0))
        Ne = rod.unit(0.5 * (Nn[1:] + Nn[:-1]))
        d1 = rod.unit(np.cross(Ne, T)) if tangent else Ne
        a = rod.bishop_frame(P)
        th = rod.frame_angle(a, T, d1)
        # rest state
        k = len(P)
        wbar, mbar = np.zeros((k - 2, 2)), np.zeros(k - 2)
        if tangent:
            rests.add("straight strips")
        else:
            got = _rest_from_collapse(bundle, lam, s_nodes / scale) \
                if k >= 3 else None
            if got is not None:
                R, D = got
                wr, mr = rod.material_curvatures(R * scale, D)
                wd, _ = rod.material_curvatures(P, d1)
                sign = 1.0 if np.sum(wr[..., 0] * wd[..., 0]) >= 0 else -1.0
                wbar[..., 0] = sign * wr[..., 0]
                rests.add(f"collapse curve ({bundle.collapse.shape})")
            elif k >= 3 and bundle.collapse is not None and bundle.collapse.shape == "circle" \
                    and bundle.collapse.radius:
                # a CNC bundle without collapse_s: every strip is an arc of the circle
                wd, _ = rod.material_curvatures(P, d1)
                sign = 1.0 if np.sum(wd[..., 0]) >= 0 else -1.0
                lb = seg[:-1] + seg[1:]
                wbar[..., 0] = sign * 2.0 * np.tan(lb / (4.0 * bundle.collapse.radius * scale))
                rests.add("collapse curve (circle)")
            elif k >= 3:
                wd, _ = rod.material_curvatures(P, d1)
                wbar[..., 0] = wd[..., 0]
                rests.add("cut to the design's in-surface curvature (no collapse curve)")
        ne = k - 1
        rods.append(RodSpec(nodes, seg, np.full(ne, EA), np.full(ne, B1), np.full(ne, B2),
                            np.full(ne, GJ), wbar, mbar, np.full(ne, mass),
                            width=section.width, thickness=section.thickness))
        theta.append(th)
        a1.append(a)
        lam_nodes.append(nodes)
        lam_ids.append(int(lam.id))
        for pos in np.flatnonzero(which >= 0):
            e_before = edge0 + pos - 1 if pos > 0 else edge0 + pos
            e_after = edge0 + pos if pos < k - 1 else edge0 + pos - 1
            joint_at.setdefault(int(nodes[pos]), []).append((len(rods) - 1, e_before, e_after))
        edge0 += ne
    if not rods:
        raise InputError("the bundle has no lamella with joints; nothing to simulate")
    Xall = np.concatenate(X)
    theta_all, a1_all = np.concatenate(theta), np.concatenate(a1)
    # joints: the director along the joint axis, signed like the net normal
    all_T = rod.unit(Xall[np.concatenate([np.stack([r.nodes[:-1], r.nodes[1:]], 1)
                                          for r in rods])][:, 1]
                     - Xall[np.concatenate([np.stack([r.nodes[:-1], r.nodes[1:]], 1)
                                            for r in rods])][:, 0])
    le = np.concatenate([r.lbar for r in rods])
    kJ = joint_factor * max(B1, B2, GJ, 1e-300) / float(np.median(le))
    joints = []
    for jn, refs in joint_at.items():
        if len(refs) < 2 or not np.any(NJ[jn]):
            continue
        for other in refs[1:]:
            edges, c = [], np.zeros((4, 3))
            for side, (ri, eb, ea) in enumerate((refs[0], other)):
                for q, e in enumerate((eb, ea)):
                    t, a = all_T[e], a1_all[e]
                    cth, sth = np.cos(theta_all[e]), np.sin(theta_all[e])
                    a2 = np.cross(t, a)
                    frame = np.stack([t, cth * a + sth * a2, -sth * a + cth * a2])
                    c[2 * side + q] = 0.5 * (1.0 if side == 0 else -1.0) * (frame @ NJ[jn])
                    edges.append(e)
            joints.append(JointSpec(np.asarray(edges), c, kJ))
    network = RodNetwork(Xall, rods, theta_all, a1_all, joints=joints)
    used = np.zeros(len(J), bool)
    for r in rods:
        used[r.nodes[r.nodes < len(J)]] = True
    joint_node = np.where(used, np.arange(len(J)), -1)
    sup = _supports(net, supports)
    sup = sup[joint_node[sup] >= 0]
    fixed = np.zeros(network.n, bool)
    fixed[network.pos_dofs(sup).reshape(-1)] = True
    network.fixed = fixed
    if gravity:
        lump = np.zeros(len(Xall))
        for r in rods:
            half = 0.5 * r.mass * r.lbar
            np.add.at(lump, r.nodes[:-1], half)
            np.add.at(lump, r.nodes[1:], half)
        network.forces[:, 2] -= GRAVITY * lump
    _check_supported(Xall, sup, len(J))
    return DeployedModel(network, joint_node, sup, lam_nodes, lam_ids, scale, bundle.kind,
                         "; ".join(sorted(rests)), section, material, gravity,
                         loops=net.loops.copy())


def _supports(net, supports) -> np.ndarray:
    n = len(net.joints)
    if isinstance(supports, str):
        if supports != "boundary":
            raise InputError(f"supports must be 'boundary' or a list of joint indices, got "
                             f"{supports!r}")
        return boundary_joints(net).astype(np.int64)
    s = np.unique(np.asarray(supports, np.int64).reshape(-1))
    if len(s) and (s.min() < 0 or s.max() >= n):
        raise InputError(f"supports: joint indices must lie in [0, {n}), got "
                         f"{s.min()}..{s.max()}")
    return s


def _check_supported(X: np.ndarray, sup: np.ndarray, n_joints: int) -> None:
    """:class:`InputError` unless at least three supports that are not on one line hold the
    structure (else it moves as a rigid body)."""
    if len(sup) < 3:
        raise InputError(f"{len(sup)} supported joints; hold at least 3 joints that are not on "
                         "one line (--supports boundary, or more joint indices)")
    P = X[sup]
    C = P - P.mean(0)
    sv = np.linalg.svd(C, compute_uv=False)
    if sv[1] <= 1e-6 * max(sv[0], 1e-300):
        raise InputError("the supported joints lie on one line, so the gridshell can turn "
                         "about it; hold joints off that line too")
