"""The GG pipeline (paper 4.1): target surface -> GG mesh -> surface of revolution -> geodesic
alignable net -> net on the designed surface -> metrics -> design bundle.

Stages (each usable alone):

1. :func:`gridshell.gg.initial.initial_grid` and :func:`gridshell.gg.design.design_gg_surface`:
   a mesh ``P (R, C, 3)`` isometric to a surface of revolution approximating the target (4.1.1);
2. :func:`gg_net_from_mesh`: :func:`~gridshell.gg.revolution.rebuild_revolution`,
   :func:`~gridshell.gg.clairaut.geodesic_net`, :func:`~gridshell.gg.mapback.map_back` (4.1.2);
3. :func:`collapse_gg`: the aligned (collapsed) configuration, and
   :func:`gridshell.gg.alignment.gg_alignment_sequence`: the states between the two;
4. :func:`gg_metrics`: paper 5.1 on the result.

:func:`design_gg` runs them as the named stages :data:`GG_STAGES` (read, grid, surface, net,
collapse, metrics, gate, sequence, bundle; :mod:`gridshell.design.stages`), each timed.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components
from scipy.sparse.linalg import lsqr

from gridshell.design.bundle import Design, DesignBundle, report_json, write_bundle
from gridshell.design.section import design_width_m
from gridshell.design.stages import run_stages, stage
from gridshell.core.errors import ConvergenceError, GridshellError, InputError, NoNetError
from gridshell.geometry.grid import grid_quads
from gridshell.measure.metrics import (alignability_error, alignability_error_arc, coverage, delta_l, deviations,
                       geodesic_turning, summary, target_deviation)
from gridshell.geometry.net import Net
from gridshell.measure.fairness import net_fairness
from gridshell.measure.quality import Gate, design_gates, gate_lines, gate_summary, passed
from gridshell.gg.clairaut import geodesic_net
from gridshell.gg.mapback import map_back, map_to_revolution, net_parameters
from gridshell.gg.path import exact_path_possible, gg_path, path_info
from gridshell.gg.revolution import rebuild_revolution
from gridshell.gg.alignment import GGSequence, gg_alignment_sequence

__all__ = ["GG_STAGES", "check_offsets", "collapse_gg", "design_gg", "gg_files", "gg_gates",
           "gg_metrics", "gg_net_from_mesh", "gg_score", "TracedNets", "write_gg"]

Progress = Callable[[str], None] | None


def _say(progress: Progress, msg: str) -> None:
    if progress is not None:
        progress(msg)


# ----------------------------------------------------------------------------- stages


def check_offsets(offsets: Any) -> tuple[np.ndarray, np.ndarray]:
    """Validate user-given lamella positions (non-uniform spacing, paper Fig. 18).

    Parameters
    ----------
    offsets : (seq, seq)
        Positions of the C1 and of the C3 curves on the reference parallel, metres of arc
        length from the first meridian (values outside the parallel are allowed: an inclined
        geodesic crossing the parallel's extension may still reach the surface).

    Returns
    -------
    (o1, o3) : two sorted (k,) float arrays, metres

    Raises
    ------
    InputError
        Not a pair; a family with fewer than 2 positions; a value that is not a finite number;
        two equal positions in one family.
    """
    if isinstance(offsets, (str, bytes)) or not hasattr(offsets, "__len__") or len(offsets) != 2:
        raise InputError("offsets must be a pair (offsets of C1, offsets of C3) in metres")
    out = []
    for fam, o in zip((1, 3), offsets):
        try:
            a = np.asarray(o, dtype=float)
        except (TypeError, ValueError):
            raise InputError(f"offsets of C{fam} must be numbers (metres), got {o!r}") from None
        if a.ndim != 1 or len(a) < 2:
            raise InputError(f"offsets of C{fam}: give at least 2 positions (metres along the "
                             f"reference parallel), got {a.size}")
        if not np.all(np.isfinite(a)):
            raise InputError(f"offsets of C{fam} must be finite numbers (metres), got "
                             f"{a.tolist()}")
        a = np.sort(a)
        if np.any(np.diff(a) <= 0):
            dup = a[1:][np.diff(a) <= 0][0]
            raise InputError(f"offsets of C{fam}: position {dup:g} m is given twice; two "
                             "lamellae of one family cannot lie on each other - remove one")
        out.append(a)
    return out[0], out[1]


#: with neither a count nor a spacing: the spacing that puts this many lamellae of each family
#: across the reference parallel (more reach the surface beyond it; the summary says how many)
DEFAULT_CROSSING = 10


def gg_net_from_mesh(P: np.ndarray, *, n_lamellae: int | None = None, spacing: float | None = None,
                     crossing_angle: float = 90.0, at_parallel: float = 0.5,
                     offsets: tuple[Sequence[float], Sequence[float]] | None = None,
                     angle: float | None = None, step: float | None = None,
                     revolution_net: bool = True, progress: Progress = None) -> dict[str, Any]:
    """The geodesic alignable net of a GG mesh (paper 4.1.2).

    Parameters
    ----------
    P : (R, C, 3) float
        GG mesh, metres (``P[:, j]`` meridians, ``P[i, :]`` parallels).
    n_lamellae : int, optional
        Lamellae made per family (``made`` of :func:`gridshell.gg.clairaut.geodesic_net`);
        with neither it nor ``spacing``: the spacing that puts :data:`DEFAULT_CROSSING` of
        each family across the reference parallel.
    spacing, crossing_angle, at_parallel
        As in :func:`gridshell.gg.clairaut.geodesic_net` (``crossing_angle`` in degrees,
        ``spacing`` in metres along the reference parallel).
    offsets : (seq, seq), optional
        Non-uniform positions of the C1 and C3 curves on the reference parallel, metres of
        arc length from the first meridian; override ``n_lamellae`` / ``spacing``.
    angle : float, optional
        Total angle of the surface of revolution, radians (default: chosen automatically).
    step : float, optional
        Sampling step of the traced curves, metres.
    revolution_net : bool
        Also map the net onto the surface of revolution (``net_rev``; a score needs only
        ``net``).

    Returns
    -------
    dict
        ``rev`` (Revolution), ``inet`` (IntrinsicNet), ``net`` (Net on ``P``), ``extra``
        (joint parameters etc., see :func:`gridshell.gg.mapback.map_net`) and ``net_rev``
        (the same net on the surface of revolution).
    """
    P = np.asarray(P, float)
    if offsets is not None:
        offsets = check_offsets(offsets)
    _say(progress, f"rebuilding the surface of revolution of the {P.shape[0]} x {P.shape[1]} mesh")
    rev = rebuild_revolution(P, angle=angle)
    o1 = o3 = None
    if offsets is not None:
        s_star = rev.s[0] + at_parallel * (rev.s[-1] - rev.s[0])
        r_star = float(rev.r_of_s(s_star))
        o1 = np.asarray(offsets[0], float) / r_star + rev.phi[0]
        o3 = np.asarray(offsets[1], float) / r_star + rev.phi[0]
        n_lamellae = spacing = None
    _say(progress, f"tracing geodesics (crossing angle {crossing_angle:g} deg)")
    try:
        inet = geodesic_net(rev, made=n_lamellae, spacing=spacing,
                            n_lamellae=(DEFAULT_CROSSING if n_lamellae is None and spacing is None
                                        and o1 is None else None),
                            crossing_angle=crossing_angle, at_parallel=at_parallel,
                            offsets1=o1, offsets3=o3, step=step)
    except NoNetError:
        if offsets is None:
            raise
        # the user's positions, not the surface, are wrong: say so in the option's unit
        length = r_star * float(rev.phi[-1] - rev.phi[0])
        raise InputError(
            f"no lamella at the given offsets reaches the surface (C1 {_metres(offsets[0])}, "
            f"C3 {_metres(offsets[1])}); the reference parallel runs from 0 to {length:.4g} m "
            "of arc length: give positions in that range (metres)") from None
    _say(progress, f"mapping {len(inet.curves1)} + {len(inet.curves3)} curves onto the surface")
    net, extra = map_back(inet, P, rev)
    if n_lamellae is not None:                  # the count asked is the count of the net
        inet, net, extra = _net_of_count(int(n_lamellae), inet, net, extra, rev, P,
                                         dict(crossing_angle=crossing_angle,
                                              at_parallel=at_parallel, step=step))
    stage = {"rev": rev, "inet": inet, "net": net, "extra": extra}
    if revolution_net:
        stage["net_rev"] = map_to_revolution(inet, rev)[0]
    return stage


def _family_count(net: Net) -> int:
    return max(len(net.family(1)), len(net.family(3)))


def _net_of_count(n: int, inet, net: Net, extra, rev, P: np.ndarray, options: dict) -> tuple:
    """The net whose larger family has ``n`` lamellae: a curve the tracer counts may leave no
    lamella on the mesh (too short to hold two joints), so the count asked of
    :func:`geodesic_net` is raised (or lowered) until the mapped net has ``n``; where no
    count gives ``n``, the nearest below. ``inet.info["lamellae"]`` records asked and made."""
    best = (net, inet, extra)
    have = _family_count(net)
    if have != n:
        step = 1 if have < n else -1
        for m in range(n + step, n + 8 * step, step):
            if m < 2:
                break
            try:
                i2 = geodesic_net(rev, made=m, **options)
            except (InputError, NoNetError):
                break
            n2, e2 = map_back(i2, P, rev)
            c = _family_count(n2)
            if c == n or (c < n and c > _family_count(best[0])) or \
                    (_family_count(best[0]) > n and c < _family_count(best[0])):
                best = (n2, i2, e2)
            if c == n or (step > 0 and c > n) or (step < 0 and c < n):
                break
    net, inet, extra = best
    inet.info["lamellae"] = {"asked": n, "made": [len(net.family(1)), len(net.family(3))]}
    return inet, net, extra


def _metres(values: Sequence[float]) -> str:
    return ", ".join(f"{float(v):g}" for v in values) + " m"


def collapse_gg(net: Net) -> tuple[np.ndarray, dict[str, float]]:
    """The collapsed (aligned) configuration of a GG net: all lamellae on one straight line.

    Every lamella keeps its length and runs in ``+x``; joint ``J`` on lamellae ``L1`` (C1) and
    ``L3`` (C3) sits at ``x_J = s_J^{L1} + a_{L1} = s_J^{L3} + a_{L3}`` with ``s`` its arc
    length along the lamella. The shifts ``a`` are the least-squares solution over all joints
    (one gauge per connected component); for an alignable net (Definition 4:
    ``l_AB + l_BC = l_AD + l_DC`` on every loop) they agree exactly, otherwise up to
    ``Delta_a`` - the disagreement is reported.

    Returns
    -------
    aligned : (n, 3) float
        ``(x_J - min x, 0, 0)``, metres. Joints of a net-loop are collinear, so the loops are
        degenerate quads, as a collapsed gridshell is.
    info : dict
        ``mismatch_max``, ``mismatch_mean``: disagreement of the lamellae about joint
        positions, metres; ``length``: length of the collapsed bundle, metres.
    """
    n = len(net.joints)
    lam_of, s_of, joint_of = [], [], []
    for li, lam in enumerate(net.lamellae):
        lam_of.append(np.full(len(lam.joints), li))
        s_of.append(lam.joint_s)
        joint_of.append(lam.joints)
    if not lam_of:
        raise InputError("the net has no lamellae; nothing to collapse")
    L, S, J = (np.concatenate(a) for a in (lam_of, s_of, joint_of))
    order = np.lexsort((L, J))
    L, S, J = L[order], S[order], J[order]
    pair = np.flatnonzero(J[1:] == J[:-1])  # consecutive memberships of one joint
    nl = len(net.lamellae)
    rows = np.arange(len(pair))
    A = sp.coo_matrix((np.concatenate([np.ones(len(pair)), -np.ones(len(pair))]),
                       (np.concatenate([rows, rows]), np.concatenate([L[pair], L[pair + 1]]))),
                      shape=(len(pair), nl))
    rhs = S[pair + 1] - S[pair]
    adj = sp.coo_matrix((np.ones(len(pair)), (L[pair], L[pair + 1])), shape=(nl, nl))
    n_comp, label = connected_components(adj, directed=False)
    first = np.array([np.flatnonzero(label == c)[0] for c in range(n_comp)])
    gauge = sp.coo_matrix((np.ones(n_comp), (np.arange(n_comp), first)), shape=(n_comp, nl))
    M = sp.vstack([A, gauge]).tocsr()
    b = np.concatenate([rhs, np.zeros(n_comp)])
    a = lsqr(M, b, atol=1e-14, btol=1e-14, iter_lim=20 * nl + 100)[0]
    xs = S + a[L]
    x = np.bincount(J, weights=xs, minlength=n) / np.maximum(np.bincount(J, minlength=n), 1)
    mism = np.abs(xs - x[J])
    x = x - x.min()
    aligned = np.zeros((n, 3))
    aligned[:, 0] = x
    return aligned, {"mismatch_max": float(mism.max()), "mismatch_mean": float(mism.mean()),
                     "length": float(x.max()), "components": int(n_comp)}


def _pct(d: dict[str, float]) -> dict[str, float]:
    return {k: 100.0 * v for k, v in d.items()}


def gg_metrics(net: Net, V: np.ndarray, F: np.ndarray, *, net_rev: Net | None = None,
               target: tuple[np.ndarray, np.ndarray] | None = None,
               target_samples: tuple[np.ndarray, np.ndarray] | None = None) -> dict[str, Any]:
    """Paper 5.1 metrics of a GG net on its surface ``(V, F)``; percentages.

    Returns
    -------
    dict
        ``alignability`` and ``alignability_arc`` (``{"mean", "max"}`` of ``Delta_a`` in %),
        ``alignability_revolution`` (the same net on the surface of revolution, if given),
        ``geodesic_turning`` (ratio, %, with the normals of the smooth surface through the grid
        when ``(V, F)`` is one, see :func:`gridshell.measure.metrics.geodesic_turning`), and with a
        target: ``deviation`` (the surface's vertices from the target; ``target_samples``, a
        working copy of a big target, if given, is what the target -> surface figures
        ``deviation_target`` and ``coverage`` sample), ``deviation_joints``
        (the joints from the target), ``deviation_target`` (the target from the surface: large
        where the design does not reach the target's boundary), all ``{"mean", "max"}`` in % of
        the target's bounding-box diagonal, and ``coverage`` (area of the surface / area of the
        target, %).
    """
    out: dict[str, Any] = {
        "alignability": _pct(summary(alignability_error(net.joints, net.loops))),
        "alignability_arc": _pct(summary(alignability_error_arc(net))),
    }
    if net_rev is not None:
        out["alignability_revolution"] = _pct(summary(alignability_error(net_rev.joints,
                                                                         net_rev.loops)))
    out["geodesic_turning"] = 100.0 * geodesic_turning(net, V, F)["ratio"]
    if target is not None:
        tV, tF = target
        dv, dj = deviations([V, net.joints], tV, tF)  # one closest-point tree of the target
        out["deviation"] = {"mean": dv["mean"], "max": dv["max"]}
        out["deviation_joints"] = {"mean": dj["mean"], "max": dj["max"]}
        sV, sF = target_samples if target_samples is not None else target
        dt = target_deviation(V, F, sV, sF)
        out["deviation_target"] = {"mean": dt["mean"], "max": dt["max"]}
        out["coverage"] = coverage(V, F, sV, sF)
        from gridshell.measure.fidelity import net_fidelity

        out["fidelity"] = {**net_fidelity(net.joints, net.loops, tV, tF),
                           "target": "the target mesh"}
    out["n_joints"] = int(len(net.joints))
    out["n_loops"] = int(len(net.loops))
    out["n_lamellae"] = {"C1": len(net.family(1)), "C3": len(net.family(3))}
    return out


def gg_gates(metrics: dict[str, Any]) -> list[Gate]:
    """The quality gates of a GG design (:func:`gridshell.measure.quality.design_gates`): ``Delta_a``
    mean < 1 % and max < 3 % on the traced net, with straight edges and with arc lengths."""
    return design_gates("GG", metrics)


def gg_score(P: np.ndarray, **net_options: Any) -> float:
    """How far the net traced on a GG mesh ``P (R, C, 3)`` is from the paper's figures: the
    largest ``figure / threshold`` over :func:`gg_gates` (below 1: every gate passes); ``inf``
    where no net can be traced. ``net_options`` as in :func:`gg_net_from_mesh`."""
    return TracedNets(**net_options).score(P)


def _stage_score(stage: dict[str, Any]) -> float:
    """:func:`gg_score` of a traced net (a :func:`gg_net_from_mesh` result)."""
    try:
        net = stage["net"]
        if len(net.loops) == 0:
            return float("inf")
        m = {"alignability": summary(alignability_error(net.joints, net.loops)),
             "alignability_arc": summary(alignability_error_arc(net))}
    except GridshellError:
        return float("inf")
    gates = gg_gates({k: _pct(v) for k, v in m.items()})
    ratios = [g.value / g.limit if g.value is not None and np.isfinite(g.value) else np.inf
              for g in gates]
    return float(max(ratios))


class TracedNets:
    """The nets traced on GG meshes, kept by mesh: the design scores its checkpoints by their
    traced nets (:meth:`score`, :func:`gg_score`) and returns one of them, whose net
    :meth:`net` then gives without tracing it again (one trace less per design; the scores
    skip the net on the surface of revolution, which :meth:`net` adds). The key is the mesh's
    exact bytes, so a reused net is the net a new trace would give. ``traced`` counts the
    traces made."""

    def __init__(self, **net_options: Any) -> None:
        self.options = net_options
        self.traced = 0
        self._nets: dict[tuple, dict[str, Any]] = {}

    @staticmethod
    def _key(P: np.ndarray) -> tuple:
        P = np.ascontiguousarray(P, dtype=float)
        return P.shape, P.tobytes()

    def _traced(self, P: np.ndarray, progress: Progress = None) -> dict[str, Any]:
        key = self._key(P)
        stage = self._nets.get(key)
        if stage is None:
            self.traced += 1  # the scores need no net on the surface of revolution
            stage = self._nets[key] = gg_net_from_mesh(P, **self.options, progress=progress,
                                                       revolution_net=False)
        else:
            _say(progress, "tracing geodesics: the net traced when the design checked this mesh")
        return stage

    def net(self, P: np.ndarray, progress: Progress = None) -> dict[str, Any]:
        """:func:`gg_net_from_mesh` of ``P`` with the options given, traced once per mesh."""
        stage = self._traced(P, progress)
        if "net_rev" not in stage:
            stage["net_rev"] = map_to_revolution(stage["inet"], stage["rev"])[0]
        return stage

    def score(self, P: np.ndarray) -> float:
        """:func:`gg_score` of ``P``; its net is kept for :meth:`net`."""
        try:
            stage = self._traced(P)
        except GridshellError:
            return float("inf")
        return _stage_score(stage)


# ----------------------------------------------------------------------------- the pipeline


def _load_target(target: Any, units: Any = None, clean: bool = True, obj: str | None = None,
                 progress: Progress = None) -> tuple[np.ndarray, np.ndarray, Any]:
    """``(V, F, input)`` of a target (path, InputGeometry, mesh or ``(V, F)``), metres, read
    through :func:`gridshell.io.read.read_input` (units, cleaning, the disk check)."""
    from gridshell.io.read import read_input

    geo = read_input(target, units=units, clean=clean, obj=obj)
    if progress is not None and geo.path is not None:
        progress(f"input: {geo.summary()}")
    return geo.V, geo.F, geo


def design_gg(target: Any, *, meridians: str = "cols", grid: tuple[int, int] | None = None,
              direction: float | None = None, n_lamellae: int | None = None,
              spacing: float | None = None, crossing_angle: float = 90.0,
              at_parallel: float = 0.5,
              offsets: tuple[Sequence[float], Sequence[float]] | None = None,
              weights: dict[str, float] | None = None, angle: float | None = None,
              rounds: int = 10, polish_iter: int = 20, allow_unconverged: bool = False,
              frames: int = 12, units: Any = None, clean: bool = True,
              obj: str | None = None, progress: Progress = None
              ) -> Design:
    """Design a geodesic alignable gridshell on (an approximation of) a target surface: the
    stages :data:`GG_STAGES` run over the parameters, each timed.

    Parameters
    ----------
    target : path (OBJ, PLY, OFF, 3DM), InputGeometry, QuadMesh/TriMesh or (V, F)
        The target surface, one disk (a .3dm NURBS surface is sampled).
    units, clean, obj
        The unit the target is drawn in (None: a .3dm's own, else metres if plausible),
        cleaning (weld, de-duplicate, orient) and the .3dm object to read: see
        :func:`gridshell.io.read.read_input`. The bundle records the unit.
    meridians : {"rows", "cols"}
        For a structured quad-grid target: which grid lines become the meridians (geodesics
        of the designed surface); passed to :func:`gridshell.gg.initial.initial_grid`.
    grid : (R, C), optional
        Resolution of the GG mesh (default from the target).
    direction : float, optional
        Meridian direction in degrees for unstructured targets (see ``initial_grid``).
    n_lamellae, spacing, crossing_angle, at_parallel, offsets, angle
        The net (see :func:`gg_net_from_mesh`).
    weights : dict, optional
        Weights of the surface optimization (see ``design_gg_surface``).
    rounds, polish_iter : int
        Outer rounds and most final projection iterations of the surface optimization (the
        projection stops once the figures of the traced net hold and stagnate, and returns
        the best of its checkpoints: a longer polish never gives a worse design).
    allow_unconverged : bool
        Return a design that misses the paper's figures instead of raising; it is marked in
        ``bundle.params["quality"]`` (``"ok": False``) and ``bundle.params["converged"]``.
    frames : int
        Steps of the alignment sequence from the deployed to the collapsed net
        (:func:`gridshell.gg.alignment.gg_alignment_sequence`); 0: none.
    progress : callable, optional
        Receives one-line progress messages.

    Raises
    ------
    ConvergenceError
        The design misses the paper's figures (:func:`gg_gates`: ``Delta_a`` mean < 1 %, max
        < 3 %, straight and arc, on the net traced on the designed surface) and
        ``allow_unconverged`` is off; the message names the failing figures.

    Returns
    -------
    bundle : DesignBundle
        ``kind="GG"``; aligned = :func:`collapse_gg`; surface = the GG mesh; revolution = the
        isometric surface of revolution; metrics = :func:`gg_metrics`; ``params["quality"]``
        = ``{"ok", "gates" (Gate.as_dict() each), "summary"}``, ``params["surface"]`` = the
        surface optimization's residuals and why its polish stopped.
    report : dict
        The surface optimization's report, the revolution's info, the collapse info,
        ``sequence`` (a :class:`~gridshell.gg.alignment.GGSequence`, or None with
        ``frames=0``) and ``timings`` (seconds per stage). With a sequence the metrics hold
        ``delta_l`` (``{"mean", "max"}``, %: edge lengths of ``aligned`` against the deployed
        chords, which lengthen to the arc lengths) and ``sequence_length_error`` (the largest
        such change over all states, %).
    """
    state = dict(locals())  # the parameters are the stages' initial state
    timings: dict[str, float] = {}
    run_stages(GG_STAGES, state, timings)
    state["report"]["timings"] = timings
    return Design(state["bundle"], state["report"])


#: the net's options, as :func:`gg_net_from_mesh` and :class:`TracedNets` take them
NET_OPTIONS = ("n_lamellae", "spacing", "crossing_angle", "at_parallel", "offsets", "angle")


@stage("read", needs=("target", "units", "clean", "obj", "offsets", "n_lamellae", "spacing",
                      "progress"),
       gives=("V", "F", "geo", "offsets", "n_lamellae", "spacing"))
def _read_stage(s: dict[str, Any]) -> dict[str, Any]:
    """The target read and cleaned (metres); user-given offsets checked first."""
    offsets, n_lamellae, spacing = s["offsets"], s["n_lamellae"], s["spacing"]
    if offsets is not None:
        offsets = check_offsets(offsets)  # before the long surface optimization
        n_lamellae = spacing = None       # the offsets place every lamella
    V, F, geo = _load_target(s["target"], s["units"], s["clean"], s["obj"], s["progress"])
    _say(s["progress"], f"target: {len(V)} vertices, {len(F)} faces")
    return {"V": V, "F": F, "geo": geo, "offsets": offsets, "n_lamellae": n_lamellae,
            "spacing": spacing}


@stage("grid", needs=("V", "F", "meridians", "grid", "direction", "progress"),
       gives=("Vw", "Fw", "work", "P0"))
def _grid_stage(s: dict[str, Any]) -> dict[str, Any]:
    """The initial grid ``P0 (R, C, 3)`` on the target (on a working copy of a big one)."""
    from gridshell.gg.initial import initial_grid
    from gridshell.io.working import working_mesh

    progress, F = s["progress"], s["F"]
    # a big target: the grid is sampled and projected on a working copy; the deviations
    # are measured against the full target
    Vw, Fw, work = working_mesh(s["V"], F)
    if work is not None:
        _say(progress, f"designing on a working copy of {work['faces'][1]} faces "
             f"({work['method']}); deviations measured against all {len(F)}")
    P0 = initial_grid(Vw, Fw, meridians=s["meridians"], grid=s["grid"],
                      direction=s["direction"])
    _say(progress, f"initial grid {P0.shape[0]} x {P0.shape[1]}; designing the GG surface")
    return {"Vw": Vw, "Fw": Fw, "work": work, "P0": P0}


@stage("surface", needs=("Vw", "Fw", "P0", "weights", "rounds", "polish_iter", "progress")
       + NET_OPTIONS, gives=("surface", "nets", "P"))
def _surface_stage(s: dict[str, Any]) -> dict[str, Any]:
    """The GG surface (4.1.1): rounds towards the target, then the polish onto the
    constraints, its checkpoints scored by the nets traced on them."""
    from gridshell.gg.design import design_gg_surface

    nets = TracedNets(**{k: s[k] for k in NET_OPTIONS})
    surface = design_gg_surface(s["Vw"], s["Fw"], s["P0"], weights=s["weights"],
                                outer=s["rounds"], polish_iter=s["polish_iter"],
                                progress=s["progress"], evaluate=nets.score)
    return {"surface": surface, "nets": nets, "P": surface.P}


@stage("net", needs=("nets", "P", "progress"), gives=("rev", "inet", "net", "net_rev"))
def _net_stage(s: dict[str, Any]) -> dict[str, Any]:
    """The geodesic net (4.1.2) on the surface of revolution of ``P``, mapped back: the net
    the design's check traced."""
    traced = s["nets"].net(s["P"], progress=s["progress"])
    net = traced["net"]
    _say(s["progress"], f"net: {len(net.joints)} joints, {len(net.loops)} loops, "
         f"{len(net.lamellae)} lamellae; collapsing and measuring")
    return {k: traced[k] for k in ("rev", "inet", "net", "net_rev")}


@stage("collapse", needs=("net",), gives=("aligned", "collapse_info"))
def _collapse_stage(s: dict[str, Any]) -> dict[str, Any]:
    """The aligned (collapsed) configuration of the net (:func:`collapse_gg`)."""
    aligned, collapse_info = collapse_gg(s["net"])
    return {"aligned": aligned, "collapse_info": collapse_info}


@stage("metrics", needs=("net", "net_rev", "P", "V", "F", "Vw", "Fw", "work", "collapse_info"),
       gives=("metrics", "surface_V", "surface_F"))
def _metrics_stage(s: dict[str, Any]) -> dict[str, Any]:
    """Paper 5.1 on the net and the GG mesh (:func:`gg_metrics`), percentages."""
    R, C = s["P"].shape[:2]
    sV, sF = s["P"].reshape(-1, 3), grid_quads(R, C)
    metrics = gg_metrics(s["net"], sV, sF, net_rev=s["net_rev"], target=(s["V"], s["F"]),
                         target_samples=(s["Vw"], s["Fw"]) if s["work"] is not None else None)
    metrics["collapse_mismatch_max"] = s["collapse_info"]["mismatch_max"]
    return {"metrics": metrics, "surface_V": sV, "surface_F": sF}


@stage("gate", needs=("metrics", "surface", "allow_unconverged", "progress"),
       gives=("quality",))
def _gate_stage(s: dict[str, Any]) -> dict[str, Any]:
    """The paper's figures gated (:func:`gg_gates`); a miss raises ConvergenceError unless
    ``allow_unconverged``."""
    gates = gg_gates(s["metrics"])
    quality = {"ok": passed(gates), "gates": [g.as_dict() for g in gates],
               "summary": gate_summary(gates)}
    _say(s["progress"], "quality: " + quality["summary"])
    if not quality["ok"] and not s["allow_unconverged"]:
        design = s["surface"]
        raise ConvergenceError(
            f"the GG design misses the paper's figures ({quality['summary']}; surface residuals: "
            f"geodesic {design.geodesic_residual_max:.2e} rad, edge-length spread "
            f"{design.length_residual_rel_max:.2e}, polish stopped: {design.stop}). Try a finer "
            "grid (--grid R C: a coarse grid carries the net poorly), fewer lamellae "
            "(--lamellae N), or a target closer to a surface of revolution; "
            "--allow-unconverged writes the design anyway, marked as failing")
    return {"quality": quality}


@stage("sequence", needs=("net", "aligned", "metrics", "frames", "progress", "inet", "rev", "P"),
       gives=("sequence", "metrics"))
def _sequence_stage(s: dict[str, Any]) -> dict[str, Any]:
    """The alignment sequence from the deployed to the collapsed net (``frames`` steps; none
    with 0): the physical path through surfaces of revolution
    (:func:`gridshell.gg.path.gg_path`), or where it does not apply (a Clairaut turning point)
    the optimized sequence (:func:`gg_alignment_sequence`); its length figures ``delta_l``,
    ``sequence_length_error`` (%) and ``sequence_path`` (how it was made)."""
    net, aligned, frames, metrics = s["net"], s["aligned"], int(s["frames"]), s["metrics"]
    seq = None
    if frames > 0:
        _say(s["progress"], f"alignment sequence: {frames} steps from deployed to collapsed")
        seq = gg_path(s["inet"], s["rev"], net, aligned, s["P"], frames=frames)
        if seq is None:
            why = exact_path_possible(net_parameters(s["inet"]), s["rev"], s["inet"].c) or \
                "the traced net does not match its parameters"
            seq = gg_alignment_sequence(net.joints, aligned, net.edges(), frames=frames,
                                        progress=s["progress"])
            metrics["sequence_path"] = {"physical": False, "why": why,
                                        "method": "optimized joint sequence (approximate)"}
        else:
            metrics["sequence_path"] = {"physical": True, **path_info(seq)}
        metrics["delta_l"] = _pct(summary(delta_l(net.joints, aligned, seq.edges)))
        metrics["sequence_length_error"] = 100.0 * max(
            float(np.nanmax(delta_l(net.joints, V, seq.edges))) for V in seq.V)
    return {"sequence": seq, "metrics": metrics}


@stage("fairness", needs=("net", "surface_V", "surface_F", "sequence", "metrics"),
       gives=("metrics",))
def _fairness_stage(s: dict[str, Any]) -> dict[str, Any]:
    """Lamella fairness and net sanity (:func:`gridshell.measure.fairness.net_fairness`:
    in-plane radius against 10 strip widths (:func:`design_width_m`),
    corners, hairpins, loops, distance from the surface, folds of the alignment states)."""
    seq = s["sequence"]
    fair = net_fairness(s["net"], s["surface_V"], s["surface_F"], tangent=True,
                        width=design_width_m(s["surface_V"]),
                        states=None if seq is None else seq.V)
    return {"metrics": {**s["metrics"], "fairness": fair}}


@stage("bundle", needs=("net", "aligned", "surface_V", "surface_F", "metrics", "rev", "inet",
                        "geo", "surface", "collapse_info", "sequence"),
       gives=("bundle", "report"))
def _bundle_stage(s: dict[str, Any]) -> dict[str, Any]:
    """The design bundle (net, aligned, GG mesh, surface of revolution, metrics, parameters)
    and the report of the run."""
    rev, inet, design = s["rev"], s["inet"], s["surface"]
    rV, rF = rev.mesh()
    metrics = dict(s["metrics"])
    counted = inet.info.get("lamellae") or {}
    if counted.get("asked") is not None:
        made = max(counted["made"])
        metrics["lamellae_count"] = {
            "asked": counted["asked"], "made": made,
            "why": "" if made == counted["asked"] else
            f"{made} is the nearest count of evenly spaced geodesics that reach this surface "
            "(the count jumps there); --spacing M sets the spacing itself"}
    bundle = DesignBundle(kind="GG", net=s["net"], aligned=s["aligned"],
                          surface_V=s["surface_V"], surface_F=s["surface_F"],
                          metrics=metrics, params=_gg_params(s), revolution_V=rV,
                          revolution_F=rF, units=s["geo"].units)
    design_report = dict(design.report, converged=design.converged, history=design.history,
                         stop=design.stop, checkpoint=design.checkpoint, score=design.score,
                         deviation=design.deviation)
    report = {"design": design_report, "revolution": rev.info, "collapse": s["collapse_info"],
              "net": inet.info, "sequence": s["sequence"]}
    return {"bundle": bundle, "report": report}


def _gg_params(s: dict[str, Any]) -> dict[str, Any]:
    """``bundle.params`` of a GG design: its options, the quality, the input, the surface
    optimization's residuals, the revolution's angles and the net's Clairaut constant."""
    R, C = s["P"].shape[:2]
    design, rev, inet, quality = s["surface"], s["rev"], s["inet"], s["quality"]
    offsets = s["offsets"]
    return {"target": s["geo"].path, "meridians": s["meridians"], "grid": [int(R), int(C)],
            "direction": s["direction"], "n_lamellae": s["n_lamellae"],
            "spacing": s["spacing"], "crossing_angle": s["crossing_angle"],
            "at_parallel": s["at_parallel"],
            "offsets": [list(map(float, o)) for o in offsets] if offsets else None,
            "weights": s["weights"], "converged": quality["ok"], "quality": quality,
            "input": {**s["geo"].info(), "working_mesh": s["work"]},
            "surface": {"geodesic_residual_max": design.geodesic_residual_max,
                        "length_residual_rel_max": design.length_residual_rel_max,
                        "residuals_at_round_off": design.converged, "polish_stop": design.stop,
                        "checkpoint": design.checkpoint},
            "dphi": rev.dphi,
            "total_angle": rev.total_angle,
            "clairaut_c": inet.c, "s_star": inet.s_star, "frames": int(s["frames"])}


#: the GG pipeline (paper 4.1), in order: :func:`design_gg` runs them over its parameters
GG_STAGES = (_read_stage, _grid_stage, _surface_stage, _net_stage, _collapse_stage,
             _metrics_stage, _sequence_stage, _fairness_stage, _gate_stage, _bundle_stage)


def _edge_families(net: Net, edges: np.ndarray) -> np.ndarray:
    """Lamella family (1 or 3) of each joint-mesh edge ``(E, 2)`` (sorted pairs)."""
    fam: dict[tuple[int, int], int] = {}
    for lam in net.lamellae:
        for a, b in zip(lam.joints[:-1].tolist(), lam.joints[1:].tolist()):
            fam[(min(a, b), max(a, b))] = lam.family
    return np.array([fam.get((int(min(a, b)), int(max(a, b))), 0) for a, b in edges], np.int64)


def write_gg(path: str | Path, bundle: DesignBundle, *, preview: bool = True,
             sequence: GGSequence | None = None, frames: int = 12,
             progress: Progress = None) -> Path:
    """Deprecated: :func:`gridshell.api.write` writes GG and NCP designs alike
    (``write(path, design_gg(...))``). Writes ``bundle`` with :func:`gg_files` (``preview``
    is ``render``; ``sequence`` the states to write, else ``frames`` computed)."""
    import warnings

    warnings.warn("write_gg(path, bundle) is deprecated; use gridshell.write(path, design)",
                  DeprecationWarning, stacklevel=2)
    report = None if sequence is None else {"sequence": sequence}
    return write_bundle(path, bundle, extra=gg_files(bundle, report, render=preview,
                                                     frames=frames, progress=progress))


def gg_files(bundle: DesignBundle, report: dict | None = None, *, render: bool = True,
             frames: int = 12, progress: Progress = None) -> dict[str, Any]:
    """The GG files of a design bundle beyond :func:`gridshell.design.bundle.write_bundle`'s, as its
    ``extra`` (name -> bytes or writer); :func:`gridshell.api.write` writes them.

    ``report.json`` (the report of :func:`design_gg` without its arrays, when given), the
    alignment sequence ``sequence/frame_000.obj ...`` (joints of every state with the
    net-loops as faces; the first equals ``net.obj``, the last ``aligned.obj``), and with
    ``render``: ``preview.png`` (the net on the designed surface, loops coloured by the
    straight-edge ``Delta_a`` in %), ``sequence/frame_*.png``, ``alignment.gif`` and
    ``states.png`` (deployed, two intermediate states and the collapsed net side by side).

    Parameters
    ----------
    report : dict, optional
        The report of :func:`design_gg`; its ``"sequence"`` (None: no sequence) is written.
        Without a report the sequence is computed with ``frames`` steps.
    frames : int
        Steps of a computed sequence; 0 writes none.
    """
    from gridshell.geometry.meshfile import write_mesh

    net = bundle.net
    extra: dict[str, Any] = {}
    if report is not None:
        sequence = report.get("sequence")
        if set(report) - {"sequence"}:
            extra["report.json"] = report_json(report).encode()
    else:
        sequence = None
        if int(frames) > 0 and len(net.joints):
            _say(progress, f"alignment sequence: {int(frames)} steps from deployed to collapsed")
            sequence = gg_alignment_sequence(net.joints, bundle.aligned, net.edges(),
                                             frames=int(frames), progress=progress)
    if sequence is not None:
        width = max(3, len(str(len(sequence.V) - 1)))
        for k, V in enumerate(sequence.V):
            extra[f"sequence/frame_{k:0{width}d}.obj"] = (
                lambda p, V=V: write_mesh(p, V, net.loops))
        if getattr(sequence, "strips", None) is not None:
            extra["sequence/strips.npz"] = sequence.strips.save
    if render:
        from gridshell.render.net_preview import net_preview

        values = 100.0 * alignability_error(net.joints, net.loops)

        def _png(p: Path) -> None:
            net_preview(p, bundle.surface_V, bundle.surface_F, net.joints,
                        net.loops, [lam.axis for lam in net.lamellae], values,
                        title=f"GG net: mean Delta_a {np.nanmean(values):.3g} %")

        extra["preview.png"] = _png
        if sequence is not None:
            from gridshell.render import ncp_maps
            from gridshell.render.state_sheet import sequence_pngs, states_png

            _say(progress, f"rendering {len(sequence.V)} alignment states and alignment.gif")
            fam = _edge_families(net, sequence.edges)
            pngs = sequence_pngs(sequence.V, sequence.edges, title="GG alignment",
                                 families=fam, t=sequence.t)
            for k, b in enumerate(pngs):
                extra[f"sequence/frame_{k:0{width}d}.png"] = b
            hold = [pngs[0]] * 3 + list(pngs) + [pngs[-1]] * 3
            extra["alignment.gif"] = ncp_maps.gif(hold, duration_ms=250)
            K = len(sequence.V) - 1
            pick = sorted({0, int(round(K / 3)), int(round(2 * K / 3)), K})
            labels = ["deployed" if k == 0 else "collapsed" if k == K else
                      f"t = {sequence.t[k]:.2f}" for k in pick]
            err = 100.0 * max(float(np.nanmax(delta_l(net.joints, V, sequence.edges)))
                              for V in sequence.V)
            extra["states.png"] = states_png(
                [sequence.V[k] for k in pick], sequence.edges, labels=labels, families=fam,
                title=f"GG alignment: joint-to-joint lengths within {err:.2g} % of the "
                      "deployed net in every state")
    return extra
