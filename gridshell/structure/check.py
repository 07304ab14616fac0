"""The structural check of a design bundle: stresses along every lamella, in the deployed
state and in the states of the alignment sequence (``gridshell check``).

:func:`check_bundle` returns the content of ``structure.json`` (contract in
:func:`check_bundle`'s docstring); :func:`write_structure_json` writes it into the bundle.
Lengths: ``*_s_m`` along the design axis (metres of the design, like ``joint_s``), ``*_s_mm``
along the cut strip (mm of the model, like the cut files), radii and thicknesses of the real
strip (``min_radius_m``: metres of the model; ``*_thickness_mm``).
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Callable

import numpy as np

from gridshell.design.bundle import DesignBundle, finite_json, read_bundle
from gridshell.core.errors import InputError
from gridshell.structure.cutshape import collapse_curvature, cut_curvature, cut_shape
from gridshell.structure.frames import darboux_curvatures, surface_normals
from gridshell.structure.materials import Material
from gridshell.structure.section import Section
from gridshell.structure.sizing import advice, demand_from
from gridshell.structure.states import bundle_states, is_judged
from gridshell.structure.stresses import (KIND_ORIENTATION, StripCurvatures, max_elastic_thickness,
                       strip_curvatures, strip_stresses)

FILENAME = "structure.json"

CRITERION = ("von Mises of the largest bending stress (both axes adding at a corner of the "
             "section) and the largest torsional shear stress: u = sqrt(sigma^2 + 3 tau^2) / "
             "allowable; u <= 1 stays elastic")


def _sign_of_cut(kn: list[np.ndarray], k_cut: list[np.ndarray]) -> float:
    """+1 or -1: the orientation of the cut curvature against the surface normal that leaves
    the smaller strong-axis bending (the surface normal's orientation is arbitrary)."""
    a = np.concatenate(kn) if kn else np.zeros(0)
    b = np.concatenate(k_cut) if k_cut else np.zeros(0)
    return 1.0 if np.sum((a - b) ** 2) <= np.sum((a + b) ** 2) else -1.0


def _nearest_joint(lam, s: float) -> int:
    if not len(lam.joints):
        return -1
    return int(lam.joints[int(np.argmin(np.abs(lam.joint_s - s)))])


def lamella_record(lam, s: np.ndarray, k: StripCurvatures, section: Section,
                   material: Material) -> dict[str, Any]:
    """The ``structure.json`` record of one lamella from its per-point strip curvatures."""
    st = strip_stresses(k, section, material)
    u = st.utilisation
    i = int(np.argmax(u)) if len(u) else 0
    bend = k.bending
    kmax = float(bend.max()) if len(bend) else 0.0
    tmax = max_elastic_thickness(k, section, material)
    return {
        "id": int(lam.id), "family": int(lam.family),
        "utilisation": u.tolist(),
        "max_utilisation": float(u[i]) if len(u) else 0.0,
        "worst_s_m": float(s[i]) if len(s) else 0.0,
        "worst_s_mm": float(section.strip_length(s[i]) * 1e3) if len(s) else 0.0,
        "worst_joint": _nearest_joint(lam, float(s[i]) if len(s) else 0.0),
        "min_radius_m": 1.0 / kmax if kmax > 0 else float("inf"),
        "max_elastic_thickness_mm": float(tmax.min() * 1e3) if len(tmax) else section.width_mm,
        "max_weak_curvature_per_m": float(np.abs(k.weak).max()) if len(u) else 0.0,
        "max_strong_curvature_per_m": float(np.abs(k.strong).max()) if len(u) else 0.0,
        "max_twist_rad_per_m": float(np.abs(k.twist).max()) if len(u) else 0.0,
        "max_sigma_weak_MPa": float(st.sigma_weak.max() * 1e-6) if len(u) else 0.0,
        "max_sigma_strong_MPa": float(st.sigma_strong.max() * 1e-6) if len(u) else 0.0,
        "max_tau_MPa": float(st.tau.max() * 1e-6) if len(u) else 0.0,
        "length_m": float(s[-1]) if len(s) else 0.0,
    }


def deployed_curvatures(bundle: DesignBundle, section: Section
                        ) -> tuple[list[np.ndarray], list[StripCurvatures], float]:
    """Per lamella the axis arc lengths ``s`` (m) and the strip curvatures of the deployed
    design (dense axes, normals of ``surface.obj``), and the sign matching the cut shape."""
    orientation = KIND_ORIENTATION[bundle.kind]
    lams = bundle.net.lamellae
    axes = [np.asarray(lam.axis, float) for lam in lams]
    N_all = surface_normals(np.concatenate(axes) if axes else np.zeros((0, 3)),
                            bundle.surface_V, bundle.surface_F)
    normals = np.split(N_all, np.cumsum([len(a) for a in axes])[:-1]) if axes else []
    dcs = [darboux_curvatures(a, n) for a, n in zip(axes, normals)]
    k_cut = [np.zeros(len(dc.s)) for dc in dcs]
    sign = 1.0
    if orientation == "orthogonal":
        curve = collapse_curvature(bundle) if cut_shape(bundle) == "curve" else None
        k_cut = [cut_curvature(bundle, lam, dc.s, curve) for lam, dc in zip(lams, dcs)]
        sign = _sign_of_cut([dc.kn for dc in dcs], k_cut)
    ks = [strip_curvatures(dc, orientation, section, sign * kc) for dc, kc in zip(dcs, k_cut)]
    return [dc.s for dc in dcs], ks, sign


def check_bundle(bundle: DesignBundle | str | Path, material: Material, section: Section, *,
                 states: bool = True, bundle_dir: str | Path | None = None,
                 progress: Callable[[str], None] | None = None) -> dict[str, Any]:
    """Stresses the design imposes on its strips (``section`` of ``material``).

    Parameters
    ----------
    bundle : DesignBundle or path
        The design; a path also gives the alignment sequence (``sequence/frame_*.obj``) and,
        for NCP kinds, the joint axes (``axes_r.npy``, ``aligned_r.npy``).
    bundle_dir : path, optional
        Where those files are when ``bundle`` is a :class:`DesignBundle` already read.
    states : bool
        Also evaluate the collapsed state and the states of the alignment sequence.

    Returns
    -------
    dict
        ``{"material", "section", "criterion", "kind", "orientation", "cut_shape",
        "max_utilisation", "max_utilisation_deployed", "governing_state", "verdict",
        "states", "lamellae": [{"id", "family", "utilisation" (one value per point of the
        lamella's axis polyline, deployed), "max_utilisation", "worst_s_m", "worst_s_mm",
        "worst_joint", "min_radius_m", "max_elastic_thickness_mm", ...}],
        "max_elastic_thickness_mm", "min_radius_m", "worst": {...}}``. ``verdict`` is
        ``"ok"`` when every evaluated state stays elastic (``max_utilisation <= 1``),
        ``"overstressed"`` otherwise; states of a folded sequence (``states["unresolved"]``)
        and the intermediate states of an approximate path (``states["approximate"]``) are
        listed, not judged.
    """
    path = None if bundle_dir is None else Path(bundle_dir)
    if not isinstance(bundle, DesignBundle):
        path = Path(bundle)
        bundle = read_bundle(path)
    if not bundle.net.lamellae:
        raise InputError("the design bundle has no lamellae; nothing to check")
    say = progress or (lambda msg: None)
    say(f"stresses along {len(bundle.net.lamellae)} lamellae (deployed)")
    s_list, ks, sign = deployed_curvatures(bundle, section)
    lams = [lamella_record(lam, s, k, section, material)
            for lam, s, k in zip(bundle.net.lamellae, s_list, ks)]
    worst = max(lams, key=lambda r: r["max_utilisation"])
    u_dep = worst["max_utilisation"]
    out_states: dict[str, Any] = {}
    governing, u_all = "deployed", u_dep
    if states:
        say("stresses in the collapsed state and the alignment sequence")
        out_states = bundle_states(bundle, path, section, material)
        for st in out_states["frames"]:    # the deployed state: the dense check above
            if st["t"] > 0 and is_judged(st) and st["max_utilisation"] > u_all:
                governing, u_all = st["name"], st["max_utilisation"]
    finite_min = [r["min_radius_m"] for r in lams if np.isfinite(r["min_radius_m"])]
    demand = demand_from(ks, [lam.id for lam in bundle.net.lamellae], section.scale, out_states)
    return {
        "format": "gridshell.structure", "version": 1,
        "kind": bundle.kind, "orientation": KIND_ORIENTATION[bundle.kind],
        "cut_shape": cut_shape(bundle),
        "material": material.to_json(), "section": section.to_json(),
        "criterion": CRITERION,
        "max_utilisation": float(u_all),
        "max_utilisation_deployed": float(u_dep),
        "governing_state": governing,
        "verdict": "ok" if u_all <= 1.0 else "overstressed",
        "worst": {"lamella": worst["id"], "family": worst["family"],
                  "s_m": worst["worst_s_m"], "s_mm": worst["worst_s_mm"],
                  "joint": worst["worst_joint"], "utilisation": u_dep},
        "max_elastic_thickness_mm": float(min(r["max_elastic_thickness_mm"] for r in lams)),
        "min_radius_m": float(min(finite_min)) if finite_min else float("inf"),
        "units": {"utilisation": "equivalent stress / allowable stress",
                  "worst_s_m": "arc length along the design axis, metres of the design",
                  "worst_s_mm": "arc length along the cut strip, mm of the model",
                  "min_radius_m": "smallest bending radius of the real strip, metres "
                                  "(null: the strip stays straight)",
                  "curvatures": "of the real strip (model), 1/m; stresses MPa"},
        "advice": advice(demand, material, section, u_all, governing),
        "states": out_states,
        "lamellae": lams,
    }


def write_structure_json(bundle_dir: str | Path, result: dict[str, Any]) -> Path:
    """Write ``result`` as ``bundle_dir/structure.json`` (atomically, listed in the bundle's
    manifest; strict JSON: an infinite radius of a straight strip is ``null``)."""
    from gridshell.core.atomic import write_text

    out = Path(bundle_dir) / FILENAME
    write_text(out, json.dumps(finite_json(result), indent=1, allow_nan=False) + "\n")
    return out
