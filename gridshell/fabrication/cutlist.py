"""The cut list (issue item 6): one CSV row per piece, in lamella order.

Columns: ``lamella, family, piece, sheet, shape, radius_mm, flat_length_mm, axis_length_mm,
n_joints, joint_positions_mm, neighbours, splice, sheet_used_pct, n_sheets, material_used_pct``. Joint positions are measured along the
axis from the piece's start (its end margin included); neighbours are the ids of the
crossing lamellae at each joint (``|`` between joints); ``splice`` says, for split lamellae,
which piece overlaps which, by how much and at which joints (named by the ids engraved beside
them). ``sheet_used_pct``: the material used on the piece's sheet (part outlines over the
sheet area, %); ``n_sheets`` and ``material_used_pct``: the same for all sheets.
"""
from __future__ import annotations

import csv
import io
from pathlib import Path

from gridshell.core.atomic import atomic_path

from gridshell.fabrication.nesting import Layout

COLUMNS = ("lamella", "family", "piece", "sheet", "shape", "radius_mm", "flat_length_mm",
           "axis_length_mm", "n_joints", "joint_positions_mm", "neighbours", "splice",
           "sheet_used_pct", "n_sheets", "material_used_pct")


def splice_text(notes: list[dict]) -> str:
    """The splice column: for each splice of the piece, which piece it overlaps, by how
    much, and where (the shared joints, each by the name engraved beside it on the strip: the
    ids of the lamellae crossing there, :func:`gridshell.fabrication.splice.joint_name`; or, between
    joints, the splice label and its position along the lamella's axis from the axis start,
    mm)."""
    parts = []
    for n in notes:
        if n.get("kind") == "span":
            where = n["where"]
            fast = ", ".join(f"{x:.1f}" for x in n["fasteners"])
            parts.append(f"overlaps piece {n['with']} by {n['overlap']:.1f} mm {where}: "
                         f"splice {n['label']} of lamella {n['lamella']} at {n['at']:.1f} mm "
                         f"along the lamella (fasteners at {fast} mm)")
            continue
        joints = " and ".join(n["shared_names"])
        parts.append(f"overlaps piece {n['with']} by {n['overlap']:.1f} mm "
                     f"(shared joints {joints})")
    return "; ".join(parts)


def cutlist_rows(layout: Layout, axis_lengths: dict[int, float]) -> list[dict]:
    """Rows of the cut list, sorted by lamella id and piece."""
    rows = []
    used = [100.0 * layout.used(k) for k in range(layout.n_sheets)]
    total = 100.0 * layout.used()
    for part, sheet in zip(layout.parts, layout.sheet_of):
        s = part.strip
        r = s.axis.radius
        rows.append({
            "lamella": s.lamella, "family": s.family, "piece": f"{s.piece}/{s.n_pieces}",
            "sheet": sheet + 1, "shape": s.axis.kind,
            "radius_mm": "" if r is None else f"{r:.3f}",
            "flat_length_mm": f"{s.length:.3f}",
            "axis_length_mm": f"{axis_lengths.get(s.lamella, float('nan')):.3f}",
            "n_joints": len(s.joint_s),
            "joint_positions_mm": " ".join(f"{x - s.s0:.3f}" for x in s.joint_s),
            "neighbours": "|".join(",".join(map(str, nb)) for nb in s.neighbours),
            "splice": splice_text(s.splices),
            "sheet_used_pct": f"{used[sheet]:.1f}", "n_sheets": layout.n_sheets,
            "material_used_pct": f"{total:.1f}",
        })
    rows.sort(key=lambda d: (d["lamella"], d["piece"]))
    return rows


def write_cutlist(path: str | Path, rows: list[dict]) -> None:
    """Write the cut list CSV, atomically."""
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=COLUMNS, lineterminator="\n")
    w.writeheader()
    w.writerows(rows)
    with atomic_path(path) as tmp:
        tmp.write_text(buf.getvalue(), encoding="utf-8")
