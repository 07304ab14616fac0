"""Tensor-product B-spline surfaces (paper eq. 4.1) as sparse linear operators on control points.

A surface ``S(u, v) = sum_ij N_i(u) N_j(v) C_ij`` is linear in its control points, and so are
its derivatives ``S_u, S_v, S_uu, S_uv, S_vv``. Everything here is therefore expressed as a
``scipy.sparse`` matrix acting on the flattened control points ``ctrl.reshape(-1, 3)``
(row-major: control point ``C_ij`` is row ``i * nv + j``), which is exactly what the
Gauss-Newton terms of the surface optimization (paper 4.2.1) need as Jacobian blocks.

Conventions
-----------
- ``u`` runs along the first control index (rows), ``v`` along the second (columns).
- Parameters live in the knot domain ``[knots[p], knots[n_ctrl]]``; with
  :func:`open_uniform_knots` that is ``[0, 1]``. The right end of the domain evaluates the
  last non-empty span (the curve interpolates the last control point there).
- Geometry (control points, evaluated points, residuals) is in metres; derivatives are in
  metres per unit parameter (squared for second derivatives).
"""
from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from gridshell.core.atomic import write_text
from gridshell.core.errors import InputError

FORMAT = "gridshell.bspline"
VERSION = 1

#: Parameters this far outside the knot domain are clipped onto it instead of rejected.
DOMAIN_TOL = 1e-10
#: Most control points per direction (the paper uses 9 to 12): more is a typo, not a design.
MAX_CTRL = 1000
#: Most samples of one tensor sampling (rows x cols): the paper's densest is 1200 x 1200.
MAX_SAMPLES = 5_000_000

__all__ = [
    "FORMAT",
    "VERSION",
    "BSplineSurface",
    "basis_matrix",
    "fit_grid",
    "fit_points",
    "local_basis",
    "open_uniform_knots",
    "paired_params",
    "uniform_params",
]


# ----------------------------------------------------------------------------- knots and basis


def open_uniform_knots(n_ctrl: int, degree: int) -> np.ndarray:
    """Clamped (open) uniform knot vector on ``[0, 1]``.

    Parameters
    ----------
    n_ctrl : int
        Number of control points, ``>= degree + 1``.
    degree : int
        Polynomial degree, ``>= 1``.

    Returns
    -------
    knots : (n_ctrl + degree + 1,) float
        ``degree + 1`` zeros, uniformly spaced interior knots, ``degree + 1`` ones.
    """
    n_ctrl, degree = int(n_ctrl), int(degree)
    if degree < 1:
        raise InputError(f"B-spline degree must be >= 1, got {degree}; use degree 2..5")
    if n_ctrl < degree + 1:
        raise InputError(f"{n_ctrl} control points cannot carry degree {degree}; "
                         f"use at least degree + 1 = {degree + 1} control points or a lower degree")
    if n_ctrl > MAX_CTRL:
        raise InputError(f"{n_ctrl} control points per direction is more than the {MAX_CTRL} "
                         "supported; use fewer (the paper uses 9 to 12)")
    interior = np.linspace(0.0, 1.0, n_ctrl - degree + 1)[1:-1]
    return np.concatenate([np.zeros(degree + 1), interior, np.ones(degree + 1)])


def _check_knots(knots: np.ndarray, degree: int, name: str = "knots") -> np.ndarray:
    """Validate a knot vector for ``degree``; return it as a float array."""
    knots = np.asarray(knots, dtype=float)
    if knots.ndim != 1:
        raise InputError(f"{name} must be a 1-D array, got shape {knots.shape}")
    if int(degree) != degree or degree < 1:
        raise InputError(f"B-spline degree must be an integer >= 1, got {degree!r}")
    if len(knots) < 2 * degree + 2:
        raise InputError(f"{name} has {len(knots)} entries; degree {degree} needs at least "
                         f"{2 * degree + 2} (n_ctrl + degree + 1 with n_ctrl >= degree + 1)")
    if not np.all(np.isfinite(knots)):
        raise InputError(f"{name} contains NaN or infinite values; use finite knots")
    if np.any(np.diff(knots) < 0):
        raise InputError(f"{name} must be non-decreasing; sort the knot vector")
    n_ctrl = len(knots) - degree - 1
    if not knots[degree] < knots[n_ctrl]:
        raise InputError(f"{name} has an empty domain [knots[{degree}], knots[{n_ctrl}]]; "
                         "the knot vector needs at least one non-empty span")
    return knots


def local_basis(knots: np.ndarray, degree: int, t: np.ndarray,
                 deriv: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Non-zero basis functions (or derivatives) at every parameter, vectorized over ``t``.

    Returns ``first (k,) int`` (index of the first non-zero basis function) and
    ``vals (k, degree + 1)`` with ``vals[s, r]`` the ``deriv``-th derivative of basis function
    ``first[s] + r`` at ``t[s]``. Knots and parameters are assumed validated.
    """
    p = degree
    n_ctrl = len(knots) - p - 1
    k = len(t)
    # Span s with knots[s] <= t < knots[s+1]; the right domain end falls in the last span.
    span = np.clip(np.searchsorted(knots, t, side="right") - 1, p, n_ctrl - 1)
    # at the right end (and with an interior knot equal to it) use the last non-empty span
    hi = knots[n_ctrl]
    span = np.where(t >= hi, int(np.searchsorted(knots, hi, side="left")) - 1, span)
    first = span - p
    if deriv > p:
        return first, np.zeros((k, p + 1))
    q0 = p - deriv
    # Cox-de Boor (Piegl & Tiller A2.2) up to degree q0, all parameters at once.
    vals = np.zeros((k, q0 + 1))
    vals[:, 0] = 1.0
    left = np.zeros((k, q0 + 1))
    right = np.zeros((k, q0 + 1))
    for j in range(1, q0 + 1):
        left[:, j] = t - knots[span + 1 - j]
        right[:, j] = knots[span + j] - t
        saved = np.zeros(k)
        for r in range(j):
            denom = right[:, r + 1] + left[:, j - r]
            temp = np.divide(vals[:, r], denom, out=np.zeros(k), where=denom != 0)
            vals[:, r] = saved + right[:, r + 1] * temp
            saved = left[:, j - r] * temp
        vals[:, j] = saved
    # Derivative recursion: d N_{i,q} = q (N_{i,q-1} / (t_{i+q} - t_i)
    #                                     - N_{i+1,q-1} / (t_{i+q+1} - t_{i+1})),
    # applied ``deriv`` times; it is linear, so it acts on values and derivatives alike.
    for q in range(q0 + 1, p + 1):
        idx = (span - q)[:, None] + np.arange(q + 1)[None, :]      # function index i
        d1 = knots[idx + q] - knots[idx]
        d2 = knots[idx + q + 1] - knots[idx + 1]
        prev = np.zeros((k, q + 2))
        prev[:, 1:q + 1] = vals             # prev[:, r] is N_{i, q-1} for i = span - q + r
        a = np.divide(prev[:, :q + 1], d1, out=np.zeros((k, q + 1)), where=d1 != 0)
        b = np.divide(prev[:, 1:q + 2], d2, out=np.zeros((k, q + 1)), where=d2 != 0)
        vals = q * (a - b)
    return first, vals


def _params(t: np.ndarray | float, knots: np.ndarray, degree: int, name: str = "t") -> np.ndarray:
    """Parameters as a 1-D float array inside the knot domain (clipping round-off)."""
    t = np.atleast_1d(np.asarray(t, dtype=float))
    if t.ndim != 1:
        raise InputError(f"{name} must be a 1-D array of parameters, got shape {t.shape}")
    if not np.all(np.isfinite(t)):
        raise InputError(f"{name} contains NaN or infinite parameters; pass finite values")
    lo, hi = knots[degree], knots[len(knots) - degree - 1]
    tol = DOMAIN_TOL * max(1.0, hi - lo)
    if t.size and (t.min() < lo - tol or t.max() > hi + tol):
        raise InputError(f"{name} has parameters in [{t.min():.6g}, {t.max():.6g}] outside the "
                         f"knot domain [{lo:.6g}, {hi:.6g}]; clip or rescale them")
    return np.clip(t, lo, hi)


def basis_matrix(knots: np.ndarray, degree: int, t: np.ndarray, deriv: int = 0) -> sp.csr_matrix:
    """B-spline basis functions (or their derivatives) at parameters ``t`` (eq. 4.1: ``N_i^d``).

    ``scipy.interpolate.BSpline.design_matrix`` has no derivative option, so this is a
    vectorized Cox-de Boor evaluation followed by the derivative recursion.

    Parameters
    ----------
    knots : (n_ctrl + degree + 1,) float
        Non-decreasing knot vector.
    degree : int
        Polynomial degree ``p >= 1``.
    t : (k,) float
        Parameters inside ``[knots[p], knots[n_ctrl]]``; the right end is evaluated in the last
        non-empty span.
    deriv : int, optional
        Order of the derivative, ``>= 0`` (zero matrix values above ``degree``).

    Returns
    -------
    B : (k, n_ctrl) scipy.sparse.csr_matrix
        ``B[s, i] = d^deriv N_i / dt^deriv (t[s])``; every row stores exactly ``degree + 1``
        entries (explicit zeros kept), so the sparsity pattern depends only on the spans.
    """
    degree = int(degree)
    knots = _check_knots(knots, degree)
    if int(deriv) != deriv or deriv < 0:
        raise InputError(f"deriv must be a non-negative integer, got {deriv!r}")
    t = _params(t, knots, degree)
    n_ctrl = len(knots) - degree - 1
    first, vals = local_basis(knots, degree, t, int(deriv))
    k, w = vals.shape
    cols = first[:, None] + np.arange(w)[None, :]
    indptr = np.arange(k + 1, dtype=np.int64) * w
    return sp.csr_matrix((vals.ravel(), cols.ravel(), indptr), shape=(k, n_ctrl))


# ----------------------------------------------------------------------------- surface


def _as_ctrl(ctrl: Any) -> np.ndarray:
    ctrl = np.asarray(ctrl, dtype=float)
    if ctrl.ndim != 3 or ctrl.shape[2] != 3:
        raise InputError(f"control points must have shape (nu, nv, 3), got {ctrl.shape}")
    if not np.all(np.isfinite(ctrl)):
        raise InputError("control points contain NaN or infinite values; use finite coordinates")
    return ctrl


def _check_spread(ctrl: np.ndarray) -> None:
    """:class:`InputError` for control points of a file that cannot carry a surface: all at one
    point or on one line (degenerate input), or spanning more than a gridshell can (metres,
    :data:`gridshell.geometry.quadmesh.EXTENT_RANGE`)."""
    from gridshell.geometry.quadmesh import EXTENT_RANGE

    P = ctrl.reshape(-1, 3)
    lo, hi = EXTENT_RANGE
    if np.abs(P).max() > hi:  # before any arithmetic that could overflow
        raise InputError(f"a control point lies at {np.abs(P).max():.3g} m from the origin, "
                         f"beyond the {hi:g} m a gridshell can have (out-of-range coordinates); "
                         "control points are read as metres - convert them")
    span = float(np.linalg.norm(P.max(axis=0) - P.min(axis=0)))
    if not span >= lo:
        raise InputError(f"the control points span {span:.3g} m: they all lie at one point, so "
                         "there is no surface (a degenerate input); re-export the surface")
    if span > hi:
        raise InputError(f"the control points span {span:.3g} m, beyond the {hi:g} m a "
                         "gridshell can have (out-of-range coordinates); control points are "
                         "read as metres - convert them")
    sv = np.linalg.svd(P - P.mean(axis=0), compute_uv=False)
    if not sv[1] > 1e-9 * sv[0]:
        raise InputError("the control points all lie on one line, so there is no surface (a "
                         "degenerate input); re-export the surface")


def paired_params(surf: "BSplineSurface", u: Any, v: Any, du: int, dv: int, who: str,
                   hint: str = "") -> tuple[np.ndarray, np.ndarray]:
    """Paired 1-D parameters ``u, v`` checked and clipped to the domain of ``surf``, after
    checking the derivative orders ``du, dv``; :class:`InputError` names ``who`` otherwise."""
    u = np.atleast_1d(np.asarray(u, dtype=float))
    v = np.atleast_1d(np.asarray(v, dtype=float))
    if u.shape != v.shape or u.ndim != 1:
        raise InputError(f"{who} needs paired 1-D u and v of equal length, got shapes "
                         f"{u.shape} and {v.shape}{hint}")
    for name, d in (("du", du), ("dv", dv)):
        if int(d) != d or d < 0:
            raise InputError(f"{name} must be a non-negative integer, got {d!r}")
    return (_params(u, surf.knots_u, surf.degree_u, "u"),
            _params(v, surf.knots_v, surf.degree_v, "v"))


_DERIVS = {"S": (0, 0), "Su": (1, 0), "Sv": (0, 1), "Suu": (2, 0), "Suv": (1, 1), "Svv": (0, 2)}


@dataclass
class BSplineSurface:
    """A tensor-product B-spline surface (eq. 4.1).

    Attributes
    ----------
    degree_u, degree_v : int
        Degrees ``d_u``, ``d_v``.
    knots_u : (nu + degree_u + 1,) float
        Knot vector in ``u``.
    knots_v : (nv + degree_v + 1,) float
        Knot vector in ``v``.
    ctrl : (nu, nv, 3) float
        Control points ``C_ij``, metres. Flattened row-major (``i * nv + j``) wherever an
        operator acts on them.
    """

    degree_u: int
    degree_v: int
    knots_u: np.ndarray
    knots_v: np.ndarray
    ctrl: np.ndarray

    def __post_init__(self) -> None:
        for name in ("degree_u", "degree_v"):
            d = getattr(self, name)
            if isinstance(d, bool) or not isinstance(d, (int, np.integer)) or d < 1:
                raise InputError(f"{name} must be an integer >= 1, got {d!r}")
            setattr(self, name, int(d))
        self.knots_u = _check_knots(self.knots_u, self.degree_u, "knots_u")
        self.knots_v = _check_knots(self.knots_v, self.degree_v, "knots_v")
        self.ctrl = _as_ctrl(self.ctrl)
        nu, nv, _ = self.ctrl.shape
        for axis, n, knots, d in (("u", nu, self.knots_u, self.degree_u),
                                  ("v", nv, self.knots_v, self.degree_v)):
            if len(knots) != n + d + 1:
                raise InputError(f"knots_{axis} has {len(knots)} entries but {n} control points of "
                                 f"degree {d} need n + d + 1 = {n + d + 1}; fix the knots or ctrl")

    # -- construction

    @classmethod
    def from_control_grid(cls, ctrl: np.ndarray, degree_u: int = 4,
                          degree_v: int = 4) -> "BSplineSurface":
        """Surface with open uniform knots on ``[0, 1]^2`` over a control grid ``(nu, nv, 3)``."""
        ctrl = _as_ctrl(ctrl)
        nu, nv, _ = ctrl.shape
        return cls(degree_u, degree_v, open_uniform_knots(nu, degree_u),
                   open_uniform_knots(nv, degree_v), ctrl.copy())

    # -- shape and domain

    @property
    def shape(self) -> tuple[int, int]:
        """``(nu, nv)``: number of control points in ``u`` and ``v``."""
        return self.ctrl.shape[0], self.ctrl.shape[1]

    @property
    def n_ctrl(self) -> int:
        """Total number of control points ``nu * nv``."""
        return self.ctrl.shape[0] * self.ctrl.shape[1]

    @property
    def domain(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """``((u_min, u_max), (v_min, v_max))``, the parameter domain."""
        nu, nv = self.shape
        return ((float(self.knots_u[self.degree_u]), float(self.knots_u[nu])),
                (float(self.knots_v[self.degree_v]), float(self.knots_v[nv])))

    # -- operators

    def basis_u(self, u: np.ndarray, du: int = 0) -> sp.csr_matrix:
        """``(k, nu)`` basis matrix in ``u`` (see :func:`basis_matrix`)."""
        return basis_matrix(self.knots_u, self.degree_u, u, du)

    def basis_v(self, v: np.ndarray, dv: int = 0) -> sp.csr_matrix:
        """``(k, nv)`` basis matrix in ``v`` (see :func:`basis_matrix`)."""
        return basis_matrix(self.knots_v, self.degree_v, v, dv)

    def operator(self, u: np.ndarray, v: np.ndarray, du: int = 0, dv: int = 0) -> sp.csr_matrix:
        """Sparse map from control points to a derivative at paired parameters (eq. 4.1).

        Parameters
        ----------
        u, v : (k,) float
            Paired parameters: sample ``s`` is ``(u[s], v[s])``.
        du, dv : int
            Derivative orders; ``(0,0) -> S``, ``(1,0) -> S_u``, ``(2,0) -> S_uu``,
            ``(1,1) -> S_uv`` etc.

        Returns
        -------
        A : (k, nu * nv) scipy.sparse.csr_matrix
            ``A @ ctrl.reshape(-1, 3)`` is the requested derivative (metres per parameter^(du+dv)).
            Row ``s`` is the Kronecker product of the ``u`` and ``v`` basis rows; each row has
            ``(d_u + 1)(d_v + 1)`` stored entries (a constant sparsity pattern per span).
        """
        u, v = paired_params(self, u, v, du, dv, "operator",
                              "; use operator_grid for a tensor grid")
        nu, nv = self.shape
        fu, bu = local_basis(self.knots_u, self.degree_u, u, int(du))
        fv, bv = local_basis(self.knots_v, self.degree_v, v, int(dv))
        k, wu = bu.shape
        wv = bv.shape[1]
        # Row-wise Kronecker product: column (fu + a) * nv + (fv + b), increasing in (a, b).
        cols = ((fu[:, None, None] + np.arange(wu)[None, :, None]) * nv
                + fv[:, None, None] + np.arange(wv)[None, None, :])
        vals = bu[:, :, None] * bv[:, None, :]
        indptr = np.arange(k + 1, dtype=np.int64) * (wu * wv)
        return sp.csr_matrix((vals.ravel(), cols.ravel(), indptr), shape=(k, nu * nv))

    def operator_grid(self, u: np.ndarray, v: np.ndarray, du: int = 0,
                      dv: int = 0) -> sp.csr_matrix:
        """Sparse map from control points to a derivative on the tensor grid ``u x v`` (eq. 4.1).

        Parameters
        ----------
        u : (a,) float
        v : (b,) float
        du, dv : int
            Derivative orders.

        Returns
        -------
        A : (a * b, nu * nv) scipy.sparse.csr_matrix
            Row ``p * b + q`` evaluates at ``(u[p], v[q])``.
        """
        Bu = self.basis_u(u, du)
        Bv = self.basis_v(v, dv)
        return sp.kron(Bu, Bv, format="csr")

    # -- evaluation

    def evaluate(self, u: np.ndarray, v: np.ndarray, du: int = 0, dv: int = 0) -> np.ndarray:
        """Points or derivatives ``(k, 3)`` at paired parameters (metres per parameter^(du+dv))."""
        return np.asarray(self.operator(u, v, du, dv) @ self.ctrl.reshape(-1, 3))

    def evaluate_grid(self, u: np.ndarray, v: np.ndarray, du: int = 0, dv: int = 0) -> np.ndarray:
        """Points or derivatives ``(a, b, 3)`` on the tensor grid ``u (a,) x v (b,)``."""
        u = np.atleast_1d(np.asarray(u, dtype=float))
        v = np.atleast_1d(np.asarray(v, dtype=float))
        Bu = self.basis_u(u, du)
        Bv = self.basis_v(v, dv)
        # Bu C Bv^T per coordinate, cheaper than the (a*b, nu*nv) Kronecker operator.
        nu, nv = self.shape
        T = np.asarray(Bu @ self.ctrl.reshape(nu, nv * 3)).reshape(len(u), nv, 3)
        R = np.asarray(Bv @ T.transpose(1, 0, 2).reshape(nv, len(u) * 3))
        return R.reshape(len(v), len(u), 3).transpose(1, 0, 2).copy()

    def derivatives(self, u: np.ndarray, v: np.ndarray) -> dict[str, np.ndarray]:
        """``S, Su, Sv, Suu, Suv, Svv`` at paired parameters, each ``(k, 3)``."""
        return {key: self.evaluate(u, v, du, dv) for key, (du, dv) in _DERIVS.items()}

    def derivatives_grid(self, u: np.ndarray, v: np.ndarray) -> dict[str, np.ndarray]:
        """``S, Su, Sv, Suu, Suv, Svv`` on the grid ``u (a,) x v (b,)``, each ``(a, b, 3)``."""
        return {key: self.evaluate_grid(u, v, du, dv) for key, (du, dv) in _DERIVS.items()}

    def sample(self, rows: int, cols: int):
        """Quad mesh of a uniform ``rows x cols`` grid over the parameter domain.

        Rows follow ``u``, columns ``v``; vertex ``i * cols + j`` is ``S(u_i, v_j)``; faces come
        from :func:`gridshell.geometry.grid.grid_quads`.

        Returns
        -------
        mesh : gridshell.geometry.quadmesh.QuadMesh
            ``V (rows * cols, 3)`` metres, ``F ((rows-1)(cols-1), 4)``.
        """
        from gridshell.geometry.grid import grid_quads          # local: keeps this module free of mesh imports
        from gridshell.geometry.quadmesh import QuadMesh

        rows, cols = int(rows), int(cols)
        if rows < 2 or cols < 2:
            raise InputError(f"sample needs at least 2 x 2 samples, got {rows} x {cols}")
        _check_sample_count(rows, cols)
        (u0, u1), (v0, v1) = self.domain
        P = self.evaluate_grid(np.linspace(u0, u1, rows), np.linspace(v0, v1, cols))
        return QuadMesh(P.reshape(-1, 3), grid_quads(rows, cols))

    # -- io

    def to_json(self) -> dict[str, Any]:
        """JSON-ready dict (format ``gridshell.bspline``, version 1, metres)."""
        return {
            "format": FORMAT,
            "version": VERSION,
            "units": "m",
            "degree_u": self.degree_u,
            "degree_v": self.degree_v,
            "knots_u": self.knots_u.tolist(),
            "knots_v": self.knots_v.tolist(),
            "ctrl": self.ctrl.tolist(),
        }

    @classmethod
    def from_json(cls, d: dict[str, Any]) -> "BSplineSurface":
        """Inverse of :meth:`to_json`; raises :class:`InputError` naming what is wrong."""
        if not isinstance(d, dict):
            raise InputError(f"a B-spline record must be a JSON object, got {type(d).__name__}")
        if d.get("format") != FORMAT:
            raise InputError(f"not a B-spline file: format is {d.get('format')!r}, "
                             f"expected {FORMAT!r}")
        if d.get("version") != VERSION:
            raise InputError(f"unsupported {FORMAT} version {d.get('version')!r}; this tool reads "
                             f"version {VERSION}; upgrade gridshell or re-export the surface")
        if d.get("units", "m") != "m":
            raise InputError(f"B-spline units must be 'm', got {d.get('units')!r}; "
                             "convert the control points to metres")
        missing = [k for k in ("degree_u", "degree_v", "knots_u", "knots_v", "ctrl") if k not in d]
        if missing:
            raise InputError(f"B-spline record misses {', '.join(missing)}; re-export the surface")
        try:
            knots_u = np.asarray(d["knots_u"], dtype=float)
            knots_v = np.asarray(d["knots_v"], dtype=float)
            ctrl = np.asarray(d["ctrl"], dtype=float)
        except (TypeError, ValueError) as exc:
            raise InputError(f"B-spline knots/ctrl are not numeric arrays ({exc}); "
                             "ctrl must be nested lists [[[x, y, z], ...], ...]") from exc
        surf = cls(d["degree_u"], d["degree_v"], knots_u, knots_v, ctrl)
        _check_spread(surf.ctrl)
        return surf

    def save(self, path: str | os.PathLike) -> None:
        """Write the surface as JSON to ``path`` atomically."""
        write_text(path, json.dumps(self.to_json(), indent=1) + "\n")

    @classmethod
    def load(cls, path: str | os.PathLike) -> "BSplineSurface":
        """Read a surface written by :meth:`save`, validating it."""
        path = Path(path)
        try:
            text = path.read_text(encoding="utf-8")
        except OSError as exc:
            raise InputError(f"cannot read B-spline file {path}: {exc.strerror or exc}; "
                             "check the path") from exc
        try:
            d = json.loads(text)
        except json.JSONDecodeError as exc:
            raise InputError(f"{path} is not valid JSON ({exc}); re-export the surface") from exc
        try:
            return cls.from_json(d)
        except InputError as exc:
            raise InputError(f"{path}: {exc}") from exc


# ----------------------------------------------------------------------------- fitting


def _chord_params(P: np.ndarray) -> np.ndarray:
    """Chord-length parameters along axis 0 of ``P (a, b, 3)``, averaged over axis 1: ``(a,)``."""
    seg = np.linalg.norm(np.diff(P, axis=0), axis=2)                # (a-1, b)
    cum = np.vstack([np.zeros((1, P.shape[1])), np.cumsum(seg, axis=0)])
    total = cum[-1]
    ok = total > 0
    if not np.any(ok):
        raise InputError("point grid rows coincide (zero chord length); "
                         "pass a grid whose rows are distinct or use params='uniform'")
    t = (cum[:, ok] / total[ok]).mean(axis=1)
    t[0], t[-1] = 0.0, 1.0
    return t


def _smoothness_operators(surf: BSplineSurface, m_u: int, m_v: int) -> list[sp.csr_matrix]:
    """Operators whose squared norms sum to the thin-plate energy sampled on an m_u x m_v grid."""
    (u0, u1), (v0, v1) = surf.domain
    uq = np.linspace(u0, u1, m_u)
    vq = np.linspace(v0, v1, m_v)
    return [surf.operator_grid(uq, vq, 2, 0),
            math.sqrt(2.0) * surf.operator_grid(uq, vq, 1, 1),
            surf.operator_grid(uq, vq, 0, 2)]


def _solve_fit(surf: BSplineSurface, A: sp.csr_matrix, P: np.ndarray,
               smoothing: float) -> tuple[BSplineSurface, float]:
    """Minimize ``mean |A C - P|^2 + w * thin_plate(C)``; return surface and RMS residual.

    ``w = smoothing * trace(A^T A / k) / trace(T)`` with ``T`` the thin-plate normal matrix.
    """
    k = A.shape[0]
    nu, nv = surf.shape
    Q = (A.T @ A) / k
    if smoothing > 0:
        T = None
        for R in _smoothness_operators(surf, max(2 * nu, 16), max(2 * nv, 16)):
            T = R.T @ R if T is None else T + R.T @ R
        # Dimensionless weight: the thin-plate stiffness is scaled to the data stiffness (ratio
        # of traces), so ``smoothing`` means the same for any n_ctrl, degree or sampling.
        Q = Q + (smoothing * Q.diagonal().sum() / T.diagonal().sum()) * T
    rhs = np.asarray(A.T @ P) / k
    try:
        solve = spla.factorized(sp.csc_matrix(Q))            # factor once, solve x, y, z
        C = np.column_stack([solve(rhs[:, c]) for c in range(3)])
    except RuntimeError as exc:                               # singular factor
        raise InputError(f"B-spline fit is singular ({exc}): too few points per control point; "
                         "increase smoothing or reduce n_ctrl_u / n_ctrl_v") from exc
    if not np.all(np.isfinite(C)):
        raise InputError("B-spline fit is singular (non-finite control points); "
                         "increase smoothing or reduce n_ctrl_u / n_ctrl_v")
    surf.ctrl = C.reshape(nu, nv, 3)
    res = np.asarray(A @ C) - P
    rms = float(np.sqrt(np.mean(np.sum(res * res, axis=1))))
    return surf, rms


def _fit_checks(n_ctrl_u: int, n_ctrl_v: int, degree_u: int, degree_v: int,
                smoothing: float) -> None:
    if not (np.isfinite(smoothing) and smoothing >= 0):
        raise InputError(f"smoothing must be a finite number >= 0, got {smoothing!r}")
    open_uniform_knots(n_ctrl_u, degree_u)   # raises on a bad count/degree pair
    open_uniform_knots(n_ctrl_v, degree_v)


def fit_grid(P: np.ndarray, n_ctrl_u: int = 9, n_ctrl_v: int = 9, degree_u: int = 4,
             degree_v: int = 4, params: Literal["chord", "uniform"] = "chord",
             smoothing: float = 1e-6) -> tuple[BSplineSurface, float]:
    """Least-squares B-spline fit of a structured point grid.

    Minimizes ``mean_s |S(u_s, v_s) - P_s|^2 + w * sum_q (|S_uu|^2 + 2|S_uv|^2 + |S_vv|^2)``,
    the second term a thin-plate regularizer sampled on a uniform grid of the domain, with
    ``w = smoothing * trace(data normal matrix) / trace(thin-plate normal matrix)`` so that
    ``smoothing`` is dimensionless and independent of ``n_ctrl``, degree and sampling. The
    normal equations are factored once (sparse LU) and solved for x, y, z.

    Parameters
    ----------
    P : (a, b, 3) float
        Points, metres; rows (first index) map to ``u``, columns to ``v``.
    n_ctrl_u, n_ctrl_v : int
        Control points per direction.
    degree_u, degree_v : int
        Degrees.
    params : {"chord", "uniform"}
        Parameters of the samples: averaged chord length per direction, or uniform in [0, 1].
    smoothing : float
        Relative weight of the thin-plate term, ``>= 0``. The default ``1e-6`` only stabilizes
        the system (it changes the curvature of a fitted sphere patch by ~1e-6 relative);
        ``1e-3 .. 1e-1`` visibly fairs noisy data.

    Returns
    -------
    surface : BSplineSurface
        Open uniform knots on ``[0, 1]^2``.
    residual_rms : float
        Root mean square distance between fitted and given points, metres.
    """
    P = np.asarray(P, dtype=float)
    if P.ndim != 3 or P.shape[2] != 3:
        raise InputError(f"fit_grid needs a point grid of shape (a, b, 3), got {P.shape}; "
                         "use fit_points for scattered points")
    if not np.all(np.isfinite(P)):
        raise InputError("point grid contains NaN or infinite values; remove or fill them")
    a, b, _ = P.shape
    if a < 2 or b < 2:
        raise InputError(f"fit_grid needs at least 2 x 2 points, got {a} x {b}")
    _fit_checks(n_ctrl_u, n_ctrl_v, degree_u, degree_v, smoothing)
    if params == "chord":
        u, v = _chord_params(P), _chord_params(P.transpose(1, 0, 2))
    elif params == "uniform":
        u, v = np.linspace(0.0, 1.0, a), np.linspace(0.0, 1.0, b)
    else:
        raise InputError(f"params must be 'chord' or 'uniform', got {params!r}")
    surf = BSplineSurface.from_control_grid(np.zeros((n_ctrl_u, n_ctrl_v, 3)), degree_u, degree_v)
    return _solve_fit(surf, surf.operator_grid(u, v), P.reshape(-1, 3), smoothing)


def fit_points(P: np.ndarray, u: np.ndarray, v: np.ndarray, n_ctrl_u: int = 9,
               n_ctrl_v: int = 9, degree_u: int = 4, degree_v: int = 4,
               smoothing: float = 1e-6) -> tuple[BSplineSurface, float]:
    """Least-squares B-spline fit of scattered points with known parameters.

    Same objective as :func:`fit_grid`; use it e.g. for a triangle mesh parameterized with
    :func:`gridshell.geometry.igl_adapter.parameterize_disk`. Control points without nearby samples
    are held by the thin-plate term, so keep ``smoothing > 0`` for scattered data.

    Parameters
    ----------
    P : (k, 3) float
        Points, metres.
    u, v : (k,) float
        Their parameters in ``[0, 1]``.
    n_ctrl_u, n_ctrl_v, degree_u, degree_v, smoothing
        As in :func:`fit_grid`.

    Returns
    -------
    surface : BSplineSurface
    residual_rms : float
        Metres.
    """
    P = np.asarray(P, dtype=float)
    if P.ndim != 2 or P.shape[1] != 3 or len(P) == 0:
        raise InputError(f"fit_points needs points of shape (k, 3), got {P.shape}")
    if not np.all(np.isfinite(P)):
        raise InputError("points contain NaN or infinite values; remove them")
    u = np.asarray(u, dtype=float).reshape(-1)
    v = np.asarray(v, dtype=float).reshape(-1)
    if len(u) != len(P) or len(v) != len(P):
        raise InputError(f"fit_points got {len(P)} points but {len(u)} u and {len(v)} v "
                         "parameters; pass one (u, v) per point")
    _fit_checks(n_ctrl_u, n_ctrl_v, degree_u, degree_v, smoothing)
    surf = BSplineSurface.from_control_grid(np.zeros((n_ctrl_u, n_ctrl_v, 3)), degree_u, degree_v)
    return _solve_fit(surf, surf.operator(u, v), P, smoothing)


def _check_sample_count(a: int, b: int) -> None:
    if a * b > MAX_SAMPLES:
        raise InputError(f"{a} x {b} samples are more than the {MAX_SAMPLES} supported; use a "
                         "coarser sampling (the paper's densest is 1200 x 1200)")


def uniform_params(surf: BSplineSurface, samples: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """Uniform sample parameters ``u (a,)``, ``v (b,)`` over the surface domain, ends included."""
    try:
        a, b = (int(s) for s in samples)
    except (TypeError, ValueError):
        raise InputError(f"samples must be a pair of integers, got {samples!r}") from None
    if a < 2 or b < 2:
        raise InputError(f"sampling needs at least 2 x 2 samples, got {a} x {b}")
    _check_sample_count(a, b)
    (u0, u1), (v0, v1) = surf.domain
    return np.linspace(u0, u1, a), np.linspace(v0, v1, b)
