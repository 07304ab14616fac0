"""Post-optimization of the NCP joint mesh (paper 4.2.4).

The joint mesh has the joints ``V_j`` as vertices and the lamella pieces between consecutive
joints as edges. Variables (one :class:`~gridshell.solver.Layout`): ``V (n, 3)`` deployed
joints, ``r (n, 3)`` their rotation axes, ``Vt (n, 2)`` the joints on the collapse curve,
``rt (n, 2)`` the axes there. Terms (weights :data:`DEFAULT_WEIGHTS`, paper Table 2):

- ``chi_l = |V_k - V_j|^2 - |Vt_k - Vt_j|^2`` per edge (:func:`edge_length_eq`),
- ``chi_r = <V_k - V_j, r_j> - <Vt_k - Vt_j, rt_j>`` per vertex and neighbour
  (:func:`rotation_axis_eq`): edges rotate about a common axis at each joint,
- ``chi_u = |r_j|^2 - 1``, ``chi_u~ = |rt_j|^2 - 1`` (:func:`unit_norm_eq`),
- ``E_c``: ``V`` near its initial position; ``E_g``: ``V`` on the tangent plane at its closest
  point of the B-spline surface; ``E_c~``, ``E_g~``: ``Vt`` near / on the tangent of the closest
  point of the collapse polyline; ``E_s = (<r_j, n_c> - 1)^2``, ``E_s~ = (<rt_j, n~_c> - 1)^2``;
  Laplacian fairness of ``V`` (interior joints).

The optimization runs on geometry scaled to a unit bounding-box diagonal of the surface, so the
weights mean the same on any model, and the length and axis constraints are weighted by the
net's density (:data:`EDGE_REF`), so they mean the same at any number of curves; results are
returned in metres. The same three constraint
terms drive the alignment simulation (:mod:`gridshell.ncp.alignment`), with the reference
configuration as fixed blocks.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any, Callable, NamedTuple

import numpy as np

from gridshell.geometry.bspline import BSplineSurface
from gridshell.core.errors import InputError
from gridshell.geometry.net import Net
from gridshell.solver import Layout, Problem, TermResult, result, solve, term
from gridshell.solver import terms as T
from gridshell.ncp.collapse import CollapseResult, closest_on_polyline

__all__ = ["DEFAULT_WEIGHTS", "EDGE_REF", "CONSTRAINT_TOL", "net_density", "constraint_errors",
           "EdgeLength", "edge_length_eq", "AxisPairs", "rotation_axis_eq", "UnitNorm",
           "unit_norm_eq", "surface_closest", "vertex_pairs", "PostOptResult", "post_optimize"]

#: mean joint-to-joint edge length, in units of the model's diagonal, at which the length and
#: axis weights hold (10 curves per family on the pseudosphere patch of the tests). ``chi_l``
#: scales like an edge length squared and ``chi_r`` like an edge length, so at a mean edge
#: length ``l`` they are weighted ``(EDGE_REF / l)^4`` and ``(EDGE_REF / l)^2`` times more
#: (:func:`net_density`). A relative length or axis error then costs the same against the
#: per-joint soft terms at any number of curves.
EDGE_REF = 0.09


def net_density(V: np.ndarray, edges: np.ndarray) -> float:
    """``EDGE_REF / l`` for the mean edge length ``l`` of joints ``V (n, 3)`` (scaled units)."""
    E = np.asarray(edges, np.int64).reshape(-1, 2)
    ell = float(np.mean(np.linalg.norm(V[E[:, 1]] - V[E[:, 0]], axis=1))) if len(E) else 0.0
    if not ell > 0:
        raise InputError("the joint mesh has no edge of positive length; check the joints")
    return EDGE_REF / ell


#: relative constraint error below which the post-optimization counts as converged even if
#: the solver still creeps along the soft terms (:func:`constraint_errors`)
CONSTRAINT_TOL = 1e-6


def constraint_errors(report: dict, ell: float) -> dict[str, float]:
    """Largest constraint residuals of a solver report, relative: ``|chi_l| / l^2`` (twice the
    relative length error), ``|chi_r| / l``, ``|chi_u|``; ``l`` the mean edge length (scaled
    units)."""
    out = {}
    for name, power in (("length (chi_l)", 2), ("axis (chi_r)", 1), ("unit (chi_u)", 0),
                        ("unit aligned (chi_u~)", 0)):
        if name in report:
            out[name] = float(report[name]["max"]) / ell ** power
    return out


#: Stopping rule of the rounds (measured in benchmarks/README.md): a round ends once a step
#: moves no joint (deployed or aligned) by more than ``ROUND_STILL`` mean edge lengths (the
#: iterations then creep along the soft terms while the constraint errors stay where they
#: are). The polish runs to the solver's tolerance: stopping it once the constraints held to
#: CONSTRAINT_TOL left Delta_n at 3.1 % on a 20-curve pseudosphere net (0.008 % in full).
ROUND_STILL = 1e-4


def still_joints(lay: Layout, x0: np.ndarray, blocks: tuple[str, ...], tol: float
                 ) -> Callable[[np.ndarray], bool]:
    """A stop test for :func:`~gridshell.solver.solve`: true once a step moves no row (joint)
    of the ``blocks`` by more than ``tol`` (the layout's units) since the last call."""
    last = {b: lay.view(x0, b).copy() for b in blocks}

    def still(x: np.ndarray) -> bool:
        move = 0.0
        for b in blocks:
            X = lay.view(x, b)
            move = max(move, float(np.max(np.linalg.norm(X - last[b], axis=-1), initial=0.0)))
            last[b] = X.copy()
        return move <= tol
    return still


#: paper Table 2 (omega_c and omega_f at the upper end of their ranges)
DEFAULT_WEIGHTS = {"length": 1.0, "axis": 1e2, "unit": 1e2, "closeness": 1e-4, "gliding": 1e-5,
                   "closeness_aligned": 1e-1, "gliding_aligned": 1e-1, "normal": 1e-2,
                   "normal_aligned": 1e-1, "fairness": 1e-4}


# ============================================================================ terms

class EdgeLength(NamedTuple):
    """Data of :func:`edge_length_eq`: ``edges (E, 2)`` and the two vertex blocks."""

    edges: np.ndarray
    a: str = "V"
    b: str = "Vt"


@term
def edge_length_eq(x: np.ndarray, layout: Layout, data: EdgeLength) -> TermResult:
    """``chi_l = |A_k - A_j|^2 - |B_k - B_j|^2`` per edge ``(j, k)`` (paper 4.2.4); the blocks
    may differ in dimension (3D deployed, 2D aligned)."""
    E = np.asarray(data.edges, np.int64).reshape(-1, 2)
    j, k = E[:, 0], E[:, 1]
    rows, cols, vals = [], [], []
    r = np.zeros(len(E))
    for name, sign in ((data.a, 1.0), (data.b, -1.0)):
        X = layout.view(x, name)
        X = X.reshape(len(X), -1)
        idx = layout.indices(name).reshape(len(X), -1)
        d = X[k] - X[j]
        r += sign * np.einsum("ij,ij->i", d, d)
        dim = X.shape[1]
        rr = np.repeat(np.arange(len(E)), dim)
        rows += [rr, rr]
        cols += [idx[k].reshape(-1), idx[j].reshape(-1)]
        vals += [(2 * sign * d).reshape(-1), (-2 * sign * d).reshape(-1)]
    return result(r, np.concatenate(rows), np.concatenate(cols), np.concatenate(vals))


class AxisPairs(NamedTuple):
    """Data of :func:`rotation_axis_eq`: pairs ``(j, k)`` of a vertex and a neighbour, the
    deployed blocks ``V, r`` and the aligned blocks ``W, s``."""

    j: np.ndarray
    k: np.ndarray
    V: str = "V"
    r: str = "r"
    W: str = "Vt"
    s: str = "rt"


@term
def rotation_axis_eq(x: np.ndarray, layout: Layout, data: AxisPairs) -> TermResult:
    """``chi_r = <V_k - V_j, r_j> - <W_k - W_j, s_j>`` (paper 4.2.4): the offset of every edge
    along the rotation axis of its vertex is kept upon alignment."""
    j = np.asarray(data.j, np.int64)
    k = np.asarray(data.k, np.int64)
    m = len(j)
    r = np.zeros(m)
    rows, cols, vals = [], [], []
    for pb, ab, sign in ((data.V, data.r, 1.0), (data.W, data.s, -1.0)):
        P = layout.view(x, pb)
        P = P.reshape(len(P), -1)
        A = layout.view(x, ab)
        A = A.reshape(len(A), -1)
        ip = layout.indices(pb).reshape(len(P), -1)
        ia = layout.indices(ab).reshape(len(A), -1)
        d = P[k] - P[j]
        a = A[j]
        r += sign * np.einsum("ij,ij->i", d, a)
        dim = P.shape[1]
        rr = np.repeat(np.arange(m), dim)
        rows += [rr, rr, rr]
        cols += [ip[k].reshape(-1), ip[j].reshape(-1), ia[j].reshape(-1)]
        vals += [(sign * a).reshape(-1), (-sign * a).reshape(-1), (sign * d).reshape(-1)]
    return result(r, np.concatenate(rows), np.concatenate(cols), np.concatenate(vals))


class UnitNorm(NamedTuple):
    """Data of :func:`unit_norm_eq`: the block of vectors to normalize."""

    block: str


@term
def unit_norm_eq(x: np.ndarray, layout: Layout, data: UnitNorm) -> TermResult:
    """``chi_u = |r_j|^2 - 1`` per row of the block (paper 4.2.4)."""
    X = layout.view(x, data.block)
    X = X.reshape(len(X), -1)
    idx = layout.indices(data.block).reshape(len(X), -1)
    r = np.einsum("ij,ij->i", X, X) - 1.0
    rows = np.repeat(np.arange(len(X)), X.shape[1])
    return result(r, rows, idx.reshape(-1), (2 * X).reshape(-1))


# ============================================================================ helpers

def vertex_pairs(edges: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Both orientations ``(j, k)`` of every edge: each vertex with each of its neighbours."""
    E = np.asarray(edges, np.int64).reshape(-1, 2)
    return np.concatenate([E[:, 0], E[:, 1]]), np.concatenate([E[:, 1], E[:, 0]])


def surface_closest(surf: BSplineSurface, P: np.ndarray, uv0: np.ndarray,
                    steps: int = 6) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Closest points of the B-spline to ``P (k, 3)`` by Gauss-Newton in ``(u, v)`` from
    ``uv0 (k, 2)`` (clipped to the domain). Returns ``uv (k, 2)``, points and unit normals."""
    (u0, u1), (v0, v1) = surf.domain
    uv = np.array(uv0, float)
    for _ in range(steps):
        S = surf.evaluate(uv[:, 0], uv[:, 1])
        Su = surf.evaluate(uv[:, 0], uv[:, 1], 1, 0)
        Sv = surf.evaluate(uv[:, 0], uv[:, 1], 0, 1)
        d = P - S
        a, b, c = (np.einsum("ij,ij->i", x, y) for x, y in ((Su, Su), (Su, Sv), (Sv, Sv)))
        f, g = np.einsum("ij,ij->i", Su, d), np.einsum("ij,ij->i", Sv, d)
        det = a * c - b * b
        uv[:, 0] = np.clip(uv[:, 0] + (c * f - b * g) / det, u0, u1)
        uv[:, 1] = np.clip(uv[:, 1] + (a * g - b * f) / det, v0, v1)
    S = surf.evaluate(uv[:, 0], uv[:, 1])
    N = np.cross(surf.evaluate(uv[:, 0], uv[:, 1], 1, 0), surf.evaluate(uv[:, 0], uv[:, 1], 0, 1))
    return uv, S, N / np.linalg.norm(N, axis=1)[:, None]


def interior_vertices(n: int, edges: np.ndarray) -> np.ndarray:
    """Vertices with four neighbours (interior joints of a quad net)."""
    j, _ = vertex_pairs(edges)
    return np.flatnonzero(np.bincount(j, minlength=n) >= 4)


# ============================================================================ optimization

_WEIGHT_OF = {"closeness (E_c)": "closeness", "fairness": "fairness", "gliding (E_g)": "gliding",
              "closeness aligned (E_c~)": "closeness_aligned",
              "gliding aligned (E_g~)": "gliding_aligned", "normal (E_s)": "normal",
              "normal aligned (E_s~)": "normal_aligned"}

@dataclass
class PostOptResult:
    """Outcome of :func:`post_optimize` (metres).

    V (n, 3) joints, r (n, 3) unit rotation axes, Vt (n, 2) aligned joints, rt (n, 2) aligned
    axes, uv (n, 2) closest surface parameters of ``V``; V0, r0, Vt0, rt0 the initial values;
    history per round; report (per term, scaled units, final round); converged.
    """

    V: np.ndarray
    r: np.ndarray
    Vt: np.ndarray
    rt: np.ndarray
    uv: np.ndarray
    V0: np.ndarray
    r0: np.ndarray
    Vt0: np.ndarray
    rt0: np.ndarray
    history: list[dict] = field(default_factory=list)
    report: dict = field(default_factory=dict)
    converged: bool = False
    weights: dict = field(default_factory=dict)


def initial_configuration(surf: BSplineSurface, joint_uv: np.ndarray, collapse: CollapseResult
                          ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``V0, r0`` (joints and surface normals) and ``Vt0, rt0`` (the joints' ``u`` mapped onto
    the collapse polyline, barycentric between rows, and the flattened normal there)."""
    uv = np.asarray(joint_uv, float)
    V0 = surf.evaluate(uv[:, 0], uv[:, 1])
    N = np.cross(surf.evaluate(uv[:, 0], uv[:, 1], 1, 0), surf.evaluate(uv[:, 0], uv[:, 1], 0, 1))
    r0 = N / np.linalg.norm(N, axis=1)[:, None]
    Vt0, rt0 = collapse.at_u(uv[:, 0])
    return V0, r0, Vt0, rt0


def post_optimize(surf: BSplineSurface, net: Net, joint_uv: np.ndarray, collapse: CollapseResult,
                  *, weights: dict[str, float] | None = None, rounds: int = 3,
                  max_iter: int = 60, polish: float = 1e-3,
                  progress: Callable[[str], None] | None = None) -> PostOptResult:
    """Post-optimize the joint mesh of ``net`` towards exact alignability (paper 4.2.4).

    Parameters
    ----------
    surf : the PHLW surface; net : the traced net; joint_uv : (n, 2) parameters of its joints
    collapse : the collapse curve (:func:`gridshell.ncp.collapse.collapse_curve`)
    weights : overrides of :data:`DEFAULT_WEIGHTS` (length and axis weights at the mean edge
        length :data:`EDGE_REF`, scaled to the net's own)
    rounds : outer rounds (closest points on the surface and the collapse curve refreshed)
    max_iter : Levenberg-Marquardt iterations per round
    polish : if > 0, a last round with the soft terms (closeness, gliding, normals, fairness)
        weighted ``polish`` times lower, so that ``chi_l, chi_r, chi_u`` vanish to solver
        precision (``Delta_n`` divides by the normal offsets of the neighbours, which are
        tiny on asymptotic nets); 0 keeps the paper's weights throughout
    """
    w = _postopt_weights(weights)
    if int(rounds) < 0:
        raise InputError(f"post-optimization rounds must be >= 0, got {rounds}")
    V0, r0, Vt0, rt0 = initial_configuration(surf, joint_uv, collapse)
    n = len(V0)
    E = net.edges()
    if len(E) == 0:
        raise InputError("the net has no edges; trace more curves")
    centre, scale = _scaled_frame(surf)
    C2, N2 = collapse.points / scale, collapse.normals
    lay = Layout([("V", (n, 3)), ("r", (n, 3)), ("Vt", (n, 2)), ("rt", (n, 2))])
    x = lay.pack({"V": (V0 - centre) / scale, "r": r0, "Vt": Vt0 / scale, "rt": rt0})
    prob, ell = _fixed_terms(lay, x, E, w, (V0 - centre) / scale)
    uv = np.asarray(joint_uv, float).copy()
    history = []
    sol = None
    t0 = time.perf_counter()
    for rnd in range(int(rounds)):
        uv, terms = _round_terms(surf, lay, x, uv, centre, scale, C2, N2)
        for name, wk, fn, data in terms:
            if rnd == 0:
                prob.add(name, w[wk], fn, data)
            else:
                prob.set_data(name, data)
        sol = solve(prob, x, method="lm", max_iter=int(max_iter), tol_rel=1e-9,
                    stop=still_joints(lay, x, ("V", "Vt"), ROUND_STILL * ell))
        x = sol.x
        history.append(_round_record(rnd + 1, sol, t0))
        if progress is not None:
            progress(f"post-optimization round {rnd + 1}/{rounds}: energy {sol.energy0:.3e} -> "
                     f"{sol.energy:.3e} in {sol.iterations} iterations")
    if polish > 0:
        sol = _polish(prob, x, w, polish, int(max_iter))
        x = sol.x
        history.append(_round_record("polish", sol, t0))
    converged = bool(sol is not None and sol.converged)
    if sol is not None:
        # the constraints are what the post-optimization is for: when they hold to
        # CONSTRAINT_TOL after at least one round (which adds the terms keeping the joints on
        # the surface and the aligned joints on the collapse curve), a solver still creeping
        # along the soft terms has done its job
        rel = constraint_errors(sol.report, ell)
        history[-1]["constraints_rel_max"] = rel
        converged = converged or (int(rounds) >= 1 and max(rel.values()) <= CONSTRAINT_TOL)
    V = lay.view(x, "V") * scale + centre
    uv, _, _ = surface_closest(surf, V, uv)
    r = lay.view(x, "r").copy()
    rt = lay.view(x, "rt").copy()
    return PostOptResult(V=V, r=r / np.linalg.norm(r, axis=1)[:, None],
                         Vt=lay.view(x, "Vt") * scale, rt=rt / np.linalg.norm(rt, axis=1)[:, None],
                         uv=uv, V0=V0, r0=r0, Vt0=Vt0, rt0=rt0, history=history,
                         report=sol.report if sol is not None else {},
                         converged=converged, weights=w)


def _postopt_weights(weights: dict[str, float] | None) -> dict[str, float]:
    """:data:`DEFAULT_WEIGHTS` with the caller's overrides (unknown names refused)."""
    w = dict(DEFAULT_WEIGHTS)
    for key, val in (weights or {}).items():
        if key not in w:
            raise InputError(f"unknown post-optimization weight {key!r}; weights are "
                             f"{', '.join(w)}")
        w[key] = float(val)
    return w


def _scaled_frame(surf: BSplineSurface) -> tuple[np.ndarray, float]:
    """``(centre (3,), scale)`` of the scaled units: the centre and the bounding-box diagonal
    (m) of the surface sampled 30 x 30."""
    S_dense = surf.evaluate_grid(*[np.linspace(a, b, 30) for a, b in surf.domain]).reshape(-1, 3)
    centre = S_dense.mean(axis=0)
    return centre, float(np.linalg.norm(S_dense.max(0) - S_dense.min(0)))


def _fixed_terms(lay: Layout, x: np.ndarray, E: np.ndarray, w: dict[str, float],
                 V0s: np.ndarray) -> tuple[Problem, float]:
    """The problem with the terms whose data do not change between rounds (``chi_l``,
    ``chi_r`` weighted by the net's density, ``chi_u``, ``chi_u~``, closeness to the initial
    joints ``V0s`` and fairness of the interior joints, scaled units), and the mean edge
    length ``ell`` (scaled units)."""
    from gridshell.solver.terms import laplacian_matrix

    n = len(V0s)
    j, k = vertex_pairs(E)
    inner = interior_vertices(n, E)
    Lap = laplacian_matrix(n, E, fixed_rows=np.setdiff1d(np.arange(n), inner))
    density = net_density(lay.view(x, "V"), E)
    prob = Problem(lay)
    prob.add("length (chi_l)", w["length"] * density ** 4, edge_length_eq, EdgeLength(E))
    prob.add("axis (chi_r)", w["axis"] * density ** 2, rotation_axis_eq, AxisPairs(j, k))
    prob.add("unit (chi_u)", w["unit"], unit_norm_eq, UnitNorm("r"))
    prob.add("unit aligned (chi_u~)", w["unit"], unit_norm_eq, UnitNorm("rt"))
    prob.add("closeness (E_c)", w["closeness"], T.closeness, T.Closeness("V", V0s))
    prob.add("fairness", w["fairness"], T.linear, T.Linear("V", Lap))
    return prob, EDGE_REF / density          # mean edge length, scaled units


def _round_terms(surf: BSplineSurface, lay: Layout, x: np.ndarray, uv: np.ndarray,
                 centre: np.ndarray, scale: float, C2: np.ndarray, N2: np.ndarray
                 ) -> tuple[np.ndarray, list[tuple]]:
    """The closest points of the state ``x`` refreshed: the joints' parameters ``uv`` (from
    the last ones) and ``(name, weight key, term, data)`` of the gliding, aligned and normal
    terms on the surface and on the collapse polyline ``C2, N2`` (scaled units)."""
    V = lay.view(x, "V") * scale + centre
    uv, foot, nrm = surface_closest(surf, V, uv)
    Ct, Nt, _ = closest_on_polyline(lay.view(x, "Vt"), C2, N2)
    return uv, [
        ("gliding (E_g)", "gliding", T.gliding, T.Gliding("V", (foot - centre) / scale, nrm)),
        ("closeness aligned (E_c~)", "closeness_aligned", T.closeness, T.Closeness("Vt", Ct)),
        ("gliding aligned (E_g~)", "gliding_aligned", T.gliding, T.Gliding("Vt", Ct, Nt)),
        ("normal (E_s)", "normal", T.gliding, T.Gliding("r", nrm, nrm)),
        ("normal aligned (E_s~)", "normal_aligned", T.gliding, T.Gliding("rt", Nt, Nt))]


def _polish(prob: Problem, x: np.ndarray, w: dict[str, float], polish: float,
            max_iter: int) -> Any:
    """The finishing round: the soft terms scaled by ``polish`` so that the constraints hold
    to the solver's precision (the geometry moves by ~polish times the soft residuals)."""
    soft = [e.name for e in prob.entries if e.fn is not edge_length_eq
            and e.fn is not rotation_axis_eq and e.fn is not unit_norm_eq]
    for name in soft:
        prob.set_weight(name, w[_WEIGHT_OF[name]] * polish)
    return solve(prob, x, method="lm", max_iter=max_iter, tol_rel=1e-9)


def _round_record(rnd: int | str, sol: Any, t0: float) -> dict[str, Any]:
    """One line of the history: round, iterations, energies, message and time (s since ``t0``)."""
    return {"round": rnd, "iterations": sol.iterations, "energy0": sol.energy0,
            "energy": sol.energy, "message": sol.message, "time": time.perf_counter() - t0}
