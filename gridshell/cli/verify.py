"""``gridshell verify``: recompute a bundle's metrics (paper 5.1) from its files alone."""
from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import numpy as np

HELP = "recompute the alignability metrics of a design bundle from its files and print JSON"


def add_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("bundle", help="design bundle directory (output of 'gridshell gg' / 'ncp')")
    p.add_argument("--per-loop", action="store_true",
                   help="also list Delta_a of every net-loop")


def verify_bundle(path: str | Path) -> dict[str, Any]:
    """Metrics of the bundle at ``path`` recomputed from design.json, net.obj, axes.obj,
    surface.obj (and aligned.obj, axes_r.npy, aligned_r.npy when present)."""
    from ..bundle import lamellae_from_design, read_design_json, read_net_mesh
    from ..errors import InputError, MeshError
    from ..metrics import (alignability_error, alignability_error_arc,
                           crossing_normal_curvature_on_mesh, delta_l, delta_n,
                           deviation, geodesic_turning, summary)
    from ..net import Net
    from ..quadmesh import read_configuration, read_mesh, read_polylines

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
    if d["kind"] == "GG":
        out["geodesic_turning"] = 100 * geodesic_turning(net, surf.V, surf.F)["ratio"]
    else:  # orthogonal lamellae: equal normal curvature of the two axes at every joint
        ck = crossing_normal_curvature_on_mesh(net, surf.V, surf.F)
        out["crossing_kn"] = {"mean": 100 * ck["mean"], "max": 100 * ck["max"],
                              "joints": int(len(ck["joints"]))}
    target = (d.get("params") or {}).get("target")
    if target:
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
    if r_star.is_file() and r_a.is_file() and (path / "aligned.obj").is_file():
        Va = read_configuration(path / "aligned.obj")[0]
        rs, ra = np.load(r_star), np.load(r_a)
        E = net.edges()
        out["delta_l"] = {k: 100 * v for k, v in summary(delta_l(net.joints, Va, E)).items()}
        out["delta_n"] = {k: 100 * v for k, v in
                          summary(delta_n(net.joints, rs, Va, ra, E)).items()}
    else:
        out["delta_l"] = out["delta_n"] = None  # no rotation axes stored (GG, or older NCP)
    out["stored"] = d.get("metrics", {})
    return out


def run(args: Any) -> int:
    res = verify_bundle(args.bundle)
    if not args.per_loop:
        res.pop("per_loop")
    print(json.dumps({"ok": True, **res}, indent=1, default=float))
    return 0
