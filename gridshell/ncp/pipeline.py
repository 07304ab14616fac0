"""The NCP pipeline (paper 4.2, 5.1): from a PHLW / CNC / PK surface to a design bundle.

:func:`design_ncp` runs :data:`NCP_STAGES`, named stages over one state dict
(:mod:`gridshell.design.stages`), each timed in the report: ``surface`` (read; the PHLW step
for a reference, :mod:`.phlw`), ``directions`` (:mod:`.directions`), ``tracing`` (level-set
tracing, :mod:`.levelset`), ``collapse`` (:mod:`.collapse`), ``postopt`` (post-optimization,
:mod:`.postopt`), ``simulation`` (the alignment, :mod:`.alignment`), ``metrics``
(:mod:`gridshell.measure.metrics` and the gates), ``gate`` (a design missing the figures
refused) and ``bundle`` (the design bundle and report). The bundle kind follows the mode:
``phlw -> "NCP"``, ``cnc -> "CNC"``, ``aa -> "AA"``.
"""
from __future__ import annotations

import json
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import numpy as np

from gridshell.geometry.bspline import BSplineSurface
from gridshell.design.bundle import CollapseCurve, Design, DesignBundle, report_json, write_bundle
from gridshell.design.section import design_width_m
from gridshell.design.stages import Stage, run_stages, stage
from gridshell.core.errors import ConvergenceError, InputError, NoNetError
from gridshell.measure.metrics import alignability_error, delta_l, delta_n, deviation, summary
from gridshell.measure.quality import design_gates, gate_summary, passed
from gridshell.geometry.net import move_joints
from gridshell.measure.fairness import net_fairness
from gridshell.ncp.collapse import (CollapseResult, closest_on_polyline, collapse_curve, fit_circle,
                       line_deviation)
from gridshell.geometry.bspline import uniform_params
from gridshell.ncp.directions import net_directions
from gridshell.ncp.levelset import TracedNet, trace
from gridshell.ncp.postopt import PostOptResult, interior_vertices, post_optimize
from gridshell.ncp.alignment import AlignmentSequence, collapse_direction, plane_frame, simulate_alignment
from gridshell.ncp.source import load_surface

__all__ = ["KIND", "NCP_STAGES", "NCPOptions", "NCPState", "crossing_normal_curvature",
           "design_ncp", "ncp_files", "ncp_state", "write_ncp", "load_surface"]

KIND = {"phlw": "NCP", "cnc": "CNC", "aa": "AA"}


@dataclass
class NCPState:
    """Intermediate results of :func:`design_ncp` (arrays, for writing and inspection)."""

    surface: BSplineSurface
    traced: TracedNet
    collapse: CollapseResult
    post: PostOptResult
    sequence: AlignmentSequence
    aligned_2d: np.ndarray
    strips: dict[str, Any] | None = None


def _phlw_failure(info: dict, mode: str, exc: Exception) -> ConvergenceError:
    """The no-net answer ``exc`` on a surface the PHLW step produced, as the optimizer's
    failure: the reference passed :func:`reference_net_check`, so a net may exist near it."""
    e0, e1 = (info.get("phlw_energy") or [None, None])[:2]
    energy = ""
    if isinstance(e0, (int, float)) and isinstance(e1, (int, float)):
        energy = f", E_PHLW {e0:.4g} -> {e1:.4g}" + (
            ": the step diverged" if e1 > max(e0, 1e-12) * 10 else "")
    err = ConvergenceError(
        f"the PHLW step (converged {info.get('phlw_converged')}{energy}, deviation "
        f"{info.get('phlw_deviation', float('nan')):.3g} % of the diagonal) left a surface "
        f"without the {mode} net: {exc}. The reference itself admits a start (distinct "
        f"principal curvatures{', K < 0 somewhere' if mode == 'aa' else ''}), so this is the "
        "optimizer's failure: raise --phlw-outer / --phlw-max-iter, or run 'gridshell phlw' on "
        "the reference and inspect its curvature diagram")
    err.phlw_failure = True     # gridshell.analysis.admissible tells it from no patch at all
    return err


def _stopped(info: dict, traced: TracedNet, post: PostOptResult) -> list[str]:
    """The optimizers of a design that stopped without meeting their own tolerances."""
    out = ["the PHLW step"] if info.get("phlw_converged") is False else []
    out += [f"the level-set fit {f}" for f, fit in traced.fits.items() if not fit.converged]
    return out + ([] if post.converged else ["the post-optimization"])


def crossing_normal_curvature(surf: BSplineSurface, traced: TracedNet) -> dict[str, Any]:
    """:func:`gridshell.measure.metrics.crossing_normal_curvature` on the traced axes with the B-spline
    normals at their parameters and Euler's-circle radius at the joints (1/m, fractions)."""
    from gridshell.geometry.diffgeo import surface_curvature
    from gridshell.measure.metrics import crossing_normal_curvature as crossing

    normals = [np.cross(surf.evaluate(uv[:, 0], uv[:, 1], 1, 0),
                        surf.evaluate(uv[:, 0], uv[:, 1], 0, 1)) for uv in traced.axis_uv]
    uv = traced.joint_uv
    g = surface_curvature(surf, uv[:, 0], uv[:, 1])
    return crossing(traced.net, normals, traced.axis_joint_index,
                    np.abs(g["kII"] - g["kI"]) / 2)


def _collapse_s(traced: TracedNet, collapse: CollapseResult,
                A2: np.ndarray) -> dict[int, np.ndarray]:
    """Arc length along the collapse curve of every joint of every lamella, from the aligned
    joints ``A2 (n, 2)`` registered onto the collapse curve's frame."""
    _, _, t = closest_on_polyline(A2, collapse.points)
    s = np.interp(t, np.arange(len(collapse.s)), collapse.s)
    return {lam.id: s[lam.joints] for lam in traced.net.lamellae}


def _register_2d(P: np.ndarray, Q: np.ndarray) -> np.ndarray:
    """``P (n, 2)`` moved by the orthogonal map + translation that best matches ``Q``."""
    pc, qc = P.mean(axis=0), Q.mean(axis=0)
    U, _, Wt = np.linalg.svd((P - pc).T @ (Q - qc))
    return (P - pc) @ (U @ Wt) + qc


def _pct(d: dict[str, float]) -> dict[str, float]:
    return {k: 100.0 * v for k, v in d.items()}


@dataclass(frozen=True)
class NCPOptions:
    """The keywords of :func:`design_ncp` (same names, defaults and units), as one value of the
    stages' state (``state["opts"]``)."""

    mode: str = "phlw"
    curves: int | tuple[int, int] | None = None
    spacing: float | None = None
    n: float | None = None
    samples: tuple[int, int] = (48, 48)
    levelset_ctrl: tuple[int, int] = (12, 12)
    levelset_degree: tuple[int, int] = (3, 3)
    omega_f: float = 0.01
    trace_grid: tuple[int, int] = (240, 240)
    collapse_samples: tuple[int, int] = (1200, 1200)
    postopt_weights: dict[str, float] | None = None
    postopt_rounds: int = 3
    frames: int = 12
    sim_weights: dict[str, float] | None = None
    surface_samples: tuple[int, int] = (100, 100)
    phlw_options: dict | None = None
    allow_unconverged: bool = False
    strict: bool = False
    units: Any = None
    clean: bool = True
    obj: str | None = None
    progress: Callable[[str], None] | None = None

    def __post_init__(self) -> None:
        if self.mode not in KIND:
            raise InputError(f"unknown mode {self.mode!r}; use 'phlw', 'cnc' or 'aa'")
        if self.n is not None and not np.isfinite(self.n):
            raise InputError(f"the net normal curvature n must be a finite number (1/m), got "
                             f"{self.n}")

    def say(self, message: str) -> None:
        """One line of progress (nothing without a ``progress`` callback)."""
        if self.progress is not None:
            self.progress(message)


def ncp_state(source: Any, opts: NCPOptions) -> dict[str, Any]:
    """The initial state of :data:`NCP_STAGES`: the ``source`` and ``opts`` of the run, the
    user's ``n`` (1/m or None), no ``notes`` yet, the ``timings`` (s) the stages fill, and
    ``t_all``, the clock at the start (``time.perf_counter``)."""
    return {"source": source, "opts": opts, "n": opts.n, "notes": [], "timings": {},
            "t_all": time.perf_counter()}


def _guarded(state: dict[str, Any], run: Callable[[], Any]) -> Any:
    """``run()``; its no-net answer on a surface of the PHLW step is the step's failure (unless
    the user's ``n`` is the reason: ``state["from_phlw"]`` is False then)."""
    try:
        return run()
    except NoNetError as exc:
        if state["from_phlw"]:
            raise _phlw_failure(state["info"], state["opts"].mode, exc) from exc
        raise


@stage("surface", needs=("source", "opts", "n"),
       gives=("surface", "n_src", "info", "input_units", "from_phlw", "reference"))
def _surface_stage(state: dict[str, Any]) -> dict[str, Any]:
    """The B-spline surface: read as it is, or the PHLW step on a reference (load_surface)."""
    o: NCPOptions = state["opts"]
    surf, n_src, info = load_surface(state["source"], mode=o.mode, phlw_options=o.phlw_options,
                                     progress=o.progress, units=o.units, clean=o.clean, obj=o.obj)
    input_units = info.pop("units")
    reference = info.pop("reference", None)      # the user's mesh: the net's fidelity to it
    if o.strict and info.get("phlw_converged") is False:
        raise ConvergenceError(
            "the PHLW step did not converge within its iteration limits (phlw_options outer x "
            "max_iter; --phlw-outer, --phlw-max-iter); raise them, or run without strict to "
            "continue from the unconverged surface")
    # a no-net answer on the PHLW step's surface is the step's failure, unless the user's n
    # is the reason
    return {"surface": surf, "n_src": n_src, "info": info, "input_units": input_units,
            "from_phlw": "phlw_converged" in info and state["n"] is None,
            "reference": reference}


@stage("directions", needs=("surface", "opts", "n", "n_src", "info", "from_phlw", "notes"),
       gives=("dirs", "n", "notes"))
def _directions_stage(state: dict[str, Any]) -> dict[str, Any]:
    """The net directions at the samples (CNC: the fitted ``n``, 1/m)."""
    o: NCPOptions = state["opts"]
    surf, n, cnc = state["surface"], state["n"], o.mode == "cnc"
    u, v = uniform_params(surf, o.samples)
    dirs = _guarded(state, lambda: net_directions(surf, u, v, mode=o.mode, n=n if cnc else None,
                                                  n_hint=state["n_src"] if cnc else None))
    if cnc:
        n = float(dirs.n_rows[0])
    ok = dirs.valid
    o.say(f"net directions on {o.samples[0]} x {o.samples[1]} samples: beta in "
          f"[{np.degrees(dirs.beta[ok].min()):.1f}, {np.degrees(dirs.beta[ok].max()):.1f}] deg")
    for note in dirs.notes:
        o.say(f"note: {note}")
    return {"dirs": dirs, "n": n, "notes": [*state["notes"], *dirs.notes]}


@stage("tracing", needs=("surface", "dirs", "opts"), gives=("traced",))
def _tracing_stage(state: dict[str, Any]) -> dict[str, Any]:
    """The level functions fitted and the net traced (joints, loops, lamellae)."""
    o: NCPOptions = state["opts"]
    traced = trace(state["surface"], state["dirs"], curves=o.curves, spacing=o.spacing,
                   n_ctrl=o.levelset_ctrl, degree=o.levelset_degree, omega_f=o.omega_f,
                   grid=o.trace_grid, progress=o.progress)
    net = traced.net
    o.say(f"traced {len(net.lamellae)} lamellae, {len(net.joints)} joints, {len(net.loops)} "
          "loops")
    for note in traced.dropped:
        o.say(f"note: {note}")
    failed = [f for f, fit in traced.fits.items() if not fit.converged]
    if o.strict and failed:
        raise ConvergenceError(
            f"the level-set fit of family {failed[0]} did not converge; use fewer level-set "
            "control points (--levelset-ctrl) or a larger fairness weight (--omega-f), or run "
            "without strict")
    return {"traced": traced}


@stage("collapse", needs=("surface", "opts", "n", "notes", "info", "from_phlw"),
       gives=("collapse", "notes"))
def _collapse_stage(state: dict[str, Any]) -> dict[str, Any]:
    """The collapse curve of the surface (eq. 4.14)."""
    o: NCPOptions = state["opts"]
    cs = o.collapse_samples
    col = _guarded(state, lambda: collapse_curve(state["surface"], mode=o.mode, n=state["n"],
                                                 samples=cs))
    notes = list(state["notes"])
    if col.fit.get("invalid_samples"):
        notes.append(f"the collapse curve counts {col.fit['invalid_samples']} of "
                     f"{cs[0] * cs[1]} samples without a net direction with the net angle "
                     "clipped to [0, pi/2]")
    o.say(f"collapse curve ({cs[0]} x {cs[1]} samples): length {col.s[-1]:.4g} m, shape "
          f"{col.shape}")
    return {"collapse": col, "notes": notes}


@stage("postopt", needs=("surface", "traced", "collapse", "opts"), gives=("post",))
def _postopt_stage(state: dict[str, Any]) -> dict[str, Any]:
    """The joint mesh post-optimized towards exact alignability (paper 4.2.4)."""
    o: NCPOptions = state["opts"]
    traced = state["traced"]
    post = post_optimize(state["surface"], traced.net, traced.joint_uv, state["collapse"],
                         weights=o.postopt_weights, rounds=o.postopt_rounds,
                         progress=o.progress)
    if o.strict and not post.converged:
        last = post.history[-1]["message"] if post.history else "no round run"
        raise ConvergenceError(
            f"the post-optimization did not converge in {o.postopt_rounds} round(s) ({last}); "
            "give it more rounds (--rounds), or run without strict")
    return {"post": post}


@stage("simulation", needs=("surface", "traced", "post", "opts"),
       gives=("sequence", "collapse_direction"))
def _simulation_stage(state: dict[str, Any]) -> dict[str, Any]:
    """The alignment simulated as a sequence of states (paper 5.1)."""
    o: NCPOptions = state["opts"]
    post = state["post"]
    d = collapse_direction(state["surface"])
    seq = simulate_alignment(post.V, post.r, state["traced"].net.edges(), d,
                             aligned=(post.Vt, post.rt), frames=o.frames,
                             weights=o.sim_weights, progress=o.progress)
    return {"sequence": seq, "collapse_direction": d}


def _design_figures(surf: BSplineSurface, traced: TracedNet, col: CollapseResult,
                    post: PostOptResult, seq: AlignmentSequence,
                    mesh: Any) -> dict[str, Any]:
    """The figures of every mode (paper 5.1; percentages): counts, Delta_a before and after
    the post-optimization, Delta_l, Delta_n (all joints and the interior ones), deviation from
    the surface ``mesh``, crossing normal curvature, collapse length (m), the plane distance
    before projection and the largest edge-length change of the alignment sequence."""
    net = traced.net
    E = net.edges()
    da0 = alignability_error(post.V0, net.loops)
    da1 = alignability_error(post.V, net.loops)
    dl = delta_l(post.V, seq.aligned, E)
    dn = delta_n(post.V, post.r, seq.aligned, seq.aligned_r, E)
    dev = deviation(post.V, mesh.V, mesh.F)
    cross = crossing_normal_curvature(surf, traced)
    inner = interior_vertices(len(net.joints), E)
    return {
        "n_joints": int(len(net.joints)), "n_loops": int(len(net.loops)),
        "n_lamellae": {"C1": len(net.family(1)), "C3": len(net.family(3))},
        "delta_a_before": _pct(summary(da0)), "delta_a_after": _pct(summary(da1)),
        "delta_a_reduction": float(np.nanmean(da0) / max(np.nanmean(da1), 1e-300)),
        "delta_l": _pct(summary(dl)), "delta_n": _pct(summary(dn)),
        "delta_n_interior": _pct(summary(dn[inner])),
        "deviation": {"mean": dev["mean"], "max": dev["max"]},
        "crossing_kn": {"mean": 100 * cross["mean"], "max": 100 * cross["max"],
                        "joints": int(len(cross["joints"]))},
        "collapse_length": float(col.s[-1]),
        "plane_distance_before_projection": seq.plane_distance,
        # the largest edge-length change of any state of the alignment sequence, %
        "sequence_length_error": 100.0 * max(float(np.nanmax(np.abs(delta_l(post.V, V, E))))
                                             for V in seq.V),
    }


def _mode_figures(mode: str, n: float | None, col: CollapseResult,
                  A2: np.ndarray) -> dict[str, Any]:
    """The figures of the collapse of CNC (``n`` 1/m, radii m, errors %: a circle) and AA
    (errors %: a line) designs, from the collapse curve and the aligned joints ``A2 (n, 2)``;
    none for PHLW."""
    if mode == "cnc":
        _, R = fit_circle(A2)
        return {"n": n, "collapse_radius": col.radius,
                "collapse_radius_error": 100 * col.fit.get("radius_error", float("nan")),
                "aligned_radius": R,
                "aligned_radius_error": 100 * abs(R - col.radius) / col.radius}
    if mode == "aa":
        return {"collapse_line_error": 100 * col.fit["line_error"],
                "aligned_line_error": 100 * line_deviation(A2)}
    return {}


@stage("metrics", needs=("surface", "traced", "collapse", "post", "sequence",
                         "collapse_direction", "n", "opts", "reference"),
       gives=("metrics", "gates", "mesh", "aligned_2d", "out_net"))
def _metrics_stage(state: dict[str, Any]) -> dict[str, Any]:
    """The design's figures and the paper's gates on them (``metrics["quality"]``)."""
    o: NCPOptions = state["opts"]
    surf, post, seq, col = state["surface"], state["post"], state["sequence"], state["collapse"]
    mesh = surf.sample(*o.surface_samples)
    B = plane_frame(state["collapse_direction"])
    A2 = _register_2d((seq.aligned - seq.centroid) @ B.T, post.Vt)
    metrics = _design_figures(surf, state["traced"], col, post, seq, mesh)
    metrics.update(_mode_figures(o.mode, state["n"], col, A2))
    # the lamellae carried onto the post-optimized joints: axes.obj and joint_s (the cut
    # files' joint positions) describe the gridshell that aligns, not the traced net; their
    # fairness is the design's
    out_net = move_joints(state["traced"].net, post.V)
    metrics["fairness"] = net_fairness(out_net, mesh.V, mesh.F,
                                       tangent=False, width=design_width_m(mesh.V), states=seq.V,
                                       gate_folds=False)
    from gridshell.measure.fidelity import net_fidelity

    ref = state.get("reference")          # the user's mesh; else the B-spline is the target
    tV, tF = ref if ref is not None else (mesh.V, mesh.F)
    metrics["fidelity"] = {**net_fidelity(out_net.joints, out_net.loops, tV, tF),
                           "target": "the reference mesh" if ref is not None
                           else "the B-spline surface"}
    gates = design_gates(KIND[o.mode], metrics)
    metrics["quality"] = {"ok": passed(gates), "summary": gate_summary(gates),
                          "gates": [{**g.as_dict(), "line": g.line()} for g in gates]}
    return {"metrics": metrics, "gates": gates, "mesh": mesh, "aligned_2d": A2,
            "out_net": out_net}


@stage("gate", needs=("metrics", "gates", "info", "traced", "post", "notes", "opts", "timings",
                      "t_all"), gives=("metrics",))
def _gate_stage(state: dict[str, Any]) -> dict[str, Any]:
    """The timings (s, ``total`` since the start) into the figures; a design missing the
    paper's figures refused unless ``allow_unconverged``."""
    o: NCPOptions = state["opts"]
    gates, notes = state["gates"], state["notes"]
    metrics = {**state["metrics"],
               "timings": {**state["timings"], "total": time.perf_counter() - state["t_all"]}}
    if not passed(gates) and not o.allow_unconverged:
        stopped = _stopped(state["info"], state["traced"], state["post"])
        raise ConvergenceError(
            f"the {KIND[o.mode]} design misses the paper's figures: {gate_summary(gates)}"
            + (f" ({', '.join(stopped)} stopped short of its tolerances)" if stopped else "")
            + (f"; notes: {'; '.join(notes)}" if notes else "")
            + "; try more post-optimization rounds (--rounds), more or fewer curves (--curves), "
            "or pass --allow-unconverged (allow_unconverged=True) to write it anyway, marked as "
            "failing")
    return {"metrics": metrics}


def _bundle_curve(col: CollapseResult) -> CollapseCurve:
    """The collapse curve of the bundle: at most about 600 of its points (m), the last kept."""
    ds = max(1, len(col.points) // 600)
    keep = np.unique(np.concatenate([np.arange(0, len(col.points), ds), [len(col.points) - 1]]))
    return CollapseCurve(points=col.points[keep], normals=col.normals[keep], shape=col.shape,
                         radius=col.radius)


def _params(o: NCPOptions, d: np.ndarray, post: PostOptResult, notes: list[str],
            info: dict) -> dict[str, Any]:
    """The bundle's ``params``: the options of the run, the collapse direction ``d``, the
    post-optimization weights, the notes and the source's ``info``."""
    return {"mode": o.mode, "curves": o.curves, "spacing": o.spacing,
            "samples": list(o.samples),
            "levelset": {"ctrl": list(o.levelset_ctrl), "degree": list(o.levelset_degree),
                         "omega_f": o.omega_f},
            "collapse_samples": list(o.collapse_samples), "frames": o.frames,
            "collapse_direction": d.tolist(), "postopt_weights": post.weights,
            "allow_unconverged": bool(o.allow_unconverged), "notes": notes, **info}


def _report(state: dict[str, Any], metrics: dict[str, Any]) -> dict[str, Any]:
    """The report of the run: figures, the level-set fits, the post-optimization and
    simulation histories, notes, and ``"state"`` (:class:`NCPState`, the arrays)."""
    traced, post, seq = state["traced"], state["post"], state["sequence"]
    return {"metrics": metrics,
            "levelset": {f: {"align_rms_sin": fit.align_rms, "density": fit.density,
                             "converged": fit.converged} for f, fit in traced.fits.items()},
            "postopt": {"history": post.history, "converged": post.converged,
                        "terms": post.report},
            "simulation": {"history": seq.history},
            "dropped": traced.dropped, "notes": state["notes"],
            "quality": metrics["quality"],
            "state": NCPState(state["surface"], traced, state["collapse"], post, seq,
                              state["aligned_2d"])}


@stage("bundle", needs=("surface", "traced", "collapse", "post", "sequence",
                        "collapse_direction", "metrics", "mesh", "aligned_2d", "notes", "info",
                        "input_units", "opts", "out_net"), gives=("design",))
def _bundle_stage(state: dict[str, Any]) -> dict[str, Any]:
    """The design: the bundle (the lamellae on the post-optimized joints) and the report."""
    o: NCPOptions = state["opts"]
    traced, col, post, seq = state["traced"], state["collapse"], state["post"], state["sequence"]
    metrics, mesh, out_net = state["metrics"], state["mesh"], state["out_net"]
    bundle = DesignBundle(kind=KIND[o.mode], net=out_net, aligned=seq.aligned, surface_V=mesh.V,
                          surface_F=mesh.F, metrics=metrics,
                          params=_params(o, state["collapse_direction"], post, state["notes"],
                                         state["info"]),
                          collapse=_bundle_curve(col),
                          collapse_s=_collapse_s(traced, col, state["aligned_2d"]),
                          units=state["input_units"])
    o.say(f"Delta_a {metrics['delta_a_before']['mean']:.3g} % -> "
          f"{metrics['delta_a_after']['mean']:.3g} %, Delta_l max "
          f"{metrics['delta_l']['max']:.3g} %, Delta_n max {metrics['delta_n']['max']:.3g} %")
    return {"design": Design(bundle, _report(state, metrics))}


@stage("strips", needs=("design", "sequence", "opts"), gives=("design",))
def _strips_stage(state: dict[str, Any]) -> dict[str, Any]:
    """The strips of every alignment state: the sequence's joints and own axes, the strips
    between them at their elastic equilibrium from the cut shape
    (:func:`gridshell.structure.heldpath.held_path`; ``sequence/strips.npz``, metrics
    ``sequence_path``)."""
    from gridshell.structure.heldpath import held_path

    design, seq, o = state["design"], state["sequence"], state["opts"]
    st = held_path(design.bundle, seq.V, seq.r, seq.t, progress=o.progress)
    design.report["state"].strips = st
    design.bundle.metrics["sequence_path"] = {
        "physical": True, "method": st["method"],
        "axis_bound_max_rad": float(np.max(st["bound"])),
        "newton_iterations": [int(i) for i in st["iterations"]],
        "fold_deg_max": float(np.max(st["turn_deg"])),
        "length_error_max": float(np.max(st["length_error"])),
        "strong_ratio_max": float(np.max(st["strong_ratio"][1:-1], initial=0.0)),
        "approximate": [int(k) for k in np.flatnonzero(st["approximate"])]}
    o.say(f"strips of {len(seq.V)} alignment states: axes within "
          f"{np.degrees(np.max(st['bound'])):.2g} deg, "
          f"{int(np.sum(st['approximate']))} approximate")
    return {"design": design}


#: The NCP pipeline as named stages over one state dict (:func:`ncp_state`), in order. Each
#: stage's wall time (s) goes to ``state["timings"][name]``; ``metrics["timings"]`` holds those
#: up to ``metrics`` and the ``total`` (taken by ``gate``). ``run_stages(NCP_STAGES, state,
#: until=name)`` stops after a stage (e.g. ``"tracing"`` for the traced net alone).
NCP_STAGES: tuple[Stage, ...] = (_surface_stage, _directions_stage, _tracing_stage,
                                 _collapse_stage, _postopt_stage, _simulation_stage,
                                 _metrics_stage, _gate_stage, _bundle_stage, _strips_stage)


def design_ncp(source: Any, *, mode: str = "phlw", curves: int | tuple[int, int] | None = None,
               spacing: float | None = None, n: float | None = None,
               samples: tuple[int, int] = (48, 48), levelset_ctrl: tuple[int, int] = (12, 12),
               levelset_degree: tuple[int, int] = (3, 3), omega_f: float = 0.01,
               trace_grid: tuple[int, int] = (240, 240),
               collapse_samples: tuple[int, int] = (1200, 1200),
               postopt_weights: dict[str, float] | None = None, postopt_rounds: int = 3,
               frames: int = 12, sim_weights: dict[str, float] | None = None,
               surface_samples: tuple[int, int] = (100, 100), phlw_options: dict | None = None,
               allow_unconverged: bool = False, strict: bool = False, units: Any = None,
               clean: bool = True, obj: str | None = None,
               progress: Callable[[str], None] | None = None) -> Design:
    """Design a normal-curvature-preserving alignable gridshell (paper 4.2.2-4.2.4, 5.1).

    Parameters
    ----------
    source : B-spline JSON written by ``gridshell phlw`` (or a BSplineSurface / PHLWResult), or
        a reference (mesh or .3dm path, or ``(V, F)``): the PHLW step runs first
    units, clean, obj : how a reference is read (:func:`gridshell.io.read.read_input`: the unit
        it is drawn in, cleaning, the .3dm object); the bundle records the unit
    mode : "phlw" (kind NCP), "cnc" (kind CNC, one normal curvature), "aa" (kind AA, n = 0)
    curves : curves per family (or a pair), or ``spacing`` in metres; default 10 curves
    n : CNC normal curvature (default: from the PHLW result or fitted), 1/m
    samples : direction samples of the level-set fit (paper 48 x 48)
    levelset_ctrl, levelset_degree, omega_f : level function (paper 12 x 12, 3, 0.1; omega_f
        defaults to 0.01, see :data:`gridshell.ncp.levelset.LEVELSET_DEFAULTS`)
    trace_grid : marching-squares grid in (u, v)
    collapse_samples : dense sampling of the collapse curve (paper 1200 x 1200)
    postopt_weights, postopt_rounds : post-optimization (Table 2 defaults)
    frames, sim_weights : alignment simulation
    surface_samples : the PHLW sample mesh of the bundle (surface.obj)
    phlw_options : options of the PHLW step for a mesh source (``ctrl``, ``degree``,
        ``transpose``, ``align`` (see :func:`gridshell.ncp.reference.initial_surface`), and any keyword of :func:`gridshell.ncp.phlw.optimize_phlw`)
    allow_unconverged : return a design whose figures miss the paper's thresholds
        (:func:`gridshell.measure.quality.design_gates`: Delta_a mean / max after the
        post-optimization, Delta_l max, Delta_n max, the collapse error of CNC / AA) instead of
        raising :class:`~gridshell.core.errors.ConvergenceError`; its ``metrics["quality"]`` says
        ``"ok": false`` with the failing gates
    strict : deprecated (the figures decide now); also raise as soon as an optimizer (the
        PHLW step, a level-set fit, the post-optimization) stops without meeting its own
        tolerances, even when the figures hold; otherwise the report records it
        (``phlw_converged`` in the params, ``converged`` of ``levelset`` and ``postopt``)
    progress : called with one line per stage

    Raises
    ------
    NoNetError : the surface has no net of ``mode`` (a B-spline source; or a reference mesh
        without one anywhere: umbilic, or K > 0 everywhere for ``aa``)
    ConvergenceError : the figures miss the thresholds (unless ``allow_unconverged``), or the
        PHLW step left a surface without the net

    Returns
    -------
    bundle : DesignBundle (joints post-optimized, ``aligned`` the last simulated state)
    report : JSON-ready figures (metrics, timings, stage details) plus ``"state"``, an
        :class:`NCPState` with the arrays (not JSON)
    """
    opts = NCPOptions(mode=mode, curves=curves, spacing=spacing, n=n, samples=samples,
                      levelset_ctrl=levelset_ctrl, levelset_degree=levelset_degree,
                      omega_f=omega_f, trace_grid=trace_grid, collapse_samples=collapse_samples,
                      postopt_weights=postopt_weights, postopt_rounds=postopt_rounds,
                      frames=frames, sim_weights=sim_weights, surface_samples=surface_samples,
                      phlw_options=phlw_options, allow_unconverged=allow_unconverged,
                      strict=strict, units=units, clean=clean, obj=obj, progress=progress)
    state = ncp_state(source, opts)
    return run_stages(NCP_STAGES, state, state["timings"])["design"]


def write_ncp(path: str | Path, bundle: DesignBundle, report: dict, *, render: bool = True,
              progress: Callable[[str], None] | None = None) -> Path:
    """Deprecated: :func:`gridshell.api.write` writes GG and NCP designs alike
    (``write(path, design_ncp(...))``). Writes ``bundle`` with :func:`ncp_files`."""
    import warnings

    warnings.warn("write_ncp(path, bundle, report) is deprecated; use "
                  "gridshell.write(path, design)", DeprecationWarning, stacklevel=2)
    return write_bundle(path, bundle, extra=ncp_files(bundle, report, render=render,
                                                      progress=progress))


def ncp_files(bundle: DesignBundle, report: dict, *, render: bool = True,
              progress: Callable[[str], None] | None = None) -> dict[str, Any]:
    """The NCP / CNC / AA files of a design bundle beyond
    :func:`gridshell.design.bundle.write_bundle`'s, as its ``extra`` (name -> bytes or writer);
    :func:`gridshell.api.write` writes them. ``report``: the report of :func:`design_ncp`
    (its ``"state"`` holds the arrays).

    ``surface.json`` (the PHLW B-spline), ``report.json``,
    ``axes_r.npy`` (rotation axes of the post-optimized joints) and ``aligned_r.npy`` (of the
    aligned ones) for ``gridshell verify``, ``sequence/frame_000.obj ...`` (the alignment
    sequence; the last frame equals ``aligned.obj``), ``sequence/strips.npz`` (the strips of
    every state, :mod:`gridshell.structure.heldpath`), and with ``render``:
    ``sequence/frame_000.png ...``, ``alignment.gif``, ``delta_a_before.png``,
    ``delta_a_after.png`` (Fig. 13), ``delta_l.png``, ``delta_n.png`` (Fig. 16) and
    ``collapse.png`` (Fig. 15).
    """
    import io

    from gridshell.geometry.meshfile import write_mesh

    st: NCPState = report["state"]
    net = bundle.net
    E = net.edges()
    loops = net.loops
    extra: dict[str, Any] = {}
    extra["surface.json"] = (json.dumps(st.surface.to_json(), indent=1) + "\n").encode()
    extra["report.json"] = report_json(report).encode()
    for name, arr in (("axes_r.npy", st.post.r), ("aligned_r.npy", st.sequence.aligned_r)):
        buf = io.BytesIO()
        np.save(buf, np.asarray(arr, float))
        extra[name] = buf.getvalue()
    nf = len(st.sequence.V)
    width = max(3, len(str(nf - 1)))
    for k, V in enumerate(st.sequence.V):
        extra[f"sequence/frame_{k:0{width}d}.obj"] = (lambda p, V=V: write_mesh(p, V, loops))
    if st.strips is not None:
        strips = st.strips
        extra["sequence/strips.npz"] = (lambda p: np.savez_compressed(
            p, **{k: strips[k] for k in ("X", "N", "lamella", "joint", "kcut", "t",
                                         "approximate", "bound", "iterations", "turn_deg",
                                         "length_error", "strong_ratio")},
            method=np.array(strips["method"])))
    if render:
        from gridshell.render import ncp_maps
        from gridshell.render.net_preview import net_preview

        if progress is not None:
            progress("rendering pictures and the alignment sequence")
        axes = [lam.axis for lam in net.lamellae]
        for tag, V, label in (("before", st.post.V0, "traced"), ("after", st.post.V,
                                                                  "post-optimized")):
            vals = 100 * alignability_error(V, loops)

            def _png(p: Path, V=V, vals=vals, label=label) -> None:
                net_preview(p, bundle.surface_V, bundle.surface_F, V, loops, axes, vals,
                            title=f"Delta_a {label}: mean {np.nanmean(vals):.3g} %, max "
                                  f"{np.nanmax(vals):.3g} %")

            extra[f"delta_a_{tag}.png"] = _png
        dl = 100 * delta_l(net.joints, bundle.aligned, E)
        dn = 100 * delta_n(net.joints, st.post.r, bundle.aligned, st.sequence.aligned_r, E)
        extra["delta_l.png"] = ncp_maps.edge_map(
            net.joints, E, dl, label="Delta_l [%]",
            title=f"Delta_l after alignment: mean {np.nanmean(dl):.3g} %, "
                  f"max {np.nanmax(dl):.3g} %")
        extra["delta_n.png"] = ncp_maps.vertex_map(
            net.joints, E, dn, label="Delta_n [%]",
            title=f"Delta_n after alignment: mean {np.nanmean(dn):.3g} %, "
                  f"max {np.nanmax(dn):.3g} %")
        extra["collapse.png"] = ncp_maps.collapse_plot(
            st.collapse.points, st.collapse.normals, st.aligned_2d,
            title=f"collapse curve ({st.collapse.shape})")
        pngs = ncp_maps.sequence_frames(st.sequence.V, E, title=f"{bundle.kind} alignment")
        for k, b in enumerate(pngs):
            extra[f"sequence/frame_{k:0{width}d}.png"] = b
        extra["alignment.gif"] = ncp_maps.gif(pngs)
    return extra
