"""Curve nets of a gridshell: joints, net-loops and lamellae (the data type, nothing else)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gridshell.core.errors import InputError
from gridshell.geometry.vectors import row_norms


def polyline_length(P: np.ndarray) -> float:
    """Arc length of a polyline ``P (k,3)`` (same units as ``P``)."""
    P = np.asarray(P, dtype=float)
    if len(P) < 2:
        return 0.0
    return float(np.linalg.norm(np.diff(P, axis=0), axis=1).sum())


def polyline_arclength(P: np.ndarray) -> np.ndarray:
    """Cumulative arc length ``s (k,)`` at the vertices of a polyline ``P (k,3)``, ``s[0] = 0``."""
    P = np.asarray(P, dtype=float)
    return np.concatenate([[0.0], np.cumsum(row_norms(np.diff(P, axis=0)))])


@dataclass
class Lamella:
    """One lamella: its axis and the joints along it.

    Attributes
    ----------
    id : int
        Identifier, unique in the net.
    family : int
        1 or 3 (the paper's C^1 and C^3).
    joints : (k,) int
        Indices into ``Net.joints`` in order along the lamella.
    joint_s : (k,) float
        Arc length of each joint along the axis, metres, increasing.
    axis : (p,3) float
        Dense polyline of the lamella axis, metres.
    """

    id: int
    family: int
    joints: np.ndarray
    joint_s: np.ndarray
    axis: np.ndarray

    def __post_init__(self) -> None:
        self.joints = np.asarray(self.joints, dtype=np.int64).reshape(-1)
        self.joint_s = np.asarray(self.joint_s, dtype=float).reshape(-1)
        self.axis = np.asarray(self.axis, dtype=float).reshape(-1, 3)
        if self.family not in (1, 3):
            raise InputError(f"lamella {self.id}: family must be 1 or 3, got {self.family}")
        if len(self.joints) != len(self.joint_s):
            raise InputError(f"lamella {self.id}: {len(self.joints)} joints but "
                             f"{len(self.joint_s)} joint_s values; they must match")
        if len(self.joint_s) > 1 and np.any(np.diff(self.joint_s) < 0):
            raise InputError(f"lamella {self.id}: joint_s must increase along the lamella")

    @property
    def length(self) -> float:
        """Arc length of the axis, metres."""
        return polyline_length(self.axis)


@dataclass
class Net:
    """A gridshell net: joints (vertices), net-loops (quad faces) and lamellae.

    Attributes
    ----------
    joints : (n,3) float
        Joint positions, metres.
    loops : (m,4) int
        Net-loops as quads of joint indices, ordered A, B, C, D around the loop.
    lamellae : list of Lamella
    """

    joints: np.ndarray
    loops: np.ndarray
    lamellae: list[Lamella] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.joints = np.asarray(self.joints, dtype=float).reshape(-1, 3)
        self.loops = np.asarray(self.loops, dtype=np.int64).reshape(-1, 4)
        n = len(self.joints)
        if self.loops.size and (self.loops.min() < 0 or self.loops.max() >= n):
            raise InputError(f"net: loop indices must lie in [0, {n}); got "
                             f"[{self.loops.min()}, {self.loops.max()}]")
        for lam in self.lamellae:
            if lam.joints.size and (lam.joints.min() < 0 or lam.joints.max() >= n):
                raise InputError(f"net: lamella {lam.id} names joints outside [0, {n})")

    def family(self, f: int) -> list[Lamella]:
        """The lamellae of family ``f`` (1 or 3), in order."""
        return [lam for lam in self.lamellae if lam.family == f]

    def edges(self) -> np.ndarray:
        """Joint-to-joint edges along lamellae, ``(E,2)`` int, each once."""
        pairs = [np.stack([lam.joints[:-1], lam.joints[1:]], axis=1)
                 for lam in self.lamellae if len(lam.joints) > 1]
        if not pairs:
            return np.zeros((0, 2), dtype=np.int64)
        e = np.sort(np.concatenate(pairs), axis=1)
        return np.unique(e, axis=0)


def move_joints(net: Net, joints: np.ndarray) -> Net:
    """The net with its joints moved to ``joints (n,3)`` (metres) and every lamella axis
    carried along.

    Each axis is displaced by the joint displacements interpolated in arc length by a natural
    cubic spline (continued linearly beyond the end joints), so the axis stays smooth, and the
    joints are inserted as axis vertices, so the moved axis passes exactly through the moved
    joints; ``joint_s`` is remeasured along it. Loops and topology are unchanged.
    """
    return move_joints_states(net, [joints])[0]


def _joint_states(net: Net, states: list[np.ndarray] | np.ndarray) -> np.ndarray | None:
    """``states`` as one ``(m, n, 3)`` array (metres), checked against ``net``; None if empty."""
    Js = [np.asarray(J, dtype=float).reshape(-1, 3) for J in states]
    for J in Js:
        if J.shape != net.joints.shape:
            raise InputError(f"move_joints: {len(J)} joint positions for a net of "
                             f"{len(net.joints)} joints")
        if not np.all(np.isfinite(J)):
            raise InputError("move_joints: joint positions must be finite")
    return np.stack(Js) if Js else None


def move_joints_states(net: Net, states: list[np.ndarray] | np.ndarray) -> list[Net]:
    """:func:`move_joints` for every joint state of ``states`` (each ``(n,3)``, metres): the
    state-independent part of each axis (its joints inserted, the smooth curve through it) is
    built once, and one displacement spline carries all states' columns at once (the splines
    of all lamellae solved together, :func:`_carry_axes`)."""
    Js = _joint_states(net, states)
    if Js is None:
        return []
    per_lam = []
    for lam, (X, S, js, s_all) in zip(net.lamellae, _carry_axes(net.lamellae, Js)):
        per_lam.append([Lamella(id=lam.id, family=lam.family, joints=lam.joints.copy(),
                                joint_s=js.copy() if s_all is None else
                                np.interp(js, s_all, S[k]), axis=X[k])
                        for k in range(len(Js))])
    return [Net(joints=J, loops=net.loops.copy(), lamellae=[lams[k] for lams in per_lam])
            for k, J in enumerate(Js)]


def carried_axes(net: Net, states: list[np.ndarray] | np.ndarray
                 ) -> list[tuple[np.ndarray, np.ndarray]]:
    """The lamella axes of :func:`move_joints_states` as arrays, without building the nets:
    for every lamella of ``net`` (in order), its axis carried to each of the ``m`` joint
    states ``(m, p, 3)`` and the cumulative arc length along each ``(m, p)`` (metres; the
    numbers of the moved lamellae's ``axis`` and of :func:`polyline_arclength` of it)."""
    Js = _joint_states(net, states)
    if Js is None:
        return [(np.zeros((0, len(lam.axis), 3)), np.zeros((0, len(lam.axis))))
                for lam in net.lamellae]
    return [carried[:2] for carried in _carry_axes(net.lamellae, Js)]


def _arclengths(X: np.ndarray) -> np.ndarray:
    """:func:`polyline_arclength` of each polyline ``X[k] (p,3)``: ``(m, p)``, the same sums."""
    seg = row_norms(np.diff(X, axis=1))
    return np.concatenate([np.zeros((len(X), 1)), np.cumsum(seg, axis=1)], axis=1)


def _smooth_at(s: np.ndarray, X: np.ndarray, js: np.ndarray) -> np.ndarray:
    """The points ``(k,3)`` at arc lengths ``js`` of the not-a-knot cubic spline through the
    vertices ``X (p,3)`` at arc lengths ``s`` (the chord's through two vertices), metres.

    Where every ``js`` is the arc length of a vertex other than the last (joints are axis
    vertices in the bundles the tool writes), these are the vertices themselves: at its knot
    ``s[i]`` the spline's piece ``i`` gives ``0.0 + X[i]`` (its constant coefficient; the other
    terms are 0), so ``X[i] + 0.0``, bit for bit, without building the spline."""
    from scipy.interpolate import CubicSpline

    if len(s) <= 2:
        return np.stack([np.interp(js, s, X[:, c]) for c in range(3)], axis=1)
    i = np.minimum(np.searchsorted(s, js), len(s) - 1)
    if np.all((s[i] == js) & (i < len(s) - 1)) and np.all(np.diff(s) > 0) \
            and np.all(np.isfinite(X)):
        return X[i] + 0.0
    return CubicSpline(s, X, axis=0)(js)


def _axis_with_joints(lam: Lamella) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray,
                                              float]:
    """The state-independent part of :func:`_carry_axis` for an axis of two or more vertices
    and one or more joints: the axis with its joints as vertices ``X (p,3)``, the arc lengths
    ``s_all (p,)`` of its vertices, the joints' arc lengths ``js (k,)`` and points ``at (k,3)``
    on it and its length, metres."""
    X, js = lam.axis, lam.joint_s
    seg = row_norms(np.diff(X, axis=0))
    if not np.all(seg > 0):                                # repeated vertices go
        X = X[np.concatenate([[True], seg > 0])]
        seg = row_norms(np.diff(X, axis=0))
    s = np.concatenate([[0.0], np.cumsum(seg)])            # polyline_arclength(X)
    js = np.clip(js, 0.0, s[-1])
    # the axis with its joints as vertices, placed on the smooth curve through the axis
    # vertices (not on a chord); vertices within a fifth of a segment of a joint give way
    seg = np.diff(s)
    near = 0.2 * np.interp(s, 0.5 * (s[:-1] + s[1:]), seg) if len(seg) else s
    keep = np.min(np.abs(s[:, None] - js[None, :]), axis=1) > near
    at = _smooth_at(s, X, js)
    order = np.argsort(np.concatenate([s[keep], js]), kind="stable")
    s_all = np.concatenate([s[keep], js])[order]
    X = np.concatenate([X[keep], at])[order]
    return X, s_all, js, at, float(s[-1])


def _carry_axis(lam: Lamella, Js: np.ndarray, joined: tuple | None = None,
                d: np.ndarray | None = None
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]:
    """``lam`` carried to each joint state ``Js (m, n, 3)``: the axes ``(m, p, 3)``, their arc
    lengths ``(m, p)``, the joints' arc lengths ``js`` on the axis before the move and the arc
    lengths ``s_all (p,)`` of the axis points before it (None when the axis is only shifted,
    ``js`` then stays the joints' arc lengths), metres. ``joined``: :func:`_axis_with_joints`
    of ``lam``, and ``d``: the displacements ``(p, 3m)`` at ``s_all`` by the spline, if known."""
    X, js = lam.axis, lam.joint_s
    if len(X) < 2 or len(js) == 0:
        Xs = np.stack([X + (J[lam.joints[0]] - X[0] if len(js) else 0) for J in Js])
        return Xs, _arclengths(Xs), js, None
    X, s_all, js, at, length = _axis_with_joints(lam) if joined is None else joined
    m = len(Js)
    if len(js) == 1 or js[-1] - js[0] <= 1e-12 * length:
        D = Js[:, lam.joints] - at[None]                   # (m, k, 3)
        disp = np.broadcast_to(D.mean(axis=1)[:, None, :], (m,) + X.shape)
    else:
        if d is None:
            from scipy.interpolate import CubicSpline

            D = Js[:, lam.joints] - at[None]
            Dc = np.moveaxis(D, 0, 1).reshape(len(js), 3 * m)  # every state's columns at once
            cs = CubicSpline(js, Dc, axis=0, bc_type="natural" if len(js) > 2 else "not-a-knot")
            t = np.clip(s_all, js[0], js[-1])
            slope0, slope1 = cs(js[[0, -1]], 1)            # the slopes at the end joints
            d = cs(t) + (s_all - t)[:, None] * np.where((s_all < js[0])[:, None], slope0, slope1)
        disp = np.moveaxis(d.reshape(len(s_all), m, 3), 1, 0)
    Xs = X[None] + disp
    return Xs, _arclengths(Xs), js, s_all


def _carry_axes(lams: list[Lamella], Js: np.ndarray
                ) -> list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]]:
    """:func:`_carry_axis` of each lamella of ``lams`` (metres), with the displacement splines
    of all lamellae with two or more joints (finite, strictly increasing in arc length) built,
    evaluated and added at once (:func:`gridshell.geometry.spline_batch.cubic_splines_at`, scipy's
    numbers); the others go one by one, in order, as before."""
    from gridshell.geometry.spline_batch import cubic_splines_at

    out: list = [None] * len(lams)
    batch = []
    m = len(Js)
    for i, lam in enumerate(lams):
        joined = None
        if len(lam.axis) >= 2 and len(lam.joint_s) >= 2:
            joined = _axis_with_joints(lam)
            _, s_all, js, at, length = joined
            Dc = np.moveaxis(Js[:, lam.joints] - at[None], 0, 1).reshape(len(js), 3 * m)
            # a finite length: a finite axis, finite s_all and js (clipped to it, or NaN)
            if np.isfinite(length) and js[-1] - js[0] > 1e-12 * length \
                    and np.all(np.diff(js) > 0) and np.all(np.isfinite(Dc)):
                batch.append((i, joined, Dc))
                continue
        out[i] = _carry_axis(lam, Js, joined)
    if not batch:
        return out
    idx, joined, Dc = zip(*batch)
    d = cubic_splines_at([j[2] for j in joined], list(Dc), [j[1] for j in joined])  # (P, 3m)
    b = 0
    for i, j in zip(idx, joined):                          # lamella by lamella: in cache
        a, b = b, b + len(j[1])
        out[i] = _carry_axis(lams[i], Js, j, d[a:b])
    return out
