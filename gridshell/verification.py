"""Verification of a design bundle (paper 5.1): its metrics recomputed from its files alone."""
from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["NCP_STORED", "verify_bundle"]


#: verified figure -> the stored metric of an NCP / CNC / AA design.json it recomputes
NCP_STORED = {"alignability": "delta_a_after", "deviation": "deviation", "delta_l": "delta_l",
              "delta_n": "delta_n", "aligned_radius": "aligned_radius",
              "aligned_radius_error": "aligned_radius_error",
              "aligned_line_error": "aligned_line_error"}


def _aligned_figures(Va: np.ndarray, d: dict) -> dict[str, Any]:
    """The collapsed configuration ``Va (n, 3)`` (aligned.obj) of an NCP / CNC / AA bundle
    fitted in its plane, then with a circle (CNC) or a line (AA); ``d`` is design.json.

    Keys (``{"mean", "max"}`` dicts or numbers; % unless stated):

    - ``aligned_plane_distance``: distance of the joints from their least-squares plane, % of
      the joints' span (bounding-box diagonal);
    - CNC: ``aligned_radius`` (metres) of the circle fitted in that plane; its error against
      the design's collapse radius (``aligned_radius_error``) and against ``1 / |n|``
      (``aligned_radius_error_n``); ``aligned_circle_deviation``, the joints' distance from
      the fitted circle, % of its radius; ``collapse_radius_error`` of the collapse polyline
      stored in design.json;
    - AA: ``aligned_line_error``, max distance of the joints from their best-fit line (in 3D),
      % of their span; ``collapse_line_error`` of the stored collapse polyline.
    """
    from .errors import InputError
    from .ncp.collapse import fit_circle, fit_plane, line_deviation
    from .quadmesh import bbox_diagonal

    span = bbox_diagonal(Va)
    if not span > 0:
        raise InputError("aligned.obj has all its joints at one point; re-run the design command")
    c, basis, dist = fit_plane(Va)
    out: dict[str, Any] = {"aligned_plane_distance": {
        "mean": 100 * float(np.abs(dist).mean()) / span,
        "max": 100 * float(np.abs(dist).max()) / span}}
    curve = d.get("collapse") or {}
    design_r, n = curve.get("radius"), (d.get("metrics") or {}).get("n")
    if d["kind"] == "CNC":
        A2 = (Va - c) @ basis.T
        centre, R = fit_circle(A2)
        off = np.abs(np.linalg.norm(A2 - centre, axis=1) - R) / R
        out["aligned_radius"] = R
        out["aligned_circle_deviation"] = {"mean": 100 * float(off.mean()),
                                           "max": 100 * float(off.max())}
        if design_r:
            out["aligned_radius_error"] = 100 * abs(R - design_r) / design_r
        if n:
            out["aligned_radius_error_n"] = 100 * abs(R * abs(n) - 1)
        if design_r and len(curve.get("points", ())) >= 3:
            r_curve = fit_circle(np.asarray(curve["points"], float))[1]
            out["collapse_radius_error"] = 100 * abs(r_curve - design_r) / design_r
    elif d["kind"] == "AA":
        # in 3D: any displacement, in the plane or out of it, moves a joint off the line
        out["aligned_line_error"] = 100 * line_deviation(Va)
        if len(curve.get("points", ())) >= 2:
            out["collapse_line_error"] = 100 * line_deviation(np.asarray(curve["points"], float))
    return out


def _mismatch(out: dict[str, Any], stored: dict[str, Any]) -> list[str]:
    """Names of the figures of ``out`` that do not reproduce their stored counterpart
    (:data:`NCP_STORED`; relative 1e-6, absolute 1e-9 of the figure's unit)."""
    bad = []
    for key, skey in NCP_STORED.items():
        a, b = out.get(key), stored.get(skey)
        if a is None or b is None:
            continue
        if isinstance(a, dict):
            a, b = [a.get(s) for s in ("mean", "max")], [b.get(s) for s in ("mean", "max")]
        x = np.asarray(a, float)
        y = np.asarray(b, float)
        if not np.all(np.isclose(x, y, rtol=1e-6, atol=1e-9, equal_nan=True)):
            bad.append(key)
    return bad


def verify_bundle(path: str | Path) -> dict[str, Any]:
    """Metrics of the bundle at ``path`` recomputed from design.json, net.obj, axes.obj,
    surface.obj (and aligned.obj, axes_r.npy, aligned_r.npy when present).

    For NCP / CNC / AA bundles also: ``deviation`` of the joints from surface.obj (% of its
    bounding-box diagonal), the figures of :func:`_aligned_figures` from aligned.obj, and
    ``mismatch``, the figures that differ from those stored in design.json (a bundle whose
    files were changed after the design). GG bundles: ``deviation`` of the surface (and
    ``deviation_joints``) from the target mesh of ``params.target`` when it is readable.
    """
    from .bundle import lamellae_from_design, read_design_json, read_net_mesh
    from .errors import InputError, MeshError
    from .metrics import (alignability_error, alignability_error_arc,
                           crossing_normal_curvature_on_mesh, delta_l, delta_n,
                           deviation, geodesic_turning, summary)
    from .net import Net
    from .quadmesh import read_configuration, read_mesh, read_polylines

    path = Path(path)
    d = read_design_json(path)
    for name in ("net.obj", "axes.obj", "surface.obj"):
        if not (path / name).is_file():
            raise InputError(f"design bundle {path} lacks {name}; re-run the design command")
    net_mesh = read_net_mesh(path / "net.obj")
    axes = read_polylines(path / "axes.obj")
    lams = lamellae_from_design(d, axes, path)
    net = Net(joints=net_mesh.V, loops=net_mesh.F, lamellae=lams)
    surf = read_mesh(path / "surface.obj", kind="any")
    da = alignability_error(net.joints, net.loops)
    da_arc = alignability_error_arc(net)
    out: dict[str, Any] = {
        "kind": d["kind"], "n_joints": len(net.joints), "n_loops": len(net.loops),
        "alignability": {k: 100 * v for k, v in summary(da).items()},
        "alignability_arc": {k: 100 * v for k, v in summary(da_arc).items()},
        "per_loop": {"alignability": (100 * da).tolist(), "alignability_arc": (100 * da_arc).tolist()},
    }
    ncp = d["kind"] != "GG"
    if not ncp:
        out["geodesic_turning"] = 100 * geodesic_turning(net, surf.V, surf.F)["ratio"]
    else:  # orthogonal lamellae: equal normal curvature of the two axes at every joint
        ck = crossing_normal_curvature_on_mesh(net, surf.V, surf.F)
        out["crossing_kn"] = {"mean": 100 * ck["mean"], "max": 100 * ck["max"],
                              "joints": int(len(ck["joints"]))}
    target = (d.get("params") or {}).get("target")
    if ncp:  # the joints from the designed (PHLW) surface, as the pipeline measures them
        dv = deviation(net.joints, surf.V, surf.F)
        out["deviation"] = {"mean": dv["mean"], "max": dv["max"]}
    elif target:
        try:
            t = read_mesh(target, kind="any")
        except MeshError as exc:
            out["deviation"] = {"skipped": f"target {target} unreadable: {exc}"}
        else:
            dv = deviation(surf.V, t.V, t.F)
            dj = deviation(net.joints, t.V, t.F)
            out["deviation"] = {"mean": dv["mean"], "max": dv["max"]}
            out["deviation_joints"] = {"mean": dj["mean"], "max": dj["max"]}
    r_star, r_a = path / "axes_r.npy", path / "aligned_r.npy"
    Va = None
    has_r = r_star.is_file() and r_a.is_file()
    if (path / "aligned.obj").is_file() and (ncp or has_r):
        Va = read_configuration(path / "aligned.obj")[0]
        if Va.shape != net.joints.shape:
            raise InputError(f"{path}: aligned.obj has {len(Va)} vertices but net.obj "
                             f"{len(net.joints)}; re-run the design command")
        if ncp:
            out.update(_aligned_figures(Va, d))
    if has_r and Va is not None:
        rs, ra = np.load(r_star), np.load(r_a)
        E = net.edges()
        out["delta_l"] = {k: 100 * v for k, v in summary(delta_l(net.joints, Va, E)).items()}
        out["delta_n"] = {k: 100 * v for k, v in
                          summary(delta_n(net.joints, rs, Va, ra, E)).items()}
    else:
        out["delta_l"] = out["delta_n"] = None  # no rotation axes stored (GG, or older NCP)
    out["stored"] = d.get("metrics", {})
    if ncp:
        out["mismatch"] = _mismatch(out, out["stored"])
    return out
