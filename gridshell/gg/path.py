"""The physical alignment path of a GG net: its states through surfaces of revolution (paper 3.3).

On a surface of revolution with profile ``r(s)``, ``z(s)`` (``s`` arc length of the meridian),
the net is the base geodesic ``(s(sigma), g(sigma))`` (Clairaut: ``r^2 dphi/dsigma = c``) turned
by ``o`` about the axis, and mirrored. State ``lambda`` (1 deployed, 0 closed) maps the point
``(s, phi)`` of the net to the surface of revolution

    x = r(s) (cos lambda phi, sin lambda phi),   z = Z_lambda(s),
    dZ_lambda/ds = sqrt((1 - lambda^2 c^2 / r^2) - r_s^2 (1 - c^2 / r^2)) / sqrt(1 - c^2 / r^2),

whose metric in ``(s, phi)`` is ``(r^2 - lambda^2 c^2) / (r^2 - c^2) ds^2 + lambda^2 r^2 dphi^2``.
Along every lamella (``ds/dsigma = sqrt(1 - c^2/r^2)``, ``dphi/dsigma = +-c/r^2``) the speed
stays 1, so **arc lengths and the joints' positions along the lamellae are kept**, and
``r^2 d(lambda phi)/dsigma = lambda c`` is Clairaut's relation of that surface: **every lamella
stays a geodesic** (unit speed + Clairaut), the net's angle closes (``sin psi = lambda c / r``
to the meridian), and a strip lying tangent to the surface only bends about its weak axis and
twists. At ``lambda = 0`` every lamella lies on the planar meridian ``(r(s), Z_0(s))``; the
second phase unbends that planar curve (tangent angle ``beta -> beta_m + (1 - tau)(beta -
beta_m)``, arc length kept), weak-axis bending only, into the straight bundle; a rigid motion,
``tau``-way (rotation by ``tau`` times its angle), carries it onto the collapsed net.

Exact where the net has no turning point (``c < r`` on every lamella: ``s`` monotone along
it) and the design surface is of revolution. Where it is only isometric to its surface of
revolution (the isometry maps the one onto the other, not the states), every closing state
carries the design's difference from the surface of revolution, scaled by ``lambda``: each
lamella keeps the design's arc lengths exactly and turns, segment to segment, by the
revolution state's turns plus ``lambda`` times the design's difference (its bending and twist
between the two), placed by its joints (:func:`_carried_state`); the joints' disagreement is
the state's bound, and a state beyond :data:`CARRIED_APPROXIMATE` of a segment is approximate.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from scipy.interpolate import CubicSpline
from scipy.spatial.transform import Rotation, Slerp

from gridshell.geometry.net import Net, polyline_arclength
from gridshell.geometry.vectors import rigid_fit
from gridshell.gg.alignment import GGSequence
from gridshell.gg.clairaut import IntrinsicNet
from gridshell.gg.mapback import NetParameters, SurfaceMap, net_parameters
from gridshell.gg.revolution import Revolution

__all__ = ["METHOD_PATH", "StripStates", "gg_path", "segment_length_error"]

#: how the states of the path are made (``structure.json["states"]["method"]``)
METHOD_PATH = ("physical path (GG): each state the net on a surface of revolution on which "
               "every lamella stays a geodesic with its arc lengths (Clairaut constant "
               "lambda c, angles lambda phi), then the closed planar bundle unbent into the "
               "straight one; dense strips with the state surface's normals "
               "(sequence/strips.npz)")

#: samples of the profile integrals (Z_lambda, the unbending)
PROFILE_SAMPLES = 4097

#: a state whose joints disagree by more than this share of the mean joint-to-joint segment
#: (a carried state, :func:`_carried_state`) is approximate (reported, not judged)
CARRIED_APPROXIMATE = 0.01

#: samples of a lamella per joint-to-joint segment in the stored strips (the traced curves
#: are denser; measured on the vase at 1:10: the states' utilisation within 0.5 % of the
#: full resolution's)
SAMPLES_PER_SEGMENT = 8

#: a design net further than this share of the diagonal from the net on its surface of
#: revolution (after the best rigid motion) is not itself of revolution: its states carry the
#: difference (:func:`_carried_state`)
CARRY_TOL = 1e-3


@dataclass
class StripStates:
    """Dense strips of every state of an alignment path (``sequence/strips.npz``).

    X, N : (F, M, 3) axis points (metres) and unit strip normals (tangent strips: the surface
    normal) of M samples in F states;  lamella : (M,) lamella id of each sample (samples of a
    lamella consecutive, in order along it);  joint : (M,) joint index of a sample on a joint,
    else -1;  t : (F,) path parameter (0 deployed, 1 collapsed);  approximate : (F,) states not
    on the exact path;  bound : (F,) largest relative change of a joint-to-joint arc length
    from the deployed state (dimensionless);  phase : (F,) ``"deployed"``, ``"close"``,
    ``"unbend"``;  method : how they were made.
    """

    X: np.ndarray
    N: np.ndarray
    lamella: np.ndarray
    joint: np.ndarray
    t: np.ndarray
    approximate: np.ndarray
    bound: np.ndarray
    phase: np.ndarray
    sphi: np.ndarray
    lam: np.ndarray
    tau: np.ndarray
    method: str = METHOD_PATH

    def save(self, path: str | Path) -> None:
        """Write the states as a compressed ``.npz``."""
        np.savez_compressed(path, X=self.X, N=self.N, lamella=self.lamella, joint=self.joint,
                            t=self.t, approximate=self.approximate, bound=self.bound,
                            phase=self.phase.astype(str), sphi=self.sphi, lam=self.lam,
                            tau=self.tau, method=np.array(self.method))


@dataclass
class GGPath(GGSequence):
    """A GG alignment path: the joints of every state (a
    :class:`gridshell.gg.alignment.GGSequence`, ``length_error`` the states'
    :attr:`StripStates.bound`, ``history`` per state ``{"frame", "t", "phase", "lambda",
    "tau"}``) and its dense strips ``strips`` (:class:`StripStates`)."""

    strips: StripStates | None = None


def _unit(X: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(X, axis=-1, keepdims=True)
    return X / np.where(n > 0, n, 1.0)


class _Profile:
    """The profile integrals of the states: ``Z_lambda(s)`` and the closed planar bundle."""

    def __init__(self, rev: Revolution, c: float, s_lo: float, s_hi: float) -> None:
        pad = 1e-6 * max(s_hi - s_lo, 1e-300)
        self.s = np.linspace(s_lo - pad, s_hi + pad, PROFILE_SAMPLES)
        self.r = np.asarray(rev.r_of_s(self.s), float)
        self.dr = np.asarray(rev.dr_of_s(self.s), float)
        self.q = 1.0 - (c / self.r) ** 2                  # cos^2 of the deployed angle psi
        self.c, self.rev = float(c), rev
        self.s_mid = 0.5 * (s_lo + s_hi)

    def dZ(self, lam: float) -> np.ndarray:
        """``dZ_lambda/ds`` on the samples (module docstring)."""
        a = (1.0 - (lam * self.c / self.r) ** 2) - self.dr ** 2 * self.q
        return np.sqrt(np.maximum(a, 0.0) / self.q)

    def Z(self, lam: float) -> CubicSpline:
        """``Z_lambda(s)``, zero at the middle parallel (an antiderivative)."""
        F = CubicSpline(self.s, self.dZ(lam)).antiderivative()
        z0 = float(F(self.s_mid))
        return CubicSpline(self.s, F(self.s) - z0)

    def unbent(self, tau: float) -> tuple[CubicSpline, CubicSpline, CubicSpline]:
        """The closed bundle ``(r(s), Z_0(s))`` unbent the fraction ``tau``: in-plane
        coordinates ``u(s), w(s)`` and the tangent angle ``beta_tau(s)``."""
        dz = self.dZ(0.0)
        beta = np.unwrap(np.arctan2(dz, self.dr))
        h = np.hypot(self.dr, dz)                       # d(arc)/ds
        k = int(np.argmin(np.abs(self.s - self.s_mid)))
        b = beta[k] + (1.0 - tau) * (beta - beta[k])
        u = CubicSpline(self.s, h * np.cos(b)).antiderivative()
        w = CubicSpline(self.s, h * np.sin(b)).antiderivative()
        u0, w0 = float(u(self.s[k])), float(w(self.s[k]))
        r0 = float(self.r[k])
        z0 = float(self.Z(0.0)(self.s[k]))
        return (CubicSpline(self.s, u(self.s) - u0 + r0), CubicSpline(self.s, w(self.s) - w0 + z0),
                CubicSpline(self.s, b))


def _closing_state(prof: _Profile, lam: float, phi_m: float):
    """Points and normals ``(s, phi) -> (k, 3)`` of state ``lambda`` (revolution frame)."""
    Z = prof.Z(lam)
    dZ = Z.derivative()

    def points(s: np.ndarray, phi: np.ndarray) -> np.ndarray:
        r = prof.rev.r_of_s(s)
        a = phi_m + lam * (phi - phi_m)
        return np.stack([r * np.cos(a), r * np.sin(a), Z(s)], axis=1)

    def normals(s: np.ndarray, phi: np.ndarray) -> np.ndarray:
        a = phi_m + lam * (phi - phi_m)
        e = np.stack([np.cos(a), np.sin(a), np.zeros_like(a)], axis=1)
        n = dZ(s)[:, None] * e - prof.rev.dr_of_s(s)[:, None] * np.array([0.0, 0.0, 1.0])
        return _unit(n)

    return points, normals


def _unbending_state(prof: _Profile, tau: float, phi_m: float):
    """Points and normals of the closed bundle unbent the fraction ``tau``."""
    u, w, b = prof.unbent(tau)
    e = np.array([np.cos(phi_m), np.sin(phi_m), 0.0])
    ez = np.array([0.0, 0.0, 1.0])

    def points(s: np.ndarray, phi: np.ndarray) -> np.ndarray:
        return u(s)[:, None] * e + w(s)[:, None] * ez

    def normals(s: np.ndarray, phi: np.ndarray) -> np.ndarray:
        bb = b(s)
        return np.sin(bb)[:, None] * e - np.cos(bb)[:, None] * ez

    return points, normals


def segment_length_error(X: np.ndarray, X0: np.ndarray, lamella: np.ndarray,
                         joint: np.ndarray) -> float:
    """Largest relative change of a joint-to-joint arc length of the dense strips ``X (M,3)``
    from ``X0 (M,3)`` (dimensionless; samples as :class:`StripStates`)."""
    worst = 0.0
    for lid in np.unique(lamella):
        m = np.flatnonzero(lamella == lid)
        at = np.flatnonzero(joint[m] >= 0)
        if len(at) < 2:
            continue
        a, a0 = polyline_arclength(X[m])[at], polyline_arclength(X0[m])[at]
        d0 = np.diff(a0)
        ok = d0 > 0
        if ok.any():
            worst = max(worst, float(np.max(np.abs(np.diff(a)[ok] - d0[ok]) / d0[ok])))
    return worst


def _thinned(par: NetParameters, per_segment: int) -> NetParameters:
    """``par`` with each lamella's samples thinned to about ``per_segment`` per
    joint-to-joint segment (the joints and the ends kept)."""
    lams = []
    for fam, idx, sp, isj in par.lamellae:
        nseg = max(int(isj.sum()) - 1, 1)
        step = max(1, int(len(sp) // (per_segment * nseg)))
        keep = np.zeros(len(sp), bool)
        keep[::step] = True
        keep[[0, -1]] = True
        keep |= isj
        lams.append((fam, idx, sp[keep], isj[keep]))
    return NetParameters(sphi=par.sphi, loops=par.loops, lamellae=lams, extra=par.extra)


def exact_path_possible(par: NetParameters, rev: Revolution, c: float) -> str:
    """Why the closed-form path does not apply to the net (empty: it does): a lamella with a
    turning point (``s`` not monotone along it, ``r = c`` reached)."""
    for i, (_, _, sp, _) in enumerate(par.lamellae):
        d = np.diff(sp[:, 0])
        if len(d) and not (np.all(d > 0) or np.all(d < 0)):
            return f"lamella {i} turns back along the meridian (Clairaut turning point r = c)"
    s = par.samples()[:, 0]
    if len(s) and float(np.min(rev.r_of_s(s))) <= abs(c) * (1.0 + 1e-9):
        return "the net reaches the parallel r = c (a turning point)"
    return ""


def _segment_frames(X: np.ndarray, N: np.ndarray) -> np.ndarray:
    """Frames ``(k-1, 3, 3)`` of the segments of a strip ``X (k,3)`` with normals ``N (k,3)``:
    columns tangent ``T``, ``U = N x T``, ``N`` (the mean normal of the segment's ends made
    orthogonal to ``T``)."""
    T = _unit(np.diff(X, axis=0))
    n = 0.5 * (N[1:] + N[:-1])
    n = _unit(n - np.einsum("ij,ij->i", n, T)[:, None] * T)
    return np.stack([T, np.cross(n, T), n], axis=2)


def _lamella_turns(X: np.ndarray, N: np.ndarray, lamella: np.ndarray
                   ) -> dict[int, tuple[np.ndarray, np.ndarray]]:
    """Per lamella of the strips ``X, N (M, 3)`` (``lamella (M,)``: the samples of a lamella
    consecutive), all at once: lamella id -> (segment frames ``(k-1, 3, 3)``, the rotation
    vectors ``(k-2, 3)`` that turn each frame into the next in the segment's own frame: its
    discrete Darboux rotations, bending about both axes and twist times the segment length),
    for lamellae of at least 3 samples."""
    F = _segment_frames(X, N)                                # (M-1): some span two lamellae
    same = lamella[1:] == lamella[:-1]
    pair = same[:-1] & same[1:]
    loc = np.einsum("kji,kjl->kil", F[:-1][pair], F[1:][pair])
    rv = np.zeros((len(pair), 3))
    if len(loc):
        rv[pair] = Rotation.from_matrix(loc).as_rotvec()
    out = {}
    for lid in np.unique(lamella):
        m = np.flatnonzero(lamella == lid)
        if len(m) >= 3:
            out[int(lid)] = (F[m[0]:m[-1]], rv[m[0]:m[-1] - 1])
    return out


def _strip(ell: np.ndarray, F0: np.ndarray, rv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The strip ``(X (k,3), N (k,3))`` with segment lengths ``ell (k-1,)``, first segment
    frame ``F0`` and the turns ``rv (k-2, 3)`` (:func:`_lamella_turns`), from the origin."""
    L = Rotation.from_rotvec(rv).as_matrix() if len(rv) else np.zeros((0, 3, 3))
    F = np.empty((len(ell), 3, 3))
    F[0] = F0
    for i in range(len(L)):
        F[i + 1] = F[i] @ L[i]
    X = np.concatenate([np.zeros((1, 3)), np.cumsum(ell[:, None] * F[:, :, 0], axis=0)])
    n = F[:, :, 2]
    N = _unit(np.concatenate([n[:1], 0.5 * (n[1:] + n[:-1]), n[-1:]]))
    return X, N


def _turn_excess(dep, rev1, lamella: np.ndarray) -> dict[int, np.ndarray]:
    """Per lamella the design's turns less those of the revolution's deployed state,
    ``omega_design - omega_1`` (:func:`_carried_state`)."""
    d, r = _lamella_turns(dep[0], dep[1], lamella), _lamella_turns(rev1[0], rev1[1], lamella)
    return {lid: d[lid][1] - r[lid][1] for lid in d}


def _carried_state(dep, rev1, revl, lam, lamella, joint, excess):
    """State ``lambda`` of a design surface only isometric to its surface of revolution: the
    revolution's state ``revl`` with the design's difference from the revolution's deployed
    state ``rev1`` carried along, scaled by ``lambda`` (all the difference deployed, none
    closed). Every lamella keeps the design's arc lengths exactly and turns, segment to
    segment, by ``omega_lambda + lambda (omega_design - omega_1)``; it is placed by the best
    rigid fit of its joints to ``J_lambda + lambda (J_design - J_1)``, a joint the mean of its
    lamellae's. ``dep``, ``rev1``, ``revl``: ``(X (M,3), N (M,3), J (n,3))``. Returns the
    state and the joints' disagreement, the largest distance between a joint's two
    placements (metres). ``excess``: lamella id -> ``omega_design - omega_1``
    (:func:`_turn_excess`, the same for every state)."""
    (Xd, Nd, Jd), (X1, N1, J1), (Xl, Nl, Jl) = dep, rev1, revl
    turns = _lamella_turns(Xl, Nl, lamella)
    target = Jl + lam * (Jd - J1)
    X, N = np.empty_like(Xd), np.empty_like(Nd)
    acc, cnt = np.zeros_like(Jd), np.zeros(len(Jd))
    seen: dict[int, np.ndarray] = {}
    worst = 0.0
    for lid in np.unique(lamella):
        m = np.flatnonzero(lamella == lid)
        on = joint[m] >= 0
        j = joint[m][on]
        if len(m) < 3:
            x, n = Xl[m] + lam * (Xd[m] - X1[m]), Nl[m]
        else:
            Fl, rl = turns[int(lid)]
            x, n = _strip(np.linalg.norm(np.diff(Xd[m], axis=0), axis=1), Fl[0],
                          rl + lam * excess[int(lid)])
            if len(j) >= 2:
                R, b = rigid_fit(x[on], target[j])
            else:
                R, b = np.eye(3), (Xl[m] + lam * (Xd[m] - X1[m])).mean(0) - x.mean(0)
            x, n = x @ R.T + b, n @ R.T
        X[m], N[m] = x, n
        for q, p in zip(j.tolist(), x[on]):
            if q in seen:
                worst = max(worst, float(np.linalg.norm(seen[q] - p)))
            seen[q] = p
        np.add.at(acc, j, x[on])
        np.add.at(cnt, j, 1.0)
    J = np.where(cnt[:, None] > 0, acc / np.maximum(cnt, 1.0)[:, None], target)
    return X, N, J, worst


def _sample_joints(par: NetParameters) -> tuple[np.ndarray, np.ndarray]:
    """Lamella index and joint index (-1: none) of every sample of ``par.samples()``."""
    lamella = np.concatenate([np.full(len(x), i) for i, (_, _, x, _) in enumerate(par.lamellae)])
    joint = np.full(len(lamella), -1, np.int64)
    pos = 0
    for _, idx, x, isj in par.lamellae:
        joint[pos + np.flatnonzero(isj)] = idx
        pos += len(x)
    return lamella, joint


def _schedule(frames: int) -> list[tuple[str, float]]:
    """``(phase, parameter)`` of states 1..frames: the closing's ``lambda``, the
    unbending's ``tau`` (a third of the states unbend)."""
    kB = max(1, int(round(frames / 3)))
    kA = max(frames - kB, 1)
    return ([("close", 1.0 - k / kA) for k in range(1, kA + 1)]
            + [("unbend", k / kB) for k in range(1, kB + 1)])


def _rigid_towards(J: np.ndarray, target: np.ndarray):
    """``move(X, tau)``: the rigid motion carrying ``J`` onto ``target`` (best fit), done the
    fraction ``tau`` (rotation by ``tau`` times its angle about the centre of ``J``, which
    moves ``tau`` of the way); ``move(N, tau, vector=True)`` turns vectors."""
    Rf, bf = rigid_fit(J, target)
    rot = Slerp([0.0, 1.0], Rotation.from_matrix(np.stack([np.eye(3), Rf])))
    c = J.mean(0)
    shift = c @ Rf.T + bf - c

    def move(X: np.ndarray, tau: float, vector: bool = False) -> np.ndarray:
        Rt = rot([tau]).as_matrix()[0]
        return X @ Rt.T if vector else (X - c) @ Rt.T + c + tau * shift

    return move


def gg_path(inet: IntrinsicNet, rev: Revolution, net: Net, aligned: np.ndarray,
            P: np.ndarray | None = None, *, frames: int = 12) -> GGPath | None:
    """The physical alignment path of the GG net ``net`` (module docstring) in ``frames``
    steps, from the deployed net (on the design surface ``P (R, C, 3)``, through which
    ``net`` was mapped; None: ``net`` lies on the surface of revolution) to the collapsed net
    ``aligned (n, 3)``. None where the closed form does not apply
    (:func:`exact_path_possible`) or the parameters do not reproduce ``net``."""
    par = net_parameters(inet)
    if len(par.sphi) != len(net.joints) or len(par.lamellae) != len(net.lamellae) or \
            exact_path_possible(par, rev, inet.c):
        return None
    par = _thinned(par, SAMPLES_PER_SEGMENT)
    sp = par.samples()
    lamella, joint = _sample_joints(par)
    prof = _Profile(rev, inet.c, float(sp[:, 0].min()), float(sp[:, 0].max()))
    phi_m = float(np.mean(par.sphi[:, 1]))
    joints = np.asarray(net.joints, float)
    diag = float(np.linalg.norm(np.ptp(joints, axis=0))) or 1.0

    def state(maps) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        points, normals = maps
        return (points(sp[:, 0], sp[:, 1]), normals(sp[:, 0], sp[:, 1]),
                points(par.sphi[:, 0], par.sphi[:, 1]))

    X1, N1, J1 = state(_closing_state(prof, 1.0, phi_m))
    if P is not None:                                   # the deployed net and its surface
        smap = SurfaceMap(P, rev.s, rev.phi)
        X_dep, N_dep = smap(sp[:, 0], sp[:, 1]), smap.normals(sp[:, 0], sp[:, 1])
    else:
        X_dep, N_dep = X1, N1
    off = np.linalg.norm(X_dep[joint >= 0] - joints[joint[joint >= 0]], axis=1)
    if np.max(off, initial=0.0) > (1e-6 if P is not None else CARRY_TOL) * diag:
        return None                                     # the net was not mapped through P
    R, b = rigid_fit(J1, joints)                          # revolution frame -> design frame
    gap = float(np.max(np.linalg.norm(J1 @ R.T + b - joints, axis=1))) / diag
    if np.dot(N_dep.ravel(), (N1 @ R.T).ravel()) < 0:
        N_dep = -N_dep                                  # one orientation for all states
    JB = state(_unbending_state(prof, 1.0, phi_m))[2] @ R.T + b
    move = _rigid_towards(JB, np.asarray(aligned, float))   # straight bundle -> aligned
    Xs, Ns, Vs, phase = [X_dep], [N_dep], [joints], ["deployed"]
    carried = gap > CARRY_TOL               # the design is not itself of revolution
    rev1 = (X1 @ R.T + b, N1 @ R.T, J1 @ R.T + b)
    mismatch = [0.0]
    excess = None                           # the design's turns beyond the revolution's
    hist = [{"frame": 0, "phase": "deployed", "lambda": 1.0, "tau": 0.0}]
    for k, (ph, x) in enumerate(_schedule(max(int(frames), 2)), start=1):
        X, N, J = state(_closing_state(prof, x, phi_m) if ph == "close"
                        else _unbending_state(prof, x, phi_m))
        X, N, J = X @ R.T + b, N @ R.T, J @ R.T + b
        miss = 0.0
        if ph == "unbend":
            X, N, J = move(X, x), move(N, x, vector=True), move(J, x)
        elif carried and x > 0:
            if excess is None:
                excess = _turn_excess((X_dep, N_dep, joints), rev1, lamella)
            X, N, J, miss = _carried_state((X_dep, N_dep, joints), rev1, (X, N, J), x,
                                           lamella, joint, excess)
        Xs.append(X)
        Ns.append(N)
        Vs.append(J)
        phase.append(ph)
        mismatch.append(miss)
        hist.append({"frame": k, "phase": ph, "lambda": x if ph == "close" else 0.0,
                     "tau": x if ph == "unbend" else 0.0})
    Vs[-1] = np.asarray(aligned, float).copy()
    t = np.linspace(0.0, 1.0, len(Vs))
    for h, tk in zip(hist, t):
        h["t"] = float(tk)
    bound = np.array([segment_length_error(X, X_dep, lamella, joint) for X in Xs])
    # a carried state's lamellae keep their lengths exactly; its error is the joints'
    # disagreement, relative to the mean joint-to-joint segment
    seg = float(np.mean(np.linalg.norm(np.diff(joints[net.edges()], axis=1)[:, 0], axis=1)))
    bound = np.maximum(bound, np.asarray(mismatch) / max(seg, 1e-300))
    strips = StripStates(X=np.stack(Xs), N=np.stack(Ns), lamella=lamella, joint=joint, t=t,
                         approximate=bound > CARRIED_APPROXIMATE, bound=bound,
                         phase=np.array(phase), sphi=sp.copy(),
                         lam=np.array([h["lambda"] for h in hist]),
                         tau=np.array([h["tau"] for h in hist]))
    return GGPath(V=Vs, t=t, edges=net.edges(), length_error=bound, strips=strips,
                  history=hist)


def path_info(path: GGPath) -> dict[str, Any]:
    """The path's figures for the report: method, phases, the largest length change."""
    s = path.strips
    return {"method": s.method, "phases": [str(p) for p in s.phase],
            "length_error_max": float(np.max(s.bound)) if len(s.bound) else 0.0,
            "approximate": [int(k) for k in np.flatnonzero(s.approximate)]}
