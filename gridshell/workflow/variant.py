"""One variant of a study, designed, verified, checked and cut as one task: a row of results.

:func:`run_variant` runs the chain of the commands a user would (``gridshell gg|ncp``,
``verify``, ``check``, ``fabricate``; the same API functions) into
``variants/<key>/design`` (the bundle, with ``fabrication/`` and ``structure.json``) and
returns the row of the results table; ``variants/<key>/row.json`` holds it too. A variant
that fails at a stage is a row with that stage's exit code and message (never an exception:
a study goes on); the variant's directory appears by one rename when the task ends, so a
killed task leaves nothing half-written and is simply run again.

Row columns (units in the names): the parameters; ``key``; ``code`` (the CLI's exit code of
the stage that ended the chain: 0 cut, 2 bad input, 3 no net, 4 figures or stresses fail, 1 a
bug), ``stage`` and ``message``; ``delta_a_mean_pct`` / ``delta_a_max_pct`` (alignability,
eq. 5.1), ``delta_l_max_pct``, ``delta_n_max_pct`` (NCP), ``deviation_mean_pct`` (of the
diagonal), ``coverage_pct``, ``verified``; ``n_lamellae`` (both families), ``n_joints``;
``max_utilisation`` and ``structure``; ``sheets``, ``material_used_pct``,
``strip_length_m`` (cut length of all pieces), ``mass_kg`` (strips only, at the material's
density); ``time_s``.
"""
from __future__ import annotations

import json
import math
import os
import shutil
import tempfile
import time
import traceback
from pathlib import Path
from typing import Any, Mapping

__all__ = ["COLUMNS", "run_variant"]

#: the result columns after the parameters, in the table's order
COLUMNS = ("key", "code", "stage", "message", "delta_a_mean_pct", "delta_a_max_pct",
           "delta_l_max_pct", "delta_n_max_pct", "deviation_mean_pct", "coverage_pct",
           "verified", "n_lamellae", "n_joints", "max_utilisation", "structure", "sheets",
           "material_used_pct", "strip_length_m", "mass_kg", "time_s")
ROW = "row.json"
BUNDLE = "design"


def run_variant(target: str, params: Mapping[str, Any], key: str, variants_dir: str,
                units: str | None = None) -> dict[str, Any]:
    """Design, verify, check and cut one variant; its row (see the module docstring).

    ``target``: the model file; ``params``: the variant's parameter values
    (:data:`gridshell.workflow.study.PARAMETERS`); ``key``: its content hash, the name of its
    directory under ``variants_dir``. Runs in a Dask worker (or anywhere): pure but for the
    files it writes; one BLAS thread."""
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    t0 = time.perf_counter()
    final = Path(variants_dir) / key
    row: dict[str, Any] = {**params, "key": key}
    tmp = Path(tempfile.mkdtemp(prefix=f".{key}.", suffix=".tmp", dir=variants_dir))
    try:
        row.update(_chain(target, dict(params), tmp / BUNDLE, units))
        row["time_s"] = round(time.perf_counter() - t0, 3)
        _finish(tmp, final, row)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return row


def _finish(tmp: Path, final: Path, row: dict[str, Any]) -> None:
    """The row into ``tmp/row.json``, the manifest, then ``tmp`` renamed onto ``final``
    (a finished variant of an earlier run, or of another worker that ran the task too after
    a lost connection, is kept as it is)."""
    from gridshell.core import manifest

    (tmp / ROW).write_text(json.dumps(_finite(row), indent=1, default=str), encoding="utf-8")
    manifest.write(tmp, manifest.build(tmp, "sweep", "sweep variant"))
    try:
        os.rename(tmp, final)
    except OSError:  # another worker finished it first (a retried task): its files stand
        if not (final / ROW).is_file():
            raise


def _finite(row: Mapping[str, Any]) -> dict[str, Any]:
    return {k: (None if isinstance(v, float) and not math.isfinite(v) else v)
            for k, v in row.items()}


def _chain(target: str, p: dict[str, Any], bundle: Path, units: str | None) -> dict[str, Any]:
    """The stages of one variant; the figures reached and where it stopped."""
    from gridshell.core.errors import GridshellError

    out: dict[str, Any] = {"code": 0, "stage": "cut", "message": ""}
    stage = "design"
    try:
        _design(target, p, bundle, units)
        out.update(_design_figures(bundle))
        stage = "verify"
        from gridshell.design.verification import verify_bundle

        out["verified"] = bool(verify_bundle(bundle)["ok"])
        stage = "check"
        out.update(_structure(bundle, p))
        stage = "fabricate"
        out.update(_fabricate(bundle, p))
    except GridshellError as exc:
        out.update(code=exc.exit_code, stage=stage, message=str(exc).splitlines()[0][:500])
    except Exception as exc:  # a bug of the tool: a row with exit code 1, the study goes on
        tb = traceback.format_exception_only(type(exc), exc)[-1].strip()
        out.update(code=1, stage=stage, message=f"a bug: {tb}"[:500])
    return out


def _design(target: str, p: Mapping[str, Any], bundle: Path, units: str | None) -> None:
    from gridshell.workflow.cut import write_design

    kind = p.get("kind", "gg")
    count = p.get("lamellae")
    if kind == "gg":
        from gridshell.gg.pipeline import design_gg

        design = design_gg(target, n_lamellae=count,
                           spacing=p.get("spacing"), crossing_angle=p.get("angle", 90.0),
                           direction=p.get("direction"), units=units)
    else:
        from gridshell.analysis.admissible import design_ncp_explained as design_ncp

        design = design_ncp(target, mode=kind, curves=count, spacing=p.get("spacing"),
                            units=units)
    write_design(bundle, design, render=False)


def _pct(m: Mapping[str, Any], *names: str, which: str = "max") -> float | None:
    for n in names:
        v = m.get(n)
        if isinstance(v, Mapping) and v.get(which) is not None:
            return float(v[which])
    return None


def _design_figures(bundle: Path) -> dict[str, Any]:
    """The design's figures from its design.json (percentages)."""
    d = json.loads((bundle / "design.json").read_text(encoding="utf-8"))
    m = d.get("metrics", {})
    n = m.get("n_lamellae") or {}
    return {"delta_a_mean_pct": _pct(m, "alignability", "delta_a_after", which="mean"),
            "delta_a_max_pct": _pct(m, "alignability", "delta_a_after"),
            "delta_l_max_pct": _pct(m, "delta_l"), "delta_n_max_pct": _pct(m, "delta_n"),
            "deviation_mean_pct": _pct(m, "deviation", which="mean"),
            "coverage_pct": m.get("coverage"),
            "n_lamellae": int(sum(n.values())) if isinstance(n, Mapping) and n
            else len(d.get("lamellae", [])),
            "n_joints": d.get("n_joints")}


def _section(p: Mapping[str, Any]) -> dict[str, Any]:
    return {"width": p.get("width"), "thickness": p.get("thickness"), "scale": p.get("scale")}


def _structure(bundle: Path, p: Mapping[str, Any]) -> dict[str, Any]:
    from gridshell.workflow.structure import check_structure

    res = check_structure(bundle, material=p.get("material"), picture=False,
                          **_section(p)).result
    return {"max_utilisation": res.get("max_utilisation"), "structure": res.get("verdict")}


def _fabricate(bundle: Path, p: Mapping[str, Any]) -> dict[str, Any]:
    """Cut files into ``bundle/fabrication``; sheets, material used, cut length and mass."""
    from gridshell.workflow.cut import fabricate_checked
    from gridshell.design.section import resolve_section
    from gridshell.structure.materials import get_material

    strip = resolve_section(None, material=p.get("material"), **_section(p))
    params = {"width": strip.width_mm, "thickness": strip.thickness_mm, "scale": strip.scale}
    if p.get("sheet"):
        params["sheet"] = p["sheet"]
    rep = fabricate_checked(bundle, bundle / "fabrication", params, material=strip.material)
    length_m = sum(float(q.get("flat_length_mm", 0.0)) for q in rep["pieces"]) / 1000.0
    rho = get_material(strip.material).density
    return {"sheets": int(rep["n_sheets"]), "material_used_pct": 100.0 * rep["material_used"],
            "strip_length_m": length_m,
            "mass_kg": length_m * strip.width_mm * strip.thickness_mm * 1e-6 * rho}
