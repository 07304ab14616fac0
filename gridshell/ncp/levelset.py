"""Tracing the NCP net as level sets of scalar B-splines (paper 4.2.2, eqs. 4.12-4.13).

For each family ``f`` (1 or 3) a scalar function ``xi_f(u, v)`` is a B-spline on the domain of
the surface, stored as the paper's ``F(u, v) = (u, v, xi)`` (a :class:`BSplineSurface` whose
first two coordinates reproduce ``u`` and ``v`` through Greville abscissae). It minimizes

    E_a + omega_f E_f = sum dxi(e_f)^2 + omega_f sum (dxi(e_f+1) - 1)^2

at the samples (eqs. 4.12, 4.13), so that its level sets follow ``e_f`` and are spaced by about
one metre of ``xi`` per metre across. Curves are level sets at uniformly subdivided values,
traced in ``(u, v)`` (marching squares on a dense grid, each vertex then projected onto the
exact level) and mapped to 3D; joints are the points where ``xi_1`` and ``xi_3`` both take
their levels (found on the traced curves, refined by Newton's method in ``(u, v)``).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, NamedTuple

import numpy as np
import scipy.sparse as sp

from gridshell.geometry.bspline import BSplineSurface, local_basis, paired_params, open_uniform_knots
from gridshell.core.errors import InputError, NoNetError
from gridshell.geometry.net import Lamella, Net
from gridshell.solver import Layout, TermResult, result, term
from gridshell.solver.linear import NotPositiveDefinite, shared_solver
from gridshell.solver.solve import lm_update
from gridshell.solver.threads import one_blas_thread
from gridshell.ncp.directions import NetDirections

__all__ = ["LEVELSET_DEFAULTS", "DirectionalDerivative", "directional_derivative", "LevelFit",
           "LevelOperators", "level_function", "level_operators", "fit_level_function",
           "level_values", "project_to_level", "trace_levels", "TracedNet", "trace_net", "trace",
           "evaluate_xi"]

#: paper 4.2.2: bi-degree 3, 12 x 12 control points, 48 x 48 samples. omega_f: the paper sets
#: 0.1; measured on the pseudosphere patch (10 curves) 0.1 leaves the level sets 0.44 degrees
#: (RMS) off the asymptotic directions, which shows as up to 4.6 % difference of the normal
#: curvatures of the two axes at a joint and Delta_a up to 1.7 %; 0.01 gives 0.06 degrees,
#: 0.6 % and 0.3 % with the same curve spacing (density within 1 %). Pass 0.1 for the paper.
LEVELSET_DEFAULTS = {"n_ctrl": (12, 12), "degree": (3, 3), "samples": (48, 48), "omega_f": 0.01,
                     "grid": (240, 240)}


# ============================================================================ the scalar B-spline

def _greville(knots: np.ndarray, degree: int, n: int) -> np.ndarray:
    return np.array([knots[i + 1:i + degree + 1].mean() for i in range(n)])


def level_function(surf: BSplineSurface, xi_ctrl: np.ndarray, n_ctrl: tuple[int, int],
                   degree: tuple[int, int]) -> BSplineSurface:
    """``F(u, v) = (u, v, xi)`` over the domain of ``surf`` with ``xi`` control values
    ``xi_ctrl (nu * nv,)``."""
    (u0, u1), (v0, v1) = surf.domain
    nu, nv = n_ctrl
    du, dv = degree
    ku = u0 + (u1 - u0) * open_uniform_knots(nu, du)
    kv = v0 + (v1 - v0) * open_uniform_knots(nv, dv)
    gu, gv = np.meshgrid(_greville(ku, du, nu), _greville(kv, dv, nv), indexing="ij")
    ctrl = np.stack([gu, gv, np.asarray(xi_ctrl, float).reshape(nu, nv)], axis=-1)
    return BSplineSurface(du, dv, ku, kv, ctrl)


def _patches(F: BSplineSurface, u: np.ndarray, v: np.ndarray, du: int, dv: int
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Local data of ``xi`` at paired parameters ``(k,)``: the ``xi`` control values of each
    parameter's span ``(k, d_u + 1, d_v + 1)``, the non-zero ``u`` basis values (or ``du``-th
    derivatives) ``(k, d_u + 1)``, those in ``v``, and the checked, clipped ``u, v``."""
    u, v = paired_params(F, u, v, du, dv, "xi")
    fu, bu = local_basis(F.knots_u, F.degree_u, u, int(du))
    fv, bv = local_basis(F.knots_v, F.degree_v, v, int(dv))
    iu = fu[:, None, None] + np.arange(bu.shape[1])[None, :, None]
    iv = fv[:, None, None] + np.arange(bv.shape[1])[None, None, :]
    return F.ctrl[..., 2][iu, iv], bu, bv, u, v


def evaluate_xi(F: BSplineSurface, u: np.ndarray, v: np.ndarray, du: int = 0,
                dv: int = 0) -> np.ndarray:
    """``xi`` (or a derivative, per parameter^(du+dv)) at paired parameters ``(k,)``.

    The same sums as ``F.operator(u, v, du, dv) @ xi`` (eq. 4.1), over each parameter's
    ``(d_u + 1) x (d_v + 1)`` non-zero basis products only, without building the operator."""
    C, bu, bv, _, _ = _patches(F, u, v, du, dv)
    return np.einsum("ka,ka->k", bu, np.einsum("kab,kb->ka", C, bv))


# ============================================================================ terms (4.12, 4.13)

class DirectionalDerivative(NamedTuple):
    """Data of :func:`directional_derivative`: ``r = a xi_u + b xi_v - target`` at ``k``
    samples; ``Du, Dv (k, nc)`` map the control values of block ``block`` to ``xi_u, xi_v``."""

    Du: sp.csr_matrix
    Dv: sp.csr_matrix
    a: np.ndarray
    b: np.ndarray
    target: np.ndarray
    block: str = "xi"


@term
def directional_derivative(x: np.ndarray, layout: Layout,
                           data: DirectionalDerivative) -> TermResult:
    """``r = dxi(e) - target = a xi_u + b xi_v - target``: eq. 4.12 (``e = e1``, target 0,
    ``a = cos b / |S_u|``, ``b = -sin b / |S_v|``) and eq. 4.13 (``e = e2``, target 1)."""
    xi = layout.view(x, data.block).reshape(-1)
    A = (sp.diags(data.a) @ data.Du + sp.diags(data.b) @ data.Dv).tocoo()
    r = A @ xi - data.target
    cols = layout.indices(data.block).reshape(-1)[A.col]
    return result(r, A.row, cols, A.data)


# ============================================================================ optimization

@dataclass
class LevelFit:
    """A fitted level function: ``F`` (``(u, v, xi)`` B-spline), the solver result and the
    alignment figures at the samples: ``align_rms`` = RMS of ``dxi(e_f) / |dxi|`` (the sine
    of the angle between level set and net direction), ``density`` = mean ``dxi(e_f+1)``."""

    family: int
    F: BSplineSurface
    converged: bool
    iterations: int
    report: dict
    align_rms: float
    density: float


class LevelOperators(NamedTuple):
    """The sample operators of a level-function fit, shared by both families: ``F0`` (the
    level function with ``xi = 0``), ``Du, Dv (k, nu * nv)`` mapping its control values to
    ``xi_u, xi_v`` at the ``k`` samples ``ok`` of ``dirs`` (``valid`` flattened), for
    ``n_ctrl`` control values of ``degree``."""

    F0: BSplineSurface
    Du: sp.csr_matrix
    Dv: sp.csr_matrix
    ok: np.ndarray
    n_ctrl: tuple[int, int]
    degree: tuple[int, int]


def level_operators(surf: BSplineSurface, dirs: NetDirections, n_ctrl: tuple[int, int] = (12, 12),
                    degree: tuple[int, int] = (3, 3)) -> LevelOperators:
    """:class:`LevelOperators` of the samples of ``dirs`` (one evaluation for both families)."""
    nu, nv = (int(k) for k in n_ctrl)
    deg = tuple(int(d) for d in degree)
    for k, d in zip((nu, nv), deg):
        open_uniform_knots(k, d)  # checks the counts before anything is allocated
    F0 = level_function(surf, np.zeros(nu * nv), (nu, nv), deg)
    uu, vv = np.meshgrid(dirs.u, dirs.v, indexing="ij")
    ok = dirs.valid.reshape(-1)
    uu, vv = uu.reshape(-1)[ok], vv.reshape(-1)[ok]
    return LevelOperators(F0, F0.operator(uu, vv, 1, 0), F0.operator(uu, vv, 0, 1), ok,
                          (nu, nv), deg)


def _combine(Du: sp.csr_matrix, Dv: sp.csr_matrix, a: np.ndarray, b: np.ndarray
             ) -> sp.csr_matrix:
    """``diag(a) Du + diag(b) Dv`` (explicit zeros kept); one pass over the values when
    ``Du`` and ``Dv`` share their pattern (as the operators of one set of samples do)."""
    if np.array_equal(Du.indptr, Dv.indptr) and np.array_equal(Du.indices, Dv.indices):
        rows = np.repeat(np.arange(Du.shape[0]), np.diff(Du.indptr))
        return sp.csr_matrix((a[rows] * Du.data + b[rows] * Dv.data, Du.indices, Du.indptr),
                             shape=Du.shape)
    return (sp.diags(a) @ Du + sp.diags(b) @ Dv).tocsr()


@one_blas_thread
def _linear_least_squares(J: sp.csr_matrix, t: np.ndarray, free: np.ndarray, *, max_iter: int,
                          damping: float, tol_rel: float, tol_energy: float = 1e-20,
                          tol_step: float = 1e-12, tol_grad: float = 1e-14
                          ) -> tuple[np.ndarray, bool, int]:
    """Minimize ``|J x - t|^2`` over ``x[free]`` from ``x = 0`` (the other entries stay 0):
    ``(x, converged, iterations)``.

    The Levenberg-Marquardt iteration of :func:`gridshell.solver.solve` (method ``"lm"``,
    the same steps, gain ratio, damping updates, rejections and stopping rules, ``damping``
    relative to the mean diagonal of ``J^T J``) for a linear residual: its Jacobian ``J`` and
    normal matrix ``J^T J`` do not change, so they are formed once here, where ``solve``
    assembles both again at every iteration and trial step; each trial damping is factored
    (:func:`~gridshell.solver.linear.shared_solver`, the analysis shared)."""
    n = J.shape[1]
    JT = J.T.tocsr()
    N = (JT @ J).tocsr()[free][:, free].tocsc()
    N.sort_indices()
    diag = N.diagonal()
    scale = float(np.mean(diag)) if diag.size and np.mean(diag) > 0 else 1.0
    lin = shared_solver()
    x = np.zeros(n)
    r = -np.asarray(t, float)           # J x - t
    E = float(r @ r)
    lam, nu = damping, 2.0
    converged, it = False, 0
    for it in range(1, max_iter + 1):
        if E <= tol_energy:
            converged, it = True, it - 1
            break
        g = (JT @ r)[free]
        if np.max(np.abs(g), initial=0.0) <= tol_grad:
            converged, it = True, it - 1
            break
        accepted = False
        while True:
            try:
                dx = -lin.factor(N + sp.diags(np.full(len(free), lam * scale), format="csc"))(g)
            except NotPositiveDefinite:  # singular: raise the damping
                lam *= 10.0
                if lam > 1e16:
                    break
                continue
            x_new = x.copy()
            x_new[free] += dx
            r_new = J @ x_new - t
            E_new = float(r_new @ r_new)
            accepted, lam, nu = lm_update(E, E_new, g, dx, N, lam, nu)
            if accepted or lam > 1e16:
                break
        if not accepted:  # no step lowers the energy: a minimum if the gradient is round-off
            converged = bool(np.max(np.abs(g)) <= max(tol_grad, 1e-8 * max(E, 1e-300) ** 0.5))
            break
        rel = (E - E_new) / max(E, 1e-300)
        x, r, E = x_new, r_new, E_new
        if 0 <= rel < tol_rel or \
                np.linalg.norm(dx) <= tol_step * (np.linalg.norm(x) + tol_step):
            converged = True
            break
    else:
        it = max_iter
    return x, converged or E <= tol_energy, it


def fit_level_function(surf: BSplineSurface, dirs: NetDirections, family: int, *,
                       n_ctrl: tuple[int, int] = (12, 12), degree: tuple[int, int] = (3, 3),
                       omega_f: float = 0.01, max_iter: int = 20,
                       operators: LevelOperators | None = None) -> LevelFit:
    """Fit ``xi_f`` minimizing ``E_a + omega_f E_f`` at the samples of ``dirs`` (paper 4.2.2).

    The problem is linear in the control values; one control value (the centre one) is fixed
    to remove the free constant. Levenberg-Marquardt of :func:`gridshell.solver.solve` on the
    terms :func:`directional_derivative`, their Jacobian and normal matrix formed once
    (:func:`_linear_least_squares`). ``operators``: :func:`level_operators` of these
    ``dirs``, ``n_ctrl`` and ``degree``, to share them between the two families (default:
    computed here). Raises :class:`InputError` for a family other than 1 or 3, a negative or
    non-finite ``omega_f``, or ``operators`` of other samples or control values.
    """
    if family not in (1, 3):
        raise InputError(f"family must be 1 or 3, got {family}")
    if not (np.isfinite(omega_f) and omega_f >= 0):
        raise InputError(f"term 'density (4.13)': weight must be finite and >= 0, got {omega_f}")
    nu, nv = (int(k) for k in n_ctrl)
    deg = tuple(int(d) for d in degree)
    ops = operators
    if ops is None:
        ops = level_operators(surf, dirs, (nu, nv), deg)
    elif ops.n_ctrl != (nu, nv) or ops.degree != deg or len(ops.ok) != dirs.valid.size:
        raise InputError(f"the level operators are for {ops.n_ctrl} control values of degree "
                         f"{ops.degree} at {len(ops.ok)} samples, not {(nu, nv)}, {deg}, "
                         f"{dirs.valid.size}")
    Du, Dv = ops.Du, ops.Dv
    a1, b1, a2, b2 = (c.reshape(-1)[ops.ok] for c in dirs.coefficients(family))
    k = Du.shape[0]
    blocks, targets = [_combine(Du, Dv, a1, b1)], [np.zeros(k)]
    if omega_f > 0:
        w = float(np.sqrt(omega_f))
        blocks.append(_combine(Du, Dv, w * a2, w * b2))
        targets.append(np.full(k, w))
    J = sp.vstack(blocks, format="csr")
    fixed = np.zeros(nu * nv, bool)
    fixed[(nu // 2) * nv + nv // 2] = True
    xi, converged, iterations = _linear_least_squares(
        J, np.concatenate(targets), np.flatnonzero(~fixed), max_iter=max_iter, damping=1e-9,
        tol_rel=1e-12)
    F = level_function(surf, xi, (nu, nv), deg)
    gu, gv = np.asarray(Du @ xi), np.asarray(Dv @ xi)
    d1 = a1 * gu + b1 * gv
    d2 = a2 * gu + b2 * gv
    report = {"alignment (4.12)": _term_report(1.0, d1)}
    if omega_f > 0:
        report["density (4.13)"] = _term_report(float(omega_f), d2 - 1.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        sin_err = d1 / np.hypot(d1, d2)
    return LevelFit(family, F, bool(converged), iterations, report,
                    float(np.sqrt(np.nanmean(sin_err ** 2))), float(np.mean(d2)))


def _term_report(weight: float, r: np.ndarray) -> dict[str, float]:
    """A term's line of the fit's report, as :meth:`gridshell.solver.Problem.report`."""
    return {"weight": weight, "energy": weight * float(r @ r),
            "rms": float(np.sqrt(np.mean(r ** 2))) if r.size else 0.0,
            "max": float(np.max(np.abs(r))) if r.size else 0.0}


# ============================================================================ tracing

def level_values(zmin: float, zmax: float, count: int | None = None,
                 spacing: float | None = None, max_count: int | None = None) -> np.ndarray:
    """Uniformly subdivided levels strictly inside ``(zmin, zmax)``: ``count`` values at
    ``zmin + k (zmax - zmin) / (count + 1)``, or values ``spacing`` apart centred on the
    middle of the range (``xi`` is in metres across the curves, eq. 4.13); at most
    ``max_count`` of them."""
    if (count is None) == (spacing is None):
        raise InputError("give either the number of curves or their spacing, not both")
    if count is not None:
        if int(count) < 1:
            raise InputError(f"the number of curves must be >= 1, got {count}")
        _check_count(int(count), max_count)
        return np.linspace(zmin, zmax, int(count) + 2)[1:-1]
    if not (spacing > 0 and np.isfinite(spacing)):
        raise InputError(f"the curve spacing must be a positive number of metres, got {spacing}")
    mid = 0.5 * (zmin + zmax)
    k = int(np.floor((zmax - mid) / spacing))
    _check_count(2 * k + 1, max_count, spacing)
    vals = mid + spacing * np.arange(-k, k + 1)
    vals = vals[(vals > zmin) & (vals < zmax)]
    if len(vals) == 0:
        raise InputError(f"spacing {spacing} m is larger than the surface; choose a smaller one")
    return vals


def _check_count(count: int, max_count: int | None, spacing: float | None = None) -> None:
    if max_count is not None and count > max_count:
        what = f"spacing {spacing} m gives {count}" if spacing is not None else f"{count}"
        raise InputError(f"{what} curves per family, more than the {max_count} the tracing grid "
                         "resolves; ask for fewer curves or a larger spacing")


def _grad_xi(F: BSplineSurface, uv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``xi (k,)`` and its gradient ``(xi_u, xi_v) (k, 2)`` at ``uv (k, 2)``: one basis
    evaluation per direction and order, shared by the value and the two derivatives."""
    C, bu, bv, u, v = _patches(F, uv[:, 0], uv[:, 1], 0, 0)
    _, du = local_basis(F.knots_u, F.degree_u, u, 1)
    _, dv = local_basis(F.knots_v, F.degree_v, v, 1)
    Cv = np.einsum("kab,kb->ka", C, bv)
    z = np.einsum("ka,ka->k", bu, Cv)
    g = np.stack([np.einsum("ka,ka->k", du, Cv),
                  np.einsum("kb,kb->k", dv, np.einsum("ka,kab->kb", bu, C))], axis=1)
    return z, g


def _clip_uv(uv: np.ndarray, dom: tuple[tuple[float, float], tuple[float, float]]) -> np.ndarray:
    (u0, u1), (v0, v1) = dom
    return np.stack([np.clip(uv[:, 0], u0, u1), np.clip(uv[:, 1], v0, v1)], axis=1)


def _split(values: np.ndarray, lengths: list[int]) -> list[np.ndarray]:
    """``values`` cut into consecutive pieces of ``lengths`` (rows)."""
    return np.split(values, np.cumsum(lengths)[:-1]) if lengths else []


def project_to_level(F: BSplineSurface, uv: np.ndarray, level: np.ndarray,
                     steps: int = 3) -> np.ndarray:
    """Move ``uv (k, 2)`` onto ``xi = level`` along the gradient (Newton, ``steps`` times)."""
    uv = np.array(uv, float)
    lev = np.broadcast_to(np.asarray(level, float), (len(uv),))
    for _ in range(steps):
        z, g = _grad_xi(F, uv)
        gg = np.einsum("ij,ij->i", g, g)
        with np.errstate(divide="ignore", invalid="ignore"):
            step = np.where(gg > 0, (lev - z) / gg, 0.0)
        uv = _clip_uv(uv + step[:, None] * g, F.domain)
    return uv


def trace_levels(F: BSplineSurface, levels: np.ndarray, grid: tuple[int, int] = (240, 240)
                 ) -> list[np.ndarray | None]:
    """Level sets of ``xi`` in ``(u, v)``: for each level the longest connected polyline
    ``(k, 2)`` (marching squares on a ``grid``, vertices projected onto the exact level),
    oriented with increasing ``u``; ``None`` where the level does not cross the domain."""
    import contourpy

    (u0, u1), (v0, v1) = F.domain
    u = np.linspace(u0, u1, int(grid[0]))
    v = np.linspace(v0, v1, int(grid[1]))
    Z = F.evaluate_grid(u, v)[..., 2]
    gen = contourpy.contour_generator(x=v, y=u, z=Z, line_type="Separate")
    longest: list[np.ndarray | None] = []
    for lev in levels:
        pieces = [p for p in gen.lines(float(lev)) if len(p) >= 2]
        longest.append(max(pieces, key=lambda p: np.linalg.norm(np.diff(p, axis=0), axis=1).sum())
                       if pieces else None)
    # every level's polyline projected in one call (each vertex independently)
    found = [k for k, P in enumerate(longest) if P is not None]
    projected: dict[int, np.ndarray] = {}
    if found:
        P = np.concatenate([longest[k][:, ::-1] for k in found])
        lev = np.concatenate([np.full(len(longest[k]), float(levels[k])) for k in found])
        uvs = _split(project_to_level(F, P, lev), [len(longest[k]) for k in found])
        projected = dict(zip(found, uvs))
    out: list[np.ndarray | None] = []
    for k in range(len(levels)):
        if k not in projected:
            out.append(None)
            continue
        uv = projected[k]
        keep = np.concatenate([[True], np.linalg.norm(np.diff(uv, axis=0), axis=1) > 1e-12])
        uv = uv[keep]
        if len(uv) < 2:
            out.append(None)
            continue
        if uv[-1, 0] < uv[0, 0]:
            uv = uv[::-1]
        out.append(uv)
    return out


def _crossings(values: np.ndarray, levels: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Segments of a polyline where ``values (k,)`` crosses ``levels (m,)``:
    ``(level index, segment index, fraction)`` (first crossing of each level)."""
    d = values[:, None] - levels[None, :]
    s = np.sign(d)
    change = (s[:-1] * s[1:] <= 0) & (d[:-1] != d[1:])
    seg, lev = np.nonzero(change)
    if len(seg) == 0:
        z = np.zeros(0, np.int64)
        return z, z, np.zeros(0)
    order = np.lexsort((seg, lev))
    seg, lev = seg[order], lev[order]
    first = np.concatenate([[True], lev[1:] != lev[:-1]])
    seg, lev = seg[first], lev[first]
    a, b = d[seg, lev], d[seg + 1, lev]
    t = np.clip(a / (a - b), 0.0, 1.0)
    return lev, seg, t


def _newton_joints(F1: BSplineSurface, F3: BSplineSurface, uv: np.ndarray, a: np.ndarray,
                   b: np.ndarray, steps: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """Solve ``xi_1 = a, xi_3 = b`` from ``uv (k, 2)``; returns ``uv`` and the max residual."""
    uv = np.array(uv, float)
    for _ in range(steps):
        z1, g1 = _grad_xi(F1, uv)
        z3, g3 = _grad_xi(F3, uv)
        det = g1[:, 0] * g3[:, 1] - g1[:, 1] * g3[:, 0]
        r1, r3 = a - z1, b - z3
        with np.errstate(divide="ignore", invalid="ignore"):
            du = np.where(det != 0, (r1 * g3[:, 1] - r3 * g1[:, 1]) / det, 0.0)
            dv = np.where(det != 0, (g1[:, 0] * r3 - g3[:, 0] * r1) / det, 0.0)
        uv = _clip_uv(uv + np.stack([du, dv], axis=1), F1.domain)
    z1, _ = _grad_xi(F1, uv)
    z3, _ = _grad_xi(F3, uv)
    return uv, np.maximum(np.abs(z1 - a), np.abs(z3 - b))


@dataclass
class TracedNet:
    """The traced NCP net.

    net : :class:`~gridshell.geometry.net.Net` (joints on the surface, loops ``A, B, C, D`` with ``A``
        the corner of least ``u`` and ``C`` the opposite one, lamellae with dense axes)
    joint_uv : (n, 2) surface parameters of the joints
    joint_ij : (n, 2) level indices (family 1, family 3) of each joint
    axis_uv : per lamella (same order as ``net.lamellae``) the ``(k, 2)`` parameters of its axis
    axis_joint_index : per lamella the indices of its joints among the axis vertices
    levels : {1: (m1,), 3: (m3,)} level values
    fits : {1: LevelFit, 3: LevelFit}
    dropped : notes on curves without enough joints
    """

    net: Net
    joint_uv: np.ndarray
    joint_ij: np.ndarray
    axis_uv: list[np.ndarray]
    axis_joint_index: list[np.ndarray]
    levels: dict[int, np.ndarray]
    fits: dict[int, LevelFit]
    dropped: list[str] = field(default_factory=list)


def _axis_vertices(uv: np.ndarray, P: np.ndarray, joints_uv: np.ndarray, seg: np.ndarray,
                   frac: np.ndarray, spacing: float) -> tuple[np.ndarray, np.ndarray]:
    """Axis vertices ``uv (q, 2)`` with the joints inserted and every piece between
    consecutive joints (and the two end pieces) resampled uniformly in 3D arc length
    ~``spacing``, before the projection of the non-joint vertices onto the level; and the
    joints' indices among them. ``P`` are the 3D points of the traced polyline ``uv``."""
    order = np.lexsort((frac, seg))
    seg, frac, joints_uv = seg[order], frac[order], joints_uv[order]
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(P, axis=0), axis=1))])
    sj = s[seg] + frac * (s[seg + 1] - s[seg])
    # knots: start, joints, end; each piece resampled with uv interpolated in arc length
    ends = np.concatenate([[0.0], sj, [s[-1]]])
    pieces, jidx = [], []
    count = 0
    for k in range(len(ends) - 1):
        a, b = ends[k], ends[k + 1]
        m = max(int(np.ceil((b - a) / spacing)), 1 if k in (0, len(ends) - 2) else 2)
        t = np.linspace(a, b, m + 1)[:-1] if k < len(ends) - 2 else np.linspace(a, b, m + 1)
        q = np.stack([np.interp(t, s, uv[:, 0]), np.interp(t, s, uv[:, 1])], axis=1)
        if k > 0:
            q[0] = joints_uv[k - 1]
            jidx.append(count)
        pieces.append(q)
        count += len(q)
    return np.concatenate(pieces), np.asarray(jidx, np.int64)


def _axis_kept(Q: np.ndarray, jidx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The projected axis vertices without repeats (the joints kept), and the joints'
    indices among them."""
    keep = np.concatenate([[True], np.linalg.norm(np.diff(Q, axis=0), axis=1) > 1e-13])
    keep[jidx] = True
    new_index = np.cumsum(keep) - 1
    return Q[keep], new_index[jidx]


def trace_net(surf: BSplineSurface, fits: dict[int, LevelFit], *, curves: int | tuple[int, int]
              | None = None, spacing: float | None = None, grid: tuple[int, int] = (240, 240),
              axis_points: int = 300, tol: float = 1e-9) -> TracedNet:
    """Trace both families and build the net (joints, loops, lamellae) as a :class:`TracedNet`.

    Parameters
    ----------
    surf : the surface
    fits : level functions of families 1 and 3 (:func:`fit_level_function`)
    curves : number of curves per family (or a pair), or
    spacing : spacing of the curves, metres (``xi`` units)
    grid : marching-squares grid in ``(u, v)``
    axis_points : about this many vertices along the longest lamella axis
    tol : joint residual ``|xi - level|`` relative to the ``xi`` range accepted as converged
    """
    if curves is not None and spacing is not None:
        raise InputError("give either curves or spacing, not both")
    if curves is None and spacing is None:
        curves = 10
    counts = (curves, curves) if curves is None or np.isscalar(curves) else tuple(curves)
    levels, polys = _trace_families(surf, fits, counts, spacing, grid)
    Ffam = {1: fits[1].F, 3: fits[3].F}
    rng = max(float(np.ptp(levels[1])), float(np.ptp(levels[3])), 1.0)
    live = {f: [a for a, uv in enumerate(polys[f]) if uv is not None] for f in (1, 3)}
    cross, pts = _along_curves(surf, Ffam, polys, levels, live)
    found = _joints(Ffam, polys, levels, live[1], cross[1], tol * rng)
    # the place (segment, fraction) of every joint along its curve of either family
    where: dict[int, dict[tuple[int, int], tuple[int, float]]] = {1: {}, 3: {}}
    for f in (1, 3):
        for a in live[f]:
            for b, sg, tt in zip(*(c.tolist() for c in cross[f][a])):
                key = (a, b) if f == 1 else (b, a)
                if key in found:
                    where[f][key] = (sg, tt)
    keys = sorted(k for k in found if k in where[1] and k in where[3])
    if len(keys) < 4:
        raise NoNetError(f"the traced curves cross at only {len(keys)} joints; ask for more "
                         "curves (--curves) or a smaller spacing")
    index = {k: n for n, k in enumerate(keys)}
    joint_uv = np.array([found[k] for k in keys])
    longest = max([0.0] + [float(np.linalg.norm(np.diff(Q, axis=0), axis=1).sum())
                           for f in (1, 3) for Q in pts[f].values()])
    h = longest / max(int(axis_points), 10)
    lamellae, axis_uv, axis_jidx, dropped = [], [], [], []
    for f in (1, 3):
        todo, notes = _family_axes(f, live[f], keys, where[f], found, polys[f], pts[f],
                                   levels[f], h)
        dropped += notes
        for mine, Q, jidx, X in _projected_axes(surf, Ffam[f], levels[f], todo):
            s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(X, axis=0), axis=1))])
            lamellae.append(Lamella(id=len(lamellae), family=f,
                                    joints=[index[k] for k in mine], joint_s=s[jidx], axis=X))
            axis_uv.append(Q)
            axis_jidx.append(jidx)
    if not lamellae:
        raise NoNetError(f"the traced curves cross at {len(keys)} joints, but no curve crosses "
                         "the other family twice, so no lamella has two joints (the net "
                         "directions are nearly parallel, or the curves too few); ask for more "
                         "curves (--curves) or a smaller spacing, or use another mode")
    net = Net(joints=surf.evaluate(joint_uv[:, 0], joint_uv[:, 1]),
              loops=_net_loops(keys, index, joint_uv), lamellae=lamellae)
    return TracedNet(net=net, joint_uv=joint_uv, joint_ij=np.array(keys, np.int64),
                     axis_uv=axis_uv, axis_joint_index=axis_jidx, levels=levels, fits=fits,
                     dropped=dropped)


def _trace_families(surf: BSplineSurface, fits: dict[int, LevelFit], counts: tuple,
                    spacing: float | None, grid: tuple[int, int]) -> tuple[dict, dict]:
    """Per family the level values (:func:`level_values` over ``xi`` on a 120 x 120 grid) and
    their polylines in ``(u, v)`` (:func:`trace_levels`)."""
    ug, vg = (np.linspace(a, b, 120) for a, b in surf.domain)
    levels, polys = {}, {}
    for f, cnt in zip((1, 3), counts):
        Z = fits[f].F.evaluate_grid(ug, vg)[..., 2]
        levels[f] = level_values(float(Z.min()), float(Z.max()), cnt, spacing,
                                 max_count=min(grid) // 2)
        polys[f] = trace_levels(fits[f].F, levels[f], grid)
    return levels, polys


def _along_curves(surf: BSplineSurface, Ffam: dict[int, BSplineSurface], polys: dict,
                  levels: dict, live: dict) -> tuple[dict, dict]:
    """Per family and traced curve: the crossings of the other family's levels
    (:func:`_crossings`) and its 3D points (m), each evaluated in one call for all curves."""
    cross: dict[int, dict] = {1: {}, 3: {}}
    pts: dict[int, dict[int, np.ndarray]] = {1: {}, 3: {}}
    for f, other in ((1, 3), (3, 1)):
        if not live[f]:
            continue
        lens = [len(polys[f][a]) for a in live[f]]
        UV = np.concatenate([polys[f][a] for a in live[f]])
        xi_o = _split(evaluate_xi(Ffam[other], UV[:, 0], UV[:, 1]), lens)
        cross[f] = {a: _crossings(z, levels[other]) for a, z in zip(live[f], xi_o)}
        pts[f] = dict(zip(live[f], _split(surf.evaluate(UV[:, 0], UV[:, 1]), lens)))
    return cross, pts


def _joints(Ffam: dict[int, BSplineSurface], polys: dict, levels: dict, live1: list[int],
            cross1: dict, tol: float) -> dict[tuple[int, int], np.ndarray]:
    """The joints ``(i, j) -> uv``: crossings of the ``xi_3`` levels along the traced curves
    of family 1, refined together by Newton's method; kept where ``|xi - level| <= tol``."""
    found: dict[tuple[int, int], np.ndarray] = {}
    gi, gj, guess = [], [], []
    for i in live1:
        lev, seg, t = cross1[i]
        uv = polys[1][i]
        gi.append(np.full(len(lev), i))
        gj.append(lev)
        guess.append(uv[seg] + t[:, None] * (uv[seg + 1] - uv[seg]))
    if gi and sum(len(g) for g in gi):
        ii, jj = np.concatenate(gi), np.concatenate(gj)
        sol, res = _newton_joints(Ffam[1], Ffam[3], np.concatenate(guess), levels[1][ii],
                                  levels[3][jj])
        for i, j, p, r in zip(ii.tolist(), jj.tolist(), sol, res.tolist()):
            if r <= tol:
                found[(i, j)] = p
    return found


def _family_axes(f: int, live: list[int], keys: list, where: dict, found: dict, polys: list,
                 pts: dict, levels: np.ndarray, h: float) -> tuple[list[tuple], list[str]]:
    """The axes of family ``f`` before projection, per curve with two or more joints
    ``(curve, joints in order, uv, joint indices, free vertices)`` (:func:`_axis_vertices`,
    spacing ``h`` m); a note per curve left out."""
    todo, notes = [], []
    for a in live:
        mine = [k for k in keys if (k[0] if f == 1 else k[1]) == a]
        if len(mine) < 2:
            notes.append(f"family {f} curve {a} (xi = {levels[a]:.4g}) has {len(mine)} "
                         "joint(s); left out")
            continue
        seg = np.array([where[k][0] for k in mine])
        frac = np.array([where[k][1] for k in mine])
        juv = np.array([found[k] for k in mine])
        order = np.lexsort((frac, seg))
        mine = [mine[o] for o in order]
        Q, jidx = _axis_vertices(polys[a], pts[a], juv, seg, frac, h)
        free = np.ones(len(Q), bool)
        free[jidx] = False
        todo.append((a, mine, Q, jidx, free))
    return todo, notes


def _projected_axes(surf: BSplineSurface, F: BSplineSurface, levels: np.ndarray,
                    todo: list[tuple]) -> list[tuple]:
    """The axes of :func:`_family_axes` with their vertices between the joints projected onto
    their levels (one call), repeats removed: ``(joints, uv, joint indices, 3D points m)``."""
    if not todo:
        return []
    lev = np.concatenate([np.full(int(fr.sum()), levels[a]) for a, _, _, _, fr in todo])
    moved = project_to_level(F, np.concatenate([Q[fr] for _, _, Q, _, fr in todo]), lev)
    axes = []
    for (a, mine, Q, jidx, fr), q in zip(todo, _split(moved, [int(t[4].sum()) for t in todo])):
        Q[fr] = q
        axes.append((mine, *_axis_kept(Q, jidx)))
    QQ = np.concatenate([Q for _, Q, _ in axes])
    Xs = _split(surf.evaluate(QQ[:, 0], QQ[:, 1]), [len(Q) for _, Q, _ in axes])
    return [(mine, Q, jidx, X) for (mine, Q, jidx), X in zip(axes, Xs)]


def _net_loops(keys: list[tuple[int, int]], index: dict, joint_uv: np.ndarray) -> np.ndarray:
    """Net-loops ``(i, j), (i+1, j), (i+1, j+1), (i, j+1)`` as joint indices ``(m, 4)``, A =
    the corner of least ``u`` first."""
    loops = []
    for (i, j) in keys:
        quad = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)]
        if all(q in index for q in quad):
            ids = np.array([index[q] for q in quad])
            start = int(np.argmin(joint_uv[ids, 0]))
            loops.append(np.roll(ids, -start))
    return np.array(loops, np.int64).reshape(-1, 4)


def trace(surf: BSplineSurface, dirs: NetDirections, *, curves: int | tuple[int, int] | None = None,
          spacing: float | None = None, n_ctrl: tuple[int, int] = (12, 12),
          degree: tuple[int, int] = (3, 3), omega_f: float = 0.01,
          grid: tuple[int, int] = (240, 240), axis_points: int = 300,
          progress: Callable[[str], None] | None = None) -> TracedNet:
    """Fit both level functions on the samples of ``dirs`` and trace the net (paper 4.2.2)."""
    fits = {}
    ops = level_operators(surf, dirs, n_ctrl, degree)
    for f in (1, 3):
        fits[f] = fit_level_function(surf, dirs, f, n_ctrl=n_ctrl, degree=degree,
                                     omega_f=omega_f, operators=ops)
        if progress is not None:
            progress(f"level function xi_{f}: alignment RMS sin {fits[f].align_rms:.2e}, "
                     f"density {fits[f].density:.3f}")
    return trace_net(surf, fits, curves=curves, spacing=spacing, grid=grid,
                     axis_points=axis_points)
