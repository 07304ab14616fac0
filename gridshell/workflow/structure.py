"""The structural check and the elastic equilibrium of a bundle as one call each, with their files.

- :func:`check_structure`: stresses along every lamella (:func:`gridshell.structure.check.check_bundle`)
  for the strip of :func:`gridshell.design.section.resolve_section`, written to
  ``DIR/structure.json`` and drawn as ``DIR/structure.png`` (``gridshell check``);
- :func:`simulate`: the elastic equilibrium of the deployed gridshell
  (:func:`gridshell.structure.equilibrium.simulate`, discrete elastic rods) written to a
  directory: ``equilibrium.obj``, ``axes.obj``, ``equilibrium.json``, ``equilibrium.png``
  (``gridshell simulate``).

Both take the strip's ``width``, ``thickness`` (mm of the model), ``scale`` and ``material``
from the caller, else the bundle's fabrication report, else the defaults (one resolver, one
error policy) and return data, never printed text.
"""
from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

from gridshell.design.section import StripSection, resolve_section

__all__ = ["Simulation", "StructureCheck", "check_structure", "simulate", "strip_of"]

Progress = Callable[[str], None] | None


def strip_of(bundle_dir: str | os.PathLike | None, material: Any = None, **section: Any):
    """``(strip, structure_section, material)``: the resolved :class:`StripSection`, the
    :class:`gridshell.structure.section.Section` of it and the
    :class:`~gridshell.structure.materials.Material` (``material`` a preset name, a Material,
    or None for the resolver's)."""
    from gridshell.structure.materials import Material, get_material
    from gridshell.structure.section import Section

    own = material if isinstance(material, Material) else None
    strip = resolve_section(bundle_dir, material=own.name if own else material, **section)
    mat = own if own is not None else get_material(strip.material)
    return strip, Section(strip.width_mm, strip.thickness_mm, strip.scale), mat


@dataclass(frozen=True)
class StructureCheck:
    """What :func:`check_structure` found: ``result`` (the content of ``structure.json``,
    :func:`gridshell.structure.check.check_bundle`), the strip (``section``, with where its values
    came from), the material, and the files written (None when not)."""

    result: dict[str, Any]
    section: StripSection
    material: Any
    file: Path | None
    picture: Path | None

    @property
    def ok(self) -> bool:
        """Every evaluated state stays elastic (utilisation <= 1)."""
        return self.result["verdict"] == "ok"


def check_structure(bundle: str | os.PathLike, *, material: Any = None,
                    width: float | None = None, thickness: float | None = None,
                    scale: Any = None, states: bool = True, write: bool = True,
                    picture: bool = True, progress: Progress = None) -> StructureCheck:
    """Will the strips bend into the design without breaking? The stresses along every
    lamella of the bundle directory ``bundle`` for a strip ``width`` x ``thickness`` mm at
    ``scale`` of ``material`` (a preset name such as ``"pp"`` or a
    :class:`~gridshell.structure.materials.Material`); ``states``: also the collapsed state and
    the alignment sequence; ``write`` / ``picture``: write ``structure.json`` (listed in the
    bundle's manifest) / draw ``structure.png``."""
    from gridshell.design.bundle import read_bundle, read_design_json
    from gridshell.structure.check import check_bundle, write_structure_json

    read_design_json(bundle)
    strip, section, mat = strip_of(bundle, material, width=width, thickness=thickness,
                                   scale=scale)
    b = read_bundle(bundle)
    res = check_bundle(b, mat, section, states=states, bundle_dir=Path(bundle),
                       progress=progress)
    out = write_structure_json(bundle, res) if write else None
    pic = None
    if picture:
        from gridshell.render.utilisation import PICTURE, render_utilisation

        if progress:
            progress(f"drawing {PICTURE}")
        pic = render_utilisation(b, res, Path(bundle) / PICTURE)
    return StructureCheck(res, strip, mat, out, pic)


@dataclass(frozen=True)
class Simulation:
    """What :func:`simulate` computed: the equilibrium
    (:class:`gridshell.structure.equilibrium.Equilibrium`; ``figures`` its summary), the bundle,
    the strip and material, ``record`` (the content of ``equilibrium.json``) and the output
    directory (None when not written)."""

    equilibrium: Any
    bundle: Any
    section: StripSection
    material: Any
    record: dict[str, Any]
    out: Path | None

    @property
    def figures(self) -> dict[str, Any]:
        return self.equilibrium.figures


def simulate(bundle: str | os.PathLike, out: str | os.PathLike | None = None, *,
             material: Any = None, width: float | None = None, thickness: float | None = None,
             scale: Any = None, supports: Any = "boundary", gravity: bool = False,
             snow: float | None = None, per_bay: int = 3, max_iter: int = 100,
             state: int | None = None, write: bool = True,
             progress: Progress = None) -> Simulation:
    """The elastic equilibrium of the deployed gridshell of the bundle directory ``bundle``:
    every lamella a discrete elastic rod of the real strip (``width`` x ``thickness`` mm at
    ``scale``, ``material``), joints turning about their axis only, ``supports`` (``"boundary"``
    or joint indices) held at the design, optionally under ``gravity`` and a ``snow`` load
    (kN/m2 of plan area, with self-weight: deflection, span / deflection and bolt shear in the
    figures); ``per_bay`` rod elements
    between joints, at most ``max_iter`` Newton iterations. ``state``: also the check of the
    alignment path, state ``frame_<state>`` of ``sequence/strips.npz`` as rods with its joints
    held (:func:`gridshell.structure.pathcheck.state_equilibrium`; figures ``path_state``).
    With ``write`` the result goes to ``out`` (default ``DIR/equilibrium``), replaced
    atomically."""
    from gridshell.core.atomic import check_output
    from gridshell.core.errors import InputError
    from gridshell.design.bundle import read_bundle
    from gridshell.structure.equilibrium import simulate as equilibrium

    bundle_dir = Path(bundle)
    b = read_bundle(bundle_dir)
    target = Path(out) if out else bundle_dir / "equilibrium"
    if write:
        check_output(target, owner="simulate")
    if per_bay < 1 or max_iter < 1:
        raise InputError("--per-bay and --max-iter must be at least 1")
    strips = _path_strips(bundle_dir, b, state) if state is not None else None
    strip, section, mat = strip_of(bundle_dir, material, width=width, thickness=thickness,
                                   scale=scale)
    if progress:
        progress(f"equilibrium of {b.kind} {bundle_dir} in {strip.width_mm:g} x "
                 f"{strip.thickness_mm:g} mm {mat.label} at {_scale(strip)}")
    eq = equilibrium(b, mat, section, supports=supports, gravity=gravity, snow=snow,
                     per_bay=per_bay,
                     max_iter=max_iter, progress=progress)
    if strips is not None:
        from gridshell.structure.pathcheck import state_equilibrium

        if progress:
            progress(f"the alignment path's frame_{state:03d} as rods with its joints held")
        eq.figures["path_state"] = state_equilibrium(b, strips, state, mat, section,
                                                     max_iter=max_iter)
    record = _record(eq, mat, section)
    if write:
        if progress:
            progress(f"writing {target}")
        _write(target, b, eq, record, strip, mat)
    return Simulation(eq, b, strip, mat, record, target if write else None)


def write_simulation(bundle: str | os.PathLike, sim: Simulation,
                     out: str | os.PathLike | None = None) -> Simulation:
    """Write a :class:`Simulation` computed with ``write=False`` (perhaps in another process)
    to ``out`` (default ``bundle/equilibrium``), atomically; the simulation with its output."""
    from dataclasses import replace

    from gridshell.core.atomic import check_output

    target = Path(out) if out else Path(bundle) / "equilibrium"
    check_output(target, owner="simulate")
    _write(target, sim.bundle, sim.equilibrium, sim.record, sim.section, sim.material)
    return replace(sim, out=target)


def _path_strips(bundle_dir: Path, b: Any, state: int) -> dict[str, Any]:
    """The dense strips of the bundle's alignment path with state ``state`` in range, or
    :class:`InputError` naming what is missing."""
    from gridshell.core.errors import InputError
    from gridshell.structure.states import STRIPS, read_strips

    strips = read_strips(bundle_dir, len(b.net.joints), len(b.net.lamellae))
    if strips is None:
        raise InputError(f"--state: {bundle_dir} has no alignment path ({STRIPS}, written by "
                         "gg with --frames >= 1 on a net without a Clairaut turning point); "
                         "re-run the design or leave out --state")
    F = len(strips["t"])
    if not 0 <= state < F:
        raise InputError(f"--state {state}: the path has states 0 to {F - 1} (frame_000 "
                         f"deployed ... frame_{F - 1:03d} collapsed)")
    return strips


def _scale(strip: StripSection) -> str:
    from gridshell.design.section import scale_text

    return scale_text(strip.scale)


def _record(eq: Any, material: Any, section: Any) -> dict[str, Any]:
    """The content of ``equilibrium.json``."""
    return {
        "format": "gridshell.equilibrium", "version": 1,
        "units": {"positions": "m of the design", "reactions": "N on the model",
                  "energy": "J on the model", "deviation": "% of the design's bbox diagonal"},
        "figures": eq.figures,
        "material": material.to_json(), "section": section.to_json(),
        "supports": eq.supports.tolist(), "reactions_N": eq.reactions.tolist(),
        "deviation_pct": eq.deviation.tolist(),
        "stresses": eq.stresses,
        "newton": eq.result.history,
    }


def _write(out: Path, b: Any, eq: Any, record: dict, strip: StripSection, material: Any) -> None:
    """The equilibrium directory: OBJ of the joints and net loops, the axes, the record and a
    picture over the design, atomically."""
    from gridshell.core.atomic import atomic_dir
    from gridshell.design.bundle import finite_json
    from gridshell.geometry.meshfile import write_mesh, write_polylines
    from gridshell.render.equilibrium import render_equilibrium

    fig = eq.figures
    family = {lm.id: lm.family for lm in b.net.lamellae}
    fams = [family[i] for i in eq.model.lamella_ids]
    with atomic_dir(out, owner="simulate", kind="elastic equilibrium") as tmp:
        if len(b.net.loops):
            write_mesh(tmp / "equilibrium.obj", eq.joints, b.net.loops)
        write_polylines(tmp / "axes.obj", eq.axes)
        (tmp / "equilibrium.json").write_text(
            json.dumps(finite_json(record), indent=1, allow_nan=False), encoding="utf-8")
        title = (f"{b.kind} equilibrium, {strip.width_mm:g} x {strip.thickness_mm:g} mm "
                 f"{material.name} at {_scale(strip)}: deviation max "
                 f"{fig['deviation_max_pct']:.3g} % of diagonal, peak utilisation "
                 f"{fig['utilisation_peak']:.2f}")
        render_equilibrium(tmp / "equilibrium.png", eq.axes0, eq.axes, fams, b.net.joints,
                           eq.joints, eq.deviation, eq.supports, title=title)
