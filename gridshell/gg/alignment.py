"""Alignment sequence of a GG gridshell: from the deployed net to the collapsed one (paper 4.1).

The joint mesh of the net (joints, and the edges between consecutive joints of a lamella) is
moved from the deployed joints ``V*`` (``net.obj``) to the collapsed configuration ``A``
(``aligned.obj``, :func:`gridshell.gg.pipeline.collapse_gg`: every lamella on one straight
line, its arc lengths kept) through ``K - 1`` intermediate states, each one optimization:

* **lengths**: edge ``e`` has length ``L_e(t) = (1 - t) |V*_q - V*_p| + t |A_q - A_p|``, from
  its chord in the deployed state to the lamella arc length between its joints (the chord of a
  straightened lamella), through the registered term
  :func:`gridshell.gg.design.equal_lengths` with one fixed length per edge;
* **proximity** to the blend ``B(t) = (1 - t) V* + t A'`` with ``A'`` the collapsed line placed
  on the deployed net (its direction the best fit of the joints' positions along the line);
  the blend alone would shrink the edges across the line, the lengths push them back out;
* **fairness**: the graph Laplacian of the joints towards that of the blend, against the
  zig-zag folds that restore the lengths most cheaply otherwise.

Every state is computed in the frame of the deployed net; state ``t`` is then moved by the
rigid motion ``t``-way from the identity to the one that carries ``A'`` onto ``A`` (rotation
about one axis by ``t`` times its angle, translation by ``t`` times its vector), which keeps the
lengths. So the first state is ``V*`` and the last one ``A``, exactly. Scaled units inside
(unit bounding-box diagonal of ``V*``).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from gridshell.core.errors import InputError
from gridshell.solver import Layout, Problem, solve
from gridshell.solver import terms as T
from gridshell.gg.design import EdgeGroups, equal_lengths

__all__ = ["GG_SIM_WEIGHTS", "GGSequence", "gg_alignment_sequence", "line_frame",
           "edge_length_errors"]

#: most states of a sequence (each intermediate one is an optimization)
MAX_FRAMES = 1000

#: weights in scaled units (unit diagonal): lengths dominate, the blend steers, fairness smooths.
#: Measured on the demo dome (8 + 8 lamellae) and a helicoid net: the joints' second differences
#: along the lamellae decrease monotonically from the deployed to the collapsed state and every
#: edge stays within 0.25 % of its length ``L_e(t)``; with fairness 1e-4 the intermediate states
#: fold into a zig-zag (second differences up to 7 times the deployed ones).
GG_SIM_WEIGHTS = {"length": 1.0, "proximity": 1e-4, "fairness": 1e-2}

#: relative energy decrease per iteration below which a state's optimization ends
STATE_TOL = 1e-4


@dataclass
class GGSequence:
    """States of a GG alignment sequence.

    V : list of (n, 3) joints per state, metres; ``V[0]`` the deployed net, ``V[-1]`` the
        collapsed configuration as given
    t : (K+1,) blending parameter per state
    edges : (E, 2) the joint-mesh edges whose lengths are kept
    length_error : (K+1,) per state ``max_e |l_e - L_e(t)| / L_e(t)`` (dimensionless)
    history : per intermediate state ``{"frame", "t", "iterations", "energy", "message", "time"}``
    """

    V: list[np.ndarray]
    t: np.ndarray
    edges: np.ndarray
    length_error: np.ndarray
    history: list[dict] = field(default_factory=list)


def edge_length_errors(V: np.ndarray, edges: np.ndarray, L: np.ndarray) -> np.ndarray:
    """``| |V_q - V_p| - L | / L`` per edge ``(p, q)`` (dimensionless; NaN where ``L = 0``)."""
    E = np.asarray(edges, np.int64).reshape(-1, 2)
    ell = np.linalg.norm(np.asarray(V, float)[E[:, 1]] - np.asarray(V, float)[E[:, 0]], axis=1)
    L = np.asarray(L, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(L > 0, np.abs(ell - L) / L, np.nan)


def line_frame(V: np.ndarray, A: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Place a collapsed configuration ``A (n, 3)`` (points on one line) on a deployed one.

    With ``a_k`` the position of joint ``k`` along the line (about its mean), the placed line
    runs through the centroid ``c`` of ``V`` in the direction ``e ~ sum_k a_k (V_k - c)``: the
    least-squares fit of ``V`` by ``c + a_k e`` over unit ``e``.

    Returns
    -------
    placed : (n, 3) float
        ``c + a_k e``, metres.
    e : (3,) float
        Unit direction of the placed line.
    axis : (3,) float
        Unit direction of the line of ``A`` with ``A_k = mean(A) + a_k axis``.
    """
    V, A = np.asarray(V, float), np.asarray(A, float)
    d = A - A.mean(axis=0)
    u, sv, _ = np.linalg.svd(d, full_matrices=False)
    if not sv[0] > 0:
        raise InputError("the collapsed configuration is a single point; nothing to align")
    axis = _unit(d.T @ u[:, 0])                        # direction of the line of A
    a = d @ axis
    e = (V - V.mean(axis=0)).T @ a
    if not np.linalg.norm(e) > 0:
        e = np.eye(3)[int(np.argmin(np.abs(axis)))]
    e = _unit(e)
    return V.mean(axis=0) + a[:, None] * e[None, :], e, axis


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def _rotation(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, float]:
    """Axis ``k`` and angle ``theta`` of the smallest rotation carrying unit ``a`` onto ``b``."""
    k = np.cross(a, b)
    s, c = np.linalg.norm(k), float(np.clip(a @ b, -1.0, 1.0))
    if s < 1e-12:
        if c > 0:
            return np.array([0.0, 0.0, 1.0]), 0.0
        k = np.cross(a, np.eye(3)[int(np.argmin(np.abs(a)))])   # half turn about any normal
        return _unit(k), np.pi
    return k / s, float(np.arctan2(s, c))


def _rotate(X: np.ndarray, k: np.ndarray, theta: float) -> np.ndarray:
    """Rodrigues: rotate rows of ``X`` about unit axis ``k`` by ``theta`` radians."""
    c, s = np.cos(theta), np.sin(theta)
    return X * c + np.cross(k, X) * s + np.outer(X @ k, k) * (1 - c)


def gg_alignment_sequence(V_star: np.ndarray, aligned: np.ndarray, edges: np.ndarray, *,
                          frames: int = 12, weights: dict[str, float] | None = None,
                          max_iter: int = 50,
                          progress: Callable[[str], None] | None = None) -> GGSequence:
    """Alignment sequence of a GG net from its deployed joints to its collapsed configuration.

    Parameters
    ----------
    V_star : (n, 3) float
        Deployed joints (``net.joints``), metres.
    aligned : (n, 3) float
        Collapsed joints on one line (:func:`gridshell.gg.pipeline.collapse_gg`), metres.
    edges : (E, 2) int
        Joint-mesh edges, consecutive joints of a lamella (``net.edges()``).
    frames : int
        Number of steps ``K`` (``K + 1`` states including both ends).
    weights : dict, optional
        Overrides of :data:`GG_SIM_WEIGHTS`.
    max_iter : int
        Levenberg-Marquardt iterations per intermediate state.
    progress : callable, optional
        Receives one line per state.

    Returns
    -------
    GGSequence
    """
    w, Vs, A, E, L0, L1 = _checked_inputs(V_star, aligned, edges, frames, weights)
    placed, e, axis = line_frame(Vs, A)
    rigid = _rigid_motion(placed, e, axis, A)
    c = placed.mean(axis=0)
    scale = float(np.linalg.norm(Vs.max(0) - Vs.min(0))) or 1.0
    Xs, Xa = (Vs - c) / scale, (placed - c) / scale
    lay, prob, Lap = _state_problem(Xs, E, w)
    fixed = lay.mask(["L"])
    ts = np.linspace(0.0, 1.0, int(frames) + 1)
    out, errs, history = [Vs.copy()], [0.0], []
    x = lay.pack({"V": Xs, "L": L0 / scale})
    t0 = time.perf_counter()
    for f, t in enumerate(ts[1:-1], start=1):
        Lt = (1 - t) * L0 + t * L1
        x, sol = _solve_state(lay, prob, Lap, x, (Xs, Xa), (ts[f - 1], t),
                              Lt / scale, fixed, max_iter)
        V = rigid(lay.view(x, "V") * scale + c, t)
        out.append(V)
        errs.append(float(np.nanmax(edge_length_errors(V, E, Lt))))
        history.append({"frame": f, "t": float(t), "iterations": sol.iterations,
                        "energy": sol.energy, "message": sol.message,
                        "time": time.perf_counter() - t0})
        if progress is not None:
            progress(f"GG alignment state {f}/{frames}: edge lengths within "
                     f"{100 * errs[-1]:.2g} % ({sol.iterations} iterations)")
    out.append(A.copy())
    errs.append(float(np.nanmax(edge_length_errors(A, E, L1))))
    return GGSequence(V=out, t=ts, edges=E, length_error=np.asarray(errs), history=history)


def _checked_inputs(V_star, aligned, edges, frames, weights):
    """The weights (defaults overridden), deployed and collapsed joints, edges and the edge
    lengths ``L0`` (deployed chords) and ``L1`` (collapsed) of a sequence; InputError naming
    the problem otherwise."""
    w = dict(GG_SIM_WEIGHTS)
    for key, val in (weights or {}).items():
        if key not in w:
            raise InputError(f"unknown simulation weight {key!r}; weights are {', '.join(w)}")
        w[key] = float(val)
    if not 1 <= int(frames) <= MAX_FRAMES:
        raise InputError(f"frames must be in 1 .. {MAX_FRAMES} (each state is an "
                         f"optimization), got {frames}; e.g. 12")
    Vs = np.asarray(V_star, float)
    A = np.asarray(aligned, float)
    if Vs.ndim != 2 or Vs.shape[1] != 3 or Vs.shape != A.shape:
        raise InputError(f"V_star {Vs.shape} and aligned {A.shape} must both have shape (n, 3)")
    E = np.asarray(edges, np.int64).reshape(-1, 2)
    if not len(E):
        raise InputError("the net has no edges between joints; nothing to align")
    L0 = np.linalg.norm(Vs[E[:, 1]] - Vs[E[:, 0]], axis=1)
    L1 = np.linalg.norm(A[E[:, 1]] - A[E[:, 0]], axis=1)
    if np.any(L0 <= 0) or np.any(L1 <= 0):
        raise InputError("the net has joints at one place (zero-length edges); remove "
                         "duplicate joints before simulating the alignment")
    return w, Vs, A, E, L0, L1


def _rigid_motion(placed: np.ndarray, e: np.ndarray, axis: np.ndarray, A: np.ndarray):
    """``rigid(X, t)``: the motion ``t``-way from the identity to the one carrying the placed
    line (direction ``e``) onto the given one ``A`` (direction ``axis``): rotation about the
    centroid by ``t`` times its angle, translation by ``t`` times its vector (metres)."""
    k_rot, theta = _rotation(e, axis)
    c = placed.mean(axis=0)
    shift = A.mean(axis=0) - c

    def rigid(X: np.ndarray, t: float) -> np.ndarray:
        return _rotate(X - c, k_rot, t * theta) + c + t * shift
    return rigid


def _state_problem(Xs: np.ndarray, E: np.ndarray, w: dict[str, float]):
    """Layout, problem (lengths, proximity, fairness) and graph Laplacian of one state
    (scaled units)."""
    n = len(Xs)
    lay = Layout([("V", (n, 3)), ("L", (len(E),))])
    groups = EdgeGroups("V", "L", E[:, 0], E[:, 1], np.arange(len(E)))
    prob = Problem(lay)
    prob.add("lengths", w["length"], equal_lengths, groups)
    prob.add("proximity", w["proximity"], T.closeness, T.Closeness("V", Xs))
    Lap = T.laplacian_matrix(n, E)
    prob.add("fairness", w["fairness"], T.linear, T.Linear("V", Lap))
    return lay, prob, Lap


def _solve_state(lay, prob, Lap, x, ends, ts, L_scaled, fixed, max_iter):
    """One intermediate state at ``t = ts[1]`` from the previous one (at ``ts[0]``), warm
    started by the blend's increment; returns the new vector and the solver's result."""
    (Xs, Xa), (t_prev, t) = ends, ts
    B = (1 - t) * Xs + t * Xa
    step = B - ((1 - t_prev) * Xs + t_prev * Xa)
    x = lay.pack({"V": lay.view(x, "V").copy() + step, "L": L_scaled})
    prob.set_data("proximity", T.Closeness("V", B))
    # the Laplacian of the blend is kept: fairness pulls towards its shape, not flat
    prob.set_data("fairness", T.Linear("V", Lap, Lap @ B))
    # a state is a compromise (lengths against the blend): it ends when an iteration
    # lowers the energy by less than 1e-4 (a 18-lamella dome: the same edge-length errors
    # within 0.003 % of a length, 4 s instead of 13 s)
    sol = solve(prob, x, fixed=fixed, method="lm", max_iter=int(max_iter), tol_rel=STATE_TOL)
    return sol.x, sol
