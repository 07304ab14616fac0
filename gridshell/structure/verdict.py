"""The structural verdict in words, and the refusal of cut files for strips that would break.

:func:`verdict_line` is the one line ``check``, ``simulate`` and ``fabricate`` end with;
:func:`require_elastic` is what writers of cut files call before the first file (as
:func:`gridshell.design.verification.require_design` for the geometric figures): an
overstressed design is refused with :class:`Overstressed` (exit 4), naming the lamella, the
state, the stress term that governs and the sections that would hold, unless forced.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any, Callable

from gridshell.core.errors import GridshellError
from gridshell.structure.materials import Material
from gridshell.structure.section import Section


class Overstressed(GridshellError):
    """The strips would not stay elastic in the design (a figure that fails: exit 4)."""

    exit_code = 4


def strip_text(result: dict[str, Any]) -> str:
    """``"20 x 1 mm pp at 1:10"``: the checked strip of ``result`` (``check_bundle``)."""
    sec = result["section"]
    return (f"{sec['width_mm']:g} x {sec['thickness_mm']:g} mm {result['material']['name']} "
            f"at {sec['scale_text']}")


def where_text(result: dict[str, Any]) -> str:
    """Where the governing utilisation is: the lamella (and joint) in the deployed state, or
    the lamella and joint in a state of the alignment sequence."""
    state = result["governing_state"]
    if state == "deployed":
        w = result["worst"]
        return f"lamella {w['lamella']} at s = {w['s_m']:.3f} m (joint {w['joint']}), deployed"
    frame = next((f for f in result["states"].get("frames", []) if f["name"] == state), {})
    return (f"lamella {frame.get('worst_lamella')} at joint {frame.get('worst_joint')} in the "
            f"alignment state {state}")


def governing_text(result: dict[str, Any]) -> str:
    """``"governed by strong-axis bending (27.1 of 34 MPa)"`` (empty without advice)."""
    adv = result.get("advice") or {}
    g = adv.get("governing")
    if not g:
        return ""
    stress = {"weak": g["sigma_weak"], "strong": g["sigma_strong"],
              "twist": 3.0 ** 0.5 * g["tau"]}[g["term"]]
    return f"governed by {adv['term']} ({stress:.3g} of {g['allowable']:.3g} MPa)"


def holds_text(result: dict[str, Any]) -> str:
    """The sections that would hold, the remedy of the governing term first: a thinner strip
    (weak-axis bending, torsion), a narrower one (strong-axis bending), a larger scale."""
    adv = result.get("advice") or {}
    sec = result["section"]
    t, w = adv.get("thickest_elastic_mm", 0.0), adv.get("widest_elastic_mm", 0.0)
    thin = (f"{sec['width_mm']:g} x {t:.2f} mm (the thickest elastic strip of this width)"
            if t > 0 else "no thickness at this width (strong-axis bending alone exceeds the "
            "allowable)")
    narrow = (f"{w:.1f} x {sec['thickness_mm']:g} mm (the widest elastic strip of this "
              "thickness)" if w > 0 else "no width at this thickness")
    first = [narrow, thin] if (adv.get("governing") or {}).get("term") == "strong" else \
        [thin, narrow]
    scale = f"this strip at {adv.get('smallest_scale_text', '?')} or larger"
    return "holds: " + "; ".join(first + [scale])


def verdict_line(result: dict[str, Any]) -> str:
    """One line: ok / OVERSTRESSED, the strip, the governing utilisation and where; for an
    overstressed design also the governing term, its remedy and what would hold."""
    u = result["max_utilisation"]
    if result["verdict"] == "ok":
        return (f"ok: {strip_text(result)} stays elastic, max utilisation {u:.2f} "
                f"({where_text(result)})")
    adv = result.get("advice") or {}
    gov = governing_text(result)
    return (f"OVERSTRESSED: {strip_text(result)}, max utilisation {u:.2f} > 1 "
            f"({where_text(result)}" + (f"; {gov}" if gov else "") + ")"
            + (f"; {adv['helps']}" if adv.get("helps") else "") + f"; {holds_text(result)}")


def require_elastic(bundle: Any, material: Material, section: Section, force: bool,
                    retry: str, *, bundle_dir: str | Path | None = None,
                    progress: Callable[[str], None] | None = None) -> dict[str, Any]:
    """The structural check of ``bundle`` (:func:`gridshell.structure.check.check_bundle`,
    with the alignment sequence where the bundle directory has one); :class:`Overstressed`
    with :func:`verdict_line` and ``retry`` (how the caller forces it) unless every judged
    state stays elastic or ``force``. Returns the check's result."""
    from gridshell.structure.check import check_bundle

    res = check_bundle(bundle, material, section, bundle_dir=bundle_dir, progress=progress)
    refuse_overstressed(res, force, retry)
    return res


def refuse_overstressed(result: dict[str, Any], force: bool, retry: str) -> None:
    """:class:`Overstressed` with :func:`verdict_line` of ``result`` (``check_bundle``) and
    ``retry`` (how the caller forces it), unless every judged state stays elastic or
    ``force``."""
    if result["verdict"] != "ok" and not force:
        raise Overstressed(f"{verdict_line(result)}; {retry}")


def verdict_record(result: dict[str, Any], forced: bool = False) -> dict[str, Any]:
    """The verdict of ``result`` as the cut files record it (``fabrication.json["structure"]``):
    ``verdict``, ``line`` (:func:`verdict_line`), ``forced`` (cut although overstressed), the
    utilisations, the governing state, the material's name, the section and the advice."""
    return {"verdict": result["verdict"], "line": verdict_line(result),
            "forced": bool(forced and result["verdict"] != "ok"),
            "max_utilisation": result["max_utilisation"],
            "max_utilisation_deployed": result["max_utilisation_deployed"],
            "governing_state": result["governing_state"],
            "material": result["material"]["name"], "section": result["section"],
            "advice": result.get("advice")}
