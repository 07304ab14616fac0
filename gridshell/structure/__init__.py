"""Structure: materials, sections and the stresses a design imposes on its lamellae.

Reads a design bundle and the fabrication parameters (width, thickness, scale); never imports
a pipeline (gg/, ncp/, fabrication/) nor the CLI. SI units inside: metres, pascals, kg/m^3.
``check`` writes structure.json; ``verdict`` judges it (and refuses cutting an overstressed
design); ``sizing`` finds the sections and scales of a material that hold.

May import: :mod:`gridshell.core`, :mod:`gridshell.geometry`, :mod:`gridshell.measure`,
:mod:`gridshell.design`; never a pipeline, render or fabrication.
"""
from gridshell.structure.materials import MATERIALS, Material, get_material, material_names, user_material
from gridshell.structure.section import Section

__all__ = ["MATERIALS", "Material", "Section", "get_material", "material_names",
           "user_material"]
