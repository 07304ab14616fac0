"""Static equilibrium of a deployed gridshell and what it says: deviation from the design,
support reactions, stored energy and the strips' stresses.

:func:`solve` minimizes the rod network's total energy (elastic + load potential) with
Newton's method (:mod:`gridshell.structure.newton`); :func:`simulate` does it for a design
bundle and returns an :class:`Equilibrium` with the figures (model units: metres, newtons,
joules, pascals; deviations in % of the design's bounding-box diagonal, scale-free).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from gridshell.core.errors import ConvergenceError
from gridshell.structure import rod
from gridshell.structure.deployed import DeployedModel, Stiffness, build_model
from gridshell.structure.jet import Jet
from gridshell.structure.newton import NewtonResult, minimize
from gridshell.structure.rodnet import RodNetwork


def force_scale(net: RodNetwork, q: np.ndarray) -> float:
    """A force scale (N) of the network at ``q``: the largest load or internal elastic force
    component (the gradient of each energy group on its own)."""
    F = float(np.max(np.abs(net.forces), initial=0.0))
    for _, fn, idx, data in net.groups():
        J = fn(Jet.variables(q[idx], 1), data)
        F = max(F, float(np.max(np.abs(J.g), initial=0.0)))
    return F


def solve(net: RodNetwork, q0: np.ndarray | None = None, *, rtol: float = 1e-9,
          max_iter: int = 200, time_limit: float | None = None) -> NewtonResult:
    """Equilibrium of ``net`` from ``q0`` (default its initial state): Newton on the total
    energy over the unknowns not in ``net.fixed``, converged when every free gradient
    component is below ``rtol`` times :func:`force_scale` (or at its round-off floor)."""
    q0 = net.q0() if q0 is None else np.asarray(q0, float)
    gtol = rtol * max(force_scale(net, q0), 1e-300)
    return minimize(net, q0, ~net.fixed, gtol=gtol, max_iter=max_iter, accept=net.accept,
                    time_limit=time_limit)


@dataclass
class Equilibrium:
    """The equilibrium of a deployed gridshell (see :func:`simulate`).

    joints : (n,3) joint positions at equilibrium, design metres (the bundle's units)
    axes : per lamella its rod nodes at equilibrium, design metres
    axes0 : the same nodes in the design
    deviation : (n,) distance of each joint from the design, % of the design's bbox diagonal
    reactions : (k,3) support forces on the model, N, for the joints ``supports``
    energy : stored energy by part (stretch, bend, twist, joints), J, and "elastic" the sum
    stresses : per lamella id: worst utilisation and where; ``peak`` over all
    figures : the summary (what the CLI prints and equilibrium.json holds)
    """

    model: DeployedModel
    result: NewtonResult
    joints: np.ndarray
    axes: list[np.ndarray]
    axes0: list[np.ndarray]
    deviation: np.ndarray
    reactions: np.ndarray
    supports: np.ndarray
    energy: dict[str, float]
    stresses: dict[str, Any]
    figures: dict[str, Any] = field(default_factory=dict)


def node_stresses(net: RodNetwork, q: np.ndarray, material, section) -> dict[str, np.ndarray]:
    """Per interior vertex of the network at ``q``: curvature changes from the rest state
    (weak / strong axis, 1/m), twist rate (rad/m) and the stresses and utilisation of the strip
    (:func:`gridshell.structure.stresses.strip_stresses`)."""
    from gridshell.structure.stresses import StripCurvatures, strip_stresses

    V = Jet.variables(q[net.bend_idx], 0)
    d = net.bend_data()
    w1, w2, m = rod.strains(V, d)
    half = 0.5 * d.lbar
    k = StripCurvatures(weak=w2.v / half, strong=w1.v / half, twist=m.v / half)
    st = strip_stresses(k, section, material)
    return {"weak": k.weak, "strong": k.strong, "twist": k.twist, "sigma": st.sigma,
            "tau": st.tau, "utilisation": st.utilisation}


def _stress_summary(model: DeployedModel, q: np.ndarray) -> dict[str, Any]:
    net = model.network
    s = node_stresses(net, q, model.material, model.section)
    u = s["utilisation"]
    # interior vertices in rod order: rod r has len(nodes) - 2 of them
    out, start = {}, 0
    worst = (-1.0, None, None)
    for lid, nodes in zip(model.lamella_ids, model.lamella_nodes):
        k = max(len(nodes) - 2, 0)
        ur = u[start:start + k]
        if k:
            i = int(np.argmax(ur))
            P = net.positions(q)[nodes]
            s_at = float(np.linalg.norm(np.diff(P[:i + 2], axis=0), axis=1).sum())
            out[lid] = {"utilisation": float(ur[i]), "at_m": s_at / model.scale}
            if ur[i] > worst[0]:
                worst = (float(ur[i]), lid, s_at / model.scale)
        start += k
    return {"lamellae": out, "peak": worst[0], "peak_lamella": worst[1],
            "peak_at_m": worst[2],
            "peak_sigma_MPa": float(np.max(s["sigma"], initial=0.0)) / 1e6,
            "peak_tau_MPa": float(np.max(s["tau"], initial=0.0)) / 1e6}


def simulate(bundle, material, section, *, supports: str | np.ndarray = "boundary",
             gravity: bool = False, snow: float | None = None, per_bay: int = 3,
             stiffness: Stiffness | None = None,
             rtol: float = 1e-9, max_iter: int = 200, time_limit: float | None = None,
             progress: Callable[[str], None] | None = None, require: bool = True
             ) -> Equilibrium:
    """The static equilibrium of a design bundle (:class:`~gridshell.design.bundle.DesignBundle`)
    built in ``section`` of ``material`` (see :mod:`gridshell.structure.deployed`); ``snow``:
    a uniform snow load, kN per m2 of plan area on the simulated structure (with self-weight;
    :func:`gridshell.structure.loads.snow_forces`), which adds the deflection, span /
    deflection and the bolts' shear to the figures.

    Raises :class:`ConvergenceError` if Newton does not converge (``require``). Long because
    the figures are one flat record, each line one figure of equilibrium.json.
    """
    from gridshell.structure import loads

    t0, c0 = time.perf_counter(), time.process_time()
    gravity = gravity or bool(snow)
    model = build_model(bundle, material, section, supports=supports, gravity=gravity,
                        per_bay=per_bay, stiffness=stiffness)
    net = model.network
    snow_total = 0.0
    if snow:
        Fs = loads.snow_forces(bundle.net.joints * model.scale, bundle.net.loops, snow)
        on = model.joint_node >= 0
        np.add.at(net.forces, model.joint_node[on], Fs[on])
        snow_total = float(-Fs[on, 2].sum())
    if progress:
        progress(f"rod model: {len(net.rods)} lamellae, {len(net.X)} nodes, {net.n_edges} "
                 f"elements, {len(net.joints)} joints, {len(model.supports)} supports")
    q0 = net.q0()
    design_util = _stress_summary(model, q0)
    res = solve(net, q0, rtol=rtol, max_iter=max_iter, time_limit=time_limit)
    if require and not res.converged:
        raise ConvergenceError(f"the equilibrium did not converge: {res.message} after "
                               f"{res.iterations} Newton iterations (largest force residual "
                               f"{res.grad:.3g}); try a thicker strip, more supports or "
                               "--max-iter")
    q = res.q
    E, g, _, parts = net.energy(q, 1, parts=True)
    P = net.positions(q)
    sc = model.scale
    J0 = bundle.net.joints
    Jeq = J0.copy()
    used = model.joint_node >= 0
    Jeq[used] = P[model.joint_node[used]] / sc
    diag = float(np.linalg.norm(J0.max(0) - J0.min(0))) or 1.0
    dev = np.linalg.norm(Jeq - J0, axis=1) / diag * 100.0
    R = g[net.pos_dofs(model.supports)].reshape(-1, 3)
    energy = {k: float(v) for k, v in parts.items() if k != "loads"}
    energy["elastic"] = float(sum(energy.values()))
    stresses = _stress_summary(model, q)
    weight = float(-net.forces[:, 2].sum()) - snow_total
    ang = joint_mismatch(net, q)
    figures = {
        "kind": model.kind,
        "material": model.material.name,
        "section": f"{model.section.width_mm:g} x {model.section.thickness_mm:g} mm "
                   f"(edge ratio {model.section.edge_ratio:.3g}:1), scale {sc:g}",
        "rest state": model.rest,
        "gravity": (f"self-weight + snow {snow:g} kN/m2" if snow else
                    "self-weight" if gravity else "off"),
        "rod model": f"{len(net.rods)} lamellae, {len(net.X)} nodes, {net.n_edges} elements, "
                     f"{len(net.joints)} joints",
        "supports": int(len(model.supports)),
        "newton": f"{res.iterations} iterations, {res.message}",
        "converged": bool(res.converged),
        "deviation_mean_pct": float(dev[used].mean()),
        "deviation_max_pct": float(dev[used].max()),
        "deviation_max_joint": int(np.flatnonzero(used)[np.argmax(dev[used])]),
        "energy_J": energy["elastic"],
        "energy_parts_J": {k: v for k, v in energy.items() if k != "elastic"},
        "reaction_sum_N": R.sum(0).tolist(),
        "reaction_max_N": float(np.max(np.linalg.norm(R, axis=1), initial=0.0)),
        "weight_N": weight,
        "utilisation_design": design_util["peak"],
        "utilisation_peak": stresses["peak"],
        "utilisation_lamella": stresses["peak_lamella"],
        "sigma_peak_MPa": stresses["peak_sigma_MPa"],
        "tau_peak_MPa": stresses["peak_tau_MPa"],
        "joint_axis_mismatch_deg": float(ang),
        **(_under_load(model, res.q, J0, Jeq, used, snow, snow_total) if snow else {}),
        "wall_s": time.perf_counter() - t0,
        "cpu_s": time.process_time() - c0,
    }
    axes = [P[n] / sc for n in model.lamella_nodes]
    axes0 = [net.X[n] / sc for n in model.lamella_nodes]
    return Equilibrium(model, res, Jeq, axes, axes0, dev, R, model.supports, energy, stresses,
                       figures)


def _under_load(model: DeployedModel, q: np.ndarray, J0: np.ndarray, Jeq: np.ndarray,
                used: np.ndarray, snow: float, snow_total: float) -> dict[str, Any]:
    """The figures of a loaded equilibrium: snow (kN/m2, total kN), deflection (mm of the
    simulated structure), span / deflection, the largest bolt shear (N) and its joint."""
    from gridshell.structure import loads

    sc = model.scale
    nodes = model.joint_node[used]
    bolts = loads.bolt_forces(model.network, q, nodes)
    k = int(np.argmax(bolts)) if len(bolts) else 0
    fig = loads.deflection_figures(J0[used] * sc, Jeq[used] * sc, J0[model.supports] * sc)
    return {"snow_kN_m2": float(snow), "snow_total_kN": snow_total / 1e3, **fig,
            "bolt_shear_max_N": float(bolts[k]) if len(bolts) else 0.0,
            "bolt_shear_max_joint": int(np.flatnonzero(used)[k]) if len(bolts) else -1,
            "bolt_shear_mean_N": float(bolts[bolts > 0].mean()) if np.any(bolts > 0) else 0.0}


def joint_mismatch(net: RodNetwork, q: np.ndarray) -> float:
    """Largest angle (degrees) between the joint axes of two lamellae at a joint (what the
    joint penalty lets through)."""
    if not net.joints:
        return 0.0
    d = net.joint_data()
    E = rod.joint_energy(Jet.variables(q[net.joint_idx], 0), d).v
    diff = np.sqrt(np.maximum(2.0 * E / d.k, 0.0))  # |n_A - n_B|
    return float(np.degrees(2.0 * np.arcsin(np.clip(diff / 2.0, 0.0, 1.0))).max())
