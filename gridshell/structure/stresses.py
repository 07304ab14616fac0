"""Stresses a design imposes on its strips as cut: bending about both section axes and twist.

Orientation of the strip (paper 3): **tangent** lamellae (GG) lie in the surface, their
thickness along the surface normal ``N``; **orthogonal** lamellae (AA, CNC, NCP) stand on the
surface, their width along ``N`` and their thickness along ``U = N x T``. With the Darboux
curvatures of the axis (:mod:`gridshell.structure.frames`):

==============  =====================  ==========================  ==============
orientation     weak axis (bends t)    strong axis (bends w)        twist
==============  =====================  ==========================  ==============
tangent         ``kn``                 ``kg`` (cut straight)        ``tau_g``
orthogonal      ``kg`` (cut flat)      ``kn - k_cut``               ``tau_g``
==============  =====================  ==========================  ==============

``k_cut`` is the curvature of the strip as cut, in its own plane: 0 for AA (straight), ``1/R``
for CNC (a circular arc), the planar collapse curve's curvature for NCP (signed against the
flattened normal). On the model at ``scale`` every curvature is multiplied by ``1/scale``.

Stresses (linear elastic, Euler-Bernoulli bending, Saint-Venant torsion):
``sigma = E (|k_weak| t / 2 + |k_strong| w / 2)`` the largest normal stress (at a corner of the
section, both bendings adding), ``tau = k G t |theta'|`` the largest torsional shear stress
(middle of the long side; ``k`` from :func:`gridshell.structure.section.torsion_stress_factor`,
1 for a thin strip). **Utilisation** ``u = sqrt(sigma^2 + 3 tau^2) / allowable`` (von Mises of
the two maxima taken at one point: conservative, as they lie at different points of the
section). ``u <= 1``: the strip stays elastic.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gridshell.structure.frames import ORIENTATIONS, DarbouxCurvatures, axis_curvatures  # noqa: F401
from gridshell.structure.materials import Material
from gridshell.structure.section import Section, torsion_stress_factor

#: design kind -> lamella orientation (as gridshell.fabrication.strips.ORIENTATION)
KIND_ORIENTATION = {"GG": "tangent", "AA": "orthogonal", "CNC": "orthogonal",
                    "NCP": "orthogonal"}


@dataclass
class StripCurvatures:
    """What the strip undergoes, per point, on the model (1/m of the real strip).

    weak, strong : (k,) bending curvature about the weak / strong section axis (changes from
    the cut shape), signed;  twist : (k,) twist rate theta', rad/m, signed.
    """

    weak: np.ndarray
    strong: np.ndarray
    twist: np.ndarray

    @property
    def bending(self) -> np.ndarray:
        """Magnitude of the bending curvature, ``hypot(weak, strong)``, 1/m."""
        return np.hypot(self.weak, self.strong)


def strip_curvatures(dc: DarbouxCurvatures, orientation: str, section: Section,
                     k_cut: np.ndarray | float = 0.0) -> StripCurvatures:
    """The curvature changes of the real strip from the design's Darboux curvatures ``dc``
    (design units) for lamellae of ``orientation`` cut with in-plane curvature ``k_cut``
    (1/m of the design; orthogonal lamellae only), scaled to the model (module table)."""
    a = axis_curvatures(dc, orientation, k_cut)
    return StripCurvatures(section.strip_curvature(a.weak), section.strip_curvature(a.strong),
                           section.strip_curvature(a.twist))


@dataclass
class StripStresses:
    """Stresses per point, Pa, and the utilisation (dimensionless).

    sigma_weak, sigma_strong : bending stress of each axis at the extreme fibre;
    sigma : their sum (corner of the section);  tau : largest torsional shear stress;
    utilisation : ``sqrt(sigma^2 + 3 tau^2) / allowable``.
    """

    sigma_weak: np.ndarray
    sigma_strong: np.ndarray
    tau: np.ndarray
    utilisation: np.ndarray

    @property
    def sigma(self) -> np.ndarray:
        return self.sigma_weak + self.sigma_strong


def strip_stresses(k: StripCurvatures, section: Section, material: Material) -> StripStresses:
    """Bending and torsional stresses of the strip ``section`` of ``material`` under the
    curvatures ``k`` (module docstring for the formulas and the utilisation)."""
    sw = material.E * np.abs(k.weak) * section.thickness / 2.0
    ss = material.E * np.abs(k.strong) * section.width / 2.0
    tau = section.torsion_factor * material.G * min(section.thickness, section.width) \
        * np.abs(k.twist)
    u = np.sqrt((sw + ss) ** 2 + 3.0 * tau ** 2) / material.allowable
    return StripStresses(sw, ss, tau, u)


def max_elastic_thickness(k: StripCurvatures, section: Section, material: Material,
                          iterations: int = 45) -> np.ndarray:
    """The thickest strip (m) of the same width that stays elastic (utilisation <= 1) under
    the curvatures ``k``, per point.

    The weak-axis bending and the torsional stress grow with the thickness, the strong-axis
    bending stress does not: where that alone exceeds the allowable stress no thickness helps
    (0). Capped at the width (beyond it the axes swap). Bisection on the monotone
    utilisation; ``inf`` never occurs (the cap).
    """
    w = section.width
    E, G, allow = material.E, material.G, material.allowable
    kw, ks, kt = np.abs(k.weak), np.abs(k.strong), np.abs(k.twist)
    s_strong = E * ks * w / 2.0

    def util(t: np.ndarray) -> np.ndarray:
        tau = torsion_stress_factor(np.clip(t / w, 1e-9, 1.0)) * G * t * kt
        return np.sqrt((E * kw * t / 2.0 + s_strong) ** 2 + 3.0 * tau ** 2) / allow

    lo = np.zeros_like(kw)
    hi = np.full_like(kw, w)
    fits = util(hi) <= 1.0
    for _ in range(int(iterations)):
        mid = 0.5 * (lo + hi)
        ok = util(mid) <= 1.0
        lo = np.where(ok, mid, lo)
        hi = np.where(ok, hi, mid)
    out = np.where(fits, w, lo)
    return np.where(s_strong >= allow, 0.0, out)
