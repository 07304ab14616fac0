"""Fabrication parameters: parsing of ``1:10`` / ``600x400`` and checks that run before any output.

All lengths in millimetres of the physical model; the design is in metres.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass

from gridshell.core.errors import InputError
from gridshell.design.section import DEFAULTS, parse_scale, scale_text

__all__ = ["AXIS_PLACES", "DXF_VERSIONS", "FabParams", "JOINT_STYLES", "ROTATIONS", "parse_scale",
           "parse_sheet", "scale_text"]

JOINT_STYLES = ("hole", "slots", "marks")
AXIS_PLACES = ("centre", "edge")
ROTATIONS = ("free", "grain")
DXF_VERSIONS = ("R2010", "R12")


def parse_sheet(text: str | tuple[float, float]) -> tuple[float, float]:
    """Sheet size ``(width, height)`` in mm from ``"600x400"``."""
    if isinstance(text, (tuple, list)):
        w, h = (float(v) for v in text)
    else:
        parts = str(text).lower().replace("*", "x").split("x")
        try:
            w, h = (float(p) for p in parts)
        except ValueError:
            raise InputError(f"sheet size {text!r} is not understood; write it as WIDTHxHEIGHT "
                             "in mm, e.g. 600x400") from None
    if not (math.isfinite(w) and math.isfinite(h)) or w <= 0 or h <= 0:
        raise InputError(f"sheet size {text!r} must be positive; write it as WIDTHxHEIGHT in mm, "
                         "e.g. 600x400")
    return w, h


@dataclass
class FabParams:
    """What to cut and how; every length in mm of the physical model.

    Attributes
    ----------
    width, thickness : float
        Strip width and sheet thickness.
    hole : float
        Hole diameter at each joint (``joints="hole"``).
    joints : str
        ``"hole"`` (default), ``"slots"`` (cross-halving notches, orthogonal lamellae only)
        or ``"marks"`` (score lines across the strip).
    clearance : float
        Slot width = thickness + clearance.
    margin : float
        Strip length beyond the first and last joint (or axis end).
    axis : str
        ``"centre"``: axis on the centre line; ``"edge"``: axis on one edge (orthogonal
        lamellae standing on the surface), the strip on the side of the flattened normal.
        Tangent (GG) lamellae take ``"centre"`` only (:meth:`check_orientation`).
    scale : float
        Model / design length ratio (``1:10`` -> 0.1); design metres -> mm is ``1000 * scale``.
    sheet : (float, float)
        Sheet width x height.
    gap : float
        Clearance between parts and from the sheet edges. Default 2 mm: with 20 mm strips a
        5 mm gap alone takes 20 % of every sheet (a strip and its gap use at most
        w / (w + g) of it), more than the 15 % a nesting may lose over the parts' area
        (issue 16); 2 mm keeps 91 % usable and is ample for a laser cut (kerf ~0.1-0.3 mm;
        SVGnest's default spacing is 0). Thick or heat-sensitive sheets: pass ``--gap``.
    rotation : str
        How nesting may turn parts on the sheet: ``"free"`` (any angle; isotropic materials
        such as polypropylene, acrylic, MDF) or ``"grain"`` (curved parts by 0 or 180 degrees
        from their chord along the sheet's long side, straight strips along it: plywood whose
        grain should run along the strips).
    overlap : float or None
        Length of a splice (lap) between two pieces of a split lamella; None: at a joint,
        one joint spacing plus two end margins, so that the pieces share two joints; between
        joints, two widths plus two end margins (:mod:`gridshell.fabrication.splice`).
    kerf : float
        Width of the laser cut; outlines move out and holes in by ``kerf / 2``. 0: off.
    dxf_version : str
        ``"R2010"`` or ``"R12"``.
    segments : bool
        Write arcs as short segments instead of bulges.
    labels : bool
        Engrave lamella and neighbour ids.
    fallback_marks : bool
        When the joints of a lamella are too close at this scale for ``joints`` (holes or
        slots would merge), engrave score marks instead and say so in the report
        (``joints_fallback``); False: refuse (an explicit ``--joints``).
    tolerance : float
        Chord tolerance for tessellated arcs and curves.
    """

    width: float = DEFAULTS["width"]
    thickness: float = DEFAULTS["thickness"]
    hole: float = 3.0
    joints: str = "hole"
    clearance: float = 0.2
    margin: float = 15.0
    axis: str = "centre"
    scale: float = DEFAULTS["scale"]
    sheet: tuple[float, float] = (600.0, 400.0)
    gap: float = 2.0
    rotation: str = "free"
    overlap: float | None = None
    kerf: float = 0.0
    dxf_version: str = "R2010"
    segments: bool = False
    labels: bool = True
    fallback_marks: bool = True
    tolerance: float = 0.01

    def __post_init__(self) -> None:
        self.scale = parse_scale(self.scale)
        self.sheet = parse_sheet(self.sheet)
        self.validate()

    @property
    def mm_per_m(self) -> float:
        """Millimetres of the model per metre of the design."""
        return 1000.0 * self.scale

    @property
    def slot_width(self) -> float:
        return self.thickness + self.clearance

    def to_json(self) -> dict:
        d = asdict(self)
        d["sheet"] = list(self.sheet)
        d["scale_text"] = scale_text(self.scale)
        return d

    def validate(self) -> None:
        """Raise :class:`InputError` naming the first nonsensical parameter and its fix."""
        for name in ("width", "thickness", "margin", "tolerance"):
            v = getattr(self, name)
            if not math.isfinite(v) or v <= 0:
                raise InputError(f"--{name} must be a positive length in mm, got {v:g}")
        for name in ("hole", "clearance", "gap", "kerf"):
            v = getattr(self, name)
            if not math.isfinite(v) or v < 0:
                raise InputError(f"--{name} must be a length >= 0 mm, got {v:g}")
        if self.joints not in JOINT_STYLES:
            raise InputError(f"--joints must be one of {', '.join(JOINT_STYLES)}, "
                             f"got {self.joints!r}")
        if self.rotation not in ROTATIONS:
            raise InputError(f"--rotation must be one of {', '.join(ROTATIONS)}, "
                             f"got {self.rotation!r}")
        if self.axis not in AXIS_PLACES:
            raise InputError(f"--axis must be one of {', '.join(AXIS_PLACES)}, got {self.axis!r}")
        if self.dxf_version not in DXF_VERSIONS:
            raise InputError(f"--dxf-version must be one of {', '.join(DXF_VERSIONS)}, "
                             f"got {self.dxf_version!r}")
        if self.joints == "hole":
            if self.hole <= 0:
                raise InputError("--hole must be positive with --joints hole; "
                                 "use --joints marks for joints without holes")
            if self.hole >= self.width - 2 * self.kerf:
                less = f" less twice the kerf {self.kerf:g} mm" if self.kerf else ""
                raise InputError(f"hole diameter {self.hole:g} mm is not smaller than the strip "
                                 f"width {self.width:g} mm{less}; choose a smaller --hole"
                                 f"{', a smaller --kerf' if self.kerf else ''} or a wider --width")
            if self.margin < self.hole / 2 + 0.5:
                raise InputError(f"end margin {self.margin:g} mm leaves no material beyond the end "
                                 f"holes (diameter {self.hole:g} mm); give --margin >= "
                                 f"{self.hole / 2 + 0.5:g}")
            if self.kerf >= self.hole:
                raise InputError(f"kerf {self.kerf:g} mm is not smaller than the hole diameter "
                                 f"{self.hole:g} mm; measure the kerf again or enlarge --hole")
        if self.joints == "slots":
            if self.margin < self.slot_width / 2 + 0.5:
                raise InputError(f"end margin {self.margin:g} mm leaves no material beyond the end "
                                 f"slots; give --margin >= {self.slot_width / 2 + 0.5:g}")
            if self.kerf >= self.slot_width:
                raise InputError(f"kerf {self.kerf:g} mm is not smaller than the slot width "
                                 f"{self.slot_width:g} mm; increase --clearance")
        short = min(self.sheet)
        if self.width + 2 * self.gap + self.kerf > short:
            raise InputError(f"strip width {self.width:g} mm plus twice the gap {self.gap:g} mm "
                             f"does not fit the sheet ({self.sheet[0]:g} x {self.sheet[1]:g} mm); "
                             "use a larger --sheet, a narrower --width or a smaller --gap")
        if self.overlap is not None:
            if not math.isfinite(self.overlap) or self.overlap < 2 * self.margin:
                raise InputError(f"--overlap {self.overlap:g} mm must be at least twice the end "
                                 f"margin ({2 * self.margin:g} mm) so that both pieces keep the "
                                 "splice joint with a full margin; omit it for the default")

    def check_orientation(self, orientation: str, kind: str = "") -> None:
        """Raise :class:`InputError` if the joint style or axis place means nothing for
        lamellae of this ``orientation`` (``"tangent"``: GG, width in the surface;
        ``"orthogonal"``: AA, CNC, NCP, standing on the surface). ``kind`` names the design
        in the message."""
        if orientation == "orthogonal":
            return
        design = f"{kind} " if kind else ""
        if self.joints == "slots":
            raise InputError(f"--joints slots needs orthogonal lamellae (AA, CNC, NCP designs); "
                             f"{design}lamellae lie in the surface: use --joints hole or marks")
        if self.axis == "edge":
            raise InputError(f"--axis edge puts the axis on the edge a lamella stands on, which "
                             f"only orthogonal lamellae (AA, CNC, NCP designs) have; {design}"
                             "lamellae are tangent to the surface with the axis on the centre "
                             "line: use --axis centre")
