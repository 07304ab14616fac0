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

from gridshell.core.atomic import atomic_path
from gridshell.core.errors import InputError
from gridshell.design.section import DEFAULTS

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
                       size: tuple[int, int] = (1000, 750), dpi: int = 100,
                       max_points: int = 200) -> Path:
    """Write the utilisation picture of ``bundle`` (a :class:`~gridshell.design.bundle.DesignBundle`
    or its directory) from ``result`` (:func:`gridshell.structure.check.check_bundle`) to
    ``path`` (PNG, atomically): the strips at the checked section (``result["section"]``,
    real size), depth-sorted as ``render.png`` (:func:`.ribbons.render_ribbons`), coloured
    by utilisation."""
    from gridshell.design.bundle import read_bundle
    from gridshell.render.ribbons import render_ribbons

    b = read_bundle(bundle) if isinstance(bundle, (str, os.PathLike)) else bundle
    recs = {int(r["id"]): r for r in result.get("lamellae", [])}
    lams = [lam for lam in b.net.lamellae if len(lam.axis) >= 2]
    if not lams:
        raise InputError("render_utilisation: no lamella axes to draw")
    top = max(float(result.get("max_utilisation_deployed", 1.0) or 1.0), 1.0)
    colours = []
    for lam in lams:
        u = np.asarray(recs.get(int(lam.id), {}).get("utilisation") or np.zeros(len(lam.axis)),
                       float)
        u = u if len(u) == len(lam.axis) else np.zeros(len(lam.axis))
        colours.append(utilisation_colours(np.maximum(u, np.r_[u[1:], u[-1]]), top))
    sec, mat = result.get("section", {}), result.get("material", {})
    scale = float(sec.get("scale") or DEFAULTS["scale"])
    width = 1e-3 * float(sec.get("width_mm") or DEFAULTS["width"]) / scale
    thickness = 1e-3 * float(sec.get("thickness_mm") or DEFAULTS["thickness"]) / scale
    w = result.get("worst") or {}
    worst = (f", worst L{w.get('lamella')} ({w.get('utilisation', 0):.2f}) at "
             f"{float(w.get('s_m', 0.0)):.2f} m" if w.get("lamella") is not None else "")
    title = (f"{b.kind}: {sec.get('width_mm', 0):g} x {sec.get('thickness_mm', 0):g} mm "
             f"{mat.get('name', '')} at {sec.get('scale_text', '')}, max utilisation "
             f"{result.get('max_utilisation_deployed', 0):.2f} deployed{worst} - "
             f"{result.get('verdict', '')}")
    return render_ribbons(path, [lam.axis for lam in lams], [lam.family for lam in lams],
                          b.surface_V, b.surface_F, b.net.joints, kind=b.kind, width=width,
                          thickness=thickness, title=title, size=size, dpi=dpi,
                          max_points=max_points, colours=colours,
                          colorbar=("RdYlGn_r", "utilisation (1 = elastic limit)"))


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
            f"<td class=num>{_num(x.get('worst_s_m'), '{:.3f}')}</td>"
            f"<td class=num>{_num(x.get('worst_joint'), '{}')}</td>"
            f"<td class=num>{_num(x.get('max_sigma_weak_MPa'))} / "
            f"{_num(x.get('max_sigma_strong_MPa'))}, {_num(x.get('max_tau_MPa'))}</td>"
            f"<td class=num>{_num(R * 1e3 if R else None, '{:.0f}')}</td>"
            f"<td class=num>{_num(x.get('max_elastic_thickness_mm'), '{:.2f}')}</td></tr>")
    more = (f"<p class=info>{len(lams) - rows} more lamellae in structure.json.</p>"
            if len(lams) > rows else "")
    return (f'<section id="structure"><h2>Structure (gridshell check)</h2><p>{verdict}</p>'
            f"<table>{kv}</table><h2>Lamellae by utilisation</h2>"
            f'<div class="scroll"><table>{head}{"".join(body)}</table></div>{more}</section>')
