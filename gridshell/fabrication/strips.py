"""Flat strips from a design bundle (issue item 1): the planar shape of every lamella.

* GG (tangent lamellae, geodesic axis) and AA (orthogonal, asymptotic axis) unroll to
  straight strips;
* CNC (orthogonal) to circular-arc strips of radius ``1/n`` (``collapse.radius`` or
  ``metrics["n"]``);
* NCP (orthogonal) to pieces of the planar collapse curve: joint 0 sits at the collapse
  curve position ``collapse_s[0]`` (0 when design.json has no ``collapse_s``), the other
  joints follow at the design's arc lengths ``joint_s``.

A strip spans the axis from ``min(0, joint_s[0])`` to ``max(length, joint_s[-1])`` plus the end
margin at both ends, all scaled to millimetres of the model.
"""
from __future__ import annotations

from collections import defaultdict

import numpy as np

from gridshell.design.bundle import DesignBundle, collapse_radius
from gridshell.design.bundle import strip_cut_shape as axis_shape
from gridshell.core.errors import InputError

from gridshell.fabrication.axis import ArcAxis, CurveAxis, DenseCurve, LineAxis
from gridshell.fabrication.params import FabParams
from gridshell.fabrication.strip import Strip

#: design kind -> lamella orientation relative to the surface
ORIENTATION = {"GG": "tangent", "AA": "orthogonal", "CNC": "orthogonal", "NCP": "orthogonal"}


def _edge_side(bundle: DesignBundle, shape: str) -> float:
    """+1 if the flattened surface normals point to the left of the collapse curve (towards
    the centre for a circle), -1 otherwise; +1 when unknown."""
    c = bundle.collapse
    if c is None or len(c.points) < 3 or len(c.normals) != len(c.points):
        return 1.0
    P = np.asarray(c.points, float)
    T = np.gradient(P, axis=0)
    left = np.stack([-T[:, 1], T[:, 0]], axis=1)
    side = float(np.sum(left * c.normals))
    if shape == "arc":
        d1, d2 = np.diff(P, axis=0)[:-1], np.diff(P, axis=0)[1:]
        side *= np.sign(np.sum(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])) or 1.0
    return 1.0 if side >= 0 else -1.0


def neighbours_by_joint(bundle: DesignBundle) -> dict[int, list[int]]:
    """Net joint index -> ids of the lamellae through it."""
    out: dict[int, list[int]] = defaultdict(list)
    for lam in bundle.net.lamellae:
        for j in lam.joints.tolist():
            out[j].append(int(lam.id))
    return out


def strips_from_bundle(bundle: DesignBundle, params: FabParams) -> list[Strip]:
    """One :class:`Strip` per lamella (not yet split to fit a sheet), in design order."""
    params.check_orientation(ORIENTATION[bundle.kind], bundle.kind)
    shape = axis_shape(bundle)
    mm = params.mm_per_m
    w = params.width
    side = _edge_side(bundle, shape)
    if params.axis == "centre":
        t_lo, t_hi = -w / 2, w / 2
    else:
        t_lo, t_hi = (0.0, w) if side > 0 else (-w, 0.0)
    through = neighbours_by_joint(bundle)
    dense = None
    if shape == "curve":
        dense = DenseCurve(np.asarray(bundle.collapse.points) * mm,
                           step=min(0.25, params.width / 40))
    arc = ArcAxis(1.0 / (collapse_radius(bundle) * mm)) if shape == "arc" else None
    strips = []
    for lam in bundle.net.lamellae:
        js = lam.joint_s * mm
        if len(js) == 0:
            raise InputError(f"lamella {lam.id} has no joints; re-run the design command")
        s0 = min(0.0, float(js[0])) - params.margin
        s1 = max(lam.length * mm, float(js[-1])) + params.margin
        if shape == "line":
            axis = LineAxis()
        elif shape == "arc":
            axis = arc
        else:
            cs = (bundle.collapse_s or {}).get(int(lam.id))
            if cs is not None and len(cs) != len(js):
                raise InputError(f"lamella {lam.id}: {len(cs)} collapse_s values for {len(js)} "
                                 "joints in design.json; re-run the NCP design")
            c_start = dense.arclength(float(cs[0]) * mm) if cs is not None else 0.0
            c0 = c_start + s0 - js[0]
            ext = 1.0 + params.kerf     # room for the kerf offset of the end edges
            axis = CurveAxis(dense.piece(c0 - ext, c0 + s1 - s0 + ext), s0=s0 - ext)
        axis.check_width(t_lo, t_hi, s0, s1)
        nb = [[i for i in through[j] if i != lam.id] for j in lam.joints.tolist()]
        strips.append(Strip(lamella=int(lam.id), family=int(lam.family),
                            orientation=ORIENTATION[bundle.kind], axis=axis, s0=s0, s1=s1,
                            t_lo=t_lo, t_hi=t_hi, joint_s=js, joint_index=lam.joints,
                            neighbours=nb))
    if not strips:
        raise InputError("the design bundle has no lamellae; re-run the design command")
    return strips
