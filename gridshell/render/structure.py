"""Pictures and the report fragment of the structural check (``structure.json``).

:func:`render_utilisation` draws every lamella as a ribbon (as :mod:`.ribbons`) coloured by
the utilisation of its strip along it (0 green .. 1 red, darker beyond), marks the worst point
and writes ``structure.png``; :func:`structure_section` is the HTML section that
``report.html`` includes when the bundle holds ``structure.json``.
"""
from __future__ import annotations

import html
import json
import os
from pathlib import Path
from typing import Any

import numpy as np

from ..atomic import atomic_path
from ..errors import InputError
from .ribbons import (TANGENT_KINDS, _camera_dir, _fit_view, _shade, _surface_near, _unit,
                      default_width, nearest_vertex_normals, ribbon_polygons, view_angles)

__all__ = ["render_utilisation", "structure_section", "utilisation_colours", "PICTURE"]

PICTURE = "structure.png"


def utilisation_colours(u: np.ndarray, top: float | None = None) -> np.ndarray:
    """RGB ``(k,3)`` of utilisations ``u`` on the map used by the pictures: RdYlGn reversed
    over ``[0, 1]`` and a darkening red over ``[1, top]`` (``top`` default ``max(u, 1)``)."""
    from matplotlib import colormaps

    u = np.nan_to_num(np.asarray(u, float), nan=0.0)
    top = max(float(np.max(u, initial=1.0)), 1.0) if top is None else max(float(top), 1.0)
    rgb = colormaps["RdYlGn_r"](np.clip(u, 0.0, 1.0))[:, :3]
    over = u > 1.0
    if over.any() and top > 1.0:
        f = np.clip((u[over] - 1.0) / (top - 1.0), 0.0, 1.0)[:, None]
        rgb[over] = (1 - f) * rgb[over] + f * np.array([0.35, 0.0, 0.05])
    return rgb


def render_utilisation(bundle, result: dict[str, Any], path: str | os.PathLike, *,
                       width: float | None = None, size: tuple[int, int] = (1000, 750),
                       dpi: int = 100, max_points: int = 200) -> Path:
    """Write the utilisation picture of ``bundle`` (a :class:`~gridshell.bundle.DesignBundle`
    or its directory) from ``result`` (:func:`gridshell.structure.check.check_bundle`) to
    ``path`` (PNG, atomically). ``width``: ribbon width, metres of the design (default as
    ``render.png``)."""
    from matplotlib import colormaps
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    from ..bundle import read_bundle

    b = read_bundle(bundle) if isinstance(bundle, (str, os.PathLike)) else bundle
    recs = {int(r["id"]): r for r in result.get("lamellae", [])}
    lams = [lam for lam in b.net.lamellae if len(lam.axis) >= 2]
    if not lams:
        raise InputError("render_utilisation: no lamella axes to draw")
    if width is None:
        gaps = np.concatenate([np.diff(lam.joint_s) for lam in lams] or [np.zeros(0)])
        gaps = gaps[gaps > 0]
        width = default_width([lam.axis for lam in lams],
                              float(np.median(gaps)) if len(gaps) else None)
    top = max(float(result.get("max_utilisation_deployed", 1.0) or 1.0), 1.0)
    pts = np.concatenate([lam.axis for lam in lams] + [b.net.joints])
    elev, azim = view_angles(pts)
    light = _unit(_camera_dir(elev + 25.0, azim - 30.0))
    polys, cols = [], []
    for lam in lams:
        idx = np.unique(np.linspace(0, len(lam.axis) - 1, min(len(lam.axis), max_points))
                        .round().astype(int))
        a = lam.axis[idx]
        u = np.asarray(recs.get(int(lam.id), {}).get("utilisation") or np.zeros(len(lam.axis)),
                       float)
        u = u[idx] if len(u) == len(lam.axis) else np.zeros(len(idx))
        q = ribbon_polygons(a, nearest_vertex_normals(a, b.surface_V, b.surface_F), width,
                            b.kind in TANGENT_KINDS)
        polys.append(q)
        cols.append(utilisation_colours(np.maximum(u[:-1], u[1:]), top))
    R = np.concatenate(polys)
    rgb = _shade(R, np.concatenate(cols), light) * 0.35 + np.concatenate(cols) * 0.65
    S = _surface_near(np.asarray(b.surface_V, float), np.asarray(b.surface_F, np.int64), pts,
                      8000)
    if S.shape[1] == 3:
        S = np.concatenate([S, S[:, 2:3]], axis=1)
    face = np.concatenate([np.tile((0.62, 0.64, 0.68, 0.15), (len(S), 1)),
                           np.column_stack([rgb, np.ones(len(R))])])
    edge = np.concatenate([np.zeros((len(S), 4)),
                           np.column_stack([0.7 * rgb, np.full(len(R), 0.9)])])
    fig = Figure(figsize=(size[0] / dpi, size[1] / dpi), dpi=dpi)
    ax = fig.add_axes((0.0, 0.0, 0.88, 0.93), projection="3d")
    ax.computed_zorder = False
    coll = Poly3DCollection(np.concatenate([S, R]), facecolors=face, edgecolors=edge,
                            linewidths=0.25)
    ax.add_collection3d(coll)
    w = result.get("worst") or {}
    wl = next((lam for lam in lams if int(lam.id) == w.get("lamella")), None)
    if wl is not None:
        from ..net import polyline_arclength

        s = polyline_arclength(wl.axis)
        p = np.array([np.interp(float(w.get("s_m", 0.0)), s, wl.axis[:, c]) for c in range(3)])
        ax.scatter([p[0]], [p[1]], [p[2]], s=60, marker="x", color="black", zorder=6,
                   depthshade=False)
        ax.text(p[0], p[1], p[2], f"  L{wl.id}: {w.get('utilisation', 0):.2f}", fontsize=8,
                zorder=7)
    ax.view_init(elev=elev, azim=azim)
    ax.set_axis_off()
    _fit_view(fig, ax, np.concatenate([pts, R.reshape(-1, 3)]))
    coll.set_clip_on(False)
    cax = fig.add_axes((0.90, 0.15, 0.025, 0.65))
    sm = ScalarMappable(norm=Normalize(0.0, 1.0), cmap=colormaps["RdYlGn_r"])
    cb = fig.colorbar(sm, cax=cax)
    cb.set_label("utilisation (1 = elastic limit)", fontsize=8)
    sec, mat = result.get("section", {}), result.get("material", {})
    fig.suptitle(f"{b.kind}: {sec.get('width_mm', 0):g} x {sec.get('thickness_mm', 0):g} mm "
                 f"{mat.get('name', '')} at {sec.get('scale_text', '')}, max utilisation "
                 f"{result.get('max_utilisation_deployed', 0):.2f} deployed - "
                 f"{result.get('verdict', '')}", fontsize=10)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=dpi)
    return Path(path)


def _num(v: Any, fmt: str = "{:.3g}") -> str:
    if v is None or (isinstance(v, float) and not np.isfinite(v)):
        return "&ndash;"
    return fmt.format(v)


def structure_section(bundle_dir: str | os.PathLike, rows: int = 40) -> str:
    """The ``<section>`` of report.html on ``bundle_dir/structure.json`` ("" without it): the
    verdict, material and section, the states, and the lamellae by utilisation (``rows``)."""
    f = Path(bundle_dir) / "structure.json"
    if not f.is_file():
        return ""
    try:
        r = json.loads(f.read_text(encoding="utf-8"))
        lams = sorted(r["lamellae"], key=lambda x: -float(x["max_utilisation"]))
        ok = r["verdict"] == "ok"
    except (OSError, ValueError, KeyError, TypeError):
        return ('<section id="structure"><h2>Structure</h2><p class=info>structure.json is '
                "unreadable; run <code>gridshell check DIR</code> again.</p></section>")
    sec, mat, w = r.get("section", {}), r.get("material", {}), r.get("worst", {})
    verdict = (f'<span class="verdict {"pass" if ok else "fail"}">'
               f'{"&#10003; elastic" if ok else "&#10007; overstressed"}: max utilisation '
               f'{_num(r.get("max_utilisation"), "{:.2f}")} ({html.escape(str(r.get("governing_state")))})'
               "</span>")
    info = [("material", f"{html.escape(str(mat.get('label', '')))}: E {_num(mat.get('E', 0) / 1e9)}"
                         f" GPa, G {_num(mat.get('G', 0) / 1e9)} GPa, allowable "
                         f"{_num(mat.get('allowable', 0) / 1e6)} MPa"),
            ("strip", f"{_num(sec.get('width_mm'))} x {_num(sec.get('thickness_mm'))} mm at "
                      f"{html.escape(str(sec.get('scale_text', '')))} (edge ratio "
                      f"{_num(sec.get('edge_ratio'))}:1)"),
            ("worst point (deployed)", f"lamella {w.get('lamella')} at s = "
                                       f"{_num(w.get('s_m'), '{:.3f}')} m, joint {w.get('joint')}: "
                                       f"{_num(w.get('utilisation'), '{:.2f}')}"),
            ("thickest elastic strip", f"{_num(r.get('max_elastic_thickness_mm'), '{:.2f}')} mm"),
            ("smallest bending radius", f"{_num((r.get('min_radius_m') or float('nan')) * 1e3, '{:.0f}')} mm"),
            ("criterion", html.escape(str(r.get("criterion", ""))))]
    st = r.get("states") or {}
    if st:
        info.append(("alignment sequence", f"max utilisation "
                     f"{_num(st.get('sequence_max_utilisation'), '{:.2f}')}; collapsed "
                     f"{_num((st.get('collapsed') or {}).get('max_utilisation'), '{:.2f}')}"
                     + (f"; folded, not judged: {html.escape(', '.join(st['unresolved']))}"
                        if st.get("unresolved") else "")))
    kv = "".join(f"<tr><th>{k}</th><td>{v}</td></tr>" for k, v in info)
    head = ("<tr><th>lamella</th><th>family</th><th>utilisation</th><th>worst s [m]</th>"
            "<th>joint</th><th>&sigma; weak / strong, &tau; [MPa]</th><th>R min [mm]</th>"
            "<th>t max [mm]</th></tr>")
    body = []
    for x in lams[:rows]:
        cls = " class=fail" if float(x["max_utilisation"]) > 1 else ""
        R = x.get("min_radius_m")
        body.append(
            f"<tr><td class=num>{int(x['id'])}</td><td>C{int(x['family'])}</td>"
            f"<td class=num><span{cls}>{float(x['max_utilisation']):.2f}</span></td>"
            f"<td class=num>{float(x['worst_s_m']):.3f}</td><td class=num>{x['worst_joint']}</td>"
            f"<td class=num>{_num(x.get('max_sigma_weak_MPa'))} / "
            f"{_num(x.get('max_sigma_strong_MPa'))}, {_num(x.get('max_tau_MPa'))}</td>"
            f"<td class=num>{_num(R * 1e3 if R else None, '{:.0f}')}</td>"
            f"<td class=num>{_num(x.get('max_elastic_thickness_mm'), '{:.2f}')}</td></tr>")
    more = (f"<p class=info>{len(lams) - rows} more lamellae in structure.json.</p>"
            if len(lams) > rows else "")
    return (f'<section id="structure"><h2>Structure (gridshell check)</h2><p>{verdict}</p>'
            f"<table>{kv}</table><h2>Lamellae by utilisation</h2>"
            f'<div class="scroll"><table>{head}{"".join(body)}</table></div>{more}</section>')
