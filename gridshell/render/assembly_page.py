"""The report's assembly section (issue 30 item 2): how to deploy, which strip goes where (its
pieces and sheets, the strips it crosses in order) and the order the joints are closed, from
:func:`gridshell.design.assembly.assembly_plan` of the bundle's design.json and cut files.
Lengths in mm of the model, as cut."""
from __future__ import annotations

import html
from pathlib import Path
from typing import Any

from gridshell.design.assembly import assembly_plan, deploy_steps
from gridshell.render.verdicts import _json

__all__ = ["assembly_of", "assembly_section"]


def assembly_of(d: Path) -> tuple[dict[str, Any], list[str]] | None:
    """``(plan, deploy steps)`` of the bundle ``d`` with cut files, else None."""
    design, fab = _json(d / "design.json"), _json(d / "fabrication" / "fabrication.json")
    if not design or not fab:
        return None
    n_states = len(list((d / "sequence").glob("frame_*.obj")))
    eq = (_json(d / "equilibrium" / "equilibrium.json") or {}).get("figures", {})
    supports = eq.get("supports")
    supports = int(supports) if isinstance(supports, (int, float)) else None
    return (assembly_plan(design, fab),
            deploy_steps(str(design.get("kind", "")), n_states, supports))


def _pieces_text(pieces: list[tuple[int, int]]) -> str:
    if not pieces:
        return "-"
    return ", ".join(f"piece {p} on sheet {s}" for p, s in pieces) if len(pieces) > 1 \
        else f"sheet {pieces[0][1]}"


def assembly_section(d: Path) -> str:
    """The ``<section id="assembly">`` of the bundle ``d`` ('' without cut files)."""
    got = assembly_of(d)
    if got is None:
        return ""
    plan, deploy = got
    steps = "".join(f"<li>{html.escape(t)}</li>" for t in deploy)
    strips = "".join(
        f"<tr><td>{s['id']}</td><td>{s['family']}</td><td class=num>{s['length_mm']:.0f}</td>"
        f"<td>{html.escape(_pieces_text(s['pieces']))}</td>"
        f"<td>{html.escape(' '.join(str(o) for _, o, _ in s['crossings'] if o is not None))}"
        "</td></tr>" for s in plan["strips"])
    joints = "".join(
        f"<tr><td class=num>{t['step']}</td><td class=num>{t['joint']}</td>"
        f"<td>{t['strip']} at {t['at_mm']:.1f}</td><td>{t['across']} at {t['across_mm']:.1f}"
        "</td></tr>" for t in plan["steps"])
    return (
        '<section id="assembly"><h2>Assembly</h2>'
        f"<ol>{steps}</ol>"
        "<h3>Strips: where each goes</h3>"
        "<table><tr><th>strip (lamella id)</th><th>family</th><th>length [mm]</th>"
        "<th>cut as</th><th>crosses, in order along it</th></tr>" + strips + "</table>"
        f"<h3>Joints, in the order they are closed ({len(plan['steps'])})</h3>"
        "<p class=info>Positions: the hole's arc length along the strip from the start of "
        "its axis (the cut strip reaches the end margin beyond it), mm of the model.</p>"
        "<table><tr><th>step</th><th>joint</th><th>strip at [mm]</th>"
        "<th>across strip at [mm]</th></tr>" + joints + "</table>"
        + (f"<p class=info>{len(plan['single'])} joints lie on one strip only (its ends at the "
           "boundary): a hole, no bolt.</p>" if plan["single"] else "") + "</section>")
