"""Named materials for lamellae, with their sources, and user values.

SI units: moduli and stresses in Pa, density in kg/m^3, strains dimensionless. The
*allowable stress* is the elastic limit the check compares the equivalent stress against
(yield stress of the plastics and the aluminium, characteristic bending strength of the
timbers, minimum longitudinal strength of the pultruded GFRP); it carries no safety factor
(divide it by one with ``--allowable`` or ``user_material(..., allowable_stress=...)``).
Strips are cut with the fibre / face grain along the lamella; the values are the ones along
that direction. Values are typical, rounded mid-range figures of the source named in
``source``: measure the actual sheet for anything that will carry load.
``sheet_thicknesses_mm`` are common stock thicknesses (polymer sheet 0.5-5 mm; aircraft birch
plywood 0.8-3 mm and Finnish birch plywood 4-18 mm; sawn spruce boards of EN 1313-1's
preferred thicknesses; pultruded GFRP flats; aluminium sheet), what ``check --suggest`` tries.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace

from gridshell.core.errors import InputError


@dataclass(frozen=True)
class Material:
    """A linear elastic strip material.

    Attributes
    ----------
    name : str
        Short key (``"pp"``) or ``"user"``.
    label : str
        Human name.
    E : float
        Young's modulus along the strip, Pa.
    G : float
        Shear modulus (torsion of the strip), Pa.
    nu : float or None
        Poisson ratio (isotropic materials; None for the orthotropic timbers and GFRP, whose
        G is measured, not derived).
    density : float
        kg/m^3.
    allowable_stress : float
        Elastic limit of the normal stress, Pa.
    allowable_strain : float or None
        Elastic limit of the strain (dimensionless), if the source gives one; the smaller
        of ``allowable_stress`` and ``E * allowable_strain`` governs.
    source : str
        Where the figures come from.
    sheet_thicknesses_mm : tuple of float
        Thicknesses the material is sold in (sheets, boards, pultruded flats), mm: the
        sections ``gridshell check --suggest`` tries.
    """

    name: str
    label: str
    E: float
    G: float
    nu: float | None
    density: float
    allowable_stress: float
    allowable_strain: float | None = None
    source: str = ""
    sheet_thicknesses_mm: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        for key in ("E", "G", "density", "allowable_stress"):
            v = getattr(self, key)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise InputError(f"material {self.name!r}: {key} must be a positive number, "
                                 f"got {v!r}")
        if self.nu is not None and not (math.isfinite(self.nu) and -1.0 < self.nu < 0.5):
            raise InputError(f"material {self.name!r}: Poisson ratio must lie in (-1, 0.5), "
                             f"got {self.nu!r}")
        if self.allowable_strain is not None and not (
                math.isfinite(self.allowable_strain) and self.allowable_strain > 0):
            raise InputError(f"material {self.name!r}: allowable strain must be positive, "
                             f"got {self.allowable_strain!r}")

    @property
    def allowable(self) -> float:
        """The governing allowable stress, Pa: min(allowable_stress, E * allowable_strain)."""
        if self.allowable_strain is None:
            return float(self.allowable_stress)
        return float(min(self.allowable_stress, self.E * self.allowable_strain))

    @property
    def elastic_strain(self) -> float:
        """Strain at the governing allowable stress (dimensionless)."""
        return self.allowable / self.E

    def to_json(self) -> dict:
        d = asdict(self)
        d["allowable"] = self.allowable
        d["elastic_strain"] = self.elastic_strain
        d["units"] = "E, G, allowable_stress, allowable: Pa; density: kg/m^3"
        return d


def _iso_G(E: float, nu: float) -> float:
    """Shear modulus of an isotropic material, G = E / (2 (1 + nu)), Pa."""
    return E / (2.0 * (1.0 + nu))


#: the presets, by short name (see :func:`get_material` for the aliases)
MATERIALS: dict[str, Material] = {m.name: m for m in (
    Material("pp", "polypropylene (homopolymer sheet)", E=1.5e9, G=_iso_G(1.5e9, 0.42), nu=0.42,
             density=905.0, allowable_stress=32e6,
             source="MatWeb, 'Overview of materials for Polypropylene, Homopolymer': tensile "
                    "modulus 1.1-2.0 GPa, yield 31-37 MPa, density 0.90-0.91 g/cm3; Poisson "
                    "0.42 (Ashby, Materials Selection in Mechanical Design, PP record)",
             sheet_thicknesses_mm=(0.5, 0.8, 1.0, 1.5, 2.0, 3.0, 4.0, 5.0)),
    Material("petg", "PETG (amorphous copolyester sheet)", E=2.0e9, G=_iso_G(2.0e9, 0.38),
             nu=0.38, density=1270.0, allowable_stress=50e6,
             source="Eastman Eastar 6763 data sheet: tensile modulus 2010 MPa, tensile stress "
                    "at yield 50 MPa, density 1.27 g/cm3; Poisson 0.38 typical of PET "
                    "copolyesters (Ashby)",
             sheet_thicknesses_mm=(0.5, 0.75, 1.0, 1.5, 2.0, 3.0, 4.0, 5.0)),
    Material("birch-plywood", "birch plywood (thin, along the face grain)", E=9.0e9, G=0.62e9,
             nu=None, density=680.0, allowable_stress=40e6,
             source="Finnish birch plywood (EN 636) handbook figures for thin 3- and 5-ply "
                    "panels bent along the face grain, rounded down: E_m about 9-12 GPa, "
                    "f_m,k about 40-60 MPa, in-plane shear modulus 620 MPa, 680 kg/m3",
             sheet_thicknesses_mm=(0.8, 1.0, 1.5, 2.0, 3.0, 4.0, 6.5, 9.0, 12.0, 15.0, 18.0)),
    Material("spruce", "spruce, strength class C24 (along the grain)", E=11.0e9, G=0.69e9,
             nu=None, density=420.0, allowable_stress=24e6,
             source="EN 338:2016 strength class C24: E0,mean 11.0 GPa, G_mean 0.69 GPa, "
                    "rho_mean 420 kg/m3, characteristic bending strength f_m,k 24 MPa "
                    "(no k_mod / gamma_M applied)",
             sheet_thicknesses_mm=(10.0, 12.0, 15.0, 19.0, 22.0, 25.0, 30.0, 40.0, 50.0)),
    Material("gfrp", "GFRP, pultruded (along the fibres)", E=23.0e9, G=3.0e9, nu=None,
             density=1850.0, allowable_stress=240e6, allowable_strain=0.01,
             source="EN 13706-3 grade E23: longitudinal modulus >= 23 GPa, longitudinal "
                    "tensile strength >= 240 MPa; in-plane shear modulus about 3 GPa and "
                    "density 1.8-1.9 g/cm3 typical of pultruded E-glass/polyester profiles; "
                    "1 % strain, the limit used for bent GFRP gridshells (Douthe, Baverel & "
                    "Caron 2006)",
             sheet_thicknesses_mm=(1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0)),
    Material("aluminium", "aluminium 6061-T6", E=69.0e9, G=26.0e9, nu=0.33, density=2700.0,
             allowable_stress=276e6,
             source="ASM Aerospace Specification Metals, aluminium 6061-T6: E 68.9 GPa, "
                    "G 26 GPa, Poisson 0.33, 2.70 g/cm3, tensile yield 276 MPa",
             sheet_thicknesses_mm=(0.5, 0.8, 1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 6.0)),
)}

_ALIASES = {
    "polypropylene": "pp", "petg": "petg", "pet-g": "petg", "plywood": "birch-plywood",
    "birch": "birch-plywood", "birch_plywood": "birch-plywood", "c24": "spruce",
    "spruce-c24": "spruce", "spruce_c24": "spruce", "glass-fibre-reinforced-polymer": "gfrp",
    "timber": "spruce", "glass-fibre": "gfrp", "fiberglass": "gfrp", "fibreglass": "gfrp",
    "aluminum": "aluminium", "al": "aluminium", "alu": "aluminium", "6061": "aluminium",
}


def material_names() -> list[str]:
    """The preset names, in the order of :data:`MATERIALS`."""
    return list(MATERIALS)


def get_material(name: str) -> Material:
    """The preset called ``name`` (case-insensitive; aliases such as ``polypropylene``,
    ``plywood``, ``aluminum``); :class:`InputError` naming the choices otherwise."""
    key = str(name).strip().lower()
    key = _ALIASES.get(key, key)
    if key not in MATERIALS:
        raise InputError(f"unknown material {name!r}; choose one of "
                         f"{', '.join(MATERIALS)} or give your own with --E and --allowable")
    return MATERIALS[key]


def user_material(base: Material | str | None = None, *, E: float | None = None,
                  G: float | None = None, nu: float | None = None,
                  density: float | None = None, allowable_stress: float | None = None,
                  allowable_strain: float | None = None) -> Material:
    """A preset with some values replaced, or a material of the user's own (``base=None``).

    SI units (Pa, kg/m^3). When ``G`` is not given it is derived from E and the Poisson ratio
    for an isotropic base (or a user material, nu 0.35 if not given) and kept for an
    orthotropic one (timber, GFRP: their G is measured, not derived). A material of the
    user's own needs ``E`` and ``allowable_stress`` (or ``allowable_strain``).
    """
    if isinstance(base, str):
        base = get_material(base)
    given = {k: v for k, v in dict(E=E, G=G, nu=nu, density=density,
                                  allowable_stress=allowable_stress,
                                  allowable_strain=allowable_strain).items() if v is not None}
    for k, v in given.items():
        if not (isinstance(v, (int, float)) and math.isfinite(v)):
            raise InputError(f"material value {k} must be a finite number, got {v!r}")
    if base is None:
        if E is None or (allowable_stress is None and allowable_strain is None):
            raise InputError("a material of your own needs --E and --allowable (or "
                             "--allowable-strain); or start from a preset with --material")
        nu_ = 0.35 if nu is None else nu
        if allowable_stress is None:
            allowable_stress = E * allowable_strain
        return Material("user", "user material", E=E, G=_iso_G(E, nu_) if G is None else G,
                        nu=nu_ if G is None or nu is not None else None,
                        density=1000.0 if density is None else density,
                        allowable_stress=allowable_stress, allowable_strain=allowable_strain,
                        source="user values")
    if not given:
        return base
    changes = dict(given)
    if G is None and (E is not None or nu is not None) and base.nu is not None:
        changes["G"] = _iso_G(E if E is not None else base.E, nu if nu is not None else base.nu)
    if G is not None and nu is None and base.nu is not None:
        changes["nu"] = None
    if allowable_stress is not None and allowable_strain is None:
        changes["allowable_strain"] = None
    names = ", ".join(f"{k}={v:g}" for k, v in given.items())
    return replace(base, name=f"{base.name}+user", label=f"{base.label} (user values)",
                   source=f"{base.source}; replaced by user values: {names}", **changes)
