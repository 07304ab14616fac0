"""``report.html``: one self-contained page of a design bundle (issue #7, "the product").

The page holds the kind, the parameters, the metrics against the paper's thresholds (5.1:
mean ``Delta_a`` < 1 %, max < 3 %; ``Delta_l`` and ``Delta_n`` < 1 %) with pass/fail marks,
every picture of the bundle (PNG and GIF as base64 ``data:`` URIs), the fabrication plan and
sheets (SVG inline) when ``fabrication/`` exists, and the lamella table; on top, the
interactive 3D view (:mod:`gridshell.render.viewer`: WebGL, three.js bundled inline). Nothing
is fetched from the network: inline CSS and scripts, pictures as ``data:`` URIs.
"""
from __future__ import annotations

import base64
import html
import json
import math
import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Iterable

from gridshell.core.atomic import write_text
from gridshell.core.errors import InputError
from gridshell.measure.quality import THRESHOLDS

__all__ = ["Check", "CHECKS", "metric_checks", "report_html", "write_report"]


@dataclass(frozen=True)
class Check:
    """A metric of ``design.json`` (``{"mean", "max"}`` in %) and the paper's limits on it."""

    key: str
    label: str
    mean_below: float | None = None
    max_below: float | None = None


#: metrics checked against the paper's thresholds (5.1), in display order
_A_MEAN, _A_MAX = THRESHOLDS["delta_a_mean"][1], THRESHOLDS["delta_a_max"][1]
_L_MAX, _N_MAX = THRESHOLDS["delta_l_max"][1], THRESHOLDS["delta_n_max"][1]
CHECKS: tuple[Check, ...] = (
    Check("alignability", "Delta_a, straight edges", _A_MEAN, _A_MAX),
    Check("alignability_arc", "Delta_a, lamella arc lengths", _A_MEAN, _A_MAX),
    Check("alignability_revolution", "Delta_a on the surface of revolution", _A_MEAN, _A_MAX),
    Check("delta_a_before", "Delta_a, traced net (before post-optimization)"),
    Check("delta_a_after", "Delta_a, post-optimized net", _A_MEAN, _A_MAX),
    Check("delta_l", "Delta_l, edge length change on alignment", None, _L_MAX),
    Check("delta_n", "Delta_n, normal curvature change on alignment", None, _N_MAX),
    Check("delta_n_interior", "Delta_n at interior joints", None, _N_MAX),
)

#: pictures first in this order, then any other picture alphabetically
_ORDER = ("render.png", "preview.png", "delta_a_before.png", "delta_a_after.png",
          "delta_l.png", "delta_n.png", "curvature_diagram.png", "collapse.png", "states.png",
          "alignment.gif")
_CAPTIONS = {
    "render.png": "The lamellae as ribbons on the surface, coloured by family.",
    "preview.png": "The net on the designed surface, loops coloured by Delta_a [%].",
    "delta_a_before.png": "Delta_a of the traced net [%] (Fig. 13c).",
    "delta_a_after.png": "Delta_a after post-optimization [%] (Fig. 13d).",
    "delta_l.png": "Delta_l: relative edge-length change after alignment [%] (Fig. 16).",
    "delta_n.png": "Delta_n: relative normal-curvature change after alignment [%] (Fig. 16).",
    "collapse.png": "The collapse curve with its flattened normals (Fig. 15).",
    "curvature_diagram.png": "Curvature diagram of the PHLW surface: samples in the (H, K) "
                             "plane, one line per u-row (Figs. 11, 13a).",
    "states.png": "States of the alignment sequence, from the deployed net to the collapsed one "
                  "(every lamella on one straight line).",
    "alignment.gif": "The alignment sequence (Fig. 16).",
    "plan.png": "Assembly plan: every lamella's id at its place.",
    "structure.png": "Utilisation of the strips (gridshell check): equivalent stress / allowable "
                     "stress along every lamella, worst point marked.",
}
_MIME = {".png": "image/png", ".gif": "image/gif", ".jpg": "image/jpeg", ".jpeg": "image/jpeg"}
MAX_SHEETS = 12
_MARK = {"pass": "&#10003; pass", "fail": "&#10007; fail", "info": "&ndash;"}

_CSS = """
body{font-family:system-ui,-apple-system,"Segoe UI",Helvetica,Arial,sans-serif;margin:0;
 color:#1d1f23;background:#f6f7f9;line-height:1.4}
header{background:#1d2d44;color:#fff;padding:18px 28px}
header h1{margin:0;font-size:22px} header p{margin:4px 0 0;opacity:.85}
main{padding:10px 28px 40px;max-width:1200px}
section{background:#fff;border:1px solid #dde1e6;border-radius:6px;padding:12px 18px;margin:16px 0}
h2{font-size:17px;margin:4px 0 10px}
table{border-collapse:collapse;font-size:13px}
th,td{padding:3px 10px;border-bottom:1px solid #e6e8eb;text-align:left;vertical-align:top}
 th{background:#f0f2f5} td.num{text-align:right;
 font-variant-numeric:tabular-nums}
.pass{color:#177a2e;font-weight:600} .fail{color:#b3261e;font-weight:600} .info{color:#6b7280}
.verdict{display:inline-block;padding:4px 10px;border-radius:4px;font-weight:600}
.verdict.pass{background:#e3f4e7} .verdict.fail{background:#fbe4e2}
.verdict.info{background:#eceef1}
figure{display:inline-block;margin:8px 12px 8px 0;vertical-align:top;max-width:100%}
figure img{max-width:100%;border:1px solid #e6e8eb;background:#fff}
figure.wide img{width:900px}
figcaption{font-size:12px;color:#4b5563;max-width:620px}
.sheet svg{width:100%;height:auto;max-width:1000px;border:1px solid #cfd4da;background:#fff}
.sheet svg *{vector-effect:non-scaling-stroke;stroke-width:0.7px}
.scroll{max-height:520px;overflow:auto}
code{font-size:12px}
"""


def _fmt(v: Any, digits: int = 4) -> str:
    if isinstance(v, bool) or v is None:
        return str(v)
    if isinstance(v, float):
        return "nan" if math.isnan(v) else f"{v:.{digits}g}"
    return str(v)


def metric_checks(metrics: dict[str, Any]) -> list[dict[str, Any]]:
    """Rows ``{key, label, mean, max, limit, status}`` of the :data:`CHECKS` present in
    ``metrics``; ``status`` is "pass", "fail" or "info" (no limit, or values missing)."""
    rows = []
    for c in CHECKS:
        m = metrics.get(c.key)
        if not isinstance(m, dict):
            continue
        mean, mx = m.get("mean"), m.get("max")
        limits, ok = [], []
        for stat, val, lim in (("mean", mean, c.mean_below), ("max", mx, c.max_below)):
            if lim is None:
                continue
            limits.append(f"{stat} &lt; {lim:g} %")
            if isinstance(val, (int, float)) and not math.isnan(float(val)):
                ok.append(float(val) < lim)
        status = "info" if not limits or not ok else ("pass" if all(ok) else "fail")
        rows.append({"key": c.key, "label": c.label, "mean": mean, "max": mx,
                     "limit": ", ".join(limits) or "&ndash;", "status": status})
    return rows


def _flatten(d: Any, prefix: str = "") -> Iterable[tuple[str, Any]]:
    if isinstance(d, dict):
        for k, v in d.items():
            yield from _flatten(v, f"{prefix}.{k}" if prefix else str(k))
    else:
        yield prefix, d


def _value_text(v: Any, limit: int = 160) -> str:
    if isinstance(v, list):
        txt = json.dumps(v)
        if len(txt) > limit:
            txt = txt[:limit] + f" ... ({len(v)} items)"
        return txt
    return _fmt(v)


def _kv_table(items: Iterable[tuple[str, Any]]) -> str:
    rows = "".join(f"<tr><th>{html.escape(k)}</th><td>{html.escape(_value_text(v))}</td></tr>"
                   for k, v in items)
    return f"<table>{rows}</table>" if rows else "<p class=info>none</p>"


#: a PNG larger than this (bytes) is embedded re-encoded when that is smaller (the files in
#: the bundle stay as they are): drawings and colour maps (at most :data:`FEW_COLOURS`
#: colours) as PNG of :data:`PALETTE` colours, shaded renders as JPEG of quality
#: :data:`JPEG_QUALITY`. Measured on the demo: plan.png 342 -> 77 kB, render.png 578 ->
#: 108 kB, the GG report 4.9 -> 1.6 MB with the packed scene
EMBED_ABOVE = 40_000
FEW_COLOURS = 10_000
PALETTE = 128
JPEG_QUALITY = 80


def _data_uri(path: Path) -> str:
    mime = _MIME.get(path.suffix.lower(), "application/octet-stream")
    data = path.read_bytes()
    if mime == "image/png" and len(data) > EMBED_ABOVE:
        smaller = _smaller_picture(data)
        if smaller is not None and len(smaller[1]) < len(data):
            mime, data = smaller
    elif mime == "image/gif" and len(data) > GIF_ABOVE:
        data = _smaller_gif(data) or data
    return f"data:{mime};base64," + base64.b64encode(data).decode("ascii")


#: an animated GIF larger than this (bytes) is embedded at :data:`GIF_WIDTH` pixels wide
GIF_ABOVE = 200_000
GIF_WIDTH = 480


def _smaller_gif(gif: bytes) -> bytes | None:
    """The animated GIF ``gif`` scaled down to :data:`GIF_WIDTH` pixels wide (frames, their
    times and the loop kept), or None if it cannot be read or is not wider."""
    import io

    from PIL import Image, ImageSequence, UnidentifiedImageError

    try:
        im = Image.open(io.BytesIO(gif))
        if im.size[0] <= GIF_WIDTH:
            return None
        size = (GIF_WIDTH, max(1, round(im.size[1] * GIF_WIDTH / im.size[0])))
        frames, times = [], []
        for fr in ImageSequence.Iterator(im):
            frames.append(fr.convert("RGB").resize(size, Image.Resampling.LANCZOS))
            times.append(fr.info.get("duration", 250))
    except (OSError, UnidentifiedImageError):
        return None
    pal = frames[0].quantize(colors=128)
    out = io.BytesIO()
    frames = [f.quantize(palette=pal, dither=Image.Dither.NONE) for f in frames]
    frames[0].save(out, "GIF", save_all=True, append_images=frames[1:], duration=times,
                   loop=im.info.get("loop", 0), optimize=True)
    return out.getvalue()


def _smaller_picture(png: bytes) -> tuple[str, bytes] | None:
    """``(mime, bytes)``: the PNG ``png`` (transparent parts on white) as a palette PNG when it
    has few colours, else as a JPEG; None if it cannot be read."""
    import io

    from PIL import Image, UnidentifiedImageError

    try:
        im = Image.open(io.BytesIO(png))
        im.load()
    except (OSError, UnidentifiedImageError):
        return None
    if im.mode in ("RGBA", "LA", "P"):
        im = im.convert("RGBA")
        flat = Image.new("RGB", im.size, (255, 255, 255))
        flat.paste(im, mask=im.getchannel("A"))
        im = flat
    im = im.convert("RGB")
    buf = io.BytesIO()
    if im.getcolors(maxcolors=FEW_COLOURS) is not None:
        im.quantize(colors=PALETTE, dither=Image.Dither.NONE).save(buf, "PNG", optimize=True)
        return "image/png", buf.getvalue()
    im.save(buf, "JPEG", quality=JPEG_QUALITY, optimize=True)
    return "image/jpeg", buf.getvalue()


def _figure(path: Path, caption: str, wide: bool = False) -> str:
    cls = ' class="wide"' if wide else ""
    return (f'<figure{cls}><img src="{_data_uri(path)}" alt="{html.escape(path.name)}">'
            f"<figcaption><code>{html.escape(path.name)}</code> {html.escape(caption)}"
            "</figcaption></figure>")


_XMLNS = re.compile(r'\s+xmlns(:[\w-]+)?="[^"]*"')


def _inline_svg(path: Path, tag: str) -> str:
    """The ``<svg>`` element of an SVG file for inlining in HTML: no XML prolog, doctype,
    comments or namespace declarations (HTML5 knows the SVG namespace), ids prefixed by
    ``tag`` so several drawings can share a page, and no scripts or external references."""
    text = path.read_text(encoding="utf-8", errors="replace")
    start = text.find("<svg")
    if start < 0:
        raise InputError(f"{path} is not an SVG drawing (no <svg> element)")
    text = text[start:]
    text = re.sub(r"<!--.*?-->", "", text, flags=re.S)
    text = re.sub(r"<script\b.*?</script>", "", text, flags=re.S | re.I)
    text = _XMLNS.sub("", text)
    text = text.replace("xlink:href", "href")
    text = re.sub(r'\b(href|src)="(?!#)[^"]*"', "", text)  # only internal references survive
    text = re.sub(r'\bid="([^"]*)"', lambda m: f'id="{tag}-{m.group(1)}"', text)
    text = re.sub(r'url\(#([^)]*)\)', lambda m: f"url(#{tag}-{m.group(1)})", text)
    text = re.sub(r'href="#([^"]*)"', lambda m: f'href="#{tag}-{m.group(1)}"', text)
    return text


def _pictures(d: Path) -> list[Path]:
    pics = [p for p in d.iterdir() if p.is_file() and p.suffix.lower() in _MIME]
    rank = {n: i for i, n in enumerate(_ORDER)}
    return sorted(pics, key=lambda p: (rank.get(p.name, len(rank)), p.name))


def _lamella_table(lamellae: list[dict]) -> str:
    head = ("<tr><th>id</th><th>family</th><th>length [m]</th><th>joints</th>"
            "<th>joint spacing [m] min / max</th></tr>")
    rows = []
    for r in lamellae:
        s = r.get("joint_s") or []
        gaps = [b - a for a, b in zip(s[:-1], s[1:])]
        sp = f"{min(gaps):.4g} / {max(gaps):.4g}" if gaps else "&ndash;"
        rows.append(f"<tr><td class=num>{int(r['id'])}</td><td>C{int(r['family'])}</td>"
                    f"<td class=num>{float(r.get('length', float('nan'))):.4f}</td>"
                    f"<td class=num>{len(r.get('joints', []))}</td><td class=num>{sp}</td></tr>")
    return f'<div class="scroll"><table>{head}{"".join(rows)}</table></div>'


#: the fabrication report's counts the report shows, named
_FAB_ROWS = (("shape", "collapsed shape of the strips"), ("n_strips", "strips (lamellae)"),
             ("n_pieces", "pieces cut"), ("n_sheets", "sheets"),
             ("n_joint_marks", "holes or marks on the parts (two per joint)"),
             ("utilisation", "share of the sheets' area the parts cover (as nested)"),
             ("material_used", "share of the sheets' area in the part outlines"),
             ("labels_dropped", "labels left out (no room)"),
             ("radius_mm", "collapse circle's radius [mm of the model]"))


def _fabrication_section(d: Path) -> str:
    """The cut files' section: the fabrication report's counts (read by
    :func:`gridshell.design.section.read_fabrication_report`: a corrupt report is an error),
    the plan and the first sheets."""
    from gridshell.design.section import read_fabrication_report

    fab = d / "fabrication"
    if not fab.is_dir():
        return ""
    parts = ['<section id="fabrication"><h2>Fabrication</h2>']
    rep = read_fabrication_report(d)
    if rep is not None:
        parts.append(_kv_table((name, rep[k]) for k, name in _FAB_ROWS
                               if rep.get(k) is not None))
    plan = fab / "plan.png"
    if plan.is_file():
        parts.append(_figure(plan, _CAPTIONS["plan.png"], wide=True))
    sheets = sorted(p for p in fab.glob("sheet_*.svg"))
    for k, p in enumerate(sheets[:MAX_SHEETS]):
        parts.append(f'<figure class="sheet">{_inline_svg(p, f"s{k}")}<figcaption>'
                     f"<code>{html.escape(p.name)}</code> cut sheet (DXF beside it)"
                     "</figcaption></figure>")
    if len(sheets) > MAX_SHEETS:
        parts.append(f"<p class=info>{len(sheets) - MAX_SHEETS} more sheets in "
                     "<code>fabrication/</code>.</p>")
    parts.append("</section>")
    return "".join(parts)


def _structure_section(d: Path) -> str:
    """The structural check's section when ``structure.json`` exists (``gridshell check``)."""
    from gridshell.render.utilisation import structure_section

    return structure_section(d)


def _figures_verdict(decided: list[str]) -> tuple[bool | None, str]:
    """(all pass, the banner's text) of the thresholded checks' statuses."""
    if not decided:
        return None, "no thresholded metrics stored"
    if all(s == "pass" for s in decided):
        return True, f"all {len(decided)} within the paper's thresholds"
    return False, (f"{decided.count('fail')} of {len(decided)} checks fail the paper's "
                   "thresholds")


def figures_line(bundle_dir: str | os.PathLike) -> tuple[bool | None, str]:
    """(all pass, the banner's text) of the paper's figures stored in the bundle's
    design.json (None: none stored)."""
    from gridshell.design.bundle import read_design_json

    checks = metric_checks(read_design_json(Path(bundle_dir)).get("metrics") or {})
    return _figures_verdict([r["status"] for r in checks if r["status"] != "info"])


def report_html(bundle_dir: str | os.PathLike) -> str:
    """The HTML text of the report of ``bundle_dir`` (see :func:`write_report`)."""
    from gridshell.core.version import __version__
    from gridshell.design.bundle import read_design_json
    from gridshell.render.viewer.page import viewer_css, viewer_section

    d = Path(bundle_dir)
    design = read_design_json(d)
    kind = str(design["kind"])
    metrics = design.get("metrics") or {}
    params = design.get("params") or {}
    lams = design["lamellae"]
    checks = metric_checks(metrics)
    decided = [r["status"] for r in checks if r["status"] != "info"]
    from gridshell.render.assembly_page import assembly_section
    from gridshell.render.verdicts import (banner_html, bill_of_materials,
                                           equilibrium_section, verdicts)

    verdict = banner_html(verdicts(d, *_figures_verdict(decided)))
    bom = bill_of_materials(d)
    fam = {f: sum(1 for r in lams if int(r["family"]) == f) for f in (1, 3)}
    total = sum(float(r.get("length", 0.0)) for r in lams)
    title = f"{kind} alignable lamella gridshell &mdash; {html.escape(d.resolve().name)}"
    overview = [("kind", kind), ("units", _units_name(design.get("units"))),
                ("joints", design.get("n_joints")), ("net-loops", design.get("n_loops")),
                ("lamellae", f"{len(lams)} (C1: {fam[1]}, C3: {fam[3]})"),
                ("total lamella length [m]", f"{total:.4g}")]
    from gridshell.measure.fidelity import fidelity_rows

    overview += fidelity_rows(metrics)   # how faithfully the net follows the user's target
    if "collapse" in design:
        c = design["collapse"]
        overview.append(("collapse curve", f"{c.get('shape')}" + (
            f", radius {c['radius']:.4g} m" if c.get("radius") else "")))

    rows = "".join(
        f"<tr><td>{html.escape(r['label'])}<br><code>{r['key']}</code></td>"
        f"<td class=num>{_fmt(r['mean'])}</td><td class=num>{_fmt(r['max'])}</td>"
        f"<td>{r['limit']}</td><td class={r['status']}>{_MARK[r['status']]}</td></tr>"
        for r in checks)
    check_table = ("<table><tr><th>metric</th><th>mean [%]</th><th>max [%]</th>"
                   f"<th>paper threshold</th><th>result</th></tr>{rows}</table>") if rows \
        else "<p class=info>No alignability metrics stored in design.json.</p>"
    checked = {r["key"] for r in checks}
    other = [(k, v) for k, v in _flatten({k: v for k, v in metrics.items()
                                          if k not in checked and k != "timings"})]
    timings = list(_flatten(metrics.get("timings", {})))

    pics = _pictures(d)
    figs = "".join(_figure(p, _CAPTIONS.get(p.name, ""), wide=p.name == "render.png")
                   for p in pics) or "<p class=info>No pictures in the bundle; run " \
                                     "<code>gridshell render DIR</code>.</p>"
    files = sorted(p.name + ("/" if p.is_dir() else "") for p in d.iterdir()
                   if not p.name.startswith("."))
    parts = [
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">",
        f"<title>{title}</title><style>{_CSS}{viewer_css()}</style></head><body>",
        f"<header><h1>{title}</h1><p>design report written by gridshell {__version__} "
        "&middot; self-contained: no external resources</p></header><main>",
        f'<section id="overview"><h2>Overview</h2>{verdict}{_kv_table(overview)}',
        ("<h2>Bill of materials</h2>" + _kv_table(bom)) if bom else "",
        "</section>",
        viewer_section(d),
        f'<section id="metrics"><h2>Metrics (paper 5.1)</h2>{check_table}',
        "<h2>Other metrics</h2>" + _kv_table(other) if other else "",
        "</section>",
        f'<section id="pictures"><h2>Pictures</h2>{figs}</section>',
        _fabrication_section(d),
        assembly_section(d),
        _structure_section(d),
        equilibrium_section(d, _kv_table, _figure),
        f'<section id="lamellae"><h2>Lamellae</h2>{_lamella_table(lams)}</section>',
        f'<section id="parameters"><h2>Parameters</h2>{_kv_table(_flatten(params))}',
        ("<h2>Timings [s]</h2>" + _kv_table(timings)) if timings else "",
        "</section>",
        f'<section id="files"><h2>Files</h2><p><code>{html.escape(", ".join(files))}</code>'
        "</p></section>",
        "</main></body></html>\n",
    ]
    return "".join(parts)


def write_report(bundle_dir: str | os.PathLike, path: str | os.PathLike | None = None, *,
                 progress: Callable[[str], None] | None = None) -> Path:
    """Write the self-contained ``report.html`` of a design bundle, atomically.

    Parameters
    ----------
    bundle_dir : path-like
        The design bundle (output of ``gridshell gg`` / ``gridshell ncp``).
    path : path-like, optional
        Output file (default ``bundle_dir/report.html``).

    Returns
    -------
    Path
        The written file.
    """
    out = Path(bundle_dir) / "report.html" if path is None else Path(path)
    if progress is not None:
        progress(f"writing {out}")
    write_text(out, report_html(bundle_dir))
    return out


def _units_name(units: object) -> str:
    """The input unit recorded in design.json (a record, a legacy string, or absent: metres)."""
    if isinstance(units, dict):
        return f"input in {units.get('name', '?')} (geometry in metres)"
    return str(units or "m")
