"""Alignment simulation of an NCP gridshell: from the deployed to the collapsed state (paper 4.2.4).

Variables: deployed joints ``V (n, 3)`` and rotation axes ``r (n, 3)``. The post-optimized
mesh ``V*, r*`` is the reference: it takes the place of the aligned configuration in the
constraints of :mod:`gridshell.ncp.postopt` (edge lengths ``chi_l``, common rotation axes
``chi_r``, unit axes ``chi_u``), entering the layout as fixed blocks. The collapse direction
``d`` is the average of the vectors from the first to the last sample of every u-row of the
surface (all points of a row collapse onto one point); collapsing energies pull the joints onto
the plane through the centroid of ``V*`` with normal ``d`` (``<V_j - c, d>``) and the axes into
that plane (``<r_j, d>``).

Intermediate states blend the weights: frame ``t = k / K`` weights the collapsing energies by
``t``. The paper's proximity to ``V*`` (weight ``1 - t``) is used when no aligned configuration
is given. With the aligned configuration ``A`` of the post-optimization (placed in the plane,
:func:`embed_aligned`), frame ``t`` starts from and stays near the blend ``(1 - t) V* + t A``
instead: the joint mesh is generically over-constrained (7 conditions per interior joint for 6
unknowns), so the constraints cannot hold exactly between the two end states, and the blend
keeps the sequence out of the folded minima the plain homotopy falls into on a pseudosphere
(edges shrinking by up to 99 %). The last frame (``t = 1``, no proximity) is exact up to the
solver tolerance. Laplacian fairness of ``V`` and ``r`` (off by default, and always in the
last frame); scaled units (unit bounding-box diagonal of ``V*``) as in the post-optimization,
with the length and axis constraints weighted by the net's density
(:func:`~gridshell.ncp.postopt.net_density`).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from gridshell.geometry.bspline import BSplineSurface
from gridshell.core.errors import InputError
from gridshell.solver import Layout, Problem, solve
from gridshell.solver import terms as T
from gridshell.ncp.postopt import (EDGE_REF, AxisPairs, EdgeLength, UnitNorm, edge_length_eq,
                      interior_vertices,
                      net_density, rotation_axis_eq, still_joints, unit_norm_eq,
                      vertex_pairs)

__all__ = ["SIM_WEIGHTS", "collapse_direction", "AlignmentSequence", "simulate_alignment",
           "plane_frame", "embed_aligned"]

#: Stopping rules of the frames (measured on the pseudosphere patch of benchmarks/run_all.py,
#: benchmarks/README.md). An intermediate frame is a blend the over-constrained joint mesh can
#: only approximate: its iterations crawl along a soft valley (40 iterations at 1e-10 moved
#: the energy by a further 10 %), so it ends at a relative energy decrease of
#: ``FRAME_TOL_REL`` per step, warm-started from the previous frame's state moved on by the
#: blend's increment (``WARM_START``): fewer iterations and a smaller edge-length error in
#: every state than from the blend itself. The last frame starts exact (the post-optimization's
#: aligned state) and ends once a step moves no joint by more than ``LAST_STILL`` mean edge
#: lengths. Each frame's Levenberg-Marquardt damping starts where the previous frame's ended
#: (``WARM_DAMPING``; the first frame at ``FRAME_DAMPING``, relative to the mean diagonal of
#: ``J^T J``): from 1e-3 every frame spent its first 5-7 iterations only lowering the damping
#: to the ~1e-7 it ends at (40 curves: 221 -> 115 iterations, same energies).
WARM_START = True
FRAME_TOL_REL = 1e-3
LAST_STILL = 1e-6
FRAME_DAMPING = 1e-3
WARM_DAMPING = True


#: Most frames of an alignment sequence (each frame is one optimization).
MAX_FRAMES = 1000

#: constraint weights as in the post-optimization (Table 2); collapse and proximity are blended
#: (scaled units, unit diagonal; measured on a pseudosphere patch: these keep Delta_l < 1.1 % in
#: every intermediate frame while the distance to the plane decreases monotonically). The
#: Laplacian fairness is off by default: since the frames stay near the blend of the two end
#: states (proximity, 10x its weight) it changed no figure beyond the frames' own scatter, and
#: its ``L^T L`` couples 2-rings, which tripled the Cholesky factor (40 curves: nnz(L) 0.30M
#: -> 1.0M, 65 of the 90 ms of an iteration); ``weights={"fairness": 1e-5}`` brings it back.
SIM_WEIGHTS = {"length": 1.0, "axis": 1e2, "unit": 1e2, "collapse": 1e-4, "proximity": 1e-4,
               "fairness": 0.0}


def collapse_direction(surf: BSplineSurface, rows: int = 48) -> np.ndarray:
    """Unit collapse direction ``d (3,)``: the mean of ``S(u_i, v_last) - S(u_i, v_first)``
    over ``rows`` u-rows (paper 4.2.4)."""
    (u0, u1), (v0, v1) = surf.domain
    P = surf.evaluate_grid(np.linspace(u0, u1, int(rows)), np.array([v0, v1]))
    d = (P[:, 1] - P[:, 0]).mean(axis=0)
    nd = np.linalg.norm(d)
    if not nd > 0:
        raise InputError("the u-rows of the surface have no mean direction (closed rows?); "
                         "the collapse direction is undefined")
    return d / nd


def plane_frame(d: np.ndarray, hint: np.ndarray | None = None) -> np.ndarray:
    """Orthonormal ``(2, 3)`` basis of the plane with normal ``d`` (first axis along the
    projection of ``hint`` when given)."""
    d = np.asarray(d, float) / np.linalg.norm(d)
    h = np.asarray(hint, float) if hint is not None else np.eye(3)[int(np.argmin(np.abs(d)))]
    a = h - (h @ d) * d
    if np.linalg.norm(a) < 1e-9:
        a = np.eye(3)[int(np.argmin(np.abs(d)))]
        a = a - (a @ d) * d
    a /= np.linalg.norm(a)
    return np.stack([a, np.cross(d, a)])


@dataclass
class AlignmentSequence:
    """Frames of the deployment sequence (metres).

    V : list of (n, 3) joints per frame, ``V[0]`` the post-optimized mesh, ``V[-1]`` aligned
    r : list of (n, 3) unit rotation axes per frame
    t : (K+1,) blending parameter per frame
    direction : (3,) collapse direction ``d``; centroid : (3,) a point of the collapse plane
    plane_distance : max distance of the last frame's joints from the plane before the final
        projection onto it, metres
    history : per frame ``{"frame", "t", "iterations", "energy", "message", "time"}``
    """

    V: list[np.ndarray]
    r: list[np.ndarray]
    t: np.ndarray
    direction: np.ndarray
    centroid: np.ndarray
    plane_distance: float
    history: list[dict] = field(default_factory=list)

    @property
    def aligned(self) -> np.ndarray:
        return self.V[-1]

    @property
    def aligned_r(self) -> np.ndarray:
        return self.r[-1]


def embed_aligned(V_star: np.ndarray, r_star: np.ndarray, Vt: np.ndarray, rt: np.ndarray,
                  direction: np.ndarray, centroid: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Place the aligned configuration ``Vt, rt (n, 2)`` of the post-optimization in the
    collapse plane (normal ``direction`` through ``centroid``): the orthogonal map (rotation or
    reflection, which keep ``chi_l`` and ``chi_r``) and translation of the plane that best match
    the projection of ``V*`` and of ``r*`` (Procrustes). Returns 3D joints and axes ``(n, 3)``."""
    B = plane_frame(direction)
    P = np.asarray(V_star, float) - centroid
    scale = float(np.linalg.norm(P.max(0) - P.min(0))) or 1.0
    X = np.vstack([np.asarray(Vt, float) - np.mean(Vt, axis=0), scale * np.asarray(rt, float)])
    Y = np.vstack([P @ B.T - (P @ B.T).mean(axis=0), scale * (np.asarray(r_star, float) @ B.T)])
    U, _, Wt = np.linalg.svd(X.T @ Y)
    Q = U @ Wt                                     # X Q ~ Y
    A2 = (np.asarray(Vt, float) - np.mean(Vt, axis=0)) @ Q + (P @ B.T).mean(axis=0)
    R2 = np.asarray(rt, float) @ Q
    return centroid + A2 @ B, R2 @ B


def simulate_alignment(V_star: np.ndarray, r_star: np.ndarray, edges: np.ndarray,
                       direction: np.ndarray, *, aligned: tuple[np.ndarray, np.ndarray] | None
                       = None, frames: int = 12,
                       weights: dict[str, float] | None = None, max_iter: int = 40,
                       project: bool = True, progress: Callable[[str], None] | None = None
                       ) -> AlignmentSequence:
    """Simulate the alignment sequence from ``V*, r*`` to the collapsed state (paper 4.2.4).

    Parameters
    ----------
    V_star, r_star : (n, 3) post-optimized joints (metres) and unit rotation axes
    edges : (E, 2) joint-mesh edges
    direction : (3,) collapse direction (:func:`collapse_direction`)
    aligned : ``(Vt, rt)`` (n, 2) aligned configuration of the post-optimization; when given,
        it is placed in the collapse plane (:func:`embed_aligned`) and frame ``t`` starts from
        the blend ``(1 - t) V* + t A`` (axes likewise) instead of the previous frame, which
        keeps the homotopy out of the folded local minima of the collapsing energy
    frames : number of steps ``K`` (``K + 1`` states including the initial one)
    weights : overrides of :data:`SIM_WEIGHTS` (length and axis weights at the mean edge
        length :data:`~gridshell.ncp.postopt.EDGE_REF`, scaled to the net's own)
    max_iter : Levenberg-Marquardt iterations per frame
    project : put the last frame's joints exactly on the plane and its axes exactly in it
    """
    w = _checked_weights(weights, frames)
    Vs = np.asarray(V_star, float)
    rs = np.asarray(r_star, float)
    d = np.asarray(direction, float) / np.linalg.norm(direction)
    c = Vs.mean(axis=0)
    scale = float(np.linalg.norm(Vs.max(0) - Vs.min(0)))
    Xs = (Vs - c) / scale
    lay, prob, edge = _frame_problem(Xs, rs, np.asarray(edges, np.int64).reshape(-1, 2), d, w)
    x = lay.pack({"V": Xs, "r": rs, "Vt": Xs, "rt": rs})
    fixed = lay.mask(["Vt", "rt"])
    ts = np.linspace(0.0, 1.0, int(frames) + 1)
    Vout, rout, history = [Vs.copy()], [rs / np.linalg.norm(rs, axis=1)[:, None]], []
    ends = None
    if aligned is not None:
        A, RA = embed_aligned(Vs, rs, aligned[0], aligned[1], d, c)
        ends = (Xs, rs, (A - c) / scale, RA)
    t0 = time.perf_counter()
    prev = (Xs, rs)                           # the blend of the previous frame
    lam = FRAME_DAMPING
    for f, t in enumerate(ts[1:], start=1):
        if ends is not None:
            x, prev = _blend_start(lay, prob, x, ends, prev, f, t)
        _frame_weights(prob, w, t, ends is not None)
        sol = solve(prob, x, fixed=fixed, method="lm", max_iter=int(max_iter), damping=lam,
                    tol_rel=FRAME_TOL_REL if t < 1 else 1e-10,
                    stop=None if t < 1 else still_joints(lay, x, ("V",), LAST_STILL * edge))
        x = sol.x
        if WARM_DAMPING and sol.history:
            lam = min(max(sol.history[-1]["lambda"], 1e-9), FRAME_DAMPING)
        history.append({"frame": f, "t": float(t), "iterations": sol.iterations,
                        "energy": sol.energy, "message": sol.message,
                        "time": time.perf_counter() - t0})
        if progress is not None:
            progress(f"alignment frame {f}/{frames}: energy {sol.energy:.3e} "
                     f"({sol.iterations} iterations)")
        r = lay.view(x, "r").copy()
        Vout.append(lay.view(x, "V") * scale + c)
        rout.append(r / np.linalg.norm(r, axis=1)[:, None])
    plane_distance = _onto_plane(Vout, rout, d, c, project)
    return AlignmentSequence(V=Vout, r=rout, t=ts, direction=d, centroid=c,
                             plane_distance=plane_distance, history=history)


def _checked_weights(weights: dict[str, float] | None, frames: int) -> dict[str, float]:
    """:data:`SIM_WEIGHTS` with the caller's overrides; InputError for an unknown weight or
    a number of frames out of range."""
    w = dict(SIM_WEIGHTS)
    for key, val in (weights or {}).items():
        if key not in w:
            raise InputError(f"unknown simulation weight {key!r}; weights are {', '.join(w)}")
        w[key] = float(val)
    if int(frames) < 1:
        raise InputError(f"frames must be >= 1, got {frames}")
    if int(frames) > MAX_FRAMES:
        raise InputError(f"{frames} frames are more than the {MAX_FRAMES} supported (each is an "
                         "optimization); ask for fewer, e.g. 12")
    return w


def _frame_problem(Xs: np.ndarray, rs: np.ndarray, E: np.ndarray, d: np.ndarray,
                   w: dict[str, float]):
    """Layout and problem of one frame (scaled joints ``Xs``, axes ``rs``, collapse direction
    ``d``) and the mean edge length in scaled units."""
    from gridshell.solver.terms import laplacian_matrix

    n = len(Xs)
    j, k = vertex_pairs(E)
    lay = Layout([("V", (n, 3)), ("r", (n, 3)), ("Vt", (n, 3)), ("rt", (n, 3))])
    inner = interior_vertices(n, E)
    Lap = laplacian_matrix(n, E, fixed_rows=np.setdiff1d(np.arange(n), inner))
    D = np.tile(d, (n, 1))
    density = net_density(Xs, E)  # constraints weighted as in the post-optimization
    prob = Problem(lay)
    prob.add("length (chi_l)", w["length"] * density ** 4, edge_length_eq,
             EdgeLength(E, "V", "Vt"))
    prob.add("axis (chi_r)", w["axis"] * density ** 2, rotation_axis_eq,
             AxisPairs(j, k, "V", "r", "Vt", "rt"))
    prob.add("unit (chi_u)", w["unit"], unit_norm_eq, UnitNorm("r"))
    prob.add("collapse points", 0.0, T.gliding, T.Gliding("V", np.zeros((n, 3)), D))
    prob.add("collapse axes", 0.0, T.gliding, T.Gliding("r", np.zeros((n, 3)), D))
    prob.add("proximity points", w["proximity"], T.closeness, T.Closeness("V", Xs))
    prob.add("proximity axes", w["proximity"], T.closeness, T.Closeness("r", rs))
    prob.add("fairness points", w["fairness"], T.linear, T.Linear("V", Lap))
    prob.add("fairness axes", w["fairness"], T.linear, T.Linear("r", Lap))
    return lay, prob, EDGE_REF / density


def _blend_start(lay, prob, x, ends, prev, f: int, t: float):
    """Start of frame ``f`` at ``t`` from the blend of the deployed and the placed aligned
    state ``ends = (Xs, rs, A, RA)``: the blend, or (warm start) the previous frame's state
    moved on by the blend's increment; the proximity targets become the blend. Returns the
    start vector and the blend."""
    Xs, rs, A, RA = ends
    rb = (1 - t) * rs + t * RA
    rb /= np.maximum(np.linalg.norm(rb, axis=1), 1e-12)[:, None]
    Vb = (1 - t) * Xs + t * A
    if WARM_START and f > 1 and t < 1:
        # warm start: keeps the corrections the previous frame's iterations found
        Vw = lay.view(x, "V") + (Vb - prev[0])
        rw = lay.view(x, "r") + (rb - prev[1])
        rw /= np.maximum(np.linalg.norm(rw, axis=1), 1e-12)[:, None]
    else:
        Vw, rw = Vb, rb
    prob.set_data("proximity points", T.Closeness("V", Vb))
    prob.set_data("proximity axes", T.Closeness("r", rb))
    return lay.pack({"V": Vw, "r": rw, "Vt": Xs, "rt": rs}), (Vb, rb)


def _frame_weights(prob, w: dict[str, float], t: float, blended: bool) -> None:
    """The weights of frame ``t``: collapse ``t`` times its weight; proximity off in the last
    frame of a blended sequence, else fading as ``1 - t``; fairness off in the last frame."""
    for name in ("collapse points", "collapse axes"):
        prob.set_weight(name, t * w["collapse"])
    for name in ("proximity points", "proximity axes"):
        prob.set_weight(name, (0.0 if t >= 1 else 1.0) * w["proximity"] if blended
                        else (1.0 - t) * w["proximity"])
    for name in ("fairness points", "fairness axes"):   # the aligned state is exact
        prob.set_weight(name, 0.0 if t >= 1 else w["fairness"])


def _onto_plane(Vout: list, rout: list, d: np.ndarray, c: np.ndarray, project: bool) -> float:
    """Largest distance (metres) of the last frame's joints from the collapse plane; with
    ``project``, its joints put on the plane and its axes in it (in place)."""
    off = (Vout[-1] - c) @ d
    if project:
        Vout[-1] = Vout[-1] - off[:, None] * d[None, :]
        r = rout[-1] - (rout[-1] @ d)[:, None] * d[None, :]
        rout[-1] = r / np.linalg.norm(r, axis=1)[:, None]
    return float(np.max(np.abs(off)))
