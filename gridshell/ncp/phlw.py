"""B-spline surface design towards PHLW, CNC and PK surfaces (paper 3.4, 4.2.1).

Theorem 2 of the paper: a normal-curvature-preserving alignable net exists exactly on surfaces
where ``aK + bH + c = 0`` (``b^2 - 4ac <= 0``) holds with coefficients constant along one
family of principal curvature lines (PHLW surfaces). With ``a = 1`` this is eq. 4.8,
``K - 2 n H + n^2 + t^2 = 0`` with one ``(n, t)`` per principal line, ``b = -2n``,
``c = n^2 + t^2``, and the net's normal curvature is ``n``.

Conventions
-----------
- Rows: the optimization samples a uniform ``rows x cols`` grid ``(u_i, v_j)`` of the domain.
  A *u-row* is the curve ``u = u_i`` (a principal line along ``S_v`` once ``F = M = 0``,
  eq. 4.7); ``n_u, t_u`` are constant along it. Sample ``s = i * cols + j``.
- Normal and signs follow :mod:`gridshell.diffgeo`: ``U = S_u x S_v`` (eq. 4.2), curvatures
  are positive when the surface bends towards ``U``, ``H = (LG - 2MF + NE) / (2 delta)``
  (eq. 4.6 with ``+ NE``: the paper's ``- NE`` is a typo). Flipping ``u`` and ``v`` flips
  ``U``, ``H`` and ``n`` together; ``K`` and ``t^2`` are unaffected.
- Units: the optimization runs on geometry scaled to a unit bounding-box diagonal of the
  reference (so that the weights mean the same on any model); everything returned is in
  metres (curvatures 1/m, ``K`` 1/m^2).

Variables (one :class:`~gridshell.solver.Layout`)
--------------------------------------------------
``C (nc, 3)`` control points; per sample ``U (k, 3)``, ``E, F, G, delta, w, L, M, N, K, H
(k,)`` with ``w = sqrt(delta)`` (keeps eq. 4.5 quadratic: ``L w = <S_uu, U>``, ``w^2 =
delta``); ``n`` (``rows`` values in mode ``phlw``, one value in ``cnc``, absent in ``aa``
where ``n = 0``) and ``t (rows,)``.

Energy (paper): ``E_PHLW + E_beta + E_c + E_g`` with ``E_PHLW = sum chi_i^2 + omega_t chi_t^2``
(constraints 4.2-4.7 weight 1, target 4.8 weight ``omega_t = 0.1``), ``E_beta = omega_beta
sum (n_u - H)^2`` (``omega_beta = 5e-4``), closeness ``E_c`` and gliding ``E_g`` to the
reference surface with closest points refreshed every outer round.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any, Callable, Literal, NamedTuple

import numpy as np
import scipy.sparse as sp

from ..bspline import BSplineSurface, uniform_params
from ..diffgeo import curvatures, fundamental_forms, principal_directions
from ..errors import InputError, NoNetError
from ..solver import Layout, Problem, TermResult, result, solve, term
from ..solver import terms as T

Mode = Literal["phlw", "cnc", "aa"]
MODES = ("phlw", "cnc", "aa")

#: Default weights, on geometry scaled to a unit bounding-box diagonal. ``target`` and ``beta``
#: are the paper's omega_t = 0.1 and omega_beta = 5e-4. The paper gives no omega_c, omega_g:
#: closeness 1e-2 (it mostly holds the samples tangentially, while the parameter lines rotate
#: onto the principal directions over the outer rounds) and gliding 10 (it keeps the shape on
#: the reference against E_beta, which otherwise pulls H towards n_u, i.e. towards a minimal
#: surface in mode aa). The paper weights its constraints 4.2-4.7 by 1; on unit-diagonal
#: geometry that makes them only ~10x stiffer than the target, and Levenberg-Marquardt then
#: trades constraint violation for target (the auxiliary K, H drift from the surface's true
#: curvature: measured E_PHLW of the true surface 1e4x above the solver's). Weighting them
#: 100 keeps the auxiliaries on the surface (re-projected exactly every outer round as well).
DEFAULT_WEIGHTS: dict[str, float] = {
    "constraints": 100.0,  # eqs. 4.2-4.7
    "target": 0.1,         # omega_t, eq. 4.8
    "beta": 5e-4,          # omega_beta
    "closeness": 1e-2,     # omega_c
    "gliding": 10.0,       # omega_g
}

#: Levenberg-Marquardt settings of every round: initial damping (relative to the mean of
#: diag(J^T J)) and the relative energy decrease per step that ends a round. Measured on the
#: demo's torus zone (18 x 18 samples, 4 rounds): the default damping of 1e-3 over-damps the
#: first ~10 steps of every round and tol_rel = 1e-7 is never met (160 iterations, 19 s);
#: these take 57 iterations to an energy within 10 % of that run's, the same deviation and
#: row relation (benchmarks/README.md).
SOLVER_DAMPING = 1e-9
SOLVER_TOL_REL = 1e-3

#: The reference is (nearly) umbilic at a sample if ``|kappa_2 - kappa_1|`` is at most this
#: fraction of ``max(|kappa_1|, |kappa_2|, FLAT_CURVATURE)`` (unit-diagonal units). A
#: reference umbilic at every sample (a plane, a sphere patch: up to 2.7 % measured on a 5 x 5
#: control-point fit of a sphere) has no principal directions to start the PHLW net from.
NEAR_UMBILIC = 0.05
#: Curvatures below this, on unit-diagonal geometry (radius above 1000 diagonals), are flat.
FLAT_CURVATURE = 1e-3

_OPS = {"S": (0, 0), "Su": (1, 0), "Sv": (0, 1), "Suu": (2, 0), "Suv": (1, 1), "Svv": (0, 2)}
_SCALARS = ("E", "F", "G", "delta", "w", "L", "M", "N", "K", "H")


# ============================================================================ samples and layout

class Samples(NamedTuple):
    """Data shared by the PHLW terms.

    ops : derivative operators ``"S", "Su", "Sv", "Suu", "Suv", "Svv"`` -> COO ``(k, nc)``
        acting on the control block ``C``
    row : (k,) int, u-row of every sample
    n_index : (k,) int index into block ``"n"`` per sample, or None (mode ``aa``: ``n = 0``)
    """

    ops: dict[str, sp.coo_matrix]
    row: np.ndarray
    n_index: np.ndarray | None



def make_samples(surf: BSplineSurface, u: np.ndarray, v: np.ndarray,
                 mode: Mode = "phlw") -> Samples:
    """Operators of the tensor sample grid ``u (rows,) x v (cols,)`` (sample ``i * cols + j``)."""
    _check_mode(mode)
    uu, vv = np.meshgrid(np.asarray(u, float), np.asarray(v, float), indexing="ij")
    uf, vf = uu.ravel(), vv.ravel()
    ops = {k: surf.operator(uf, vf, du, dv).tocoo() for k, (du, dv) in _OPS.items()}
    row = np.repeat(np.arange(len(u)), len(v))
    n_index = {"phlw": row, "cnc": np.zeros_like(row), "aa": None}[mode]
    return Samples(ops, row, n_index)


def make_layout(n_ctrl: int, k: int, rows: int, mode: Mode = "phlw") -> Layout:
    """The variable blocks of the PHLW problem (see the module docstring)."""
    _check_mode(mode)
    lay = Layout([("C", (n_ctrl, 3)), ("U", (k, 3))] + [(s, k) for s in _SCALARS])
    if mode == "phlw":
        lay.add("n", rows)
    elif mode == "cnc":
        lay.add("n", 1)
    lay.add("t", rows)
    return lay


def _check_mode(mode: str) -> None:
    if mode not in MODES:
        raise InputError(f"unknown mode {mode!r}; use one of {', '.join(MODES)}")


# ============================================================================ Jacobian helpers

def _derivs(x: np.ndarray, layout: Layout, data: Samples, names: tuple[str, ...]
            ) -> list[np.ndarray]:
    C = layout.view(x, "C")
    return [np.asarray(data.ops[nm] @ C) for nm in names]


def _cjac(op: sp.coo_matrix, Cidx: np.ndarray, coef: np.ndarray,
          rowmap: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Triplets of ``d r / d C`` where ``r[rowmap[s, m]]`` depends on ``X = op @ C`` through
    ``coef[s, m, j] = d r[rowmap[s, m]] / d X[s, j]``; ``coef (k, m, 3)``, ``rowmap (k, m)``."""
    s, p, a = op.row, op.col, op.data
    m = coef.shape[1]
    rows = np.broadcast_to(rowmap[s][:, :, None], (len(s), m, 3))
    cols = np.broadcast_to(Cidx[p][:, None, :], (len(s), m, 3))
    vals = a[:, None, None] * coef[s]
    return rows.ravel(), cols.ravel(), vals.ravel()


def _assemble(r: np.ndarray, parts: list[tuple[np.ndarray, np.ndarray, np.ndarray]]
              ) -> TermResult:
    rows = np.concatenate([np.asarray(p[0]).ravel() for p in parts])
    cols = np.concatenate([np.asarray(p[1]).ravel() for p in parts])
    vals = np.concatenate([np.broadcast_to(p[2], np.shape(p[0])).ravel() for p in parts])
    return result(r, rows, cols, vals)


def _skew(a: np.ndarray) -> np.ndarray:
    """``[a]_x (k, 3, 3)`` with ``[a]_x b = a x b``."""
    z = np.zeros(len(a))
    return np.stack([np.stack([z, -a[:, 2], a[:, 1]], 1),
                     np.stack([a[:, 2], z, -a[:, 0]], 1),
                     np.stack([-a[:, 1], a[:, 0], z], 1)], 1)


# ============================================================================ terms (eqs. 4.2-4.8)

@term
def normal_eq(x: np.ndarray, layout: Layout, data: Samples) -> TermResult:
    """Eq. 4.2: ``U - S_u x S_v = 0`` per sample (3 rows each)."""
    Su, Sv = _derivs(x, layout, data, ("Su", "Sv"))
    U = layout.view(x, "U")
    k = len(U)
    r = (U - np.cross(Su, Sv)).ravel()
    rowmap = np.arange(3 * k).reshape(k, 3)
    Cidx = layout.indices("C")
    parts = [(rowmap, layout.indices("U"), np.ones((k, 3))),
             _cjac(data.ops["Su"], Cidx, _skew(Sv), rowmap),      # d(-Su x Sv)/dSu = [Sv]x
             _cjac(data.ops["Sv"], Cidx, -_skew(Su), rowmap)]     # d(-Su x Sv)/dSv = -[Su]x
    return _assemble(r, parts)


def init_normal(Su: np.ndarray, Sv: np.ndarray) -> np.ndarray:
    """Initial ``U = S_u x S_v`` (eq. 4.2)."""
    return np.cross(Su, Sv)


@term
def first_form_eq(x: np.ndarray, layout: Layout, data: Samples) -> TermResult:
    """Eq. 4.3: ``E - <S_u,S_u>``, ``F - <S_u,S_v>``, ``G - <S_v,S_v>`` (rows: E block, F, G)."""
    Su, Sv = _derivs(x, layout, data, ("Su", "Sv"))
    E, F, G = (layout.view(x, s) for s in "EFG")
    k = len(E)
    dot = lambda a, b: np.einsum("ij,ij->i", a, b)  # noqa: E731
    r = np.concatenate([E - dot(Su, Su), F - dot(Su, Sv), G - dot(Sv, Sv)])
    ar = np.arange(k)
    Cidx = layout.indices("C")
    parts = [(ar, layout.indices("E"), 1.0), (k + ar, layout.indices("F"), 1.0),
             (2 * k + ar, layout.indices("G"), 1.0)]
    # Su feeds rows E (-2 Su) and F (-Sv); Sv feeds rows F (-Su) and G (-2 Sv).
    parts.append(_cjac(data.ops["Su"], Cidx, np.stack([-2 * Su, -Sv], 1),
                       np.stack([ar, k + ar], 1)))
    parts.append(_cjac(data.ops["Sv"], Cidx, np.stack([-Su, -2 * Sv], 1),
                       np.stack([k + ar, 2 * k + ar], 1)))
    return _assemble(r, parts)


def init_first_form(Su: np.ndarray, Sv: np.ndarray) -> dict[str, np.ndarray]:
    """Initial ``E, F, G`` (eq. 4.3)."""
    return {"E": np.einsum("ij,ij->i", Su, Su), "F": np.einsum("ij,ij->i", Su, Sv),
            "G": np.einsum("ij,ij->i", Sv, Sv)}


@term
def delta_eq(x: np.ndarray, layout: Layout, data: Any = None) -> TermResult:
    """Eq. 4.4: ``delta - (E G - F^2) = 0``."""
    E, F, G, d = (layout.view(x, s) for s in ("E", "F", "G", "delta"))
    ar = np.arange(len(E))
    r = d - (E * G - F * F)
    return _assemble(r, [(ar, layout.indices("delta"), 1.0), (ar, layout.indices("E"), -G),
                         (ar, layout.indices("G"), -E), (ar, layout.indices("F"), 2 * F)])


@term
def sqrt_delta_eq(x: np.ndarray, layout: Layout, data: Any = None) -> TermResult:
    """Auxiliary ``w = sqrt(delta)`` of eq. 4.5: ``w^2 - delta = 0``."""
    w, d = layout.view(x, "w"), layout.view(x, "delta")
    ar = np.arange(len(w))
    return _assemble(w * w - d, [(ar, layout.indices("w"), 2 * w),
                                 (ar, layout.indices("delta"), -1.0)])


def init_delta(E: np.ndarray, F: np.ndarray, G: np.ndarray) -> dict[str, np.ndarray]:
    """Initial ``delta = EG - F^2`` (eq. 4.4) and ``w = sqrt(delta)``."""
    d = E * G - F * F
    return {"delta": d, "w": np.sqrt(np.maximum(d, 0.0))}


@term
def second_form_eq(x: np.ndarray, layout: Layout, data: Samples) -> TermResult:
    """Eq. 4.5 times ``w = sqrt(delta)``: ``L w - <S_uu, U>``, ``M w - <S_uv, U>``,
    ``N w - <S_vv, U>`` (rows: L block, M, N)."""
    Suu, Suv, Svv = _derivs(x, layout, data, ("Suu", "Suv", "Svv"))
    U, w = layout.view(x, "U"), layout.view(x, "w")
    k = len(w)
    ar = np.arange(k)
    Cidx, Uidx, widx = layout.indices("C"), layout.indices("U"), layout.indices("w")
    rs, parts = [], []
    for b, (nm, D, op) in enumerate((("L", Suu, "Suu"), ("M", Suv, "Suv"), ("N", Svv, "Svv"))):
        X = layout.view(x, nm)
        rs.append(X * w - np.einsum("ij,ij->i", D, U))
        rr = b * k + ar
        parts += [(rr, layout.indices(nm), w), (rr, widx, X),
                  (np.repeat(rr, 3).reshape(k, 3), Uidx, -D),
                  _cjac(data.ops[op], Cidx, -U[:, None, :], rr[:, None])]
    return _assemble(np.concatenate(rs), parts)


def init_second_form(Suu: np.ndarray, Suv: np.ndarray, Svv: np.ndarray, U: np.ndarray,
                     w: np.ndarray) -> dict[str, np.ndarray]:
    """Initial ``L, M, N = <S_.., U> / sqrt(delta)`` (eq. 4.5)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return {nm: np.einsum("ij,ij->i", D, U) / w
                for nm, D in (("L", Suu), ("M", Suv), ("N", Svv))}


@term
def curvature_eq(x: np.ndarray, layout: Layout, data: Any = None) -> TermResult:
    """Eq. 4.6 times ``delta``: ``K delta - (LN - M^2)``, ``2 H delta - (LG - 2MF + NE)``
    (rows: K block, H block; ``+ NE``, see the module docstring)."""
    v = {s: layout.view(x, s) for s in ("E", "F", "G", "delta", "L", "M", "N", "K", "H")}
    i = {s: layout.indices(s) for s in v}
    k = len(v["K"])
    ar, ar2 = np.arange(k), k + np.arange(k)
    E, F, G, d, L, M, N, K, H = (v[s] for s in ("E", "F", "G", "delta", "L", "M", "N", "K", "H"))
    r = np.concatenate([K * d - (L * N - M * M), 2 * H * d - (L * G - 2 * M * F + N * E)])
    parts = [(ar, i["K"], d), (ar, i["delta"], K), (ar, i["L"], -N), (ar, i["N"], -L),
             (ar, i["M"], 2 * M),
             (ar2, i["H"], 2 * d), (ar2, i["delta"], 2 * H), (ar2, i["L"], -G), (ar2, i["G"], -L),
             (ar2, i["M"], 2 * F), (ar2, i["F"], 2 * M), (ar2, i["N"], -E), (ar2, i["E"], -N)]
    return _assemble(r, parts)


def init_curvature(E, F, G, L, M, N) -> dict[str, np.ndarray]:
    """Initial ``K``, ``H`` (eq. 4.6, ``+ NE``)."""
    K, H, _, _ = curvatures(E, F, G, L, M, N)
    return {"K": K, "H": H}


@term
def principal_eq(x: np.ndarray, layout: Layout, data: Any = None) -> TermResult:
    """Eq. 4.7: ``F = 0``, ``M = 0`` (principal parametrization; rows: F block, M block)."""
    F, M = layout.view(x, "F"), layout.view(x, "M")
    k = len(F)
    ar = np.arange(2 * k)
    return _assemble(np.concatenate([F, M]),
                     [(ar, np.concatenate([layout.indices("F"), layout.indices("M")]), 1.0)])


def _row_n(x: np.ndarray, layout: Layout, data: Samples) -> tuple[np.ndarray, np.ndarray | None]:
    """``n`` per sample and its column (None in mode aa, where n = 0)."""
    k = len(data.row)
    if data.n_index is None:
        return np.zeros(k), None
    return layout.view(x, "n")[data.n_index], layout.indices("n")[data.n_index]


@term
def phlw_target(x: np.ndarray, layout: Layout, data: Samples) -> TermResult:
    """Eq. 4.8: ``K - 2 n_u H + n_u^2 + t_u^2 = 0`` with ``(n_u, t_u)`` of the sample's u-row."""
    K, H = layout.view(x, "K"), layout.view(x, "H")
    t = layout.view(x, "t")[data.row]
    n, ncol = _row_n(x, layout, data)
    ar = np.arange(len(K))
    r = K - 2 * n * H + n * n + t * t
    parts = [(ar, layout.indices("K"), 1.0), (ar, layout.indices("H"), -2 * n),
             (ar, layout.indices("t")[data.row], 2 * t)]
    if ncol is not None:
        parts.append((ar, ncol, 2 * n - 2 * H))
    return _assemble(r, parts)


@term
def beta_fairness(x: np.ndarray, layout: Layout, data: Samples) -> TermResult:
    """E_beta: ``n_u - H`` (the net angle beta is pi/4 where ``n_u = H``)."""
    H = layout.view(x, "H")
    n, ncol = _row_n(x, layout, data)
    ar = np.arange(len(H))
    parts = [(ar, layout.indices("H"), -1.0)]
    if ncol is not None:
        parts.append((ar, ncol, 1.0))
    return _assemble(n - H, parts)


class SampleGliding(NamedTuple):
    """Data of :func:`sample_gliding`: B-spline samples ``A @ C`` glide on the tangent planes
    ``(foot (k,3), normal (k,3))`` of the reference."""

    A: sp.coo_matrix
    foot: np.ndarray
    normal: np.ndarray


@term
def sample_gliding(x: np.ndarray, layout: Layout, data: SampleGliding) -> TermResult:
    """E_g: ``<S(u, v) - S_c^r, n_c^r>`` with ``S = A C`` (metres)."""
    C = layout.view(x, "C")
    S = np.asarray(data.A @ C)
    N = np.asarray(data.normal, float)
    r = np.einsum("ij,ij->i", S - data.foot, N)
    k = len(r)
    rr, cc, vv = _cjac(data.A, layout.indices("C"), N[:, None, :], np.arange(k)[:, None])
    return result(r, rr, cc, vv)


# ============================================================================ initialization

def init_auxiliary(ctrl: np.ndarray, data: Samples) -> dict[str, np.ndarray]:
    """Every per-sample auxiliary variable computed exactly from control points ``(nc, 3)``."""
    D = {k: np.asarray(op @ ctrl) for k, op in data.ops.items()}
    out: dict[str, np.ndarray] = {"U": init_normal(D["Su"], D["Sv"])}
    out.update(init_first_form(D["Su"], D["Sv"]))
    out.update(init_delta(out["E"], out["F"], out["G"]))
    out.update(init_second_form(D["Suu"], D["Suv"], D["Svv"], out["U"], out["w"]))
    out.update(init_curvature(out["E"], out["F"], out["G"], out["L"], out["M"], out["N"]))
    return out


class RowFit(NamedTuple):
    """Per-row coefficients of eq. 4.8 from linear fitting, and rows whose ``t^2 < 0``."""

    n: np.ndarray
    t: np.ndarray
    clamped: np.ndarray


def fit_rows(K: np.ndarray, H: np.ndarray, mode: Mode = "phlw", rtol: float = 1e-4) -> RowFit:
    """Least-squares fit of ``K = 2 n H - (n^2 + t^2)`` per u-row (rows of ``K, H (rows, cols)``).

    ``phlw``: a line ``K = alpha H + beta`` per row, ``n = alpha / 2``, ``t^2 = -beta - n^2``;
    a row whose ``H`` hardly varies (e.g. a parallel of a surface of revolution) has no
    defined slope and gets ``n = mean H`` (the net angle pi/4, as E_beta prefers).
    ``cnc``: one slope for all rows, one intercept per row. ``aa``: ``n = 0``,
    ``t^2 = -mean K``. Rows where the fitted line has ``t^2 < 0`` (``b^2 - 4ac > 0``: a
    secant of the parabola ``K = H^2``, no net) are listed in ``clamped``; in ``phlw`` mode
    they restart from ``n = mean H`` (net angle pi/4) with ``t^2 = (mean H)^2 - mean K``,
    elsewhere ``t = 0``.

    Returns
    -------
    RowFit : ``n (rows,)`` (all equal in cnc, zero in aa), ``t (rows,) >= 0``, ``clamped``
        indices of rows whose ``t^2`` was negative.
    """
    _check_mode(mode)
    K = np.atleast_2d(np.asarray(K, float))
    H = np.atleast_2d(np.asarray(H, float))
    if K.shape != H.shape:
        raise InputError(f"K and H must have the same (rows, cols) shape, got {K.shape} and "
                         f"{H.shape}")
    if not (np.all(np.isfinite(K)) and np.all(np.isfinite(H))):
        raise InputError("curvatures are not finite at some samples (singular "
                         "parametrization); check the initial surface")
    R, m = K.shape
    scale = max(float(np.max(np.abs(H))), math.sqrt(float(np.max(np.abs(K)))), 1e-300)
    if mode == "aa":
        n = np.zeros(R)
        beta = K.mean(axis=1)
    elif mode == "phlw":
        n, beta = np.empty(R), np.empty(R)
        for i in range(R):
            h, kk = H[i], K[i]
            if np.std(h) <= rtol * scale:
                n[i] = h.mean()
                beta[i] = np.mean(kk - 2 * n[i] * h)
            else:
                alpha, beta[i] = np.polyfit(h, kk, 1)
                n[i] = alpha / 2
    else:  # cnc: K_ij = 2 n H_ij + beta_i
        A = sp.hstack([sp.csr_matrix(2 * H.reshape(-1, 1)),
                       sp.kron(sp.identity(R), np.ones((m, 1)))]).toarray()
        Hc = H - H.mean(axis=1, keepdims=True)
        if np.linalg.norm(Hc) <= rtol * scale * math.sqrt(H.size):
            n0 = float(H.mean())
            n = np.full(R, n0)
            beta = (K - 2 * n0 * H).mean(axis=1)
        else:
            sol = np.linalg.lstsq(A, K.ravel(), rcond=None)[0]
            n, beta = np.full(R, sol[0]), sol[1:]
    t2 = -beta - n * n
    clamped = np.flatnonzero(t2 < 0)
    if mode == "phlw":
        # t = 0 would start from a degenerate net (beta = 0); start at beta = pi/4 instead:
        # n = mean H and the best intercept for it, t^2 = (mean H)^2 - mean K
        for i in clamped:
            n[i] = H[i].mean()
            t2[i] = n[i] ** 2 - K[i].mean()
    elif mode == "cnc" and len(clamped):
        n[:] = H.mean()
        t2 = (2 * n[:, None] * H - K).mean(axis=1) - n * n
    return RowFit(n, np.sqrt(np.maximum(t2, 0.0)), clamped)


# ============================================================================ evaluation helpers

def _grid_geometry(surf: BSplineSurface, u: np.ndarray, v: np.ndarray) -> dict[str, np.ndarray]:
    """Fundamental forms and curvatures on the grid ``u x v``, each ``(rows, cols)``."""
    D = surf.derivatives_grid(u, v)
    R, Cn = len(u), len(v)
    flat = {k: a.reshape(-1, 3) for k, a in D.items()}
    ff = fundamental_forms(flat["Su"], flat["Sv"], flat["Suu"], flat["Suv"], flat["Svv"])
    K, H, k1, k2 = curvatures(ff["E"], ff["F"], ff["G"], ff["L"], ff["M"], ff["N"])
    _, _, d1, _ = principal_directions(flat["Su"], flat["Sv"], ff["E"], ff["F"], ff["G"],
                                       ff["L"], ff["M"], ff["N"])
    with np.errstate(divide="ignore", invalid="ignore"):
        kI, kII = ff["L"] / ff["E"], ff["N"] / ff["G"]
        cos1 = np.abs(np.einsum("ij,ij->i", flat["Su"], d1)) / np.sqrt(ff["E"])
    ang = np.degrees(np.arccos(np.clip(cos1, 0.0, 1.0)))
    ang = np.minimum(ang, 90.0 - ang)           # S_u may follow either principal direction
    with np.errstate(divide="ignore", invalid="ignore"):
        ortho = np.degrees(np.abs(np.arcsin(np.clip(ff["F"] / np.sqrt(ff["E"] * ff["G"]),
                                                    -1, 1))))
    out = {"S": D["S"], "K": K, "H": H, "k1": k1, "k2": k2, "kI": kI, "kII": kII,
           "E": ff["E"], "F": ff["F"], "G": ff["G"], "M": ff["M"],
           "angle": np.maximum(ang, ortho)}
    return {k: (a.reshape(R, Cn) if k != "S" else a) for k, a in out.items()}


def row_relation_residual(surf: BSplineSurface, u_samples: np.ndarray, v_samples: np.ndarray,
                          n_rows: np.ndarray | None = None, t_rows: np.ndarray | None = None,
                          mode: Mode = "phlw") -> np.ndarray:
    """Relative residual of eq. 4.8 on the grid ``u_samples x v_samples``: ``(rows, cols)``.

    ``|K - 2 n H + n^2 + t^2| / max(|K|, |2 n H|, n^2 + t^2)``, i.e. the violation relative to
    the largest term of the relation (for ``n = 0`` this is ``|K - K_row| / |K|``). Without
    ``n_rows``/``t_rows`` they are fitted per row (:func:`fit_rows` with ``mode``), as paper
    4.2.2 does on a sampling other than the optimization's.
    """
    u = np.atleast_1d(np.asarray(u_samples, float))
    v = np.atleast_1d(np.asarray(v_samples, float))
    g = _grid_geometry(surf, u, v)
    K, H = g["K"], g["H"]
    if n_rows is None or t_rows is None:
        fit = fit_rows(K, H, mode)
        n_rows = fit.n if n_rows is None else n_rows
        t_rows = fit.t if t_rows is None else t_rows
    n = np.broadcast_to(np.asarray(n_rows, float).reshape(-1), (len(u),))[:, None]
    t = np.broadcast_to(np.asarray(t_rows, float).reshape(-1), (len(u),))[:, None]
    num = np.abs(K - 2 * n * H + n * n + t * t)
    den = np.maximum.reduce([np.abs(K), np.abs(2 * n * H), np.broadcast_to(n * n + t * t, K.shape)])
    with np.errstate(divide="ignore", invalid="ignore"):
        return num / np.maximum(den, 1e-300)


def principal_angle_error(surf: BSplineSurface, u_samples: np.ndarray,
                          v_samples: np.ndarray) -> np.ndarray:
    """Degrees by which the parameter lines miss the principal directions, ``(rows, cols)``:
    the larger of the angle between ``S_u`` and its nearest principal direction and the
    deviation of the angle between ``S_u`` and ``S_v`` from 90 degrees."""
    return _grid_geometry(surf, np.atleast_1d(u_samples), np.atleast_1d(v_samples))["angle"]


def phlw_energy(surf: BSplineSurface, n_rows: np.ndarray | None, t_rows: np.ndarray,
                samples: tuple[int, int] = (18, 18), *, omega_t: float = 0.1,
                scale: float | None = None) -> dict[str, float]:
    """E_PHLW (paper 4.2.1) of a surface with its auxiliary variables exact.

    With every auxiliary variable computed from the surface the residuals of eqs. 4.2-4.6
    vanish and ``E_PHLW = sum (F^2 + M^2) + omega_t sum chi_t^2`` over the samples. Evaluated
    on geometry scaled by ``1 / scale`` (default: the bounding-box diagonal of the samples)
    so that it is dimensionless.

    Returns
    -------
    dict : ``total``, ``principal`` (the ``F, M`` part), ``target`` (``omega_t * sum chi_t^2``),
        ``target_rms`` (RMS of ``chi_t`` in 1/m^2 of the scaled geometry).
    """
    u, v = uniform_params(surf, samples)
    g = _grid_geometry(surf, u, v)
    if scale is None:
        S = g["S"].reshape(-1, 3)
        scale = float(np.linalg.norm(S.max(0) - S.min(0))) or 1.0
    n = np.zeros(len(u)) if n_rows is None else \
        np.broadcast_to(np.asarray(n_rows, float).reshape(-1), (len(u),))
    t = np.asarray(t_rows, float).reshape(-1)
    # scale lengths by 1/scale: E, F, G by 1/scale^2 (param speeds), M by 1/scale, K by scale^2
    F = g["F"] / scale ** 2
    M = g["M"] / scale
    chi = (g["K"] - 2 * n[:, None] * g["H"] + (n * n + t * t)[:, None]) * scale ** 2
    Ep = float(np.sum(F * F) + np.sum(M * M))
    Et = float(omega_t * np.sum(chi * chi))
    return {"total": Ep + Et, "principal": Ep, "target": Et,
            "target_rms": float(np.sqrt(np.mean(chi * chi)))}


# ============================================================================ diagnostics

def _regions(mask: np.ndarray, u: np.ndarray, v: np.ndarray) -> list[dict[str, Any]]:
    """Connected regions of a boolean sample grid as parameter boxes."""
    from scipy import ndimage

    lab, nlab = ndimage.label(mask)
    out = []
    for sl in ndimage.find_objects(lab):
        su, sv = sl
        cnt = int(np.sum(lab[sl] > 0))
        out.append({"u": (float(u[su.start]), float(u[su.stop - 1])),
                    "v": (float(v[sv.start]), float(v[sv.stop - 1])), "samples": cnt})
    return out


@dataclass
class NetCheck:
    """Outcome of :func:`net_direction_check` on a ``rows x cols`` grid.

    sin2beta : (rows, cols) ``(n - kappa_I) / (kappa_II - kappa_I)`` (eq. 4.10), NaN at umbilics
    umbilic, out_of_range : (rows, cols) bool
    regions : list of ``{"kind": "umbilic" | "no-net", "u": (u0, u1), "v": (v0, v1), "samples"}``
    messages : one human-readable line per region
    """

    u: np.ndarray
    v: np.ndarray
    sin2beta: np.ndarray
    umbilic: np.ndarray
    out_of_range: np.ndarray
    regions: list[dict[str, Any]] = field(default_factory=list)
    messages: list[str] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return not self.regions


def net_direction_check(surf: BSplineSurface, n_rows: np.ndarray | None,
                        u_rows: np.ndarray | None = None, *,
                        samples: tuple[int, int] | None = None,
                        u_samples: np.ndarray | None = None, v_samples: np.ndarray | None = None,
                        umbilic_tol: float = 1e-3) -> NetCheck:
    """Where the net of normal curvature ``n_u`` has a real direction (eq. 4.10).

    ``sin^2 beta = (n_u - kappa_I) / (kappa_II - kappa_I)`` with ``kappa_I = L / E``,
    ``kappa_II = N / G`` (normal curvatures along ``S_u``, ``S_v``: the principal ones on a
    principal parametrization). Umbilics (``|kappa_II - kappa_I| <= umbilic_tol *`` the
    surface's curvature scale) leave ``beta`` undefined; ``sin^2 beta`` outside ``[0, 1]``
    (``n_u`` outside ``[kappa_I, kappa_II]``) means no real net direction.

    Parameters
    ----------
    surf : the (optimized) surface
    n_rows : (len(u_rows),) ``n_u`` per row, a single value (cnc) or None (aa: ``n = 0``)
    u_rows : (len(n_rows),) u values of ``n_rows``; default: the uniform sampling of
        ``len(n_rows)`` rows. ``n_u`` is interpolated linearly onto the check rows.
    samples : (rows, cols) check grid (default: ``len(n_rows) x len(n_rows)``), or explicit
        ``u_samples`` / ``v_samples``.
    """
    if u_samples is None or v_samples is None:
        if samples is None:
            m = 18 if n_rows is None or np.size(n_rows) == 1 else int(np.size(n_rows))
            samples = (m, m)
        u_samples, v_samples = uniform_params(surf, samples)
    u = np.asarray(u_samples, float)
    v = np.asarray(v_samples, float)
    if n_rows is None:
        n = np.zeros(len(u))
    elif np.size(n_rows) == 1:
        n = np.full(len(u), float(np.ravel(n_rows)[0]))
    else:
        nr = np.asarray(n_rows, float).ravel()
        ur = uniform_params(surf, (len(nr), 2))[0] if u_rows is None else np.asarray(u_rows, float)
        n = np.interp(u, ur, nr)
    g = _grid_geometry(surf, u, v)
    kI, kII = g["kI"], g["kII"]
    scale = float(np.nanmax(np.maximum(np.abs(kI), np.abs(kII))))
    gap = kII - kI
    umb = ~(np.abs(gap) > umbilic_tol * max(scale, 1e-300))
    with np.errstate(divide="ignore", invalid="ignore"):
        s2 = np.where(umb, np.nan, (n[:, None] - kI) / gap)
    bad = ~umb & ~((s2 >= 0) & (s2 <= 1))
    regions, msgs = [], []
    for kind, mask, what in (("umbilic", umb, "umbilic (kappa_I = kappa_II: net angle undefined)"),
                             ("no-net", bad, "n_u outside [kappa_I, kappa_II]: no real net "
                                             "direction (eq. 4.10)")):
        for reg in _regions(mask, u, v):
            reg = {"kind": kind, **reg}
            regions.append(reg)
            msgs.append(f"{what} at u in [{reg['u'][0]:.3f}, {reg['u'][1]:.3f}], v in "
                        f"[{reg['v'][0]:.3f}, {reg['v'][1]:.3f}] ({reg['samples']} samples)")
    return NetCheck(u, v, s2, umb, bad, regions, msgs)


# ============================================================================ optimization

def check_reference_net(K: np.ndarray, H: np.ndarray, mode: str) -> None:
    """Raise :class:`NoNetError` if a surface with curvatures ``K, H`` at its samples (unit
    bounding-box diagonal) admits no net of ``mode`` anywhere: umbilic at every sample (no
    principal directions), or, in mode ``aa``, ``K > 0`` at every sample (no asymptotic
    directions)."""
    K, H = np.asarray(K, float), np.asarray(H, float)
    d = np.sqrt(np.maximum(H * H - K, 0.0))
    scale = np.maximum(np.abs(H) + d, FLAT_CURVATURE)
    if np.all(2 * d <= NEAR_UMBILIC * scale):
        raise NoNetError(
            f"the reference is umbilic at all {K.size} samples (kappa_I = kappa_II within "
            f"{100 * NEAR_UMBILIC:g} %, as on a plane or a sphere): it has no principal "
            "directions, so no PHLW / CNC / PK net can start from it; give a reference with "
            "distinct principal curvatures (e.g. a saddle or a torus patch), or design a "
            "geodesic gridshell (gridshell gg)")
    if mode == "aa" and np.all(K > 0):
        raise NoNetError(
            f"the reference has K > 0 at all {K.size} samples (it bends like a dome), and "
            "asymptotic directions exist only where K <= 0, so no AA net (n = 0) exists near "
            "it; use mode 'phlw' or 'cnc', or a reference with K < 0 (e.g. a saddle)")


@dataclass
class PHLWResult:
    """Outcome of :func:`optimize_phlw` (metres, 1/m, 1/m^2).

    surface : optimized BSplineSurface
    mode : "phlw" | "cnc" | "aa"
    u_rows : (rows,) u of every optimization row; ``v_samples (cols,)``
    n_rows, t_rows : (rows,) eq. 4.8 per u-row (n equal in cnc, zero in aa), 1/m
    abc : (rows, 3) ``a = 1, b = -2 n, c = n^2 + t^2`` of ``aK + bH + c = 0``
    history : per outer round ``{"round", "iterations", "energy0", "energy", "message",
        "terms", "time"}``
    report_before, report_after : per term ``{"weight", "energy", "rms", "max"}`` (scaled units),
        plus ``"E_PHLW"`` (:func:`phlw_energy`) and the acceptance figures
    converged : the last round's solve met a tolerance
    deviation : max distance of the surface (check sampling) to the reference, % of the
        reference's bounding-box diagonal
    diagnostics : human-readable lines (clamped rows, umbilic / no-net regions)
    net_check : :class:`NetCheck` at the optimization samples
    """

    surface: BSplineSurface
    mode: str
    u_rows: np.ndarray
    v_samples: np.ndarray
    n_rows: np.ndarray
    t_rows: np.ndarray
    abc: np.ndarray
    history: list[dict] = field(default_factory=list)
    report_before: dict = field(default_factory=dict)
    report_after: dict = field(default_factory=dict)
    converged: bool = False
    deviation: float = float("nan")
    diagnostics: list[str] = field(default_factory=list)
    net_check: NetCheck | None = None
    weights: dict = field(default_factory=dict)
    reference_diagonal: float = float("nan")


def _scaled_surface(surf: BSplineSurface, center: np.ndarray, scale: float) -> BSplineSurface:
    return BSplineSurface(surf.degree_u, surf.degree_v, surf.knots_u.copy(), surf.knots_v.copy(),
                          (surf.ctrl - center) / scale)


def _reference_arrays(reference: Any) -> tuple[np.ndarray, np.ndarray]:
    if hasattr(reference, "V") and hasattr(reference, "F"):
        V, F = reference.V, reference.F
    else:
        try:
            V, F = reference
        except (TypeError, ValueError):
            raise InputError("reference must be a mesh (V, F) or an object with V and F") from None
    V = np.asarray(V, float)
    F = np.asarray(F)
    if V.ndim != 2 or V.shape[1] != 3 or len(V) < 3:
        raise InputError(f"reference vertices must have shape (n, 3), n >= 3; got {V.shape}")
    return V, F


def deviation_percent(surf: BSplineSurface, V: np.ndarray, F: np.ndarray,
                      samples: tuple[int, int] = (60, 60)) -> float:
    """Max distance of the surface (sampled ``samples``) to the mesh ``(V, F)``, in % of the
    mesh's bounding-box diagonal."""
    from ..igl_adapter import closest_points

    u, v = uniform_params(surf, samples)
    P = surf.evaluate_grid(u, v).reshape(-1, 3)
    d2, _, _ = closest_points(P, V, F)
    diag = float(np.linalg.norm(V.max(0) - V.min(0)))
    return float(100.0 * np.sqrt(d2.max()) / diag)


def _acceptance(surf: BSplineSurface, n: np.ndarray, t: np.ndarray, u: np.ndarray, v: np.ndarray,
                mode: str, omega_t: float, diag: float) -> dict[str, float]:
    rel = row_relation_residual(surf, u, v, n, t)
    return {"E_PHLW": phlw_energy(surf, n, t, (len(u), len(v)), omega_t=omega_t, scale=diag),
            "relation_max_rel": float(np.nanmax(rel)),
            "angle_max_deg": float(np.nanmax(principal_angle_error(surf, u, v)))}


def phlw_problem(s0: BSplineSurface, data: Samples, lay: Layout, weights: dict[str, float],
                 reference: tuple[np.ndarray, np.ndarray], mode: Mode = "phlw"
                 ) -> tuple[Problem, np.ndarray, RowFit]:
    """The PHLW problem of one round (eqs. 4.2-4.8, E_beta, closeness, gliding) and its start.

    ``s0`` and ``reference = (V, F)`` are in unit-diagonal coordinates; ``weights`` are all
    of :data:`DEFAULT_WEIGHTS`. The auxiliary variables start exact on ``s0`` and the row
    coefficients from :func:`fit_rows`; closest points on the reference are computed here.
    Raises :class:`InputError` for a singular parametrization and :class:`NoNetError` where
    no net of ``mode`` exists (:func:`check_reference_net`).

    Returns
    -------
    (Problem, x0 (lay.size,), RowFit)
    """
    from ..igl_adapter import closest_points_with_normals

    R = int(data.row.max()) + 1
    aux = init_auxiliary(s0.ctrl.reshape(-1, 3), data)
    if not np.all(aux["delta"] > 0):
        raise InputError("the initial surface has a singular parametrization (S_u x S_v = 0) at "
                         f"{int(np.sum(~(aux['delta'] > 0)))} samples; refit the reference")
    check_reference_net(aux["K"], aux["H"], mode)
    fit = fit_rows(aux["K"].reshape(R, -1), aux["H"].reshape(R, -1), mode)
    vals = {"C": s0.ctrl.reshape(-1, 3), **aux, "t": fit.t}
    if mode == "phlw":
        vals["n"] = fit.n
    elif mode == "cnc":
        vals["n"] = fit.n[:1]
    x = lay.pack(vals)

    S0 = np.asarray(data.ops["S"] @ s0.ctrl.reshape(-1, 3))
    foot, nrm = closest_points_with_normals(S0, *reference)
    prob = Problem(lay)
    c = weights["constraints"]
    prob.add("normal (4.2)", c, normal_eq, data)
    prob.add("first form (4.3)", c, first_form_eq, data)
    prob.add("delta (4.4)", c, delta_eq)
    prob.add("sqrt delta", c, sqrt_delta_eq)
    prob.add("second form (4.5)", c, second_form_eq, data)
    prob.add("curvature (4.6)", c, curvature_eq)
    prob.add("principal (4.7)", c, principal_eq)
    prob.add("target (4.8)", weights["target"], phlw_target, data)
    prob.add("beta", weights["beta"], beta_fairness, data)
    prob.add("closeness", weights["closeness"], T.linear, T.Linear("C", data.ops["S"], foot))
    prob.add("gliding", weights["gliding"], sample_gliding,
             SampleGliding(data.ops["S"], foot, nrm))
    return prob, x, fit


def optimize_phlw(surf: BSplineSurface, reference: Any, *, mode: Mode = "phlw",
                  samples: tuple[int, int] = (18, 18), weights: dict[str, float] | None = None,
                  outer: int = 4, max_iter: int = 40, check_samples: tuple[int, int] = (60, 60),
                  progress: Callable[[str], None] | None = None) -> PHLWResult:
    """Optimize a B-spline towards a PHLW (``phlw``), CNC (``cnc``) or PK (``aa``) surface
    close to a reference mesh (paper 4.2.1).

    Parameters
    ----------
    surf : initial BSplineSurface (e.g. from :func:`gridshell.ncp.reference.initial_surface`)
    reference : the reference surface as ``(V (n,3), F (m,3|4))`` or a mesh with ``V``, ``F``;
        closest points on it are refreshed each outer round (libigl)
    mode : "phlw" one ``(n_u, t_u)`` per u-row; "cnc" one ``n`` for the whole surface;
        "aa" ``n = 0`` (PK surface, asymptotic net)
    samples : (rows, cols) optimization samples (paper: 18 x 18)
    weights : overrides of :data:`DEFAULT_WEIGHTS` (keys ``constraints``, ``target``, ``beta``,
        ``closeness``, ``gliding``); in mode ``aa`` ``beta`` defaults to 0 (see the code)
    outer : rounds of (refresh closest points, Levenberg-Marquardt solve)
    max_iter : solver iterations per round
    check_samples : sampling for the deviation figure
    progress : called with one line per round

    Returns
    -------
    PHLWResult
    """
    from ..igl_adapter import closest_points_with_normals

    _check_mode(mode)
    w = dict(DEFAULT_WEIGHTS)
    if mode == "aa":
        # n = 0 is fixed: E_beta has no net variable left to regularize and only pulls H -> 0
        # (towards a minimal surface); measured on a pseudosphere it moves K off row-constancy
        # by 1 %. Off by default in aa; pass weights={"beta": 5e-4} for the paper's setting.
        w["beta"] = 0.0
    for key, val in (weights or {}).items():
        if key not in w:
            raise InputError(f"unknown weight {key!r}; weights are {', '.join(w)}")
        w[key] = float(val)
    if int(outer) < 1 or int(max_iter) < 1:
        raise InputError(f"outer and max_iter must be >= 1, got {outer} and {max_iter}")
    V, Fr = _reference_arrays(reference)
    center = V.mean(axis=0)
    diag = float(np.linalg.norm(V.max(0) - V.min(0)))
    if not diag > 0:
        raise InputError("the reference mesh has zero extent; pass a real surface")
    Vs = (V - center) / diag
    s0 = _scaled_surface(surf, center, diag)
    u, v = uniform_params(s0, samples)
    R = len(u)
    data = make_samples(s0, u, v, mode)
    lay = make_layout(s0.n_ctrl, R * len(v), R, mode)

    prob, x, fit = phlw_problem(s0, data, lay, w, (Vs, Fr), mode)
    diagnostics: list[str] = []
    if len(fit.clamped):
        diagnostics.append(f"initial fit: t_u^2 < 0 (b^2 - 4ac > 0) on rows {fit.clamped.tolist()}"
                           "; restarted there from n_u = mean H (net angle pi/4)")

    before = {"terms": prob.report(x), **_acceptance(surf, fit.n / diag, fit.t / diag, u, v,
                                                     mode, w["target"], diag)}
    history: list[dict] = []
    sol = None
    t0 = time.perf_counter()
    for rnd in range(int(outer)):
        if rnd > 0:
            # re-project: auxiliaries exact from the control points, closest points refreshed
            x = lay.pack({**lay.unpack(x), **init_auxiliary(lay.view(x, "C"), data)})
            S = np.asarray(data.ops["S"] @ lay.view(x, "C"))
            foot, nrm = closest_points_with_normals(S, Vs, Fr)
            prob.set_data("closeness", T.Linear("C", data.ops["S"], foot))
            prob.set_data("gliding", SampleGliding(data.ops["S"], foot, nrm))
        sol = solve(prob, x, method="lm", max_iter=int(max_iter), damping=SOLVER_DAMPING,
                    tol_rel=SOLVER_TOL_REL)
        x = sol.x
        history.append({"round": rnd + 1, "iterations": sol.iterations, "energy0": sol.energy0,
                        "energy": sol.energy, "message": sol.message,
                        "terms": {k: v_["energy"] for k, v_ in sol.report.items()},
                        "time": time.perf_counter() - t0})
        if progress is not None:
            progress(f"round {rnd + 1}/{outer}: energy {sol.energy0:.3e} -> {sol.energy:.3e} "
                     f"in {sol.iterations} iterations ({sol.message})")

    ctrl = lay.view(x, "C").reshape(s0.shape[0], s0.shape[1], 3) * diag + center
    out_surf = BSplineSurface(surf.degree_u, surf.degree_v, surf.knots_u.copy(),
                              surf.knots_v.copy(), ctrl)
    t_rows = np.abs(lay.view(x, "t")) / diag
    if mode == "phlw":
        n_rows = lay.view(x, "n") / diag
    elif mode == "cnc":
        n_rows = np.full(R, lay.view(x, "n")[0] / diag)
    else:
        n_rows = np.zeros(R)
    abc = np.column_stack([np.ones(R), -2 * n_rows, n_rows ** 2 + t_rows ** 2])
    after = {"terms": prob.report(x), **_acceptance(out_surf, n_rows, t_rows, u, v, mode,
                                                    w["target"], diag)}
    check = net_direction_check(out_surf, n_rows if mode == "phlw" else
                                (n_rows[:1] if mode == "cnc" else None),
                                u_rows=u, u_samples=u, v_samples=v)
    diagnostics += check.messages
    if np.all(check.umbilic | check.out_of_range):
        raise NoNetError(
            f"after the optimization the net has no real direction at any of the "
            f"{check.umbilic.size} samples ({check.messages[0]}); the reference is too far from "
            f"a {mode.upper()} surface: give the optimizer more rounds / iterations, a smaller "
            "closeness or gliding weight, or another mode")
    dev = deviation_percent(out_surf, V, Fr, check_samples)
    return PHLWResult(surface=out_surf, mode=mode, u_rows=u, v_samples=v, n_rows=n_rows,
                      t_rows=t_rows, abc=abc, history=history, report_before=before,
                      report_after=after, converged=bool(sol.converged), deviation=dev,
                      diagnostics=diagnostics, net_check=check, weights=w,
                      reference_diagonal=diag)


# ============================================================================ output

def result_summary(res: PHLWResult) -> dict[str, Any]:
    """JSON-ready report of a :class:`PHLWResult` (what ``report.json`` holds)."""
    def clean(o: Any) -> Any:
        if isinstance(o, dict):
            return {str(k): clean(v) for k, v in o.items()}
        if isinstance(o, (list, tuple)):
            return [clean(v) for v in o]
        if isinstance(o, np.ndarray):
            return clean(o.tolist())
        if isinstance(o, np.generic):
            return o.item()
        if isinstance(o, float) and not math.isfinite(o):
            return None
        return o

    return clean({
        "mode": res.mode, "converged": res.converged, "deviation_percent": res.deviation,
        "reference_diagonal_m": res.reference_diagonal, "weights": res.weights,
        "samples": [len(res.u_rows), len(res.v_samples)],
        "control_points": list(res.surface.shape),
        "degree": [res.surface.degree_u, res.surface.degree_v],
        "before": res.report_before, "after": res.report_after,
        "rows": [{"u": float(u), "n": float(n), "t": float(t), "a": float(a), "b": float(b),
                  "c": float(c)} for u, n, t, (a, b, c) in zip(res.u_rows, res.n_rows, res.t_rows,
                                                             res.abc)],
        "history": res.history, "diagnostics": res.diagnostics,
        "net_regions": res.net_check.regions if res.net_check is not None else [],
    })


def write_phlw(directory: str | Any, res: PHLWResult, sample_grid: tuple[int, int] = (60, 60),
               overwrite: bool = True) -> dict[str, str]:
    """Write a PHLW design into ``directory`` atomically (all files or none).

    Files: ``surface.json`` (:meth:`BSplineSurface.save`), ``surface.obj`` (quad mesh sampled
    ``sample_grid`` over the domain: rows = u, columns = v, so principal lines are mesh
    polylines), ``rows.csv`` (``u, n_u, t_u, a, b, c`` per optimization row, 1/m),
    ``report.json`` (:func:`result_summary`), ``curvature_diagram.png`` (paper Fig. 11 at the
    optimization samples).

    Returns
    -------
    dict : file role -> final path
    """
    import json
    from pathlib import Path

    from ..atomic import atomic_dir, write_text
    from ..quadmesh import write_mesh
    from ..render.curvature_diagram import curvature_diagram

    directory = Path(directory)
    rows, cols = (int(s) for s in sample_grid)
    with atomic_dir(directory, overwrite=overwrite) as tmp:
        res.surface.save(tmp / "surface.json")
        mesh = res.surface.sample(rows, cols)
        write_mesh(tmp / "surface.obj", mesh.V, mesh.F)
        lines = ["u,n_u,t_u,a,b,c"] + [
            f"{u:.12g},{n:.12g},{t:.12g},{a:.12g},{b:.12g},{c:.12g}"
            for u, n, t, (a, b, c) in zip(res.u_rows, res.n_rows, res.t_rows, res.abc)]
        write_text(tmp / "rows.csv", "\n".join(lines) + "\n")
        write_text(tmp / "report.json", json.dumps(result_summary(res), indent=1) + "\n")
        g = _grid_geometry(res.surface, res.u_rows, res.v_samples)
        curvature_diagram(tmp / "curvature_diagram.png", g["H"], g["K"], res.n_rows, res.t_rows,
                          u_rows=res.u_rows, title=f"curvature diagram ({res.mode})")
    names = ("surface.json", "surface.obj", "rows.csv", "report.json", "curvature_diagram.png")
    return {n.split(".")[0] if n != "surface.obj" else "mesh": str(directory / n) for n in names}
