"""Discrete elastic rod energies (Bergou, Wardetzky, Robinson, Audoly & Grinspun 2008).

A rod is a polyline ``x_0 .. x_n`` (metres) with one material-frame angle ``theta_j`` per edge
(radians). Each edge carries a reference frame ``(t_j, a1_j, a2_j)`` kept by time-parallel
transport (:func:`transport`): between solver steps the stored ``a1`` is carried from the stored
tangent to the current one, so the energies are smooth functions of the positions and angles.
The material frame is ``a1, a2`` turned by ``theta_j`` about ``t_j``: ``m1`` is the strip's
width direction, ``m2`` its thickness direction.

Energies (each a stencil function of :class:`~gridshell.structure.jet.Jet` variables, so its
gradient and Hessian are exact):

- stretching, per edge: ``1/2 EA (|e|/|e_bar| - 1)^2 |e_bar|``;
- bending, per interior vertex ``i`` (Bergou eq. 3-4): ``1/l_bar_i (w_i - w_bar_i)^T
  diag(B1_i, B2_i) (w_i - w_bar_i)`` with the curvature binormal ``kb_i = 2 e_{i-1} x e_i /
  (|e_{i-1}||e_i| + e_{i-1}.e_i)``, ``l_bar_i = |e_bar_{i-1}| + |e_bar_i|``, the stiffnesses the
  mean of the two edges' and the material curvatures ``w_i = (kb_i . m2_i, -kb_i . m1_i)``
  taken against the mean ``m_i = (m_{i-1} + m_i) / 2`` of the two edges' directors. (Bergou's
  sum over the two edges' own directors reads a strip twisting at the rate ``tau`` as bent
  about its strong axis by ``h tau / 2`` per unit curvature; with a strip's ``(w/t)^2`` stiffness
  ratio that is first-order error in the energy that matters (+7 % on a 60-element helix,
  tests/structure/test_structure_rod.py); the mean directors make it second order.)
  ``w1`` bends the axis towards the width direction ``m1`` (strong axis, ``B1 = E t w^3/12``),
  ``w2`` towards the thickness direction ``m2`` (weak axis, ``B2 = E w t^3/12``);
- twisting, per interior vertex (Bergou eq. 5): ``GJ (m_i - m_bar_i)^2 / l_bar_i`` with
  ``m_i = theta_i - theta_{i-1} + m_ref_i`` and the reference twist ``m_ref_i``, the angle from
  the space-parallel transport of ``a1_{i-1}`` onto ``t_i`` to ``a1_i``.

Energies in joules when lengths are metres and stiffnesses N (EA), N m^2 (EI, GJ).
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from gridshell.structure.jet import Jet, atan2, cross, dot, norm, stack


# ---------------------------------------------------------------------------------------------
# frames (plain arrays)
# ---------------------------------------------------------------------------------------------

def unit(X: np.ndarray) -> np.ndarray:
    """Rows of ``X (..., 3)`` scaled to unit length (zero rows stay zero)."""
    n = np.linalg.norm(X, axis=-1, keepdims=True)
    return np.divide(X, n, out=np.zeros_like(X, dtype=float), where=n > 0)


def transport(a: np.ndarray, t0: np.ndarray, t1: np.ndarray) -> np.ndarray:
    """Parallel transport of ``a (..., 3)`` (perpendicular to unit ``t0``) onto unit ``t1``: the
    rotation about ``t0 x t1`` taking ``t0`` to ``t1``, ``a - (t1.a)/(1 + t0.t1) (t0 + t1)``."""
    c = np.sum(t0 * t1, axis=-1, keepdims=True)
    return a - np.sum(t1 * a, axis=-1, keepdims=True) / (1.0 + c) * (t0 + t1)


def bishop_frame(X: np.ndarray, a0: np.ndarray | None = None) -> np.ndarray:
    """Reference directors ``a1 (n-1, 3)`` of a polyline ``X (n,3)`` by space-parallel transport
    along it, starting from ``a0`` (projected onto the first edge's normal plane; default any
    perpendicular)."""
    T = unit(np.diff(np.asarray(X, float), axis=0))
    if a0 is None:
        a0 = np.eye(3)[int(np.argmin(np.abs(T[0])))]
    a = unit(a0 - np.dot(a0, T[0]) * T[0])
    out = np.empty_like(T)
    out[0] = a
    for j in range(1, len(T)):
        out[j] = unit(transport(out[j - 1], T[j - 1], T[j]))
    return out


def frame_angle(a1: np.ndarray, t: np.ndarray, d1: np.ndarray) -> np.ndarray:
    """Angles ``theta (k,)`` turning the reference directors ``a1`` of consecutive edges about
    their tangents ``t`` onto the projections of ``d1 (k,3)`` (the wanted width directions),
    unwrapped along the edges (no jumps of 2 pi: the twist between edges is their difference)."""
    d = unit(d1 - np.sum(d1 * t, axis=-1, keepdims=True) * t)
    a2 = np.cross(t, a1)
    return np.unwrap(np.arctan2(np.sum(d * a2, axis=-1), np.sum(d * a1, axis=-1)))


def material_curvatures(X: np.ndarray, d1: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Material curvatures of a polyline ``X (n,3)`` whose edges carry width directions
    ``d1 (n-1,3)``: ``w (n-2, 2)`` (vertex, (w1, w2)) and the twist ``m (n-2,)`` of the material
    frame, radians (the rest state of a rod; formulas of :func:`bend_twist`)."""
    X = np.asarray(X, float)
    if len(X) < 3:
        return np.zeros((0, 2)), np.zeros(0)
    T = unit(np.diff(X, axis=0))
    a1 = bishop_frame(X)
    th = frame_angle(a1, T, d1)
    e = np.diff(X, axis=0)
    e0, e1 = e[:-1], e[1:]
    le0, le1 = np.linalg.norm(e0, axis=1), np.linalg.norm(e1, axis=1)
    kb = 2 * np.cross(e0, e1) / (le0 * le1 + np.sum(e0 * e1, axis=1))[:, None]
    c, s = np.cos(th)[:, None], np.sin(th)[:, None]
    a2 = np.cross(T, a1)
    m1, m2 = c * a1 + s * a2, -s * a1 + c * a2
    m1, m2 = 0.5 * (m1[:-1] + m1[1:]), 0.5 * (m2[:-1] + m2[1:])
    w = np.stack([np.sum(kb * m2, axis=1), -np.sum(kb * m1, axis=1)], axis=1)
    return w, np.diff(th)  # Bishop frame: no reference twist


# ---------------------------------------------------------------------------------------------
# energies on stencils (Jets)
# ---------------------------------------------------------------------------------------------

def _vec(V: list[Jet], k: int) -> Jet:
    return stack(V[3 * k:3 * k + 3])


def _jet_transport(a: np.ndarray, t0: np.ndarray, t1: Jet) -> Jet:
    """:func:`transport` of fixed ``a``, ``t0 (B,3)`` onto a variable unit ``t1``."""
    c = dot(t1, Jet(t0))
    s = dot(t1, Jet(a)) / (c + 1.0)
    return (t1 + t0) * s.expand() * -1.0 + a


def _jet_transport_var(a: Jet, t0: Jet, t1: Jet) -> Jet:
    """:func:`transport` with every argument variable."""
    c = dot(t0, t1)
    s = dot(t1, a) / (c + 1.0)
    return a - (t0 + t1) * s.expand()


def _material(a_old: np.ndarray, t_old: np.ndarray, t: Jet, theta: Jet) -> tuple[Jet, Jet, Jet]:
    """Reference director ``a1`` (transported from the stored one onto ``t``) and the material
    directors ``m1, m2`` turned by ``theta``."""
    a1 = _jet_transport(a_old, t_old, t)
    a2 = cross(t, a1)
    c, s = theta.cos().expand(), theta.sin().expand()
    return a1, a1 * c + a2 * s, a2 * c - a1 * s


class StretchData(NamedTuple):
    """Per edge: rest length ``lbar (B,)`` m, axial stiffness ``EA (B,)`` N."""

    lbar: np.ndarray
    EA: np.ndarray


def stretch_energy(V: list[Jet], d: StretchData) -> Jet:
    """Stretching energy of edges ``x0 -> x1`` (variables: x0, x1), J."""
    e = _vec(V, 1) - _vec(V, 0)
    eps = norm(e) / d.lbar - 1.0
    return eps.square() * (0.5 * d.EA * d.lbar)


class BendTwistData(NamedTuple):
    """Per interior vertex (edges j = 0: before it, 1: after it):

    a_old, t_old : (B, 2, 3) stored reference directors and tangents of the two edges
    wbar : (B, 2) rest material curvatures (w1, w2)
    B1, B2 : (B,) bending stiffness towards m1 (strong) and m2 (weak), N m^2
    GJ : (B,) torsional stiffness, N m^2
    mbar : (B,) rest twist, radians
    lbar : (B,) rest length |e_bar_{i-1}| + |e_bar_i|, m
    """

    a_old: np.ndarray
    t_old: np.ndarray
    wbar: np.ndarray
    B1: np.ndarray
    B2: np.ndarray
    GJ: np.ndarray
    mbar: np.ndarray
    lbar: np.ndarray


def _curvature_binormal(e0: Jet, e1: Jet) -> Jet:
    den = norm(e0) * norm(e1) + dot(e0, e1)
    return cross(e0, e1) * (den.reciprocal() * 2.0).expand()


def _frames(V: list[Jet], d: BendTwistData):
    e0, e1 = _vec(V, 1) - _vec(V, 0), _vec(V, 2) - _vec(V, 1)
    t0, t1 = e0 * norm(e0).reciprocal().expand(), e1 * norm(e1).reciprocal().expand()
    f0 = _material(d.a_old[:, 0], d.t_old[:, 0], t0, V[9])
    f1 = _material(d.a_old[:, 1], d.t_old[:, 1], t1, V[10])
    return e0, e1, t0, t1, f0, f1


def _curvatures(e0: Jet, e1: Jet, f0, f1, d: BendTwistData) -> tuple[Jet, Jet]:
    kb = _curvature_binormal(e0, e1)
    m1, m2 = (f0[1] + f1[1]) * 0.5, (f0[2] + f1[2]) * 0.5
    return dot(kb, m2) - d.wbar[:, 0], -dot(kb, m1) - d.wbar[:, 1]


def _twist(t0: Jet, t1: Jet, f0, f1, V: list[Jet], d: BendTwistData) -> Jet:
    u = _jet_transport_var(f0[0], t0, t1)
    mref = atan2(dot(cross(u, f1[0]), t1), dot(u, f1[0]))
    return V[10] - V[9] + mref - d.mbar


def bend_twist(V: list[Jet], d: BendTwistData, bend: bool = True,
               twist: bool = True) -> tuple[Jet | None, Jet | None]:
    """Bending and twisting energies at interior vertices (variables x0, x1, x2, theta0,
    theta1), J (Bergou 2008, eqs. 3-5; module docstring)."""
    e0, e1, t0, t1, f0, f1 = _frames(V, d)
    Eb = Et = None
    if bend:
        w1, w2 = _curvatures(e0, e1, f0, f1, d)
        Eb = (w1.square() * d.B1 + w2.square() * d.B2) * (1.0 / d.lbar)
    if twist:
        Et = _twist(t0, t1, f0, f1, V, d).square() * (d.GJ / d.lbar)
    return Eb, Et


def bend_energy(V: list[Jet], d: BendTwistData) -> Jet:
    """Bending energy alone (see :func:`bend_twist`), J."""
    return bend_twist(V, d, twist=False)[0]


def twist_energy(V: list[Jet], d: BendTwistData) -> Jet:
    """Twisting energy alone (see :func:`bend_twist`), J."""
    return bend_twist(V, d, bend=False)[1]


def strains(V: list[Jet], d: BendTwistData) -> tuple[Jet, Jet, Jet]:
    """Integrated curvature changes ``w1 - w1_bar`` (strong axis), ``w2 - w2_bar`` (weak
    axis) and twist ``m - m_bar`` at interior vertices, radians (divide by ``l_bar / 2`` for
    curvatures in 1/m)."""
    e0, e1, t0, t1, f0, f1 = _frames(V, d)
    w1, w2 = _curvatures(e0, e1, f0, f1, d)
    return w1, w2, _twist(t0, t1, f0, f1, V, d)


class JointData(NamedTuple):
    """Per joint: four edges (two of each lamella; an end joint repeats its one edge), each
    with variables (x_a, x_b, theta): 28 variables.

    a_old, t_old : (B, 4, 3) stored reference directors and tangents
    c : (B, 4, 3) coordinates of the joint axis in each edge's frame ``(t, m1, m2)`` at the
        design, times +1/2 for lamella A's edges and -1/2 for lamella B's: their sum is the
        difference of the two lamellae's (body-fixed) joint axes, zero at the design
    k : (B,) rotational stiffness of the joint about the in-surface axes, N m / rad
    """

    a_old: np.ndarray
    t_old: np.ndarray
    c: np.ndarray
    k: np.ndarray


def joint_energy(V: list[Jet], d: JointData) -> Jet:
    """``1/2 k |n_A - n_B|^2``: the two lamellae at a joint keep a common joint axis ``n`` and
    turn freely about it (a pin), J."""
    diff = None
    for q in range(4):
        x0, x1 = _vec(V, 2 * q), _vec(V, 2 * q + 1)
        e = x1 - x0
        t = e * norm(e).reciprocal().expand()
        _, m1, m2 = _material(d.a_old[:, q], d.t_old[:, q], t, V[24 + q])
        part = t * d.c[:, q, 0:1] + m1 * d.c[:, q, 1:2] + m2 * d.c[:, q, 2:3]
        diff = part if diff is None else diff + part
    return dot(diff, diff) * (0.5 * d.k)


class MomentData(NamedTuple):
    """A follower end moment ``M (B,)`` N m about the fixed unit ``axis (B,3)``, its angle measured
    from ``ref (B,3)`` (perpendicular to ``axis``) in the plane perpendicular to it."""

    M: np.ndarray
    axis: np.ndarray
    ref: np.ndarray


def moment_energy(V: list[Jet], d: MomentData) -> Jet:
    """Potential ``-M phi`` of a moment acting on an edge ``x0 -> x1`` whose tangent makes the
    angle ``phi`` with ``ref`` about ``axis`` (a conservative end moment), J."""
    e = _vec(V, 1) - _vec(V, 0)
    y = dot(cross(Jet(d.ref), e), Jet(d.axis))
    x = dot(Jet(d.ref), e)
    return atan2(y, x) * (-d.M)
