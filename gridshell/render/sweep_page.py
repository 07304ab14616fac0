"""The trade-offs of a design study: ``sweep.html`` (a sortable table, plots, the best variants'
pictures; one self-contained file, offline like report.html) and ``sweep.png`` for print.

The Pareto front is taken over the variants that were cut (exit 0), minimising together the
largest stress utilisation, the sheets (then the strips' mass) and the mean deviation from
the target: a variant is on the front when no other is at least as good in all three and
better in one.
"""
from __future__ import annotations

import base64
import html
import math
import os
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from gridshell.render.figure import png_bytes, pyplot

__all__ = ["pareto_front", "write_sweep_page"]

#: the objectives of the front: column, label (all minimised)
OBJECTIVES = (("max_utilisation", "max utilisation"), ("sheets", "sheets"),
              ("deviation_mean_pct", "mean deviation [% diag]"))
#: figures plotted against each varied parameter
FIGURES = (("delta_a_max_pct", "Delta_a max [%]"), ("max_utilisation", "max utilisation"),
           ("sheets", "sheets"), ("mass_kg", "strip mass [kg]"))
BEST = 3


def pareto_front(values: np.ndarray) -> np.ndarray:
    """Mask of the rows of ``values (n, k)`` (all minimised; NaN is worst) that no other row
    dominates."""
    V = np.where(np.isfinite(values), values, np.inf)
    n = len(V)
    keep = np.ones(n, bool)
    for i in range(n):
        le = np.all(V <= V[i], axis=1)
        lt = np.any(V < V[i], axis=1)
        keep[i] = not np.any(le & lt)
    return keep


def _column(table: Any, name: str) -> np.ndarray:
    if name not in table:
        return np.full(len(table), np.nan)
    return np.asarray([float(v) if v is not None and v == v else np.nan
                       for v in table[name].tolist()], float)


def _front(table: Any) -> np.ndarray:
    ok = _column(table, "code") == 0
    V = np.column_stack([_column(table, c) for c, _ in OBJECTIVES])
    mask = np.zeros(len(table), bool)
    if ok.any():
        mask[np.flatnonzero(ok)] = pareto_front(V[ok])
    return mask


def _plots(table: Any, varied: Sequence[str], front: np.ndarray) -> Any:
    """One figure: the front (utilisation vs sheets, colour the deviation) and each figure
    against each varied parameter."""
    plt = pyplot()
    ok = _column(table, "code") == 0
    panels = 1 + len(varied)
    fig, axes = plt.subplots(1, panels, figsize=(4.2 * panels, 3.6), dpi=110, squeeze=False)
    ax = axes[0][0]
    u, s, d = (_column(table, c) for c, _ in OBJECTIVES)
    sc = ax.scatter(u[ok], s[ok], c=d[ok], cmap="viridis", s=36, edgecolors="none")
    ax.scatter(u[front], s[front], facecolors="none", edgecolors="crimson", s=110, lw=1.5,
               label="Pareto front")
    ax.scatter(u[~ok], np.full((~ok).sum(), np.nanmin(s) if ok.any() else 0), marker="x",
               c="grey", label="not cut")
    ax.axvline(1.0, color="crimson", lw=0.8, ls=":")
    ax.set_xlabel("max utilisation (1 = elastic limit)")
    ax.set_ylabel("sheets")
    ax.set_title("trade-off: stress, sheets, deviation", fontsize=10)
    if ok.any():
        fig.colorbar(sc, ax=ax, label="mean deviation [% diag]")
    ax.legend(fontsize=7, loc="best")
    for ax, name in zip(axes[0][1:], varied):
        x = table[name].tolist() if name in table else []
        labels = sorted({str(v) for v in x}, key=_natural)
        pos = {lab: i for i, lab in enumerate(labels)}
        xs = np.array([pos[str(v)] for v in x], float)
        for (col, lab), mk in zip(FIGURES, "osD^"):
            y = _column(table, col)
            scale = np.nanmax(np.abs(y[ok])) if ok.any() and np.isfinite(y[ok]).any() else 1.0
            ax.plot(xs[ok], y[ok] / (scale or 1.0), mk, alpha=0.7, label=f"{lab} / {scale:.3g}")
        ax.set_xticks(range(len(labels)), labels, rotation=30 if len(labels) > 6 else 0)
        ax.set_xlabel(name)
        ax.set_ylabel("figure / its largest")
        ax.set_title(f"figures against {name}", fontsize=10)
        ax.legend(fontsize=6, loc="best")
    fig.tight_layout()
    return fig


def _natural(text: str) -> tuple:
    try:
        return (0, float(text), "")
    except ValueError:
        return (1, 0.0, text)


def _cell(v: Any) -> tuple[str, str]:
    """(shown text, sort key) of one table cell."""
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "", ""
    if isinstance(v, float):
        return f"{v:.4g}", repr(v)
    return html.escape(str(v)), html.escape(str(v))


def _table_html(table: Any, front: np.ndarray) -> str:
    cols = list(table.columns)
    head = "".join(f"<th onclick='sortBy({i})'>{html.escape(c)}</th>" for i, c in enumerate(cols))
    rows = []
    for i, rec in enumerate(table.to_dict("records")):
        cells = "".join(f"<td data-v='{k}'>{t}</td>" for t, k in (_cell(rec[c]) for c in cols))
        cls = " class='front'" if front[i] else (" class='fail'" if rec.get("code") else "")
        rows.append(f"<tr{cls}>{cells}</tr>")
    return f"<table id='t'><thead><tr>{head}</tr></thead><tbody>{''.join(rows)}</tbody></table>"


_SCRIPT = """<script>
let dir = {};
function sortBy(i) {
  const tb = document.querySelector('#t tbody'), rows = Array.from(tb.rows);
  dir[i] = -(dir[i] || -1);
  const key = r => { const v = r.cells[i].dataset.v; const x = parseFloat(v);
                     return isNaN(x) ? v : x; };
  rows.sort((a, b) => { const x = key(a), y = key(b);
    if (x === '' ) return 1; if (y === '') return -1;
    return (x < y ? -1 : x > y ? 1 : 0) * dir[i]; });
  rows.forEach(r => tb.appendChild(r));
}
</script>"""
_STYLE = """<style>
body{font-family:system-ui,sans-serif;margin:1.5em;color:#222}
table{border-collapse:collapse;font-size:12px} th,td{border:1px solid #ccc;padding:2px 6px}
th{background:#eee;cursor:pointer;position:sticky;top:0} tr.front td{background:#fff3f3}
tr.fail td{color:#999} img{max-width:100%} .best{display:flex;gap:1em;flex-wrap:wrap}
.best figure{margin:0;max-width:32%} figcaption{font-size:12px}
</style>"""


def _best(table: Any, front: np.ndarray, pictures: dict[str, Path]) -> str:
    """The front's first variants by utilisation, with their pictures."""
    idx = [i for i in np.argsort(_column(table, "max_utilisation")) if front[i]][:BEST]
    out = []
    for i in idx:
        rec = table.iloc[int(i)].to_dict()
        pic = pictures.get(str(rec.get("key")))
        img = (f"<img alt='variant {rec['key']}' src='data:image/png;base64,"
               f"{base64.b64encode(pic.read_bytes()).decode()}'>" if pic and pic.is_file() else "")
        cap = ", ".join(f"{k} {_cell(rec.get(k))[0]}" for k in
                        ("key", "max_utilisation", "sheets", "deviation_mean_pct", "mass_kg"))
        out.append(f"<figure>{img}<figcaption>{cap}</figcaption></figure>")
    return "<div class='best'>" + "".join(out) + "</div>" if out else "<p>no variant was cut</p>"


def best_keys(table: Any) -> list[str]:
    """The keys of the variants :func:`write_sweep_page` shows pictures of."""
    front = _front(table)
    idx = [i for i in np.argsort(_column(table, "max_utilisation")) if front[i]][:BEST]
    return [str(table.iloc[int(i)]["key"]) for i in idx]


def write_sweep_page(table: Any, out: str | os.PathLike, varied: Sequence[str],
                     pictures: dict[str, Path] | None = None) -> Path:
    """``out/sweep.html`` and ``out/sweep.png`` of the results ``table`` (a DataFrame of
    :func:`gridshell.workflow.sweep.sweep`); ``varied``: the parameters the study varies;
    ``pictures``: key -> PNG of a variant. Returns the page's path."""
    from gridshell.core.atomic import write_bytes, write_text

    out = Path(out)
    front = _front(table)
    fig = _plots(table, list(varied), front)
    png = png_bytes(fig)
    write_bytes(out / "sweep.png", png)
    ok = int((_column(table, "code") == 0).sum())
    codes = ", ".join(f"exit {int(c)}: {n}" for c, n in
                      sorted(table["code"].value_counts().items())) if len(table) else "-"
    body = (f"<h1>Design study: {len(table)} variants</h1>"
            f"<p>{ok} cut (exit 0); {codes}. Varied: {html.escape(', '.join(varied))}. "
            f"Pareto front (minimising {', '.join(lab for _, lab in OBJECTIVES)} over the cut "
            f"variants): {int(front.sum())} variants, shaded in the table. Click a column "
            "heading to sort.</p>"
            f"<img alt='trade-offs' src='data:image/png;base64,{base64.b64encode(png).decode()}'>"
            f"<h2>Best variants</h2>{_best(table, front, pictures or {})}"
            f"<h2>All variants</h2>{_table_html(table, front)}")
    page = out / "sweep.html"
    write_text(page, f"<!doctype html><html><head><meta charset='utf-8'><title>gridshell "
                     f"sweep</title>{_STYLE}</head><body>{body}{_SCRIPT}</body></html>")
    return page
