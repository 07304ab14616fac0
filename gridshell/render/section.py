"""The strip section a bundle's pictures show: the cut strip's width and thickness at its scale.

The strips that are cut are ``width x thickness`` mm at a model scale (``1:10`` -> 0.1); the
gridshell they stand for has strips ``width / scale`` wide (20 mm at 1:10 = 200 mm). The values
come from the bundle's ``fabrication/fabrication.json`` when ``gridshell fabricate`` has run,
else from the fabrication defaults (:data:`DEFAULT_CUT`, the same as
``gridshell.fabrication.params.FabParams``; a test keeps the two equal). The pictures
(:mod:`.ribbons`) and the WebGL viewer (:mod:`.viewer`) draw this section.
"""
from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass
from pathlib import Path

from gridshell.geometry.strips3d import real_section_m

__all__ = ["DEFAULT_CUT", "StripSection", "bundle_section"]

#: the cut strip when no fabrication output says otherwise: mm, mm, model / design
DEFAULT_CUT = {"width": 20.0, "thickness": 1.0, "scale": 0.1}


@dataclass(frozen=True)
class StripSection:
    """A strip's section: cut size (mm of the model), scale, and real size (metres)."""

    width_mm: float
    thickness_mm: float
    scale: float
    source: str

    @property
    def width_m(self) -> float:
        """Real width, metres of the design."""
        return real_section_m(self.width_mm, self.thickness_mm, self.scale)[0]

    @property
    def thickness_m(self) -> float:
        """Real thickness, metres of the design."""
        return real_section_m(self.width_mm, self.thickness_mm, self.scale)[1]

    def text(self) -> str:
        """E.g. ``"200 x 10 mm (20 x 1 mm cut at 1:10)"``."""
        s = 1.0 / self.scale
        sc = f"1:{s:.4g}" if s >= 1 else f"{self.scale:.4g}:1"
        return (f"{1000 * self.width_m:.4g} x {1000 * self.thickness_m:.4g} mm "
                f"({self.width_mm:g} x {self.thickness_mm:g} mm cut at {sc})")


def _positive(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) and v > 0


def bundle_section(bundle_dir: str | os.PathLike | None) -> StripSection:
    """The strip section of a bundle directory: ``fabrication/fabrication.json``'s
    ``params`` (width, thickness, scale) when present and valid, else :data:`DEFAULT_CUT`."""
    if bundle_dir is not None:
        f = Path(bundle_dir) / "fabrication" / "fabrication.json"
        try:
            p = json.loads(f.read_text(encoding="utf-8")).get("params") or {}
        except (OSError, ValueError, AttributeError):
            p = {}
        if isinstance(p, dict) and all(_positive(p.get(k)) for k in DEFAULT_CUT):
            return StripSection(float(p["width"]), float(p["thickness"]), float(p["scale"]),
                                "fabrication/fabrication.json")
    return StripSection(DEFAULT_CUT["width"], DEFAULT_CUT["thickness"], DEFAULT_CUT["scale"],
                        "fabrication defaults")
