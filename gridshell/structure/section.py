"""The strip's cross-section from the fabrication parameters: a thin solid rectangle.

The strip as built is ``width_mm`` x ``thickness_mm`` (the sheet it is cut from), and the
model is the design at ``scale`` (``1:10 -> 0.1``): a design length ``L`` (m) is
``scale * L`` on the model, a design curvature ``k`` (1/m) is ``k / scale`` on the strip.
Section properties are of the real strip, in metres. "Weak" axis: bending that curves the
thickness (I = w t^3 / 12); "strong" axis: bending in the plane of the strip (t w^3 / 12).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gridshell.core.errors import InputError


#: odd n of the Saint-Venant series; for b/a <= 1 every neglected term is below sech(41 pi/2)
#: ~ 1e-28 (the tanh series is summed as (31/32) zeta(5) less exponentially small terms)
_ODD = np.arange(1, 42, 2, dtype=float)
_ODD_INV5 = 31.0 / 32.0 * 1.0369277551433699   # sum over odd n of 1/n^5 = (31/32) zeta(5)


def _sech(x: np.ndarray) -> np.ndarray:
    return 2.0 * np.exp(-x) / (1.0 + np.exp(-2.0 * x))


def torsion_beta(aspect: float | np.ndarray) -> float | np.ndarray:
    """J / (a b^3) of a solid a x b rectangle (a >= b), ``aspect = b / a`` in (0, 1].

    Saint-Venant's series (Timoshenko & Goodier, Theory of Elasticity, sec. 109):
    beta = (1 - (192 / pi^5) (b/a) sum_{n odd} tanh(n pi a / 2b) / n^5) / 3; 1/3 for a thin
    strip, 0.1406 for a square.
    """
    r = np.atleast_1d(np.asarray(aspect, dtype=float))
    x = np.outer(0.5 * np.pi / r, _ODD)
    one_minus_tanh = 2.0 * np.exp(-2.0 * x) / (1.0 + np.exp(-2.0 * x))
    total = _ODD_INV5 - (one_minus_tanh / _ODD ** 5).sum(axis=1)
    out = (1.0 - 192.0 / np.pi ** 5 * r * total) / 3.0
    return float(out[0]) if np.ndim(aspect) == 0 else out.reshape(np.shape(aspect))


def torsion_stress_factor(aspect: float | np.ndarray) -> float | np.ndarray:
    """k with tau_max = k G b theta' for a solid a x b rectangle twisted at theta' (rad/m).

    Saint-Venant's series for the shear stress at the middle of the long side (Timoshenko &
    Goodier, sec. 109): k = 1 - (8 / pi^2) sum_{n odd} 1 / (n^2 cosh(n pi a / 2b)); 1 for a
    thin strip (tau = G t theta'), 0.675 for a square.
    """
    r = np.atleast_1d(np.asarray(aspect, dtype=float))
    out = 1.0 - 8.0 / np.pi ** 2 * (_sech(np.outer(0.5 * np.pi / r, _ODD)) / _ODD ** 2).sum(axis=1)
    return float(out[0]) if np.ndim(aspect) == 0 else out.reshape(np.shape(aspect))


@dataclass(frozen=True)
class Section:
    """A rectangular strip section: ``width_mm`` x ``thickness_mm`` on a model at ``scale``.

    Build it from the fabrication parameters with :meth:`from_params` so that ``fabricate``
    and the structural check talk about the same strip.
    """

    width_mm: float
    thickness_mm: float
    scale: float = 1.0

    def __post_init__(self) -> None:
        for key in ("width_mm", "thickness_mm", "scale"):
            v = getattr(self, key)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise InputError(f"section: {key} must be a positive number, got {v!r}")

    @classmethod
    def from_params(cls, params) -> "Section":
        """The section of :class:`gridshell.fabrication.params.FabParams` (``width``, ``thickness`` in mm,
        ``scale`` as a ratio); any object with those three attributes will do."""
        return cls(float(params.width), float(params.thickness), float(params.scale))

    # --- the real strip, metres -----------------------------------------------------------
    @property
    def width(self) -> float:
        """Strip width, m."""
        return self.width_mm * 1e-3

    @property
    def thickness(self) -> float:
        """Strip thickness, m."""
        return self.thickness_mm * 1e-3

    @property
    def area(self) -> float:
        """A = w t, m^2."""
        return self.width * self.thickness

    @property
    def I_weak(self) -> float:
        """Second moment for bending across the thickness, w t^3 / 12, m^4."""
        return self.width * self.thickness ** 3 / 12.0

    @property
    def I_strong(self) -> float:
        """Second moment for bending in the strip's plane, t w^3 / 12, m^4."""
        return self.thickness * self.width ** 3 / 12.0

    @property
    def _ab(self) -> tuple[float, float]:
        return max(self.width, self.thickness), min(self.width, self.thickness)

    @property
    def J(self) -> float:
        """Saint-Venant torsion constant beta a b^3 (:func:`torsion_beta`; a b^3 / 3 for a thin
        strip, corrected for the finite width), m^4."""
        a, b = self._ab
        return torsion_beta(b / a) * a * b ** 3

    @property
    def W_weak(self) -> float:
        """Section modulus for weak-axis bending, w t^2 / 6, m^3."""
        return self.width * self.thickness ** 2 / 6.0

    @property
    def W_strong(self) -> float:
        """Section modulus for strong-axis bending, t w^2 / 6, m^3."""
        return self.thickness * self.width ** 2 / 6.0

    @property
    def torsion_factor(self) -> float:
        """k in tau_max = k G b theta' (:func:`torsion_stress_factor`; b the shorter side)."""
        a, b = self._ab
        return torsion_stress_factor(b / a)

    @property
    def W_torsion(self) -> float:
        """Torsional section modulus T / tau_max = J / (k b), m^3."""
        return self.J / (self.torsion_factor * self._ab[1])

    @property
    def edge_ratio(self) -> float:
        """Width / thickness (the paper's 10:1 remark)."""
        return self.width_mm / self.thickness_mm

    def strip_length(self, design_length):
        """A design length (m) on the model (m): ``scale * L``."""
        return np.asarray(design_length, dtype=float) * self.scale

    def strip_curvature(self, design_curvature):
        """A design curvature or twist rate (1/m) on the model strip (1/m): ``k / scale``."""
        return np.asarray(design_curvature, dtype=float) / self.scale

    def with_thickness(self, thickness_mm: float) -> "Section":
        """The same strip in another thickness."""
        return Section(self.width_mm, thickness_mm, self.scale)

    def to_json(self) -> dict:
        return {"width_mm": self.width_mm, "thickness_mm": self.thickness_mm,
                "scale": self.scale,
                "scale_text": (f"1:{1 / self.scale:g}" if self.scale < 1 else f"{self.scale:g}:1"),
                "edge_ratio": self.edge_ratio, "area_m2": self.area,
                "I_weak_m4": self.I_weak, "I_strong_m4": self.I_strong, "J_m4": self.J,
                "W_weak_m3": self.W_weak, "W_strong_m3": self.W_strong,
                "W_torsion_m3": self.W_torsion, "torsion_factor": self.torsion_factor,
                "units": "real strip (the model as built), metres"}

