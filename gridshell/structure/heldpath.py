"""The strips of an NCP / CNC / AA alignment sequence: at every state the kinematic model's
joints and axes (paper 4.2.4), the strips between the joints at their elastic equilibrium from
their cut shape (issue 28).

The alignment simulation (:mod:`gridshell.ncp.alignment`) moves the joints and their rotation
axes only; a strip's shape between two joints follows from the strip itself. At each state:

1. every joint-to-joint piece of a lamella's design axis is carried rigidly onto the state
   (its chord onto the state's chord, the design's joint axis onto the state's axis at its
   first joint) and its ends moved onto the state's joints: the strip's arc lengths are the
   design's, changed by the state's change of the chord (the kinematic sequence keeps the
   chords only approximately; ``length_error``, a state above :data:`LENGTH_TOL` is
   approximate);
2. the lamellae become discrete elastic rods of the strip as cut
   (:func:`gridshell.structure.deployed.build_model`: rest shape the cut shape, strong-axis
   curvature only), every joint held at the state's position, the rods' width direction at
   the joints held along the state's axes (the edges beside a joint keep their frame angle);
   Newton finds the equilibrium between the joints (:func:`gridshell.structure.equilibrium.solve`).

The equilibrium's shape depends on the stiffness ratios only (no load: neither the modulus
nor the scale changes it), so one strip (:data:`SECTION`, 20:1) serves every material. The
result has the layout of ``sequence/strips.npz`` (:func:`gridshell.structure.states.read_strips`):
dense rod nodes ``X`` and width directions ``N`` (the strips' own frames: for orthogonal
strips the surface normal), ``kcut`` the cut curvature at each node (1/m of the design); the
bound of a state is the largest angle (radians) between the strips' width direction at a
joint and the sequence's axis there; a state whose Newton iteration did not converge or whose
bound exceeds :data:`AXIS_TOL`, or whose joints fold a lamella (its joint-to-joint chords turn
by more than :data:`gridshell.structure.states.FOLD_DEG`, or by :data:`FOLD_MARGIN_DEG` more
than in both end states: the blended kinematic sequence there is no path a strip takes), or
(an intermediate state) whose strips must bend about their strong axis by more than
:data:`STRONG_TOL` of the sequence's largest weak-axis curvature, is approximate (reported, not judged).
"""
from __future__ import annotations

import dataclasses
from typing import Any, Callable

import numpy as np

from gridshell.design.bundle import DesignBundle
from gridshell.geometry.net import Lamella, Net, polyline_arclength
from gridshell.structure import rod
from gridshell.structure.materials import get_material
from gridshell.structure.section import Section
from gridshell.measure.metrics import delta_l
from gridshell.structure.states import FOLD_DEG, max_turn, signed_like

__all__ = ["AXIS_TOL", "METHOD_HELD", "SECTION", "carried_lamellae", "held_path", "held_state"]

#: the strip the states are solved with (mm and model scale): width / thickness 20:1
SECTION = Section(20.0, 1.0, 0.1)

#: a state whose strips leave the sequence's axes at a joint by more than this (radians,
#: about 3 degrees) is approximate
AXIS_TOL = 0.05

#: a state whose joints turn a lamella between consecutive joint-to-joint chords by more than
#: the deployed and the collapsed state do, plus this (degrees), is a fold of the blended
#: kinematic simulation (:mod:`gridshell.ncp.alignment`), not a motion the strips take: the
#: AA pseudosphere's sequence turns them by up to 79 degrees where both ends turn them by 10
FOLD_MARGIN_DEG = 10.0

#: Newton iterations given to the strips of a folded state (approximate whatever they reach)
FOLDED_ITER = 4

#: a state whose joint-to-joint chords differ from the design's by more than this share is
#: approximate: the strips, inextensible, are given the state's chord lengths between joints
#: (the kinematic sequence keeps them only approximately, paper 4.2.4), as GG's carried states
LENGTH_TOL = 0.01

#: an intermediate state whose held strips bend about their strong axis by more than this
#: share of the sequence's largest weak-axis curvature is approximate: a strip 20 times wider than
#: thick does not bend in its plane where it can bend and twist out of it, so the kinematic
#: sequence there is not the strips' motion (the criterion of a physical path, issue 28:
#: strong-axis curvature below 5 % of the weak one)
STRONG_TOL = 0.05

#: samples of the carried design axis per joint-to-joint piece
CARRY_SAMPLES = 8

#: rod elements between neighbouring joints
PER_BAY = 3

METHOD_HELD = ("the alignment sequence's joints and own rotation axes (paper 4.2.4); between "
               "them every strip at its elastic equilibrium from its cut shape (discrete rods "
               f"of a {SECTION.width_mm:g}:{SECTION.thickness_mm:g} strip, joints held, width "
               f"directions held along the axes at the joints, {PER_BAY} elements per bay); "
               "bound: the largest angle (rad) between a strip's width direction and the axis "
               "at a joint")


def _chord_frame(c: np.ndarray, r: np.ndarray) -> np.ndarray:
    """Rows: the unit chord, the axis ``r`` made perpendicular to it, their cross product."""
    c = c / max(float(np.linalg.norm(c)), 1e-300)
    r = r - float(r @ c) * c
    n = float(np.linalg.norm(r))
    if n < 1e-12:                                    # the axis along the chord: any normal
        r = np.eye(3)[int(np.argmin(np.abs(c)))]
        r = r - float(r @ c) * c
        n = float(np.linalg.norm(r))
    r = r / n
    return np.stack([c, r, np.cross(c, r)])


def carried_lamellae(net: Net, r0: np.ndarray, V: np.ndarray, R: np.ndarray,
                     samples: int = CARRY_SAMPLES) -> list[Lamella]:
    """The design lamellae of ``net`` (joints with axes ``r0``) carried piece by piece onto the
    state with joints ``V`` and axes ``R (n, 3)`` (module docstring, step 1): axes from the
    first to the last joint, ``joint_s`` from 0 along them, metres."""
    J0 = net.joints
    out = []
    u = np.linspace(0.0, 1.0, samples + 1)[:, None]
    for lam in net.lamellae:
        if len(lam.joints) < 2:
            continue
        A = lam.axis
        sA = polyline_arclength(A)
        pieces = []
        for k in range(len(lam.joints) - 1):
            j0, j1 = int(lam.joints[k]), int(lam.joints[k + 1])
            ss = np.linspace(lam.joint_s[k], lam.joint_s[k + 1], samples + 1)
            P = np.stack([np.interp(ss, sA, A[:, c]) for c in range(3)], 1)
            P[0], P[-1] = J0[j0], J0[j1]
            Fd = _chord_frame(J0[j1] - J0[j0], r0[j0])
            Fs = _chord_frame(V[j1] - V[j0], R[j0])
            Q = (P - J0[j0]) @ Fd.T @ Fs + V[j0]
            Q += (1.0 - u) * (V[j0] - Q[0]) + u * (V[j1] - Q[-1])
            pieces.append(Q if k == 0 else Q[1:])
        P = np.concatenate(pieces)
        s = polyline_arclength(P)
        out.append(Lamella(lam.id, lam.family, lam.joints, s[::samples], P))
    return out


def _edge_directors(net, q: np.ndarray) -> np.ndarray:
    """Material width directions ``m1 (E, 3)`` of the rod network's edges at ``q``."""
    P = net.positions(q)
    T = rod.unit(P[net.edge_nodes[:, 1]] - P[net.edge_nodes[:, 0]])
    a = rod.unit(rod.transport(net.a1, net.tref, T))
    th = q[3 * len(net.X):]
    return np.cos(th)[:, None] * a + np.sin(th)[:, None] * np.cross(T, a)


def held_state(bundle: DesignBundle, V: np.ndarray, R: np.ndarray, r0: np.ndarray, *,
               rtol: float = 1e-9, max_iter: int = 40) -> dict[str, Any]:
    """One state (module docstring): per lamella (bundle order, lamellae of >= 2 joints) its
    rod nodes ``X`` (design metres), width directions ``N``, joint index per node (-1 between)
    ``joint``, cut curvature ``kcut`` (1/m of the design); ``converged``, ``iterations``,
    ``bound`` (rad)."""
    from gridshell.structure.cutshape import collapse_curvature, cut_curvature, cut_shape
    from gridshell.structure.deployed import build_model
    from gridshell.structure.equilibrium import solve

    lams = carried_lamellae(bundle.net, r0, V, R)
    sb = dataclasses.replace(bundle, net=Net(V, bundle.net.loops, lams))
    held = np.unique(np.concatenate([lam.joints for lam in lams]))
    model = build_model(sb, get_material("pp"), SECTION, supports=held, per_bay=PER_BAY,
                        joint_axes=R, couple=False, rigid_check=False)
    net = model.network
    nJ = len(V)
    fixed = net.fixed.copy()
    at_joint = np.flatnonzero(np.any(net.edge_nodes < nJ, axis=1))
    fixed[net.theta_dofs(at_joint)] = True
    net.fixed = fixed
    res = solve(net, rtol=rtol, max_iter=max_iter)
    m1 = _edge_directors(net, res.q)
    P = net.positions(res.q) / model.scale
    curve = collapse_curvature(sb) if cut_shape(sb) == "curve" else None
    X, N, joint, kcut, bound, e0 = [], [], [], [], 0.0, 0
    for lam, nodes in zip(lams, model.lamella_nodes):
        k = len(nodes)
        m = m1[e0:e0 + k - 1]
        e0 += k - 1
        Nn = rod.unit(np.concatenate([m[:1], m[:-1] + m[1:], m[-1:]]))
        j = np.where(nodes < nJ, nodes, -1)
        on = j >= 0
        c = np.abs(np.einsum("ij,ij->i", Nn[on], rod.unit(R[j[on]])))
        bound = max(bound, float(np.arccos(np.clip(c, -1.0, 1.0)).max(initial=0.0)))
        s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(P[nodes], axis=0),
                                                             axis=1))])
        X.append(P[nodes])
        N.append(Nn)
        joint.append(j)
        kcut.append(cut_curvature(sb, lam, s, curve))
    strong, weak = _strong_and_weak(X, N, kcut)
    dl = delta_l(bundle.net.joints, V, bundle.net.edges())
    return {"X": X, "N": N, "joint": joint, "kcut": kcut, "ids": [lam.id for lam in lams],
            "converged": bool(res.converged), "iterations": int(res.iterations),
            "bound": bound, "turn_deg": max((max_turn(V[lam.joints]) for lam in lams),
                                            default=0.0),
            "length_error": float(np.nanmax(dl, initial=0.0)), "strong": strong, "weak": weak}


def _strong_and_weak(X: list, N: list, kcut: list) -> tuple[float, float]:
    """The largest strong-axis curvature change (in-plane, against the cut curvature, signed
    like it) and the largest weak-axis curvature of the strips ``X, N`` (1/m of the design)."""
    from gridshell.structure.frames import darboux_curvatures

    strong = weak = 0.0
    for x, n, kc in zip(X, N, kcut):
        dc = darboux_curvatures(x, n)
        kc = signed_like(kc, dc.kn)
        inner = slice(1, -1) if len(x) > 2 else slice(None)
        strong = max(strong, float(np.abs(dc.kn - kc)[inner].max(initial=0.0)))
        weak = max(weak, float(np.abs(dc.kg)[inner].max(initial=0.0)))
    return strong, weak


def held_path(bundle: DesignBundle, frames: list[np.ndarray], axes: list[np.ndarray],
              t: np.ndarray, *, progress: Callable[[str], None] | None = None
              ) -> dict[str, Any]:
    """Every state of an alignment sequence (joints ``frames``, own axes ``axes``, path
    parameter ``t``) as strips (:func:`held_state`), in the layout of
    ``sequence/strips.npz`` (module docstring); axes signed continuously along the path."""
    r0 = rod.unit(np.asarray(axes[0], float))
    prev = r0
    states = []
    # a state the blended simulation folds is approximate whatever its equilibrium: its strips
    # get FOLDED_ITER Newton iterations, not a full solve (the fold is known from the joints)
    lams = [lam for lam in bundle.net.lamellae if len(lam.joints) >= 2]
    turns = np.array([max((max_turn(np.asarray(V, float)[lam.joints]) for lam in lams),
                          default=0.0) for V in frames])
    folds = (turns > FOLD_DEG) | (turns > max(turns[0], turns[-1]) + FOLD_MARGIN_DEG)
    folds[[0, -1]] = False
    for f, (V, R) in enumerate(zip(frames, axes)):
        R = rod.unit(np.asarray(R, float))
        R = np.where((np.einsum("ij,ij->i", R, prev) < 0)[:, None], -R, R)
        prev = R
        states.append(held_state(bundle, np.asarray(V, float), R, r0,
                                 **({"max_iter": FOLDED_ITER} if folds[f] else {})))
        if progress is not None:
            st = states[-1]
            progress(f"strips of state {f}/{len(frames) - 1}: {st['iterations']} Newton "
                     f"iterations, axes within {np.degrees(st['bound']):.2g} deg")
    ids = states[0]["ids"]
    lamella = np.concatenate([np.full(len(x), i) for i, x in zip(ids, states[0]["X"])])
    bound = np.array([s["bound"] for s in states])
    turn = np.array([s["turn_deg"] for s in states])
    folded = (turn > FOLD_DEG) | (turn > max(turn[0], turn[-1]) + FOLD_MARGIN_DEG)
    weak_max = max(max(s["weak"] for s in states), 1e-300)
    ratio = np.array([s["strong"] for s in states]) / weak_max
    forced = ratio > STRONG_TOL
    forced[[0, -1]] = False                    # the end states are the design's own
    approximate = np.array([(not s["converged"]) or s["bound"] > AXIS_TOL or
                            s["length_error"] > LENGTH_TOL for s in states]) | folded | forced
    return {"X": np.stack([np.concatenate(s["X"]) for s in states]),
            "N": np.stack([np.concatenate(s["N"]) for s in states]),
            "lamella": lamella, "joint": np.concatenate(states[0]["joint"]),
            "kcut": np.concatenate(states[0]["kcut"]), "t": np.asarray(t, float),
            "approximate": approximate, "bound": bound, "method": METHOD_HELD,
            "iterations": np.array([s["iterations"] for s in states]),
            "turn_deg": turn, "strong_ratio": ratio,
            "length_error": np.array([s["length_error"] for s in states])}
