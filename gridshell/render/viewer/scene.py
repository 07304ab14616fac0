"""The scene of the WebGL viewer: a bundle's surface, strips and joints as compact arrays.

Everything the page draws, in metres, as little-endian float32 / uint32 arrays in base64
(:func:`encode`, :func:`decode`):

- the **surface** (``surface.obj``, triangulated);
- the **strips**: each lamella axis resampled to ``m`` points by arc length and swept by the
  real section (:func:`gridshell.render.section.bundle_section`) into a closed solid
  (:func:`gridshell.strips3d.strip_solid`), one vertex array per **state** of the alignment
  sequence (``sequence/frame_*.obj``, else the deployed and the aligned joints), one face array;
- the **joints** of every state and the **net-loops** (quads of joint indices) with their
  Delta_a;
- **scalars** per axis sample for the colours: ``delta_a`` (Delta_a of the net-loops, paper
  5.1, in %, the largest of the loops at each joint, interpolated along the lamella) and, when
  ``structure.json`` exists, ``utilisation`` (its per-axis-point values, by arc length).

In a state ``k > 0`` the axes are carried with the joints (:func:`gridshell.net.move_joints`),
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
from typing import Any

import numpy as np

from ...errors import InputError
from ...strips3d import is_tangent, nearest_vertex_normals, strip_frames, strip_solid
from ..section import bundle_section

__all__ = ["encode", "decode", "build_scene", "scene_json", "strip_solids_vertices",
           "MAX_SAMPLES", "MAX_STATES"]

#: axis samples per lamella at most (and at least 8); the step is ~1/100 of the bbox diagonal
MAX_SAMPLES = 96
_STEP = 1.0 / 100.0
#: states of the alignment sequence shown at most (evenly picked, first and last kept)
MAX_STATES = 25
#: a joint's loops count as collapsed below this fraction of their deployed vector area
_COLLAPSED = 1e-3


def encode(a: np.ndarray, dtype: str) -> str:
    """Base64 of ``a`` as little-endian ``dtype`` ("f4" or "u4"), flattened."""
    arr = np.ascontiguousarray(np.asarray(a).reshape(-1), dtype=np.dtype(dtype).newbyteorder("<"))
    return base64.b64encode(arr.tobytes()).decode("ascii")


def decode(text: str, dtype: str) -> np.ndarray:
    """The flat array of :func:`encode`."""
    return np.frombuffer(base64.b64decode(text), dtype=np.dtype(dtype).newbyteorder("<"))


def _unit(X: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(X, axis=-1, keepdims=True)
    return np.divide(X, n, out=np.zeros_like(X), where=n > 0)


def _arc(P: np.ndarray) -> np.ndarray:
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(P, axis=0), axis=1))])


def _sample(P: np.ndarray, frac: np.ndarray) -> np.ndarray:
    """Points of polyline ``P (k,3)`` at arc-length fractions ``frac (m,)`` in [0, 1]."""
    s = _arc(P)
    if s[-1] <= 0:
        return np.repeat(P[:1], len(frac), axis=0)
    return np.stack([np.interp(frac * s[-1], s, P[:, c]) for c in range(3)], axis=1)


def _interp_along(frac: np.ndarray, joint_frac: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Per-joint ``values (j,...)`` at the arc-length fractions ``frac`` of a lamella."""
    values = np.asarray(values, float)
    if len(joint_frac) == 0:
        return np.zeros((len(frac),) + values.shape[1:])
    if len(joint_frac) == 1:
        return np.repeat(values[:1], len(frac), axis=0)
    if values.ndim == 1:
        return np.interp(frac, joint_frac, values)
    return np.stack([np.interp(frac, joint_frac, values[:, c]) for c in range(values.shape[1])],
                    axis=1)


def _loop_area_vectors(J: np.ndarray, loops: np.ndarray) -> np.ndarray:
    """Sum of the vector areas of the loops at each joint ``(n,3)``, m^2."""
    L = np.asarray(loops, np.int64).reshape(-1, 4)
    A = 0.5 * np.cross(J[L[:, 2]] - J[L[:, 0]], J[L[:, 3]] - J[L[:, 1]])
    out = np.zeros_like(J)
    for c in range(4):
        np.add.at(out, L[:, c], A)
    return out


def joint_normals(states: list[np.ndarray], loops: np.ndarray, n0: np.ndarray) -> list[np.ndarray]:
    """Unit normals ``(n,3)`` at the joints of every state: ``n0`` in the first, the normals of
    the net-loops in the others, each oriented as in the state before and kept from it where
    the loops have collapsed (vector area below 1e-3 of the deployed one)."""
    out = [_unit(np.asarray(n0, float))]
    if not len(loops):
        return out * len(states)
    A0 = np.linalg.norm(_loop_area_vectors(states[0], loops), axis=1)
    for J in states[1:]:
        A = _loop_area_vectors(J, loops)
        prev = out[-1]
        n = _unit(A)
        n = np.where(np.sum(n * prev, axis=1, keepdims=True) < 0, -n, n)
        ok = np.linalg.norm(A, axis=1) > _COLLAPSED * np.maximum(A0, 1e-300)
        out.append(np.where(ok[:, None], n, prev))
    return out


def joint_delta_a(J: np.ndarray, loops: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Delta_a (paper 5.1, %) per net-loop ``(m,)`` and per joint ``(n,)`` (the largest of its
    loops; 0 at a joint without loops)."""
    from ...metrics import alignability_error

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
    from ..sequence import read_sequence, sequence_files

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
    """The vertices of :func:`gridshell.strips3d.strip_solid` of every axis ``(k_i,3)`` (metres,
    ``k_i >= 2``) with its normals, concatenated ``(4 sum k_i, 3)``: the same numbers, in one
    vectorized pass instead of one call per lamella (the frame's tangent is ``np.gradient``'s
    at unit spacing: central differences inside, one-sided at each axis's ends)."""
    if not (np.isfinite(width) and np.isfinite(thickness) and width > 0 and thickness > 0):
        raise InputError(f"strip solid: width {width!r} and thickness {thickness!r} must be "
                         "positive lengths in metres")
    if not axes:
        return np.zeros((0, 3))
    P, _, _, W, H = strip_frames(axes, normals, tangent)
    w, h = 0.5 * float(width) * W, 0.5 * float(thickness) * H
    return np.stack([P - w - h, P + w - h, P + w + h, P - w + h], axis=1).reshape(-1, 3)


def build_scene(bundle_dir: str | os.PathLike) -> dict[str, Any]:
    """The viewer's scene of a design bundle directory (see the module docstring).

    Returns a JSON-ready dict; arrays are base64 strings (:func:`decode` them with the dtype
    in their key's ``*_dtype`` companion or as documented: vertices ``f4``, faces ``u4``).
    """
    from ...bundle import read_bundle
    from ...net import move_joints_states

    d = Path(bundle_dir)
    b = read_bundle(d)
    section = bundle_section(d)
    w, t = section.width_m, section.thickness_m
    tangent = is_tangent(b.kind)
    net = b.net
    lams = [lam for lam in net.lamellae if len(lam.axis) >= 2]
    if not lams:
        raise InputError(f"{d}: no lamella axis with two points; nothing to show")
    states, labels = _states(d, b)
    V, F = np.asarray(b.surface_V, float), np.asarray(b.surface_F, np.int64)
    allP = np.concatenate([lam.axis for lam in lams] + [V])
    diag = float(np.linalg.norm(allP.max(axis=0) - allP.min(axis=0))) or 1.0

    # axis samples by arc-length fraction, fixed over the states
    fracs, joint_fracs = [], []
    for lam in lams:
        L = float(_arc(lam.axis)[-1])
        m = int(np.clip(np.ceil(L / (_STEP * diag)) + 1, 8, MAX_SAMPLES))
        fracs.append(np.linspace(0.0, 1.0, m))
        joint_fracs.append(np.clip(lam.joint_s / L, 0.0, 1.0) if L > 0 else lam.joint_s * 0)
    n0 = nearest_vertex_normals(states[0], V, F)
    normals = joint_normals(states, net.loops, n0)

    strip_V, strip_F, offsets = [], None, []
    carried = [net] + move_joints_states(net, list(states[1:]))
    for k, J in enumerate(states):
        moved = carried[k]
        by_id = {lam.id: lam for lam in moved.lamellae}
        Pk, Nk, Fk, nv = [], [], [], 0
        for lam, frac, jf in zip(lams, fracs, joint_fracs):
            P = _sample(by_id[lam.id].axis, frac)
            if len(lam.joints) >= 2:  # smooth along the strip (the nearest vertex's is not)
                N = _unit(_interp_along(frac, jf, normals[k][lam.joints]))
            else:
                N = nearest_vertex_normals(P, V, F) if k == 0 else \
                    np.repeat(normals[k][lam.joints[:1]], len(P), axis=0)
            if tangent:  # two layers, bolted at the joints: C1 on the outer side, C3 inside
                P = P + (0.5 * t if lam.family == 1 else -0.5 * t) * N
            if k == 0:  # the faces (the same in every state) from the strip's own solid
                SV, SF = strip_solid(P, N, w, t, tangent)
                offsets.append((nv, len(SV), sum(len(f) for f in Fk), len(SF)))
                Fk.append(SF + nv)
                nv += len(SV)
            Pk.append(P)
            Nk.append(N)
        strip_V.append(strip_solids_vertices(Pk, Nk, w, t, tangent))
        if k == 0:
            strip_F = np.concatenate(Fk)

    loop_da, jda = joint_delta_a(states[0], net.loops)
    da = np.concatenate([_interp_along(f, jf, jda[lam.joints])
                         for lam, f, jf in zip(lams, fracs, joint_fracs)])
    scalars: dict[str, Any] = {"delta_a": encode(da, "f4")}
    structure = _structure(d)
    lam_util: dict[int, float] = {}
    if structure is not None:
        util = []
        for lam, f in zip(lams, fracs):
            u = structure.get(int(lam.id))
            if u is None or not len(u):
                util.append(np.full(len(f), np.nan))
                continue
            if len(u) == len(lam.axis):
                s = _arc(lam.axis)
                uf = s / s[-1] if s[-1] > 0 else np.linspace(0, 1, len(u))
            else:  # not one value per axis point: spread evenly
                uf = np.linspace(0.0, 1.0, len(u))
            util.append(np.interp(f, uf, u))
            lam_util[int(lam.id)] = float(np.nanmax(u))
        scalars["utilisation"] = encode(np.concatenate(util), "f4")

    Ftri = F if F.shape[1] == 3 else np.concatenate([F[:, [0, 1, 2]], F[:, [0, 2, 3]]])
    Ftri = Ftri[np.all(Ftri >= 0, axis=1)]
    lo, hi = allP.min(axis=0), allP.max(axis=0)
    centres = [(0.5 * (X.min(axis=0) + X.max(axis=0))).tolist() for X in strip_V]
    return {
        "format": "gridshell.viewer", "version": 1, "kind": b.kind, "units": "m",
        "tangent": bool(tangent),
        "section": {"width_m": w, "thickness_m": t, "width_mm": section.width_mm,
                    "thickness_mm": section.thickness_mm, "scale": section.scale,
                    "source": section.source, "text": section.text()},
        "bbox": [lo.tolist(), hi.tolist()],
        "surface": {"V": encode(V, "f4"), "F": encode(Ftri, "u4"), "nv": len(V),
                    "nf": len(Ftri)},
        "strips": {"F": encode(strip_F, "u4"), "nv": int(len(strip_V[0])),
                   "nf": int(len(strip_F)), "V": [encode(X, "f4") for X in strip_V]},
        "lamellae": [{"id": int(lam.id), "family": int(lam.family),
                      "length": float(_arc(lam.axis)[-1]), "samples": len(f),
                      "v0": o[0], "nv": o[1], "f0": o[2], "nf": o[3],
                      **({"max_utilisation": lam_util[int(lam.id)]}
                         if int(lam.id) in lam_util else {})}
                     for lam, f, o in zip(lams, fracs, offsets)],
        "joints": {"n": int(len(net.joints)), "radius": min(0.6 * w, diag / 80.0),
                   "V": [encode(J, "f4") for J in states],
                   "delta_a": encode(jda, "f4")},
        "loops": {"m": int(len(net.loops)),
                  "F": encode(np.asarray(net.loops, np.int64).reshape(-1, 4), "u4"),
                  "delta_a": encode(loop_da, "f4")},
        "states": labels,
        "centres": centres,
        "scalars": scalars,
        "delta_a": {"mean": float(np.mean(loop_da)) if len(loop_da) else None,
                    "max": float(np.max(loop_da)) if len(loop_da) else None},
        "has_structure": structure is not None,
        "max_utilisation": max(lam_util.values()) if lam_util else None,
    }


def scene_json(bundle_dir: str | os.PathLike) -> str:
    """:func:`build_scene` as compact JSON, safe inside an HTML ``<script>`` element."""
    from ...bundle import finite_json

    text = json.dumps(finite_json(build_scene(bundle_dir)), separators=(",", ":"),
                      allow_nan=False)
    return text.replace("</", "<\\/")
