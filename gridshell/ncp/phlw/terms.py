"""The terms of the PHLW / CNC / PK surface design (paper 4.2.1, eqs. 4.2-4.8) and their
exact initialization from control points.

Conventions (shared by :mod:`.phlw`, :mod:`.phlw_checks`)
-------------------------------------------------------
- Rows: the optimization samples a uniform ``rows x cols`` grid ``(u_i, v_j)`` of the domain.
  A *u-row* is the curve ``u = u_i`` (a principal line along ``S_v`` once ``F = M = 0``,
  eq. 4.7); ``n_u, t_u`` are constant along it. Sample ``s = i * cols + j``.
- Normal and signs follow :mod:`gridshell.geometry.diffgeo`: ``U = S_u x S_v`` (eq. 4.2), curvatures
  are positive when the surface bends towards ``U``, ``H = (LG - 2MF + NE) / (2 delta)``
  (eq. 4.6 with ``+ NE``: the paper's ``- NE`` is a typo).
- Variables (one :class:`~gridshell.solver.Layout`): ``C (nc, 3)`` control points; per sample
  ``U (k, 3)``, ``E, F, G, delta, w, L, M, N, K, H (k,)`` with ``w = sqrt(delta)``; ``n``
  (``rows`` values in mode ``phlw``, one in ``cnc``, absent in ``aa``) and ``t (rows,)``.
"""
from __future__ import annotations

from typing import Any, Literal, NamedTuple

import numpy as np
import scipy.sparse as sp

from gridshell.geometry.bspline import BSplineSurface
from gridshell.geometry.diffgeo import curvatures
from gridshell.core.errors import InputError
from gridshell.solver import Layout, TermResult, result, term

Mode = Literal["phlw", "cnc", "aa"]
MODES = ("phlw", "cnc", "aa")

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


@term
def boundary_inward(x: np.ndarray, layout: Layout, data: SampleGliding) -> TermResult:
    """``min(0, <S(u, v) - S_c^b, m^b>)`` with ``S = A C``: boundary samples may glide along the
    reference's boundary or overhang it, never move inside (``m^b`` the outward in-surface
    normal of the reference boundary at the closest point ``S_c^b``)."""
    C = layout.view(x, "C")
    S = np.asarray(data.A @ C)
    N = np.asarray(data.normal, float)
    d = np.einsum("ij,ij->i", S - data.foot, N)
    inside = d < 0
    k = len(d)
    rr, cc, vv = _cjac(data.A, layout.indices("C"), (N * inside[:, None])[:, None, :],
                       np.arange(k)[:, None])
    return result(np.where(inside, d, 0.0), rr, cc, vv)


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


class Regularity(NamedTuple):
    """Data of :func:`parametrization_guard`: floors of ``E, G, w`` per sample, ``(k,)`` each
    (positive; typically a fraction of their values on the initial surface)."""

    E: np.ndarray
    G: np.ndarray
    w: np.ndarray


@term
def parametrization_guard(x: np.ndarray, layout: Layout, data: Regularity) -> TermResult:
    """Keeps the parametrization regular: ``max(0, 1 - X / X_min)`` for ``X = E, G, w``
    (rows: E block, G block, w block; zero while every ``X >= X_min``).

    The constraints 4.3-4.6 are multiplied out (``L w = <S_uu, U>``, ``K delta = LN - M^2``):
    where ``E``, ``G`` or ``w = sqrt(delta)`` collapse they stop tying ``L, M, N, K, H`` to the
    surface and ``F = M = 0`` holds trivially, and ``w`` may cross zero to the other root of
    ``w^2 = delta`` (flipping ``L, M, N, H``). Measured on a freeform hill (cnc): ``G`` fell
    from 0.27 to 1e-6 and ``w`` to -0.2 in one round, the true E_PHLW rose to 1e12.
    """
    k = len(data.E)
    rs, parts = [], []
    for b, name in enumerate(("E", "G", "w")):
        X, lo = layout.view(x, name), np.asarray(getattr(data, name), float)
        active = X < lo
        rs.append(np.where(active, 1.0 - X / lo, 0.0))
        parts.append((b * k + np.arange(k), layout.indices(name), np.where(active, -1.0 / lo, 0.0)))
    return _assemble(np.concatenate(rs), parts)


class UmbilicMargin(NamedTuple):
    """Data of :func:`umbilic_guard`: the least ``H^2 - K = ((kappa_2 - kappa_1) / 2)^2`` per
    sample, ``(k,)`` or a scalar (positive, in the units of the optimized geometry)."""

    r2_min: np.ndarray | float


@term
def umbilic_guard(x: np.ndarray, layout: Layout, data: UmbilicMargin) -> TermResult:
    """Keeps the surface away from umbilics: ``max(0, 1 - (H^2 - K) / r2_min)`` per sample.

    ``H^2 - K`` is the squared half-gap of the principal curvatures; at an umbilic it is zero,
    the principal directions are undefined and eq. 4.8 forces ``t_u = 0`` (a degenerate net).
    Measured on a saddle (cnc, before this term and the round guards): the optimization drove
    288 of 324 samples to umbilics.
    """
    K, H = layout.view(x, "K"), layout.view(x, "H")
    lo = np.broadcast_to(np.asarray(data.r2_min, float), K.shape)
    active = H * H - K < lo
    ar = np.arange(len(K))
    r = np.where(active, 1.0 - (H * H - K) / lo, 0.0)
    return _assemble(r, [(ar, layout.indices("H"), np.where(active, -2 * H / lo, 0.0)),
                         (ar, layout.indices("K"), np.where(active, 1.0 / lo, 0.0))])
