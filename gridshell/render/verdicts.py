"""What a report says first: every verdict of a bundle in one banner (figures, structure,
equilibrium, sheets), the equilibrium's figures with their units, and the bill of materials
of its cut files - each from the file the tool wrote (design.json, structure.json,
equilibrium/equilibrium.json, fabrication/fabrication.json), none when the file is absent."""
from __future__ import annotations

import html
import json
from pathlib import Path
from typing import Any

__all__ = ["banner_html", "bill_of_materials", "equilibrium_rows", "equilibrium_section",
           "verdicts"]


def _json(path: Path) -> dict[str, Any] | None:
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None


def verdicts(d: Path, figures_ok: bool | None, figures_text: str) -> list[tuple[str, str, str]]:
    """``[(topic, "pass" | "fail" | "info", text)]`` of the bundle ``d``: the paper's figures
    (``figures_ok`` None: none stored), the strips' stresses, the equilibrium, the sheets."""
    out = [("figures", "info" if figures_ok is None else "pass" if figures_ok else "fail",
            figures_text)]
    s = _json(d / "structure.json")
    if s:
        sec, mat = s.get("section", {}), s.get("material", {}).get("name", "?")
        strip = (f"{sec.get('width_mm', 0):g} x {sec.get('thickness_mm', 0):g} mm {mat} at "
                 f"{sec.get('scale_text', '?')}")
        u = float(s.get("max_utilisation", float("nan")))
        ok = s.get("verdict") == "ok"
        out.append(("structure", "pass" if ok else "fail",
                    f"{strip}: {'elastic' if ok else 'overstressed'}, max utilisation "
                    f"{u:.2f} ({s.get('governing_state', '?')})"))
    e = _json(d / "equilibrium" / "equilibrium.json")
    if e:
        f = e.get("figures", {})
        ok = bool(f.get("converged")) and float(f.get("utilisation_peak", 2)) <= 1.0
        out.append(("equilibrium", "pass" if ok else "fail",
                    f"{f.get('gravity', 'off')}: joints within "
                    f"{float(f.get('deviation_max_pct', float('nan'))):.3g} % of the diagonal "
                    f"of the design, peak utilisation {float(f.get('utilisation_peak', 0)):.2f}"
                    + ("" if f.get("converged") else ", NOT converged")))
    fab = _json(d / "fabrication" / "fabrication.json")
    if fab:
        out.append(("sheets", "pass",
                    f"{fab.get('n_sheets')} sheet(s) of {_sheet(fab)}, "
                    f"{100 * float(fab.get('material_used', 0)):.0f} % used, "
                    f"{fab.get('n_pieces')} pieces"))
    return out


def _sheet(fab: dict[str, Any]) -> str:
    w, h = (fab.get("params") or {}).get("sheet", [0, 0])
    return f"{w:g} x {h:g} mm"


_MARK = {"pass": "&#10003;", "fail": "&#10007;", "info": "&#8226;"}


def banner_html(items: list[tuple[str, str, str]]) -> str:
    """The verdicts as one line each, the failing ones first."""
    order = sorted(items, key=lambda t: {"fail": 0, "pass": 1, "info": 2}[t[1]])
    return "".join(f'<p><span class="verdict {st}">{_MARK[st]} {html.escape(topic)}: '
                   f"{html.escape(text)}</span></p>" for topic, st, text in order)


def bill_of_materials(d: Path) -> list[tuple[str, str]]:
    """``[(item, quantity with unit)]`` of the cut files: sheets, strips and pieces, joints
    and their holes, total strip length, mass (at the density of structure.json's
    material)."""
    fab = _json(d / "fabrication" / "fabrication.json")
    if not fab:
        return []
    p = fab.get("params") or {}
    length_mm = sum(float(q.get("flat_length_mm", 0.0)) for q in fab.get("pieces", []))
    rows = [("sheets", f"{fab.get('n_sheets')} x {_sheet(fab)}, {p.get('thickness', 0):g} mm "
                       "thick"),
            ("strips", f"{fab.get('n_strips')} lamellae cut as {fab.get('n_pieces')} pieces, "
                       f"{p.get('width', 0):g} mm wide"),
            ("total strip length", f"{length_mm / 1000:.2f} m")]
    design = _json(d / "design.json") or {}
    if design.get("lamellae"):
        from gridshell.design.assembly import assembly_plan

        joints = len(assembly_plan(design, fab)["steps"])      # where two strips cross
        rows.append(("joints", f"{joints}: one bolt or rivet each, through a "
                               f"{p.get('hole', 0):g} mm hole in both strips"
                               if p.get("joints", "hole") == "hole" else
                               f"{joints} ({p.get('joints')})"))
    mat = (_json(d / "structure.json") or {}).get("material") or {}
    if mat.get("density"):              # the material the strips were checked in
        rho = float(mat["density"])
        kg = length_mm * 1e-3 * p.get("width", 0) * 1e-3 * p.get("thickness", 0) * 1e-3 * rho
        rows.append(("mass of the strips", f"{kg:.3g} kg ({mat.get('name')}, {rho:g} kg/m3)"))
    return rows


_EQ_ROWS = (("gravity", "load", ""), ("supports", "supported joints", ""),
            ("deviation_mean_pct", "joint deviation, mean", "% of the diagonal"),
            ("deviation_max_pct", "joint deviation, max", "% of the diagonal"),
            ("utilisation_design", "utilisation of the design state", ""),
            ("utilisation_peak", "utilisation at equilibrium", ""),
            ("reaction_max_N", "largest support reaction", "N"),
            ("weight_N", "self-weight", "N"), ("snow_total_kN", "snow load, total", "kN"),
            ("deflection_max_mm", "largest deflection", "mm"),
            ("deflection_vertical_max_mm", "largest vertical deflection", "mm"),
            ("span_m", "span", "m"), ("span_over_deflection", "span / deflection", ""),
            ("bolt_shear_max_N", "largest bolt shear (joint force)", "N"),
            ("bolt_shear_mean_N", "mean bolt shear", "N"), ("newton", "Newton", ""))


def equilibrium_rows(f: dict[str, Any]) -> list[tuple[str, Any]]:
    """``[(name [unit], value)]`` of the equilibrium's figures ``f`` (equilibrium.json's
    ``figures``) that are there, in the report's order."""
    return [(f"{label}" + (f" [{unit}]" if unit else ""), f[k]) for k, label, unit in _EQ_ROWS
            if k in f]


def equilibrium_section(d: Path, kv_table: Any, figure: Any) -> str:
    """The equilibrium's section (``gridshell simulate``): its figures named, with units,
    and its picture (``kv_table`` / ``figure``: the page's blocks)."""
    e = _json(d / "equilibrium" / "equilibrium.json")
    if not e:
        return ""

    rows = equilibrium_rows(e.get("figures", {}))
    pic = d / "equilibrium" / "equilibrium.png"
    fig = figure(pic, "the equilibrium over the design (deviation coloured)") \
        if pic.is_file() else ""
    return (f'<section id="equilibrium"><h2>Elastic equilibrium</h2>{kv_table(rows)}{fig}'
            "</section>")
