"""The deployed gridshell of a design bundle as a network of discrete elastic rods.

Every lamella becomes one rod through its joints (``per_bay`` elements between consecutive
joints, the axis's tails beyond the end joints kept), on the model (the design times the
scale) with the real strip's section. Its material frame at the design: width direction ``m1``
in the surface (``n x t``) for GG's tangent strips, along the surface normal ``n`` for the
orthogonal strips of NCP / CNC / AA; ``n`` is the joints' net normal (sum of the loops' vector
areas), interpolated along the lamella by arc length.

Rest state, the strip as cut (:mod:`gridshell.structure.cutshape`, the rule fabrication cuts
by; so the design is a stressed state): GG and AA straight; CNC arcs of the collapse circle;
NCP pieces of the planar collapse curve from the lamella's first ``collapse_s`` on; strong-axis
curvature only, untwisted, signed like the design's in-surface curvature.

Crossing lamellae share the joint's node and keep a common joint axis (the net normal at the
joint) while turning freely about it (:func:`~gridshell.structure.rod.joint_energy`). Supports
hold joints at their design positions (pinned: rotations free). Self-weight: density times
area times length, lumped at the nodes, -z.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gridshell.core.errors import InputError
from gridshell.geometry.net import polyline_arclength
from gridshell.structure import rod
from gridshell.structure.cutshape import collapse_curvature, collapse_radius, cut_curvature, cut_shape
from gridshell.structure.frames import joint_normals
from gridshell.structure.materials import Material
from gridshell.structure.rodnet import JointSpec, RodNetwork, RodSpec
from gridshell.structure.section import Section

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


def boundary_joints(net) -> np.ndarray:
    """Joints on the boundary of the net's loops (an edge of one loop only); the lamellae's end
    joints when the net has no loops."""
    from gridshell.geometry.quadmesh import boundary_vertices_of

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


def build_model(bundle, material: Material, section: Section, *,
                supports: str | np.ndarray = "boundary", gravity: bool = False,
                per_bay: int = 3, stiffness: Stiffness | None = None,
                joint_factor: float = 100.0,
                joint_axes: np.ndarray | None = None, couple: bool = True,
                rigid_check: bool = True) -> DeployedModel:
    """The rod network of a design bundle (:class:`~gridshell.design.bundle.DesignBundle`) built as
    ``section`` of ``material`` (module docstring). ``supports``: "boundary" or joint indices;
    ``joint_factor``: joint stiffness relative to the strips' stiffest rotation (a penalty);
    ``joint_axes (n, 3)``: the joint axes to start from instead of the net normals (an NCP
    state's own rotation axes, signed consistently: the strips' width directions follow
    them); ``couple``: False leaves out the joints' common-axis terms (rods that only share
    their joint nodes); ``rigid_check``: False when the caller holds more than the supports'
    positions (the rods' frame angles: supports on one line then hold)."""
    net = bundle.net
    st = stiffness or Stiffness()
    if per_bay < 1:
        raise InputError(f"per_bay must be >= 1, got {per_bay}")
    scale = float(section.scale)
    J = net.joints * scale
    NJ = joint_normals(net.joints, net.loops) if joint_axes is None else \
        rod.unit(np.asarray(joint_axes, float))
    tangent = bundle.kind in TANGENT_KINDS
    E, G = material.E, material.G
    EA, B1 = E * section.area, st.strong * E * section.I_strong
    B2, GJ = st.weak * E * section.I_weak, st.torsion * G * section.J
    mass = material.density * section.area
    shape = cut_shape(bundle)
    curve = collapse_curvature(bundle) if shape == "curve" else None
    rest = {"line": "straight strips", "arc": f"arcs of the collapse circle (radius "
            f"{collapse_radius(bundle) if shape == 'arc' else 0:.4g} m of the design)",
            "curve": "pieces of the collapse curve"}[shape]
    X = [J]
    n_nodes = len(J)
    rods, theta, a1, lam_nodes, lam_ids = [], [], [], [], []
    joint_at: dict[int, list[tuple[int, int, int]]] = {}  # joint -> (rod, node pos, edges)
    edge0 = 0
    for li, lam in enumerate(net.lamellae):
        if len(lam.joints) == 0 or len(lam.axis) < 2:
            continue
        s_nodes, which, P, nodes, seg = _lamella_nodes(lam, J, scale, n_nodes, per_bay)
        free = which < 0
        n_nodes += int(free.sum())
        X.append(P[free])
        d1, a, th = _design_frame(P, s_nodes, which, NJ[nodes[which >= 0]], tangent)
        wbar, mbar = _rest_curvatures(bundle, lam, P, d1, s_nodes, seg, scale, shape, curve)
        k = len(P)
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
    le = np.concatenate([r.lbar for r in rods])
    kJ = joint_factor * max(B1, B2, GJ, 1e-300) / float(np.median(le))
    joints = _joint_specs(Xall, rods, theta_all, a1_all, joint_at, NJ, kJ) if couple else []
    network = RodNetwork(Xall, rods, theta_all, a1_all, joints=joints)
    used = np.isin(np.arange(len(J)), np.concatenate([r.nodes for r in rods]))
    joint_node = np.where(used, np.arange(len(J)), -1)
    sup = _supports(net, supports)
    sup = sup[joint_node[sup] >= 0]
    network.fixed = np.isin(np.arange(network.n), network.pos_dofs(sup).reshape(-1))
    if gravity:
        network.forces[:, 2] -= GRAVITY * _lumped_mass(len(Xall), rods)
    if rigid_check:
        _check_supported(Xall, sup, len(J))
    return DeployedModel(network, joint_node, sup, lam_nodes, lam_ids, scale, bundle.kind,
                         rest, section, material, gravity, loops=net.loops.copy())


def _lamella_nodes(lam, J: np.ndarray, scale: float, n_nodes: int, per_bay: int):
    """A lamella's rod nodes on the model (metres): their arc lengths ``s_nodes``, the joint
    position of each (``which``, -1 in between), positions ``P (k, 3)`` (the joints' own
    where a joint lies), node indices (joints keep theirs, the others numbered on from
    ``n_nodes``) and the edge lengths ``seg (k-1,)``; :class:`InputError` where two joints
    coincide."""
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
    seg = np.linalg.norm(np.diff(P, axis=0), axis=1)
    if np.any(seg <= 1e-9 * max(sA[-1], 1e-300)):
        raise InputError(f"lamella {lam.id}: two of its joints coincide; re-run the design")
    return s_nodes, which, P, nodes, seg


def _design_frame(P: np.ndarray, s_nodes: np.ndarray, which: np.ndarray, jn: np.ndarray,
                  tangent: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The rod's material frame at the design: width direction ``d1`` per edge (``n x t``
    when ``tangent``, else ``n``; ``n`` the joints' normals ``jn`` interpolated between the
    joints by arc length), the Bishop frame's ``a`` and the angle ``theta`` from it to ``d1``."""
    Nn = rod.unit(_interp_rows(s_nodes, s_nodes[which >= 0], jn)) if len(jn) > 1 \
        else np.broadcast_to(jn[0], P.shape).copy()
    T = rod.unit(np.diff(P, axis=0))
    Ne = rod.unit(0.5 * (Nn[1:] + Nn[:-1]))
    d1 = rod.unit(np.cross(Ne, T)) if tangent else Ne
    a = rod.bishop_frame(P)
    return d1, a, rod.frame_angle(a, T, d1)


def _rest_curvatures(bundle, lam, P: np.ndarray, d1: np.ndarray, s_nodes: np.ndarray,
                     seg: np.ndarray, scale: float, shape: str, curve) -> tuple[np.ndarray, np.ndarray]:
    """Rest curvatures ``wbar (k-2, 2)`` and twists ``mbar (k-2,)`` of the rod: the strip as
    cut (:mod:`gridshell.structure.cutshape`, as fabrication cuts it), strong-axis only,
    signed like the design's (material curvatures about ``d1``)."""
    k = len(P)
    wbar, mbar = np.zeros((k - 2, 2)), np.zeros(k - 2)
    if k >= 3 and shape != "line":
        # a vertex's curvature belongs between its edges' midpoints
        s_mid = 0.25 * (s_nodes[:-2] + 2 * s_nodes[1:-1] + s_nodes[2:])
        kc = cut_curvature(bundle, lam, s_mid / scale, curve) / scale
        wd, _ = rod.material_curvatures(P, d1)
        lb = seg[:-1] + seg[1:]
        w = 2.0 * np.tan(0.25 * kc * lb)
        wbar[:, 0] = w if np.sum(w * wd[:, 0]) >= 0 else -w
    return wbar, mbar


def _joint_specs(Xall: np.ndarray, rods: list[RodSpec], theta_all: np.ndarray,
                 a1_all: np.ndarray, joint_at: dict, NJ: np.ndarray, kJ: float) -> list[JointSpec]:
    """The joints of crossing rods (``joint_at``: node -> its rods' edges before and after
    it): each keeps the director along the joint axis, signed like the net normal ``NJ``,
    common to its first rod and each other (stiffness ``kJ``)."""
    ends = np.concatenate([np.stack([r.nodes[:-1], r.nodes[1:]], 1) for r in rods])
    all_T = rod.unit(Xall[ends][:, 1] - Xall[ends][:, 0])
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
    return joints


def _lumped_mass(n: int, rods: list[RodSpec]) -> np.ndarray:
    """Mass per node ``(n,)`` (kg): half of each element's mass at each of its ends."""
    lump = np.zeros(n)
    for r in rods:
        half = 0.5 * r.mass * r.lbar
        np.add.at(lump, r.nodes[:-1], half)
        np.add.at(lump, r.nodes[1:], half)
    return lump


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
