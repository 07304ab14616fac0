"""The strip section and scale of a bundle: one resolver, one set of defaults, one error policy.

The strips that are cut are ``width x thickness`` mm of the physical model at a scale
(model / design length, ``1:10`` -> 0.1); the gridshell they stand for has strips
``width / scale`` wide (20 mm at 1:10 = 200 mm). Every command that needs the strip
(``check``, ``simulate``, ``export``, ``render``, the server's components) asks
:func:`resolve_section`, which takes each value from, in this order:

1. the caller (``--width``, ``--thickness``, ``--scale``, ``--material``, or the API's
   keywords), when given (not None);
2. the bundle's fabrication report ``DIR/fabrication/fabrication.json`` (the parameters the
   cut files were written with), when there is one;
3. :data:`DEFAULTS` (20 x 1 mm polypropylene at 1:10; ``FabParams`` takes its defaults from
   here too).

The result says where each value came from (:attr:`StripSection.sources`). A missing report is
no error (the defaults apply); a report that cannot be read or holds no valid section
(unreadable, not JSON, ``params`` not an object, a width, thickness or scale that is not a
positive number) is an :class:`~gridshell.core.errors.InputError` naming the file and the fix
(exit 2), for every command alike: :func:`read_fabrication_report` is the one reader.
"""
from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from gridshell.core.errors import InputError
from gridshell.geometry.strips3d import real_section_m

__all__ = ["DEFAULTS", "DEFAULT_CUT", "FABRICATION_REPORT", "StripSection", "built_width_m", "design_width_m", "fabrication_report_path", "parse_scale", "read_fabrication_report",
           "resolve_section", "scale_text", "stored_params"]

#: the one definition of the strip's defaults: cut width and thickness (mm of the model), scale
#: (model / design) and material (a preset of :mod:`gridshell.structure.materials`)
DEFAULTS: Mapping[str, Any] = {"width": 20.0, "thickness": 1.0, "scale": 0.1, "material": "pp"}

#: the cut strip's defaults alone (width, thickness in mm; scale), as the renderers name them
DEFAULT_CUT = {k: DEFAULTS[k] for k in ("width", "thickness", "scale")}

#: where a bundle's cut files and their report live (``gridshell fabricate`` default)
FABRICATION_REPORT = Path("fabrication") / "fabrication.json"

#: the source of a value the caller gave, and of a default
GIVEN, DEFAULT = "given", "defaults"


def built_width_m(width_mm: float | None = None, scale: float | None = None) -> float:
    """The strip's width at the built scale, metres: the cut width (mm of the model; default
    :data:`DEFAULTS`) over the scale (20 mm at 1:10 -> 0.2 m)."""
    w = DEFAULTS["width"] if width_mm is None else float(width_mm)
    sc = DEFAULTS["scale"] if scale is None else float(scale)
    return w * 1e-3 / sc


#: a design's strip is at most this share of its bounding-box diagonal wide (the default
#: strip at 1:10 is 0.2 m: too wide for a 0.5 m object, which a user cuts at another scale)
WIDTH_PER_DIAGONAL = 0.01


def design_width_m(V: Any) -> float:
    """The strip width a design is judged with before it is cut (its lamella fairness),
    metres: the default strip at the built scale (:func:`built_width_m`), at most
    :data:`WIDTH_PER_DIAGONAL` of the bounding-box diagonal of the design's points ``V (n, 3)``
    (metres)."""
    P = np.asarray(V, float).reshape(-1, 3)
    diagonal = float(np.linalg.norm(P.max(0) - P.min(0))) if len(P) else 0.0
    return min(built_width_m(), WIDTH_PER_DIAGONAL * diagonal)


def parse_scale(text: str | float) -> float:
    """Model/design length ratio from ``"1:10"``, ``"1:1"`` or ``"0.1"``; e.g. ``1:10 -> 0.1``."""
    if isinstance(text, (int, float)) and not isinstance(text, bool):
        value = float(text)
    else:
        s = str(text).strip()
        try:
            if ":" in s:
                a, b = s.split(":")
                value = float(a) / float(b)
            else:
                value = float(s)
        except (ValueError, ZeroDivisionError):
            raise InputError(f"scale {text!r} is not understood; "
                             "write it as 1:10, 1:1 or 0.1") from None
    if not math.isfinite(value) or value <= 0:
        raise InputError(f"scale {text!r} must be positive; write it as 1:10, 1:1 or 0.1")
    return value


def scale_text(scale: float) -> str:
    """``0.1 -> "1:10"``, ``2 -> "2:1"``, otherwise the number."""
    if scale <= 1 and abs(1 / scale - round(1 / scale)) < 1e-9:
        return f"1:{round(1 / scale)}"
    if scale > 1 and abs(scale - round(scale)) < 1e-9:
        return f"{round(scale)}:1"
    return f"{scale:g}"


def fabrication_report_path(bundle_dir: str | os.PathLike) -> Path:
    """``bundle_dir/fabrication/fabrication.json``."""
    return Path(bundle_dir) / FABRICATION_REPORT


def _corrupt(f: Path, why: str) -> InputError:
    return InputError(f"{f} is not a readable fabrication report ({why}); re-run 'gridshell "
                      f"fabricate {f.parent.parent}' or remove it")


def read_fabrication_report(bundle_dir: str | os.PathLike | None) -> dict[str, Any] | None:
    """The fabrication report of a bundle (``fabrication/fabrication.json`` as a dict), None
    when there is none; :class:`InputError` naming the file and the fix when it cannot be read
    or is not a JSON object whose ``params`` (if any) is an object."""
    if bundle_dir is None:
        return None
    f = fabrication_report_path(bundle_dir)
    if not f.is_file():
        return None
    try:
        rep = json.loads(f.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError) as exc:
        raise _corrupt(f, f"cannot be read: {exc}") from None
    except ValueError as exc:
        raise _corrupt(f, f"not JSON: {exc}") from None
    if not isinstance(rep, dict):
        raise _corrupt(f, "not a JSON object")
    if not isinstance(rep.get("params", {}), dict):
        raise _corrupt(f, "its 'params' is not an object")
    return rep


def stored_params(bundle_dir: str | os.PathLike | None) -> tuple[dict[str, Any], str | None]:
    """``(params, path)``: the fabrication parameters stored in the bundle's report and its
    path as text; ``({}, None)`` when there is none. Errors: those of
    :func:`read_fabrication_report`, and a stored width, thickness or scale that is not a
    positive number."""
    rep = read_fabrication_report(bundle_dir)
    if rep is None:
        return {}, None
    f = fabrication_report_path(bundle_dir)
    params = dict(rep.get("params") or {})
    for name in DEFAULT_CUT:
        if name in params and not _positive(params[name]):
            raise _corrupt(f, f"params.{name} is {params[name]!r}, not a positive number")
    return params, str(f)


def _positive(v: Any) -> bool:
    return (isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
            and v > 0)


@dataclass(frozen=True)
class StripSection:
    """A strip's section: cut size (mm of the model), scale (model / design), material name,
    and where each came from (``sources``: field -> ``"given"``, the report's path or
    ``"defaults"``). The real size is in metres of the design (:attr:`width_m`)."""

    width_mm: float
    thickness_mm: float
    scale: float
    material: str = DEFAULTS["material"]
    sources: Mapping[str, str] = field(default_factory=dict, compare=False)

    @property
    def width_m(self) -> float:
        """Real width, metres of the design."""
        return real_section_m(self.width_mm, self.thickness_mm, self.scale)[0]

    @property
    def thickness_m(self) -> float:
        """Real thickness, metres of the design."""
        return real_section_m(self.width_mm, self.thickness_mm, self.scale)[1]

    @property
    def source(self) -> str:
        """Where the cut size and scale came from, in one phrase: ``"defaults"``, the report's
        path, or e.g. ``"given (width), defaults (thickness, scale)"`` (the material's source:
        ``sources["material"]``)."""
        groups: dict[str, list[str]] = {}
        for k, s in self.sources.items():
            if k != "material":
                groups.setdefault(s, []).append(k)
        if len(groups) <= 1:
            return next(iter(groups), DEFAULT)
        return ", ".join(f"{s} ({', '.join(ks)})" for s, ks in groups.items())

    def given(self, name: str) -> bool:
        """The caller gave ``name`` (``"width"``, ``"thickness"``, ``"scale"``, ``"material"``)."""
        return self.sources.get(name) == GIVEN

    def text(self) -> str:
        """E.g. ``"200 x 10 mm (20 x 1 mm cut at 1:10)"``."""
        s = 1.0 / self.scale
        sc = f"1:{s:.4g}" if s >= 1 else f"{self.scale:.4g}:1"
        return (f"{1000 * self.width_m:.4g} x {1000 * self.thickness_m:.4g} mm "
                f"({self.width_mm:g} x {self.thickness_mm:g} mm cut at {sc})")


def _given(name: str, v: Any) -> Any:
    """A caller's value, checked: a positive length in mm, a scale, or a material name."""
    if name == "scale":
        return parse_scale(v)
    if name == "material":
        if not isinstance(v, str) or not v.strip():
            raise InputError(f"material must be a preset name such as 'pp', got {v!r}")
        return v.strip()
    if not _positive(v):
        got = f"{v:g}" if isinstance(v, (int, float)) else repr(v)
        raise InputError(f"--{name} must be a positive length in mm, got {got}")
    return float(v)


def resolve_section(bundle_dir: str | os.PathLike | None = None, *, width: Any = None,
                    thickness: Any = None, scale: Any = None, material: Any = None,
                    stored: bool = True) -> StripSection:
    """The strip section of a bundle: each of ``width``, ``thickness`` (mm of the model),
    ``scale`` (``"1:10"`` or 0.1) and ``material`` (a preset name) from the caller when not
    None, else from ``bundle_dir``'s fabrication report (``stored``; the report has no
    material), else :data:`DEFAULTS` (see the module docstring, also for the errors).

    A caller's value that is no positive length, scale or name is an :class:`InputError`; so is
    a report whose width, thickness or scale is not a positive number (:func:`stored_params`).
    """
    caller = {"width": width, "thickness": thickness, "scale": scale, "material": material}
    params, path = stored_params(bundle_dir) if stored else ({}, None)
    values: dict[str, Any] = {}
    sources: dict[str, str] = {}
    for name, v in caller.items():
        if v is not None:
            values[name], sources[name] = _given(name, v), GIVEN
        elif name != "material" and path is not None and name in params:
            values[name], sources[name] = float(params[name]), path
        else:
            values[name], sources[name] = DEFAULTS[name], DEFAULT
    return StripSection(values["width"], values["thickness"], values["scale"],
                        values["material"], sources)

