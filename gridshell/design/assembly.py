"""The assembly plan a builder follows (issue 30 item 2): which strip goes where, in which order
the joints are closed, how the gridshell is deployed - from the design's lamellae (design.json:
each lamella's joints and their arc lengths ``joint_s``) and the cut files' pieces
(fabrication/fabrication.json). Lengths in mm of the model (the design's metres x 1000 x the
scale), as the strips are cut and engraved.

An alignable gridshell is assembled in its collapsed state, where every lamella lies along one
planar curve (the paper, section 3): the strips are stacked and bolted there, each family-3
strip across the family-1 strips it meets, then the bundle is opened along the alignment
sequence into the deployed shape."""
from __future__ import annotations

from typing import Any

__all__ = ["assembly_plan", "deploy_steps"]


def _pieces(fab: dict[str, Any] | None) -> dict[int, list[tuple[int, int]]]:
    """``lamella id -> [(piece, sheet)]`` of the cut files, in piece order."""
    out: dict[int, list[tuple[int, int]]] = {}
    for q in (fab or {}).get("pieces", []):
        out.setdefault(int(q["lamella"]), []).append((int(q.get("piece", 1)),
                                                      int(q.get("sheet", 0))))
    return {k: sorted(v) for k, v in out.items()}


def assembly_plan(design: dict[str, Any], fab: dict[str, Any] | None = None,
                  scale: float | None = None) -> dict[str, Any]:
    """The strips and the joints' closing order of a design (design.json's dict).

    ``scale`` is the model scale (default the cut files' ``params.scale``, else 1). Returns
    ``strips``: per lamella (family 1 first, by id) its ``id``, ``family``, ``length_mm``,
    ``pieces`` ``[(piece, sheet)]`` and ``crossings`` ``[(joint, other lamella, s_mm)]`` in
    order along it; ``steps``: every joint once, in the order they are closed - the family-3
    strips one after the other by id, each from its start to its end - as ``{step, joint,
    strip (family 3), at_mm, across (family 1), across_mm}``; ``single``: the joints on one
    lamella only (its ends at the boundary: a hole, no bolt).
    """
    if scale is None:
        scale = float(((fab or {}).get("params") or {}).get("scale") or 1.0)
    mm = 1000.0 * scale
    lams = sorted(design["lamellae"], key=lambda r: (int(r["family"]), int(r["id"])))
    where: dict[int, list[tuple[int, float]]] = {}      # joint -> [(lamella, s_mm)]
    for r in lams:
        for j, s in zip(r["joints"], r["joint_s"]):
            where.setdefault(int(j), []).append((int(r["id"]), float(s) * mm))
    pieces = _pieces(fab)
    strips = []
    for r in lams:
        own = int(r["id"])
        cross = []
        for j, s in sorted(zip(r["joints"], r["joint_s"]), key=lambda t: float(t[1])):
            other = [lam for lam, _ in where[int(j)] if lam != own]
            cross.append((int(j), other[0] if other else None, float(s) * mm))
        strips.append({"id": own, "family": int(r["family"]),
                       "length_mm": float(r.get("length", 0.0)) * mm,
                       "pieces": pieces.get(own, []), "crossings": cross})
    family = {s["id"]: s["family"] for s in strips}
    steps, done = [], set()
    for s in strips:
        if s["family"] != 3:
            continue
        for j, other, at in s["crossings"]:
            if j in done or other is None:
                continue
            across = next(v for lam, v in where[j] if lam == other)
            steps.append({"step": len(steps) + 1, "joint": j, "strip": s["id"], "at_mm": at,
                          "across": other, "across_mm": across})
            done.add(j)
    for s in strips:                 # joints no family-3 strip closes (a net of one family)
        for j, other, at in s["crossings"]:
            if j not in done and other is not None and family.get(other) == s["family"]:
                across = next(v for lam, v in where[j] if lam == other)
                steps.append({"step": len(steps) + 1, "joint": j, "strip": s["id"],
                              "at_mm": at, "across": other, "across_mm": across})
                done.add(j)
    single = sorted(j for j, on in where.items() if len(on) < 2)
    return {"scale": scale, "strips": strips, "steps": steps, "single": single}


def deploy_steps(kind: str, n_states: int, supports: int | None = None) -> list[str]:
    """How the assembled bundle becomes the shell, as numbered sentences (``n_states``: the
    states of the alignment sequence in ``sequence/``; ``supports``: the joints held at the
    supports in the equilibrium, if it was run)."""
    collapsed = ("one straight strip" if kind in ("GG", "AA") else
                 "one circular arc" if kind == "CNC" else "one planar curve")
    held = (f"fix its {supports} support joints to the ground at their deployed positions "
            "(equilibrium/: the supports the equilibrium held)" if supports else
            "fix its boundary joints to the ground at their deployed positions")
    return [
        "Cut the sheets; every strip is engraved with its lamella id and, after each hole, "
        "the id of the strip that crosses it there.",
        f"Stack the strips in the collapsed state: all of them lie along {collapsed} "
        "(the .3dm's layer \"collapsed\", aligned.obj), family 1 below, family 3 above.",
        "Close the joints in the order of the table below: a bolt or rivet through the two "
        "holes, snug but free to turn (the strips rotate about it while deploying).",
        f"Open the bundle along the alignment sequence ({n_states} states in sequence/, "
        "alignment.gif, states.png): from the collapsed state to the deployed one, every "
        "strip turning about its joints, none bent beyond the structure check's states.",
        f"In the deployed shape {held}, then tighten the joints.",
    ]
