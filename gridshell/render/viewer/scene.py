"""The scene of the WebGL viewer: a bundle's surface, strips and joints as compact arrays.

Everything the page draws, in metres, as little-endian float32 / uint32 arrays in base64
(:func:`encode`, :func:`decode`; the strips' vertices, most of the scene, as uint16 over their
bounding box, :func:`quantized` / :func:`strip_vertices`):

- the **surface** (``surface.obj``, triangulated);
- the **strips**: each lamella axis resampled to ``m`` points by arc length and swept by the
  real section (:func:`gridshell.design.section.resolve_section`) into a closed solid
  (:func:`gridshell.geometry.strips3d.strip_solid`), one vertex array per **state** of the alignment
  sequence (``sequence/frame_*.obj``, else the deployed and the aligned joints), one face array;
- the **joints** of every state and the **net-loops** (quads of joint indices) with their
  Delta_a;
- **scalars** per axis sample for the colours: ``delta_a`` (Delta_a of the net-loops, paper
  5.1, in %, the largest of the loops at each joint, interpolated along the lamella) and, when
  ``structure.json`` exists, ``utilisation`` (its per-axis-point values, by arc length).

In a state ``k > 0`` the axes are carried with the joints (:func:`gridshell.geometry.net.move_joints`),
sampled at the same arc-length fractions as in the deployed state, and the strip frame takes
the normals of the net-loops at the joints of that state (oriented as in the state before; where
the loops have collapsed, the normal of the state before). The deployed state takes the
surface's normals at the joints; between joints the normals are interpolated by arc length.
Tangent (GG) strips lie in two layers that meet at the joints: family C1 on the side of the
normal, C3 on the other, each at half a thickness from the surface.
"""
from __future__ import annotations

import base64
import json
import os
from pathlib import Path
from typing import Any, Callable

import numpy as np

from gridshell.core.errors import InputError
from gridshell.geometry.net import polyline_arclength
from gridshell.geometry.strips3d import (is_tangent, nearest_vertex_normals, packed_strip_frames, strip_frames,
                         strip_solid_faces)
from gridshell.geometry.vectors import row_norms, unit_rows as _unit
from gridshell.design.section import resolve_section

__all__ = ["encode", "decode", "build_scene", "quantized", "scene_json", "strip_solids_vertices",
           "strip_vertices", "MAX_SAMPLES", "MAX_STATES", "QUANT"]

#: axis samples per lamella at most (and at least 8); the step is ~1/100 of the bbox diagonal
MAX_SAMPLES = 96
_STEP = 1.0 / 100.0
#: states of the alignment sequence shown at most (evenly picked, first and last kept)
MAX_STATES = 9
#: the strips' vertices are stored as uint16 over their bounding box: this many steps
QUANT = 65535
#: a joint's loops count as collapsed below this fraction of their deployed vector area
_COLLAPSED = 1e-3


def encode(a: np.ndarray, dtype: str) -> str:
    """Base64 of ``a`` as little-endian ``dtype`` ("f4" or "u4"), flattened."""
    arr = np.ascontiguousarray(np.asarray(a).reshape(-1), dtype=np.dtype(dtype).newbyteorder("<"))
    return base64.b64encode(arr.tobytes()).decode("ascii")


def quantized(X: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> str:
    """Base64 of the points ``X (k, 3)`` as little-endian uint16 per coordinate over the box
    ``lo``, ``hi`` (:data:`QUANT` steps: about 1.5e-5 of the box)."""
    span = np.where(hi > lo, hi - lo, 1.0)
    q = np.rint((np.asarray(X, float).reshape(-1, 3) - lo) / span * QUANT)
    return encode(np.clip(q, 0, QUANT), "u2")


def strip_vertices(S: dict[str, Any], k: int) -> np.ndarray:
    """The strip vertices ``(nv, 3)`` (metres) of state ``k`` of a scene (:func:`build_scene`),
    from their uint16 quantization (:func:`quantized`)."""
    st = S["strips"]
    lo, hi = np.asarray(st["quant"]["lo"], float), np.asarray(st["quant"]["hi"], float)
    span = np.where(hi > lo, hi - lo, 1.0)
    return lo + decode(st["V"][k], "u2").reshape(-1, 3).astype(float) / QUANT * span


def decode(text: str, dtype: str) -> np.ndarray:
    """The flat array of :func:`encode`."""
    return np.frombuffer(base64.b64decode(text), dtype=np.dtype(dtype).newbyteorder("<"))


def _interp_rows(x: np.ndarray, rx: np.ndarray, xp: np.ndarray, rxp: np.ndarray
                 ) -> Callable[[np.ndarray], np.ndarray]:
    """``np.interp`` in many rows at once, bit for bit: the function of ``fp (..., M, c)`` that
    gives ``(..., N, c)`` with ``np.interp(x[rx == r], xp[rxp == r], fp[..., rxp == r, c])``
    for every row ``r`` and column ``c`` (0 in a row without knots).

    ``xp (M,)`` must be sorted by row ``rxp (M,)``, then by value, and ``x (N,)``, ``xp``
    finite. The knot of each ``x`` is found once, for any number of ``fp``: the last of its
    row at or below it (``searchsorted`` in the (row, value) pairs, ordered as complex numbers
    are, lexicographically), and the value is numpy's: ``fp[j]`` at or beyond the row's ends
    or on a knot, else ``slope * (x - xp[j]) + fp[j]`` with ``slope = (fp[j+1] - fp[j]) /
    (xp[j+1] - xp[j])``, the same operations in the same order.
    """
    x, xp = np.asarray(x, float), np.asarray(xp, float)
    rx, rxp = np.asarray(rx, np.int64), np.asarray(rxp, np.int64)
    ends = np.cumsum(np.bincount(rxp, minlength=int(rx.max(initial=-1)) + 1))
    first, last = (ends - np.bincount(rxp, minlength=len(ends)))[rx], ends[rx] - 1
    empty = last < first
    kp = np.empty(len(xp), complex)
    kp.real, kp.imag = rxp, xp
    kx = np.empty(len(x), complex)
    kx.real, kx.imag = rx, x
    j = np.searchsorted(kp, kx, side="right") - 1
    below = j < first
    j = np.where(empty, 0, np.minimum(np.maximum(j, first), last))
    inner = np.flatnonzero(~empty & ~below & (j < last))
    inner = inner[xp[j[inner]] != x[inner]]
    ji = j[inner]
    dx, at = xp[ji + 1] - xp[ji], x[inner] - xp[ji]
    gone = np.flatnonzero(empty)

    def lookup(fp: np.ndarray) -> np.ndarray:
        fp = np.asarray(fp, float)
        if not len(xp):
            return np.zeros(fp.shape[:-2] + (len(x),) + fp.shape[-1:])
        out = np.take(fp, j, axis=-2)
        f0, f1 = np.take(fp, ji, axis=-2), np.take(fp, ji + 1, axis=-2)
        # dx, at spread over the columns as full-shape views: the same numbers, and numpy's
        # loops run along the rows instead of once per 3-long row
        out[..., inner, :] = (f1 - f0) / np.broadcast_to(dx[:, None], f0.shape) \
            * np.broadcast_to(at[:, None], f0.shape) + f0
        out[..., gone, :] = 0.0
        return out
    return lookup


def _loop_area_vectors(J: np.ndarray, loops: np.ndarray) -> np.ndarray:
    """Sum of the vector areas of the loops at each joint ``(..., n, 3)``, m^2, of joints
    ``J (..., n, 3)`` (several states at once): the loops' areas added corner by corner (all
    first corners, then all second ones, ...), each loop in order, from 0."""
    J = np.asarray(J, float)
    L = np.asarray(loops, np.int64).reshape(-1, 4)
    A = 0.5 * np.cross(J[..., L[:, 2], :] - J[..., L[:, 0], :],
                       J[..., L[:, 3], :] - J[..., L[:, 1], :])        # (..., m, 3)
    lead, n, m = J.shape[:-2], J.shape[-2], len(L)
    cols = int(np.prod(lead, dtype=np.int64)) * 3
    # np.add.at(out, L[:, c], A) for c = 0..3 as one bincount: the same terms in the same order
    W = np.moveaxis(A.reshape(-1, m, 3), 0, 1).reshape(m, cols)       # (m, states * 3)
    idx = (L.T.reshape(-1)[:, None] * cols + np.arange(cols)).reshape(-1)
    out = np.bincount(idx, weights=np.tile(W, (4, 1)).reshape(-1), minlength=n * cols)
    return np.moveaxis(out.reshape(n, -1, 3), 1, 0).reshape(J.shape)


def joint_normals(states: list[np.ndarray], loops: np.ndarray, n0: np.ndarray) -> list[np.ndarray]:
    """Unit normals ``(n,3)`` at the joints of every state: ``n0`` in the first, the normals of
    the net-loops in the others, each oriented as in the state before and kept from it where
    the loops have collapsed (vector area below 1e-3 of the deployed one)."""
    out = [_unit(np.asarray(n0, float))]
    if not len(loops):
        return out * len(states)
    A = _loop_area_vectors(np.stack(states), loops)                    # (K, n, 3)
    size = row_norms(A)
    U = _unit(A)
    floor = _COLLAPSED * np.maximum(size[0], 1e-300)
    for k in range(1, len(states)):
        prev = out[-1]
        n = np.where(np.sum(U[k] * prev, axis=1, keepdims=True) < 0, -U[k], U[k])
        out.append(np.where((size[k] > floor)[:, None], n, prev))
    return out


def joint_delta_a(J: np.ndarray, loops: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Delta_a (paper 5.1, %) per net-loop ``(m,)`` and per joint ``(n,)`` (the largest of its
    loops; 0 at a joint without loops)."""
    from gridshell.measure.metrics import alignability_error

    loops = np.asarray(loops, np.int64).reshape(-1, 4)
    da = 100.0 * np.asarray(alignability_error(J, loops), float) if len(loops) else np.zeros(0)
    da = np.where(np.isfinite(da), da, 0.0)
    per_joint = np.zeros(len(J))
    for c in range(4):
        np.maximum.at(per_joint, loops[:, c], da)
    return da, per_joint


def _structure(bundle_dir: Path) -> dict[int, np.ndarray] | None:
    """``{lamella id: utilisation per axis point}`` of ``structure.json``, or None."""
    f = bundle_dir / "structure.json"
    if not f.is_file():
        return None
    try:
        d = json.loads(f.read_text(encoding="utf-8"))
        out = {int(r["id"]): np.asarray(r["utilisation"], float).reshape(-1)
               for r in d["lamellae"]}
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise InputError(f"{f}: not a structural check result ({exc!r}); re-run "
                         "'gridshell check DIR'") from None
    return out


def _states(bundle_dir: Path, bundle) -> tuple[list[np.ndarray], list[str]]:
    from gridshell.render.sequence import read_sequence, sequence_files

    if sequence_files(bundle_dir):
        frames, _ = read_sequence(bundle_dir)
        if all(f.shape == bundle.net.joints.shape for f in frames):
            K = len(frames) - 1
            keep = np.unique(np.linspace(0, K, min(K + 1, MAX_STATES)).round().astype(int))
            return [frames[k] for k in keep], [
                f"state {k}/{K}" + (" (deployed)" if k == 0 else " (aligned)" if k == K else "")
                for k in keep]
    return [bundle.net.joints, bundle.aligned], ["deployed", "aligned"]


def strip_solids_vertices(axes: list[np.ndarray], normals: list[np.ndarray], width: float,
                          thickness: float, tangent: bool) -> np.ndarray:
    """The vertices of :func:`gridshell.geometry.strips3d.strip_solid` of every axis ``(k_i,3)`` (metres,
    ``k_i >= 2``) with its normals, concatenated ``(4 sum k_i, 3)``: the same numbers, in one
    vectorized pass instead of one call per lamella (the frame's tangent is ``np.gradient``'s
    at unit spacing: central differences inside, one-sided at each axis's ends)."""
    _check_section(width, thickness)
    if not axes:
        return np.zeros((0, 3))
    P, _, _, W, H = strip_frames(axes, normals, tangent)
    return _solids_vertices(P, W, H, width, thickness)


def _check_section(width: float, thickness: float) -> None:
    if not (np.isfinite(width) and np.isfinite(thickness) and width > 0 and thickness > 0):
        raise InputError(f"strip solid: width {width!r} and thickness {thickness!r} must be "
                         "positive lengths in metres")


def _solids_vertices(P: np.ndarray, W: np.ndarray, H: np.ndarray, width: float,
                     thickness: float) -> np.ndarray:
    """The corners ``-W-H, +W-H, +W+H, -W+H`` of the sections at the axis points ``P``
    (:func:`gridshell.geometry.strips3d.strip_solid`'s vertices), ``(4 len(P), 3)``, metres."""
    _check_section(width, thickness)
    w, h = 0.5 * float(width) * W, 0.5 * float(thickness) * H
    return np.stack([P - w - h, P + w - h, P + w + h, P - w + h], axis=1).reshape(-1, 3)


def _axis_samples(net, use: list[int], states: list[np.ndarray], arcs: list[np.ndarray],
                  fracs: list[np.ndarray]) -> np.ndarray:
    """The points ``(K, T, 3)`` (metres) of the lamellae ``net.lamellae[i]``, ``i`` in ``use``,
    at their arc-length fractions ``fracs`` in each of the ``K`` states: on the axes in the
    first state (arc lengths ``arcs``), on the axes carried with the joints
    (:func:`gridshell.geometry.net.carried_axes`) in the others; samples of all lamellae one after the
    other (``T = sum len(fracs)``). A lamella of zero length gives its first point."""
    from gridshell.geometry.net import carried_axes

    K, n = len(states), len(use)
    every = carried_axes(net, list(states[1:]))
    carried = [every[i] for i in use]
    # the rows (lamella i, state k), numbered i * K + k, in order: knots xp, values fp
    xp = np.concatenate([a for s, (_, S) in zip(arcs, carried) for a in (s, S.reshape(-1))])
    fp = np.concatenate([a for i, (X, _) in zip(use, carried)
                         for a in (net.lamellae[i].axis, X.reshape(-1, 3))])
    counts = np.repeat([[len(s), S.shape[1]] for s, (_, S) in zip(arcs, carried)],
                       [1, K - 1], axis=1)
    length = np.concatenate([np.array([[s[-1]] for s in arcs]),
                             np.stack([S[:, -1] for _, S in carried])], axis=1)    # (n, K)
    sizes = [len(f) for f in fracs]
    lam = np.repeat(np.arange(n), sizes)
    rows = lam[None, :] * K + np.arange(K)[:, None]                      # (K, T)
    x = np.concatenate(fracs)[None, :] * length[lam].T
    rxp = np.repeat(np.arange(n * K), counts.reshape(-1))
    P = _interp_rows(x.reshape(-1), rows.reshape(-1), xp, rxp)(fp)
    zero = (length[lam].T <= 0).reshape(-1)
    if zero.any():
        P[zero] = fp[np.searchsorted(rxp, rows.reshape(-1)[zero])]
    return P.reshape(K, len(lam), 3)


def _sample_normals(lams: list, sizes: list[int], P0: np.ndarray, normals: list[np.ndarray],
                    at_joints: Callable[[np.ndarray], np.ndarray], joints: np.ndarray,
                    V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """The strips' normals ``(K, T, 3)`` at the axis samples of every state: the joints'
    ``normals`` interpolated by arc length (``at_joints`` of the lamellae's ``joints``), made
    unit; for a lamella with fewer than two joints the surface's nearest-vertex normal at its
    samples ``P0`` in the first state and its joint's normal in the others."""
    NS = np.stack(normals)
    N = _unit(at_joints(NS[:, joints]))  # smooth along the strip (the nearest vertex's is not)
    start = np.concatenate([[0], np.cumsum(sizes)])
    few = [i for i, lam in enumerate(lams) if len(lam.joints) < 2]
    if few and len(NS) > 1 and any(not len(lams[i].joints) for i in few):
        T = int(start[-1])
        none = sum(sizes[i] for i in few if not len(lams[i].joints))
        raise InputError(f"strip frame: {T} axis points but {T - none} normals")
    for i in few:
        a, b = start[i], start[i + 1]
        N[0, a:b] = nearest_vertex_normals(P0[a:b], V, F)
        N[1:, a:b] = NS[1:, lams[i].joints[:1]]
    return N


def _extremes(X: np.ndarray) -> np.ndarray:
    """``[X[k].min(axis=0), X[k].max(axis=0)]`` of every ``X[k] (n,3)``: ``(2, K, 3)``, the
    same numbers. Taken along contiguous rows (fast); a minimum or maximum that is not 0 is
    one value whatever the order, and where one is 0 (+0.0 or -0.0 may depend on the order)
    that state is taken as ``X[k].min(axis=0)``, ``X[k].max(axis=0)``."""
    Xt = np.ascontiguousarray(np.swapaxes(X, 1, 2))                   # (K, 3, n)
    out = np.stack([Xt.min(axis=2), Xt.max(axis=2)])
    for k in np.flatnonzero(np.any(out == 0.0, axis=(0, 2))):
        out[:, k] = X[k].min(axis=0), X[k].max(axis=0)
    return out


def _sample_fractions(lams: list, diag: float) -> tuple[list, list, list]:
    """Axis samples by arc-length fraction, fixed over the states: per lamella its arc
    lengths (metres), its sample fractions (one per ``_STEP * diag`` of length, 8 to
    ``MAX_SAMPLES``) and its joints' fractions."""
    arcs = [polyline_arclength(lam.axis) for lam in lams]
    fracs, joint_fracs = [], []
    for lam, s in zip(lams, arcs):
        L = float(s[-1])
        m = int(np.clip(np.ceil(L / (_STEP * diag)) + 1, 8, MAX_SAMPLES))
        fracs.append(np.linspace(0.0, 1.0, m))
        joint_fracs.append(np.clip(lam.joint_s / L, 0.0, 1.0) if L > 0 else lam.joint_s * 0)
    return arcs, fracs, joint_fracs


def _strip_meshes(P: np.ndarray, N: np.ndarray, lams: list, sizes: list[int], w: float,
                  t: float, tangent: bool) -> tuple[np.ndarray, np.ndarray, list]:
    """The strip solids (section ``w x t`` metres) on the axis samples ``P (K, T, 3)`` with
    normals ``N``: vertices ``(K, 4 T, 3)`` per state, faces (the same in every state:
    strip_solid's of each strip, one after the other) and per strip ``(v0, nv, f0, nf)``."""
    if tangent:  # two layers, bolted at the joints: C1 on the outer side, C3 inside
        side = np.repeat([0.5 * t if lam.family == 1 else -0.5 * t for lam in lams], sizes)
        P = P + side[None, :, None] * N
    K, T = P.shape[:2]
    frames = packed_strip_frames(P.reshape(-1, 3), N.reshape(-1, 3), np.tile(sizes, K), tangent)
    strip_V = _solids_vertices(frames[0], frames[3], frames[4], w, t).reshape(K, 4 * T, 3)
    Fk, offsets, nv, nf, of_k = [], [], 0, 0, {}
    for k in sizes:
        SF = of_k[k] if k in of_k else of_k.setdefault(k, strip_solid_faces(k))
        offsets.append((nv, 4 * k, nf, len(SF)))
        Fk.append(SF + nv)
        nv, nf = nv + 4 * k, nf + len(SF)
    return strip_V, np.concatenate(Fk), offsets


def _utilisation(structure: dict[int, np.ndarray], lams: list, arcs: list,
                 fracs: list) -> tuple[np.ndarray, dict[int, float]]:
    """structure.json's utilisation at every axis sample (NaN on a lamella it lacks), by
    arc length (spread evenly when not one value per axis point), and each lamella's max."""
    util, lam_util = [], {}
    for lam, s, f in zip(lams, arcs, fracs):
        u = structure.get(int(lam.id))
        if u is None or not len(u):
            util.append(np.full(len(f), np.nan))
            continue
        if len(u) == len(lam.axis):
            uf = s / s[-1] if s[-1] > 0 else np.linspace(0, 1, len(u))
        else:  # not one value per axis point: spread evenly
            uf = np.linspace(0.0, 1.0, len(u))
        util.append(np.interp(f, uf, u))
        lam_util[int(lam.id)] = float(np.nanmax(u))
    return np.concatenate(util), lam_util


def build_scene(bundle_dir: str | os.PathLike) -> dict[str, Any]:
    """The viewer's scene of a design bundle directory (see the module docstring).

    Returns a JSON-ready dict; arrays are base64 strings (:func:`decode` them with the dtype
    in their key's ``*_dtype`` companion or as documented: vertices ``f4``, faces ``u4``).
    """
    from gridshell.design.bundle import read_bundle

    d = Path(bundle_dir)
    b = read_bundle(d)
    section = resolve_section(d)
    w, t = section.width_m, section.thickness_m
    tangent = is_tangent(b.kind)
    net = b.net
    use = [i for i, lam in enumerate(net.lamellae) if len(lam.axis) >= 2]
    lams = [net.lamellae[i] for i in use]
    if not lams:
        raise InputError(f"{d}: no lamella axis with two points; nothing to show")
    states, labels = _states(d, b)
    V, F = np.asarray(b.surface_V, float), np.asarray(b.surface_F, np.int64)
    allP = np.concatenate([lam.axis for lam in lams] + [V])
    diag = float(np.linalg.norm(allP.max(axis=0) - allP.min(axis=0))) or 1.0

    arcs, fracs, joint_fracs = _sample_fractions(lams, diag)
    n0 = nearest_vertex_normals(states[0], V, F)
    normals = joint_normals(states, net.loops, n0)
    sizes = [len(f) for f in fracs]
    at_joints = _interp_rows(np.concatenate(fracs), np.repeat(np.arange(len(lams)), sizes),
                             np.concatenate(joint_fracs),
                             np.repeat(np.arange(len(lams)), [len(jf) for jf in joint_fracs]))
    joints = np.concatenate([lam.joints for lam in lams])

    P = _axis_samples(net, use, states, arcs, fracs)                      # (K, T, 3)
    N = _sample_normals(lams, sizes, P[0], normals, at_joints, joints, V, F)
    strip_V, strip_F, offsets = _strip_meshes(P, N, lams, sizes, w, t, tangent)

    loop_da, jda = joint_delta_a(states[0], net.loops)
    da = at_joints(jda[joints][:, None])[:, 0]
    scalars: dict[str, Any] = {"delta_a": encode(da, "f4")}
    structure = _structure(d)
    lam_util: dict[int, float] = {}
    if structure is not None:
        util, lam_util = _utilisation(structure, lams, arcs, fracs)
        scalars["utilisation"] = encode(util, "f4")

    Ftri = F if F.shape[1] == 3 else np.concatenate([F[:, [0, 1, 2]], F[:, [0, 2, 3]]])
    Ftri = Ftri[np.all(Ftri >= 0, axis=1)]
    lo, hi = allP.min(axis=0), allP.max(axis=0)
    lo_hi = _extremes(strip_V)
    q_lo = np.min([X.min(axis=0) for X in strip_V], axis=0)
    q_hi = np.max([X.max(axis=0) for X in strip_V], axis=0)
    return {
        "format": "gridshell.viewer", "version": 2, "kind": b.kind, "units": "m",
        "tangent": bool(tangent), "section": _section_json(section),
        "bbox": [lo.tolist(), hi.tolist()],
        "surface": {"V": encode(V, "f4"), "F": encode(Ftri, "u4"), "nv": len(V),
                    "nf": len(Ftri)},
        "strips": {"F": encode(strip_F, "u4"), "nv": int(len(strip_V[0])),
                   "nf": int(len(strip_F)),
                   "quant": {"lo": q_lo.tolist(), "hi": q_hi.tolist(), "steps": QUANT},
                   "V": [quantized(X, q_lo, q_hi) for X in strip_V]},
        "lamellae": _lamellae_json(lams, arcs, fracs, offsets, lam_util),
        "joints": {"n": int(len(net.joints)), "radius": min(0.6 * w, diag / 80.0),
                   "V": [encode(J, "f4") for J in states],
                   "delta_a": encode(jda, "f4")},
        "loops": {"m": int(len(net.loops)),
                  "F": encode(np.asarray(net.loops, np.int64).reshape(-1, 4), "u4"),
                  "delta_a": encode(loop_da, "f4")},
        "states": labels,
        "centres": (0.5 * (lo_hi[0] + lo_hi[1])).tolist(),
        "scalars": scalars,
        "delta_a": {"mean": float(np.mean(loop_da)) if len(loop_da) else None,
                    "max": float(np.max(loop_da)) if len(loop_da) else None},
        "has_structure": structure is not None,
        "max_utilisation": max(lam_util.values()) if lam_util else None,
    }


def _section_json(section) -> dict[str, Any]:
    """The strip's section of the scene: metres, mm, scale, where it came from, its text."""
    return {"width_m": section.width_m, "thickness_m": section.thickness_m,
            "width_mm": section.width_mm, "thickness_mm": section.thickness_mm,
            "scale": section.scale, "source": section.source, "text": section.text()}


def _lamellae_json(lams: list, arcs: list, fracs: list, offsets: list,
                   lam_util: dict[int, float]) -> list[dict[str, Any]]:
    """One record per drawn lamella: id, family, length (metres), samples, its strip's
    vertex and face ranges, and its max utilisation when structure.json gives one."""
    return [{"id": int(lam.id), "family": int(lam.family),
             "length": float(s[-1]), "samples": len(f),
             "v0": o[0], "nv": o[1], "f0": o[2], "nf": o[3],
             **({"max_utilisation": lam_util[int(lam.id)]}
                if int(lam.id) in lam_util else {})}
            for lam, s, f, o in zip(lams, arcs, fracs, offsets)]


def scene_json(bundle_dir: str | os.PathLike, faces: bool = True) -> str:
    """:func:`build_scene` as compact JSON, safe inside an HTML ``<script>`` element; without
    ``faces`` the strips' faces are left out (they depend on each lamella's number of samples
    alone, :func:`gridshell.geometry.strips3d.strip_solid_faces`: the viewer makes them)."""
    from gridshell.design.bundle import finite_json

    S = build_scene(bundle_dir)
    if not faces:
        S["strips"].pop("F")
    text = json.dumps(finite_json(S), separators=(",", ":"), allow_nan=False)
    # no "<" (base64 and numbers have none): no "</" either, and the 2 MB need no second scan
    return text.replace("</", "<\\/") if "<" in text else text
