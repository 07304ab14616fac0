"""Verification of a design bundle (paper 5.1): its metrics recomputed from its files alone."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from gridshell.measure.quality import Gate

__all__ = ["GG_STORED", "NCP_STORED", "exit_code", "verify_bundle"]


#: verified figure -> the stored metric of an NCP / CNC / AA design.json it recomputes
NCP_STORED = {"alignability": "delta_a_after", "deviation": "deviation", "delta_l": "delta_l",
              "delta_n": "delta_n", "aligned_radius": "aligned_radius",
              "aligned_radius_error": "aligned_radius_error",
              "aligned_line_error": "aligned_line_error"}


#: verified figure -> the stored metric of a GG design.json it recomputes
GG_STORED = {"alignability": "alignability", "alignability_arc": "alignability_arc",
             "geodesic_turning": "geodesic_turning", "deviation": "deviation",
             "deviation_joints": "deviation_joints"}

#: files each bundle kind needs for its figures (besides design.json, net.obj, axes.obj and
#: surface.obj, without which nothing can be checked): a missing one makes ``ok`` false
FIGURE_FILES = {"GG": ("aligned.obj",),
                "NCP": ("aligned.obj", "axes_r.npy", "aligned_r.npy"),
                "CNC": ("aligned.obj", "axes_r.npy", "aligned_r.npy"),
                "AA": ("aligned.obj", "axes_r.npy", "aligned_r.npy")}


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
    from gridshell.core.errors import InputError
    from gridshell.geometry.fit import fit_circle, fit_plane, line_deviation
    from gridshell.geometry.quadmesh import bbox_diagonal

    span = bbox_diagonal(Va)
    if not span > 0:
        raise InputError("aligned.obj has all its joints at one point; re-run the design command")
    c, basis, dist = fit_plane(Va)
    out: dict[str, Any] = {"aligned_plane_distance": {
        "mean": 100 * float(np.abs(dist).mean()) / span,
        "max": 100 * float(np.abs(dist).max()) / span}}
    curve = d.get("collapse") or {}
    design_r, n = curve.get("radius"), (d.get("metrics") or {}).get("n")
    if not (isinstance(n, (int, float)) and not isinstance(n, bool) and np.isfinite(n)):
        n = None  # the stored normal curvature is not a number: no figure against it
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


def _as_floats(v: Any) -> np.ndarray | None:
    try:
        return np.asarray(v, float)
    except (TypeError, ValueError):
        return None


def _mismatch(out: dict[str, Any], stored: dict[str, Any], table: dict[str, str]) -> list[str]:
    """Names of the figures of ``out`` that do not reproduce their stored counterpart
    (``table``: :data:`GG_STORED` or :data:`NCP_STORED`; relative 1e-6, absolute 1e-9 of the
    figure's unit). A stored figure that is not a number (or a ``{"mean", "max"}`` of numbers)
    is a mismatch too."""
    bad = []
    for key, skey in table.items():
        a, b = out.get(key), stored.get(skey)
        if a is None or b is None or (isinstance(a, dict) and "skipped" in a):
            continue
        if isinstance(a, dict):
            if not isinstance(b, dict):
                bad.append(key)
                continue
            a, b = [a.get(s) for s in ("mean", "max")], [b.get(s) for s in ("mean", "max")]
        x, y = _as_floats(a), _as_floats(b)
        if x is None or y is None or x.shape != y.shape or not np.all(
                np.isclose(x, y, rtol=1e-6, atol=1e-9, equal_nan=True)):
            bad.append(key)
    return bad


def _fidelity_mismatch(f: dict | None, stored: dict | None) -> list[str]:
    """``["fidelity"]`` when the recomputed fidelity ``f`` does not reproduce the stored one
    (mean deviation relative 1e-3, coverage 0.5 points: the joints are read back from text and
    a target sample may sit on the 2 % limit), else ``[]`` (nothing to compare)."""
    if not f or "skipped" in f or not isinstance(stored, dict) or "coverage" not in stored:
        return []
    try:
        same = (np.isclose(f["deviation_mean"], float(stored["deviation_mean"]), rtol=1e-3,
                           atol=1e-6) and abs(f["coverage"] - float(stored["coverage"])) <= 0.5)
    except (TypeError, ValueError, KeyError):
        same = False
    return [] if same else ["fidelity"]


def _count_mismatch(d: dict, n_joints: int, n_loops: int, families: dict[str, int]) -> list[str]:
    """The stored counts of design.json ``d`` (top level and ``metrics``) that differ from the
    files: ``n_joints`` / ``n_loops`` (net.obj), ``n_lamellae`` (lamella records per family)."""
    m = d.get("metrics") if isinstance(d.get("metrics"), dict) else {}
    bad = []
    for key, real in (("n_joints", n_joints), ("n_loops", n_loops)):
        for where, src in (("", d), ("metrics.", m)):
            if key in src and not (isinstance(src[key], int) and src[key] == real):
                bad.append(f"{where}{key}")
    if "n_lamellae" in m:
        st = m["n_lamellae"]
        if not (isinstance(st, dict) and all(st.get(k) == v for k, v in families.items())):
            bad.append("metrics.n_lamellae")
    return bad


def _load_axes(path: Path, n: int) -> np.ndarray:
    """Rotation axes ``(n, 3)`` of ``path`` (axes_r.npy / aligned_r.npy), loaded without
    pickles; :class:`InputError` naming the file when it is not such an array."""
    from gridshell.core.errors import InputError

    try:
        r = np.load(path, allow_pickle=False)
    except (ValueError, OSError, EOFError) as exc:
        raise InputError(f"{path}: not a readable NumPy array of rotation axes ({exc}); re-run "
                         "the design command") from None
    if not isinstance(r, np.ndarray) or r.shape != (n, 3) or r.dtype.kind not in "fi":
        raise InputError(f"{path}: expected ({n}, 3) rotation axes (one per joint of net.obj), "
                         f"got {getattr(r, 'shape', '?')} {getattr(r, 'dtype', '')}; re-run the "
                         "design command")
    r = r.astype(float)
    if not np.all(np.isfinite(r)):
        raise InputError(f"{path}: {int((~np.isfinite(r)).any(axis=1).sum())} rotation axes are "
                         "not finite (NaN or Inf); re-run the design command")
    return r


def exit_code(res: dict[str, Any]) -> int:
    """The exit code of ``gridshell verify`` for the result ``res`` of :func:`verify_bundle`:
    0 ok; 2 the bundle is incomplete or its files disagree with design.json (``problems``);
    4 the bundle is consistent but its figures miss the paper's thresholds (``gates``)."""
    if res["ok"]:
        return 0
    return 2 if res["problems"] else 4


def _read_files(path: Path) -> tuple[dict, Any, Any, np.ndarray, np.ndarray]:
    """design.json ``d`` of the bundle at ``path``, the cached bundle (or None), the
    :class:`~gridshell.geometry.net.Net` of net.obj and axes.obj, and surface.obj's
    ``V (n, 3)`` (metres) and ``F``; :class:`InputError` when one of them is missing."""
    from gridshell.core.errors import InputError
    from gridshell.design.bundle import (cached_bundle, check_collapse, lamellae_from_design,
                                         read_design_json, read_net_mesh)
    from gridshell.geometry.meshfile import read_mesh, read_polylines
    from gridshell.geometry.net import Net

    d = read_design_json(path)
    check_collapse(d, path)
    for name in ("net.obj", "axes.obj", "surface.obj"):
        if not (path / name).is_file():
            raise InputError(f"design bundle {path} lacks {name}; re-run the design command")
    # files this process has read (read_bundle) and are byte for byte unchanged give the
    # arrays their parsing gives: they are not parsed again
    done = cached_bundle(path)
    if done is not None:
        net_V, net_F = done.net.joints, done.net.loops
        axes = [lam.axis for lam in done.net.lamellae]
        surf_V, surf_F = done.surface_V, done.surface_F
    else:
        net_mesh = read_net_mesh(path / "net.obj")
        net_V, net_F = net_mesh.V, net_mesh.F
        axes = read_polylines(path / "axes.obj")
        surf = read_mesh(path / "surface.obj", kind="any")
        surf_V, surf_F = surf.V, surf.F
    lams = lamellae_from_design(d, axes, path)
    return d, done, Net(joints=net_V, loops=net_F, lamellae=lams), surf_V, surf_F


def _net_figures(d: dict, net: Any, surf_V: np.ndarray, surf_F: np.ndarray) -> dict[str, Any]:
    """Counts, alignability (eq. 5.1, per loop and arc-length, %) of ``net``, and the GG
    ``geodesic_turning`` or the NCP ``crossing_kn`` (%) on surface.obj ``surf_V, surf_F``."""
    from gridshell.measure.metrics import (alignability_error, alignability_error_arc,
                                           crossing_normal_curvature_on_mesh,
                                           geodesic_turning, summary)

    da = alignability_error(net.joints, net.loops)
    da_arc = alignability_error_arc(net)
    out: dict[str, Any] = {
        "kind": d["kind"], "n_joints": len(net.joints), "n_loops": len(net.loops),
        "alignability": {k: 100 * v for k, v in summary(da).items()},
        "alignability_arc": {k: 100 * v for k, v in summary(da_arc).items()},
        "per_loop": {"alignability": (100 * da).tolist(), "alignability_arc": (100 * da_arc).tolist()},
    }
    if d["kind"] == "GG":
        out["geodesic_turning"] = 100 * geodesic_turning(net, surf_V, surf_F)["ratio"]
    else:  # orthogonal lamellae: equal normal curvature of the two axes at every joint
        ck = crossing_normal_curvature_on_mesh(net, surf_V, surf_F, reuse=True)
        out["crossing_kn"] = {"mean": 100 * ck["mean"], "max": 100 * ck["max"],
                              "joints": int(len(ck["joints"]))}
    return out


def _read_target(d: dict) -> Any:
    """The user's target of design.json ``d`` (``params.target`` of GG, ``params.source`` of
    NCP) read as the design read it: the recorded unit, object and cleaning; None without a
    target file (a B-spline surface.json or arrays given to the API);
    :class:`~gridshell.core.errors.InputError` when it cannot be read."""
    from gridshell.core.units import Units
    from gridshell.io.read import read_input

    params = d.get("params") or {}
    target = params.get("target") or params.get("source")
    if not isinstance(target, str) or not target or target.startswith("(") \
            or target.lower().endswith(".json"):
        return None
    given = params.get("input") or {}
    return read_input(target, units=Units.from_json(d.get("units") or params.get("units")),
                      obj=given.get("object_query"),
                      clean=given.get("clean", True) is not None, require_disk=False)


def _deviation_figures(d: dict, net: Any, surf_V: np.ndarray, surf_F: np.ndarray,
                       fidelity: bool = True) -> dict[str, Any]:
    """``deviation`` (% of the diagonal): NCP kinds, of the joints from surface.obj; GG, of
    surface.obj (and ``deviation_joints``) from the target of ``params.target``, read as the
    design read it (``{"skipped": reason}`` when unreadable; nothing without a target).
    Both: ``fidelity``, the net's deviation from the user's target and its coverage
    (:func:`gridshell.measure.fidelity.net_fidelity`, issue 29 item 4), from the target file
    (NCP from a B-spline surface.json: from surface.obj); not with ``fidelity`` False."""
    from gridshell.core.errors import InputError
    from gridshell.measure.fidelity import net_fidelity
    from gridshell.measure.metrics import deviation, deviations

    out: dict[str, Any] = {}
    if d["kind"] != "GG":  # the joints from the designed (PHLW) surface, as the pipeline measures them
        dv = deviation(net.joints, surf_V, surf_F, reuse=True)
        out["deviation"] = {"mean": dv["mean"], "max": dv["max"]}
    if not fidelity and d["kind"] != "GG":
        return out
    try:
        t = _read_target(d)
    except InputError as exc:
        out["fidelity"] = {"skipped": f"the target is unreadable: {exc}"}
        if d["kind"] == "GG":
            out["deviation"] = {"skipped": f"the target is unreadable: {exc}"}
        return out
    if t is None and d["kind"] == "GG":
        return out
    tV, tF = (t.V, t.F) if t is not None else (surf_V, surf_F)
    if fidelity:
        out["fidelity"] = {**net_fidelity(net.joints, net.loops, tV, tF),
                           "target": t.path if t is not None else "surface.obj"}
    if d["kind"] == "GG":
        dv, dj = deviations([surf_V, net.joints], t.V, t.F)
        out["deviation"] = {"mean": dv["mean"], "max": dv["max"]}
        out["deviation_joints"] = {"mean": dj["mean"], "max": dj["max"]}
    return out


def _read_aligned(path: Path, done: Any, net: Any) -> np.ndarray | None:
    """The collapsed joints ``(n, 3)`` of aligned.obj (None when absent), checked against
    net.obj's count and for finiteness (:class:`InputError` naming the file)."""
    from gridshell.core.errors import InputError
    from gridshell.geometry.meshfile import read_configuration

    if not (path / "aligned.obj").is_file():
        return None
    Va = done.aligned if done is not None else read_configuration(path / "aligned.obj")[0]
    if Va.shape != net.joints.shape:
        raise InputError(f"{path}: aligned.obj has {len(Va)} vertices but net.obj "
                         f"{len(net.joints)}; re-run the design command")
    if not np.all(np.isfinite(Va)):
        raise InputError(f"{path / 'aligned.obj'}: "
                         f"{int((~np.isfinite(Va)).any(axis=1).sum())} vertices are not "
                         "finite (NaN or Inf); re-run the design command")
    return Va


def _delta_figures(path: Path, net: Any, Va: np.ndarray | None) -> dict[str, Any]:
    """``delta_l`` and ``delta_n`` (%, mean / max) between the net and its collapsed state
    ``Va`` with the stored rotation axes; both None without axes_r.npy, aligned_r.npy or Va."""
    from gridshell.measure.metrics import delta_l, delta_n, summary

    r_star, r_a = path / "axes_r.npy", path / "aligned_r.npy"
    if not (r_star.is_file() and r_a.is_file() and Va is not None):
        return {"delta_l": None, "delta_n": None}  # no rotation axes stored (GG, or older NCP)
    rs, ra = _load_axes(r_star, len(net.joints)), _load_axes(r_a, len(net.joints))
    E = net.edges()
    return {"delta_l": {k: 100 * v for k, v in summary(delta_l(net.joints, Va, E)).items()},
            "delta_n": {k: 100 * v for k, v in
                        summary(delta_n(net.joints, rs, Va, ra, E)).items()}}


def _verdict(out: dict[str, Any], d: dict, net: Any, problems: list[str]) -> None:
    """Add to ``out`` the stored metrics, ``mismatch`` (counts and figures against
    design.json), ``required``, ``gates``, ``checks``, ``problems`` and ``ok``."""
    from gridshell.measure.quality import design_gates, failing

    stored = d.get("metrics", {})
    out["stored"] = stored if isinstance(stored, dict) else {}
    families = {"C1": len(net.family(1)), "C3": len(net.family(3))}
    out["mismatch"] = (_count_mismatch(d, len(net.joints), len(net.loops), families)
                       + _mismatch(out, out["stored"],
                                   NCP_STORED if d["kind"] != "GG" else GG_STORED))
    out["mismatch"] += _fidelity_mismatch(out.get("fidelity"), out["stored"].get("fidelity"))
    if out["mismatch"]:
        problems.append("design.json disagrees with the files on " + ", ".join(out["mismatch"])
                        + " (the bundle was changed after the design)")
    gates = design_gates(d["kind"], out)
    bad = failing(gates)
    out["required"] = {"figures": [g.name for g in gates], "files": list(FIGURE_FILES[d["kind"]])}
    out["gates"] = [g.as_dict() for g in gates]
    out["checks"] = [g.line() for g in gates]
    f = out.get("fidelity")
    if f:
        from gridshell.measure.fidelity import fidelity_line

        out["checks"].append("fidelity (not a gate): " + (f"skipped, {f['skipped']}" if
                                                          "skipped" in f else fidelity_line(f)))
    out["problems"] = problems
    out["ok"] = not bad and not problems


def verify_bundle(path: str | Path, *, fidelity: bool = True) -> dict[str, Any]:
    """Metrics of the bundle at ``path`` recomputed from design.json, net.obj, axes.obj,
    surface.obj (and aligned.obj, axes_r.npy, aligned_r.npy when present).

    For NCP / CNC / AA bundles also: ``deviation`` of the joints from surface.obj (% of its
    bounding-box diagonal), the figures of :func:`_aligned_figures` from aligned.obj, and
    ``mismatch``, the figures that differ from those stored in design.json (a bundle whose
    files were changed after the design). GG bundles: ``deviation`` of the surface (and
    ``deviation_joints``) from the target mesh of ``params.target`` when it is readable, and
    ``mismatch`` against :data:`GG_STORED`. Both: the stored counts (``n_joints``,
    ``n_loops``, ``n_lamellae``) against the files.

    The verdict: ``required`` (the figures and files this kind needs), ``gates`` (:func:`gridshell.measure.quality.design_gates` of the recomputed figures,
    as dicts), ``checks`` (their pass / FAIL lines), ``problems`` (a file of
    :data:`FIGURE_FILES` missing, a figure not computed, a mismatch) and ``ok``: every gate
    holds and there is no problem. ``fidelity`` (default True): also the net's ``fidelity``
    to the user's target (no gate; the pre-cut verdict leaves it out). A bundle whose net.obj,
    axes.obj, surface.obj or design.json cannot be read raises :class:`~gridshell.core.errors.InputError`.
    """
    path = Path(path)
    d, done, net, surf_V, surf_F = _read_files(path)
    out = _net_figures(d, net, surf_V, surf_F)
    out.update(_deviation_figures(d, net, surf_V, surf_F, fidelity))
    problems = [f"{name} is missing: the figures that need it were not computed"
                for name in FIGURE_FILES[d["kind"]] if not (path / name).is_file()]
    Va = _read_aligned(path, done, net)
    if Va is not None and d["kind"] != "GG":
        out.update(_aligned_figures(Va, d))
    out.update(_delta_figures(path, net, Va))
    _verdict(out, d, net, problems)
    return out


@dataclass(frozen=True)
class Verdict:
    """The pre-cut verdict of a design: its gates on the recomputed figures and the problems
    of its files (a bundle directory); ``report`` is :func:`verify_bundle`'s result there."""

    gates: tuple[Gate, ...]
    problems: tuple[str, ...] = ()
    report: dict | None = None

    @property
    def ok(self) -> bool:
        return not self.problems and all(g.ok for g in self.gates)

    def why(self) -> str:
        """The failing figures and the problems, ``"; "``-separated (empty when ok)."""
        return "; ".join([g.statement() for g in self.gates if not g.ok] + list(self.problems))


def design_verdict(bundle: Any) -> Verdict:
    """The :class:`Verdict` on a design, for writers of cut geometry (which refuse a failing one
    unless forced). A bundle directory is judged on the figures recomputed from its files
    (:func:`verify_bundle`); an in-memory :class:`~gridshell.design.bundle.DesignBundle` on its
    metrics (:func:`gridshell.measure.quality.design_gates`)."""
    if isinstance(bundle, (str, Path)):
        res = verify_bundle(bundle, fidelity=False)   # no gate on it: not measured here
        return Verdict(tuple(Gate.from_dict(g) for g in res["gates"]), tuple(res["problems"]), res)
    from gridshell.measure.quality import design_gates

    return Verdict(tuple(design_gates(bundle.kind, bundle.metrics)))


def require_design(bundle: Any, force: bool, retry: str) -> Verdict:
    """:func:`design_verdict` of ``bundle``; :class:`InputError` naming the failing figures and
    problems unless it holds or ``force`` (``retry``: how the caller forces it, e.g.
    ``"pass --force to cut it anyway"``)."""
    from gridshell.core.errors import InputError

    verdict = design_verdict(bundle)
    if not (verdict.ok or force):
        where = f"{bundle}: " if isinstance(bundle, (str, Path)) else ""
        raise InputError(f"{where}the design fails its checks ({verdict.why()}); {retry}")
    return verdict
