"""Stresses in the states of the alignment sequence and in the collapsed state (transport).

A bundle with the dense strips of a **physical path** (``sequence/strips.npz``, written by the
GG pipeline: :mod:`gridshell.gg.path`, the net through surfaces of revolution on which every
lamella stays a geodesic with its arc lengths; by the NCP pipeline:
:mod:`gridshell.structure.heldpath`, the strips at equilibrium between the kinematic
sequence's joints and axes) is measured on them: the Darboux curvatures of every lamella's
dense axis with the state's own strip normals (less the cut curvature), every state judged
but those the path marks approximate (:func:`strip_state_record`). Otherwise (GG nets with a
Clairaut turning point, older bundles):

A state is known by its joints only (``sequence/frame_*.obj``, ``aligned.obj``): each lamella
is the cubic spline (not-a-knot) through its joints at the design's arc lengths (the alignment
keeps them), and the strip's section normal at a joint is the normal of the joint mesh there
(:func:`gridshell.structure.frames.joint_normals`; GG: the strips lie tangent to the net) or,
for NCP kinds, the joint axis, which is the strip's width direction: stored deployed
(``axes_r.npy``) and collapsed (``aligned_r.npy``), turned the fraction ``t`` of the way from
one to the other in the intermediate states (:func:`slerp_axes`; the sequence's own axes are
not stored).
GG: each lamella is taken as a geodesic of the state's surface (the GG alignment keeps them
so): the spline's whole curvature bends the strip about its weak axis, none about its strong
axis, and the geodesic curvature the joint mesh would imply is reported as the error bound
(``max_geodesic_residual_per_m``, :data:`METHOD_GG`).
In a collapsed GG net every lamella lies on one line: no curvature, and the strips lie stacked
untwisted. The resolution is the joint spacing, coarser than the dense axes of the deployed
check; the deployed state is evaluated the same way (``frame_000``) so that the states compare
with each other.
"""
from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np

from gridshell.design.bundle import DesignBundle
from gridshell.structure.cutshape import collapse_curvature, cut_curvature, cut_shape
from gridshell.structure.frames import DarbouxCurvatures, joint_curvatures, joint_normals
from gridshell.structure.materials import Material
from gridshell.structure.section import Section
from gridshell.structure.stresses import KIND_ORIENTATION, strip_curvatures, strip_stresses

METHOD = ("joints only: a cubic spline (not-a-knot) through each lamella's joints at the design's "
          "arc lengths; section normals from the joint mesh (NCP: the joint axes, deployed and "
          "collapsed as stored, interpolated between); resolution the joint spacing")

#: the method for tangent (GG) strips
METHOD_GG = ("joints only: a cubic spline (not-a-knot) through each lamella's joints at the "
             "design's arc lengths; each lamella a geodesic of the state's surface (the GG "
             "alignment keeps them so): strong-axis curvature 0 by construction, weak-axis "
             "curvature the spline's whole curvature (its normal curvature on that surface), "
             "twist from the joint mesh's normals; error bound: max_geodesic_residual_per_m, "
             "the largest geodesic curvature the joint mesh implies (design units), the "
             "strong-axis curvature if the stored state were the path; resolution the joint "
             "spacing")

#: the method of the states by strip orientation
METHODS = {"tangent": METHOD_GG, "orthogonal": METHOD}

_FRAME = re.compile(r"^frame_(\d+)\.obj$")

#: the intermediate states of the sequence are an approximate path (splines through the
#: joints of a kinematic sequence, not the strips' physical path): their utilisation is
#: reported, not judged; the deployed and the collapsed state are the design's own
APPROXIMATE = ("intermediate states: a spline through the joints of the kinematic sequence, not "
               "the strips' physical path; reported, not judged")

#: a state whose lamellae turn by more than this between consecutive joint-to-joint chords
#: (degrees) is folded: a spline through the joints no longer describes a strip there, and the
#: state is reported as unresolved instead of judged (a folded kinematic sequence)
FOLD_DEG = 30.0


def _frames(path: Path | None, n: int) -> list[np.ndarray]:
    """The joints of every frame of ``path/sequence`` in order (empty if none or unreadable
    as a configuration of ``n`` joints)."""
    from gridshell.geometry.meshfile import read_configuration

    if path is None or not (path / "sequence").is_dir():
        return []
    found = sorted((int(m.group(1)), p) for p in (path / "sequence").iterdir()
                   if (m := _FRAME.match(p.name)))
    out = []
    for _, p in found:
        V = read_configuration(p)[0]
        if V.shape != (n, 3):
            return []
        out.append(V)
    return out


def _axes(path: Path | None, name: str, n: int) -> np.ndarray | None:
    if path is None or not (path / name).is_file():
        return None
    try:
        r = np.load(path / name)
    except (OSError, ValueError):
        return None
    return r if r.shape == (n, 3) and np.all(np.isfinite(r)) else None


def slerp_axes(r0: np.ndarray, r1: np.ndarray, t: float) -> np.ndarray:
    """Unit axes ``(n,3)`` turned the fraction ``t`` of the way from ``r0`` to ``r1`` (rows,
    unit; a row of ``r1`` is taken with the sign nearer to ``r0``: axes are lines), about
    their common normal (spherical linear interpolation)."""
    a = np.asarray(r0, float)
    b = np.asarray(r1, float)
    a = a / np.maximum(np.linalg.norm(a, axis=1), 1e-300)[:, None]
    b = b / np.maximum(np.linalg.norm(b, axis=1), 1e-300)[:, None]
    c = np.einsum("ij,ij->i", a, b)
    b = np.where((c < 0)[:, None], -b, b)
    th = np.arccos(np.clip(np.abs(c), -1.0, 1.0))
    sn = np.sin(th)
    small = sn < 1e-9
    wa = np.where(small, 1.0 - t, np.sin((1.0 - t) * th) / np.where(small, 1.0, sn))
    wb = np.where(small, t, np.sin(t * th) / np.where(small, 1.0, sn))
    r = wa[:, None] * a + wb[:, None] * b
    return r / np.maximum(np.linalg.norm(r, axis=1), 1e-300)[:, None]


def signed_like(k_cut: np.ndarray, kn: np.ndarray) -> np.ndarray:
    """The cut curvature ``k_cut`` with the sign (one for the whole lamella) that fits the
    measured in-plane curvature ``kn`` best (a strip's normal, and so the sign of its in-plane
    curvature, is arbitrary)."""
    k_cut = np.asarray(k_cut, float)
    return -k_cut if np.sum((kn - k_cut) ** 2) > np.sum((kn + k_cut) ** 2) else k_cut


def max_turn(X: np.ndarray) -> float:
    """Largest angle (degrees) between consecutive chords of the joint polyline ``X (j,3)``."""
    d = np.diff(np.asarray(X, float), axis=0)
    n = np.linalg.norm(d, axis=1)
    d = d[n > 0] / n[n > 0, None]
    if len(d) < 2:
        return 0.0
    c = np.clip(np.einsum("ij,ij->i", d[1:], d[:-1]), -1.0, 1.0)
    return float(np.degrees(np.arccos(c)).max())


def _lamella_curvatures(lams, V: np.ndarray, normals: np.ndarray, orientation: str):
    """The Darboux curvatures of every lamella of a state from its joints ``V (n,3)`` and the
    joint normals ``normals (n,3)``, and the largest geodesic curvature (1/m) the joint mesh
    implies. Tangent strips (GG): the alignment keeps each lamella a geodesic of the state's
    surface, so ``kg = 0`` and the spline's whole curvature is normal curvature (the strip's
    normal its principal normal, do Carmo 3-2), ``kn = sign(kn) hypot(kn, kg)``, the twist
    ``tau_g`` from the joint normals; the residual ``max |kg|`` says how far the stored state
    is from that. Orthogonal strips: as measured (residual 0)."""
    dcs, resid = [], 0.0
    for lam in lams:
        dc = joint_curvatures(V[lam.joints], lam.joint_s, normals[lam.joints])
        if orientation == "tangent" and np.all(np.isfinite(dc.kg)):
            resid = max(resid, float(np.abs(dc.kg).max(initial=0.0)))
            sign = np.where(dc.kn < 0, -1.0, 1.0)
            dc = DarbouxCurvatures(dc.s, sign * np.hypot(dc.kn, dc.kg), np.zeros_like(dc.kg),
                                   dc.tau_g)
        dcs.append(dc)
    return dcs, resid


def state_record(bundle: DesignBundle, V: np.ndarray, normals: np.ndarray, section: Section,
                 material: Material, curve=None) -> dict[str, Any]:
    """Utilisation of every lamella in the state with joints ``V (n,3)`` and section normals
    ``normals (n,3)`` (zero rows: unknown); the cut shape is matched with the orientation of
    the normals that fits it best (their sign is arbitrary). Lamellae of fewer than 3 joints
    are not measured (``None`` in ``lamellae_max_utilisation``). ``resolved`` is False when a
    lamella turns by more than :data:`FOLD_DEG` between joints (``max_turn_deg``)."""
    orientation = KIND_ORIENTATION[bundle.kind]
    lams = bundle.net.lamellae
    dcs, resid = _lamella_curvatures(lams, V, normals, orientation)
    k_cut = [np.zeros(len(lam.joints)) for lam in lams]
    sign = 1.0
    if orientation == "orthogonal":
        k_cut = [cut_curvature(bundle, lam, lam.joint_s, curve) for lam in lams]
        a, b = np.concatenate([dc.kn for dc in dcs]), np.concatenate(k_cut)
        a, b = np.nan_to_num(a), np.where(np.isfinite(a), b, 0.0)
        sign = 1.0 if np.sum((a - b) ** 2) <= np.sum((a + b) ** 2) else -1.0
    turn = max((max_turn(V[lam.joints]) for lam in lams), default=0.0)
    per, best = [], (0.0, -1, -1)
    kw = ks = kt = 0.0
    for lam, dc, kc in zip(lams, dcs, k_cut):
        k = strip_curvatures(dc, orientation, section, sign * kc)
        u = strip_stresses(k, section, material).utilisation
        if not np.all(np.isfinite(u)):    # fewer than 3 joints: not measured
            per.append(None)
            continue
        m = float(u.max()) if len(u) else 0.0
        per.append(m)
        if len(u) and m > best[0]:
            best = (m, int(lam.id), int(lam.joints[int(np.argmax(u))]))
        if len(u):
            kw = max(kw, float(np.abs(k.weak).max()))
            ks = max(ks, float(np.abs(k.strong).max()))
            kt = max(kt, float(np.abs(k.twist).max()))
    return {"max_utilisation": best[0], "worst_lamella": best[1], "worst_joint": best[2],
            "max_turn_deg": turn, "resolved": bool(turn <= FOLD_DEG),
            "max_weak_curvature_per_m": kw, "max_strong_curvature_per_m": ks,
            "max_twist_rad_per_m": kt, "max_geodesic_residual_per_m": resid,
            "lamellae_max_utilisation": per}


#: the dense strips of a physical alignment path (written by the GG pipeline)
STRIPS = "sequence/strips.npz"


def read_strips(path: Path | None, n_joints: int, n_lamellae: int) -> dict[str, Any] | None:
    """The dense strips of every state (``sequence/strips.npz``: ``X``, ``N (F, M, 3)``,
    ``lamella``, ``joint (M,)``, ``t``, ``approximate``, ``bound (F,)``, ``method``; ``kcut
    (M,)`` the strips' cut curvature, 1/m of the design, 0 when absent), or None
    when absent, unreadable or not of this net (``n_joints`` joints, lamella ids below
    ``n_lamellae``)."""
    if path is None or not (path / STRIPS).is_file():
        return None
    try:
        with np.load(path / STRIPS, allow_pickle=False) as z:
            d = {k: z[k] for k in ("X", "N", "lamella", "joint", "t", "approximate", "bound",
                                   "method")}
            d["kcut"] = z["kcut"] if "kcut" in z.files else np.zeros(z["X"].shape[1])
    except (OSError, ValueError, KeyError):
        return None
    X, N = d["X"], d["N"]
    F = len(d["t"])
    if X.ndim != 3 or X.shape != N.shape or X.shape[0] != F or X.shape[2] != 3 or \
            d["lamella"].shape != (X.shape[1],) or d["joint"].shape != (X.shape[1],) or \
            d["kcut"].shape != (X.shape[1],) or not np.all(np.isfinite(d["kcut"])) or \
            not np.all(np.isfinite(X)) or not np.all(np.isfinite(N)) or F < 2 or \
            d["joint"].max(initial=-1) >= n_joints or d["lamella"].max(initial=0) >= n_lamellae:
        return None
    d["method"] = str(d["method"])
    return d


def strip_state_record(strips: dict[str, Any], f: int, orientation: str, section: Section,
                       material: Material) -> dict[str, Any]:
    """Utilisation of every lamella in state ``f`` of the dense strips of a physical path
    (:func:`read_strips`): the Darboux curvatures of each lamella's dense axis with the
    state's strip normals (:func:`gridshell.structure.frames.darboux_curvatures`), measured,
    not assumed, less the cut curvature ``kcut`` (orthogonal strips; signed like the state's
    in-plane curvature); the worst point's nearest joint."""
    from gridshell.structure.frames import darboux_curvatures

    X, N, lam_of, joint = strips["X"][f], strips["N"][f], strips["lamella"], strips["joint"]
    ids = np.unique(lam_of)
    per: dict[int, float] = {}
    best = (0.0, -1, -1)
    kw = ks = kt = 0.0
    for lid in ids:
        m = np.flatnonzero(lam_of == lid)
        dc = darboux_curvatures(X[m], N[m])
        k = strip_curvatures(dc, orientation, section, signed_like(strips["kcut"][m], dc.kn))
        u = strip_stresses(k, section, material).utilisation
        if not len(u) or not np.all(np.isfinite(u)):
            continue
        i = int(np.argmax(u))
        per[int(lid)] = float(u[i])
        if u[i] > best[0]:
            at = np.flatnonzero(joint[m] >= 0)
            j = int(joint[m][at[np.argmin(np.abs(at - i))]]) if len(at) else -1
            best = (float(u[i]), int(lid), j)
        kw = max(kw, float(np.abs(k.weak).max()))
        ks = max(ks, float(np.abs(k.strong).max()))
        kt = max(kt, float(np.abs(k.twist).max()))
    return {"max_utilisation": best[0], "worst_lamella": best[1], "worst_joint": best[2],
            "max_turn_deg": 0.0, "resolved": True,
            "max_weak_curvature_per_m": kw, "max_strong_curvature_per_m": ks,
            "max_twist_rad_per_m": kt, "max_geodesic_residual_per_m": 0.0,
            ("length_error" if orientation == "tangent" else "axis_error_rad"):
                float(strips["bound"][f]),
            "lamellae_max_utilisation": [per.get(i) for i in range(int(ids.max()) + 1)]}


def _path_states(bundle: DesignBundle, strips: dict[str, Any], section: Section,
                 material: Material) -> dict[str, Any]:
    """:func:`bundle_states` from the dense strips of a physical path: every state judged
    but those the path marks approximate (their length error is their bound)."""
    orientation = KIND_ORIENTATION[bundle.kind]
    F = len(strips["t"])
    out = []
    for f in range(F):
        rec = strip_state_record(strips, f, orientation, section, material)
        out.append({"name": f"frame_{f:03d}", "t": float(strips["t"][f]),
                    "approximate": bool(strips["approximate"][f]), **rec})
    collapsed = out[-1]
    judged = [f["max_utilisation"] for f in out if is_judged(f)]
    return {"method": strips["method"], "fold_deg": FOLD_DEG, "frames": out,
            "physical_path": True,
            "approximate_path": PATH_APPROXIMATE[orientation],
            "approximate": [f["name"] for f in out if f["approximate"]],
            "unresolved": [],
            "collapsed": {"name": collapsed["name"],
                          "max_utilisation": collapsed["max_utilisation"],
                          "worst_lamella": collapsed["worst_lamella"],
                          "worst_joint": collapsed["worst_joint"]},
            "sequence_max_utilisation": max(judged, default=0.0)}


#: the approximate states of a physical path: where the design surface is only isometric to
#: the surface of revolution, the blend between them
PATH_APPROXIMATE = {
    "tangent": ("approximate states: the lamellae carried from the design surface onto the "
                "surface of revolution it is isometric to, their joints disagreeing by more "
                "than 1 % of a segment (length_error); reported, not judged"),
    "orthogonal": ("approximate states: the strips' equilibrium between the held joints did "
                   "not converge, their width directions leave the sequence's axes at a "
                   "joint by more than 0.05 rad (axis_error_rad), the sequence changes a "
                   "joint-to-joint length by more than 1 %, or the kinematic sequence "
                   "folds a lamella there (its joint-to-joint chords turn by more than 30 "
                   "degrees, or by 10 degrees more than in both end states: no path a strip "
                   "takes), or (between the ends) it bends the strips about their strong "
                   "axis by more than 5 % of their weak-axis curvature (not the strips' own "
                   "motion); reported, not judged")}


def bundle_states(bundle: DesignBundle, path: Path | None, section: Section,
                  material: Material) -> dict[str, Any]:
    """``structure.json["states"]``: the record of :func:`state_record` for every frame of the
    alignment sequence (``frame_000`` deployed ... last = collapsed) or, without a sequence,
    for the deployed and the collapsed joints; ``frames`` in order, each with ``name`` and
    ``t`` (0 deployed, 1 collapsed) and ``approximate`` (the intermediate states:
    :data:`APPROXIMATE`, not judged); ``collapsed``; ``unresolved``: the names of the folded
    states (not judged); ``sequence_max_utilisation`` over the resolved ones. A bundle with
    the dense strips of a physical path (:data:`STRIPS`) is measured on them instead
    (:func:`strip_state_record`; ``physical_path`` True)."""
    n = len(bundle.net.joints)
    strips = read_strips(path, n, len(bundle.net.lamellae))
    if strips is not None:
        return _path_states(bundle, strips, section, material)
    METHOD = METHODS[KIND_ORIENTATION[bundle.kind]]     # noqa: N806 (this kind's method)
    loops = bundle.net.loops
    frames = _frames(path, n)
    named = [(f"frame_{k:03d}", V) for k, V in enumerate(frames)] if frames else \
        [("deployed", bundle.net.joints), ("collapsed", bundle.aligned)]
    K = max(len(named) - 1, 1)
    curve = collapse_curvature(bundle) if cut_shape(bundle) == "curve" else None
    r_dep, r_col = _axes(path, "axes_r.npy", n), _axes(path, "aligned_r.npy", n)
    out = []
    for k, (name, V) in enumerate(named):
        N = joint_normals(V, loops)
        if r_dep is not None and r_col is not None:
            N = slerp_axes(r_dep, r_col, k / K)
        elif k == 0 and r_dep is not None:
            N = r_dep
        elif k == len(named) - 1 and r_col is not None:
            N = r_col
        rec = state_record(bundle, np.asarray(V, float), N, section, material, curve)
        out.append({"name": name, "t": k / K, "approximate": 0 < k < len(named) - 1, **rec})
    collapsed = out[-1]
    judged = [f["max_utilisation"] for f in out if f["resolved"]]
    return {"method": METHOD, "fold_deg": FOLD_DEG, "frames": out,
            "approximate_path": APPROXIMATE,
            "approximate": [f["name"] for f in out if f["approximate"]],
            "unresolved": [f["name"] for f in out if not f["resolved"]],
            "collapsed": {"name": collapsed["name"],
                          "max_utilisation": collapsed["max_utilisation"],
                          "worst_lamella": collapsed["worst_lamella"],
                          "worst_joint": collapsed["worst_joint"]},
            "sequence_max_utilisation": max(judged, default=0.0)}


def is_judged(frame: dict[str, Any]) -> bool:
    """Whether the state ``frame`` (of :func:`bundle_states`) counts in the verdict: resolved
    (not folded) and not on an approximate path (:data:`APPROXIMATE`)."""
    return bool(frame["resolved"]) and not frame.get("approximate", False)
