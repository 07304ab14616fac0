"""``report.pdf``: the build pack on paper (issue 30 item 2), A4 pages through matplotlib's PDF
backend (no display, no pyplot state, no new dependency): the overview (verdicts, bill of
materials, render.png), the assembly (how to deploy, plan.png, the strips, the joints in the
order they are closed), every cut sheet's picture, the structure (structure.png, the
equilibrium's figures and picture). Text from the same functions as report.html."""
from __future__ import annotations

import os
import re
from pathlib import Path
from textwrap import wrap
from typing import Any

__all__ = ["pdf_document", "write_pdf"]

A4 = (8.27, 11.69)          # inches, portrait
LINES = 58                  # lines of monospaced table text per page
_TAG = re.compile(r"<[^>]+>")


def _page(pdf: Any, title: str, lines: list[str] = (), image: Path | None = None,
          mono: bool = False) -> None:
    """One A4 page: ``title``, the text ``lines`` and below them ``image`` scaled to fit."""
    import matplotlib.image as mpimg
    from matplotlib.figure import Figure

    fig = Figure(figsize=A4)
    fig.text(0.07, 0.955, title, fontsize=15, weight="bold", va="top")
    size, step = (7.5, 0.0145) if mono else (9.5, 0.0185)    # font pt, line height
    rows = [part for line in lines for part in (wrap(line, 120 if mono else 95) or [""])]
    if rows:                        # one text object per page: matplotlib lays it out once
        fig.text(0.07, 0.92, "\n".join(rows), fontsize=size, va="top", linespacing=1.35,
                 family="monospace" if mono else "sans-serif")
    y = 0.92 - step * len(rows)
    if image is not None and image.is_file() and y > 0.15:
        img = mpimg.imread(str(image))
        h, w = img.shape[:2]
        box_w, box_h = 0.86, y - 0.04
        aspect = (h / w) * (A4[0] / A4[1])           # height in figure units per width unit
        width = min(box_w, box_h / aspect)
        ax = fig.add_axes((0.5 - width / 2, y - 0.01 - width * aspect, width, width * aspect))
        ax.imshow(img)
        ax.set_axis_off()
        fig.text(0.5, 0.025, image.name, fontsize=7, ha="center", color="#555")
    pdf.savefig(fig)


def _table_pages(pdf: Any, title: str, head: str, rows: list[str]) -> None:
    for k in range(0, max(len(rows), 1), LINES):
        part = f" ({k // LINES + 1} of {(len(rows) - 1) // LINES + 1})" if len(rows) > LINES \
            else ""
        _page(pdf, title + part, [head, "-" * len(head), *rows[k:k + LINES]], mono=True)


def _overview(d: Path) -> list[str]:
    from gridshell.render.report import figures_line
    from gridshell.render.verdicts import bill_of_materials, verdicts

    lines = [f"{topic}: {status} - {_TAG.sub('', text)}"
             for topic, status, text in verdicts(d, *figures_line(d))]
    from gridshell.design.bundle import read_design_json
    from gridshell.measure.fidelity import fidelity_rows

    lines += [f"{k}: {v}" for k, v in
              fidelity_rows(read_design_json(d).get("metrics") or {})]
    bom = bill_of_materials(d)
    if bom:
        lines += ["", "Bill of materials"] + [f"  {k}: {v}" for k, v in bom]
    return lines


def _assembly(pdf: Any, d: Path) -> None:
    from gridshell.render.assembly_page import assembly_of

    got = assembly_of(d)
    if got is None:
        return
    plan, deploy = got
    _page(pdf, "Assembly", [f"{k + 1}. {t}" for k, t in enumerate(deploy)],
          image=d / "fabrication" / "plan.png")
    _table_pages(pdf, "Strips: where each goes", f"{'strip':>6} {'fam':>3} {'length mm':>10}  "
                 "crosses, in order along it",
                 [f"{s['id']:>6} {s['family']:>3} {s['length_mm']:>10.0f}  "
                  + " ".join(str(o) for _, o, _ in s["crossings"] if o is not None)
                  for s in plan["strips"]])
    _table_pages(pdf, "Joints, in the order they are closed",
                 f"{'step':>5} {'joint':>6} {'strip':>6} {'at mm':>8} {'across':>7} "
                 f"{'at mm':>8}",
                 [f"{t['step']:>5} {t['joint']:>6} {t['strip']:>6} {t['at_mm']:>8.1f} "
                  f"{t['across']:>7} {t['across_mm']:>8.1f}" for t in plan["steps"]])


def _structure(pdf: Any, d: Path) -> None:
    import json

    if (d / "structure.png").is_file():
        _page(pdf, "Structure: utilisation of the strips", [], image=d / "structure.png")
    eq = d / "equilibrium" / "equilibrium.json"
    if eq.is_file():
        from gridshell.render.verdicts import equilibrium_rows

        rows = equilibrium_rows(json.loads(eq.read_text(encoding="utf-8")).get("figures", {}))
        _page(pdf, "Equilibrium", [f"{k}: {v}" for k, v in rows],
              image=d / "equilibrium" / "equilibrium.png")


def pdf_document(bundle_dir: str | os.PathLike, path: str | os.PathLike) -> str:
    """Write the PDF of a design bundle to ``path`` as it is (no manifest entry: a caller
    publishes it, e.g. :mod:`gridshell.workflow.outputs` from a second process); returns
    ``path``."""
    from matplotlib.backends.backend_pdf import PdfPages

    d = Path(bundle_dir)
    with PdfPages(path, metadata={"Title": f"gridshell {d.resolve().name}"}) as pdf:
        _page(pdf, f"{d.resolve().name}: overview", _overview(d), image=d / "render.png")
        _assembly(pdf, d)
        for sheet in sorted((d / "fabrication").glob("sheet_*.png")):
            _page(pdf, f"Cut sheet {sheet.stem.split('_')[-1]}", [], image=sheet)
        _structure(pdf, d)
    return str(path)


def write_pdf(bundle_dir: str | os.PathLike, path: str | os.PathLike | None = None) -> Path:
    """Write ``report.pdf`` of a design bundle (default ``bundle_dir/report.pdf``), atomically
    and added to the bundle's manifest; returns its path."""
    from gridshell.core.atomic import atomic_path

    out = Path(path) if path is not None else Path(bundle_dir) / "report.pdf"
    with atomic_path(out) as tmp:
        pdf_document(bundle_dir, tmp)
    return out
