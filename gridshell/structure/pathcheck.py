"""The check of an alignment path by elastics: a state's rod equilibrium with its joints held.

A geometric state of the path (the dense strips of ``sequence/strips.npz``,
:func:`gridshell.structure.states.read_strips`) is built as the rod network of the strips as
cut (:func:`gridshell.structure.deployed.build_model`: rest shape the cut shape, the real
section), every joint held at the position the state gives it (rotations free, the crossing
strips' joint axes common). Released, the strips between the joints settle into their elastic
equilibrium; where the state is the strips' own, they hardly move. :func:`state_equilibrium`
reports the largest and mean distance of the rod nodes from the state, in % of the design's
bounding-box diagonal (scale-free), and the utilisation at equilibrium.
"""
from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from gridshell.core.errors import InputError
from gridshell.design.bundle import DesignBundle
from gridshell.geometry.net import Lamella, Net, polyline_arclength
from gridshell.structure.materials import Material
from gridshell.structure.section import Section

__all__ = ["state_bundle", "state_equilibrium"]


def state_bundle(bundle: DesignBundle, strips: dict[str, Any], f: int) -> DesignBundle:
    """The design bundle in state ``f`` of the dense strips: every lamella's axis the state's
    dense strip, its joints where the strip passes them (a joint on two strips at the mean
    of the two), the net's loops unchanged; metres of the design."""
    X, lam_of, joint = strips["X"][f], strips["lamella"], strips["joint"]
    J = bundle.net.joints.copy()
    acc, cnt = np.zeros_like(J), np.zeros(len(J))
    lamellae = []
    for lam in bundle.net.lamellae:
        m = np.flatnonzero(lam_of == lam.id)
        at = joint[m] >= 0
        if len(m) < 2 or at.sum() < 2:
            continue
        P = X[m]
        s = polyline_arclength(P)
        js = joint[m][at]
        np.add.at(acc, js, P[at])
        np.add.at(cnt, js, 1.0)
        lamellae.append(Lamella(lam.id, lam.family, js, s[at], P))
    if not lamellae:
        raise InputError("the alignment path's strips name no lamella with two joints; "
                         "re-run the design")
    seen = cnt > 0
    J[seen] = acc[seen] / cnt[seen, None]
    return dataclasses.replace(bundle, net=Net(J, bundle.net.loops, lamellae))


def state_equilibrium(bundle: DesignBundle, strips: dict[str, Any], f: int,
                      material: Material, section: Section, *, per_bay: int = 4,
                      max_iter: int = 100) -> dict[str, Any]:
    """The rod equilibrium of state ``f`` with all its joints held (module docstring):
    ``deviation_max_pct`` / ``deviation_mean_pct`` of the rod nodes from the state (% of the
    design's diagonal), ``utilisation_peak`` at equilibrium, ``converged``, ``newton``."""
    from gridshell.structure.deployed import build_model
    from gridshell.structure.equilibrium import node_stresses, solve

    sb = state_bundle(bundle, strips, f)
    held = np.unique(np.concatenate([lam.joints for lam in sb.net.lamellae]))
    model = build_model(sb, material, section, supports=held, per_bay=per_bay)
    net = model.network
    res = solve(net, max_iter=max_iter)
    X0, X1 = net.X, net.positions(res.q)
    lo, hi = bundle.net.joints.min(0), bundle.net.joints.max(0)
    diag = float(np.linalg.norm(hi - lo)) * model.scale
    d = np.linalg.norm(X1 - X0, axis=1) / max(diag, 1e-300) * 100.0
    u = node_stresses(net, res.q, material, section)["utilisation"]
    return {"state": f"frame_{f:03d}", "t": float(strips["t"][f]),
            "deviation_max_pct": float(d.max(initial=0.0)),
            "deviation_mean_pct": float(d.mean()) if len(d) else 0.0,
            "utilisation_peak": float(np.max(u, initial=0.0)),
            "held_joints": int(len(held)), "converged": bool(res.converged),
            "newton": f"{res.iterations} iterations"}
