"""Old module paths (the flat layout before 0.2) kept importable for one release.

``import gridshell.bspline`` still works and gives :mod:`gridshell.geometry.bspline` (the same
module object) with a :class:`DeprecationWarning` naming the new path; so does the top-level
``fabrication`` package (now :mod:`gridshell.fabrication`). :func:`install` puts the finder on
``sys.meta_path`` once; ``gridshell/__init__`` calls it.
"""
from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys
import warnings

#: old module path -> new module path
MOVED: dict[str, str] = {
    "fabrication": "gridshell.fabrication",
    "fabrication.axis": "gridshell.fabrication.axis",
    "fabrication.cutlist": "gridshell.fabrication.cutlist",
    "fabrication.dxf": "gridshell.fabrication.dxf",
    "fabrication.joints": "gridshell.fabrication.joints",
    "fabrication.kerf": "gridshell.fabrication.kerf",
    "fabrication.labels": "gridshell.fabrication.labels",
    "fabrication.layers": "gridshell.fabrication.layers",
    "fabrication.nesting": "gridshell.fabrication.nesting",
    "fabrication.params": "gridshell.fabrication.params",
    "fabrication.part": "gridshell.fabrication.part",
    "fabrication.path": "gridshell.fabrication.path",
    "fabrication.pipeline": "gridshell.fabrication.pipeline",
    "fabrication.plan": "gridshell.fabrication.plan",
    "fabrication.preview": "gridshell.fabrication.preview",
    "fabrication.raster": "gridshell.fabrication.raster",
    "fabrication.rows": "gridshell.fabrication.rows",
    "fabrication.splice": "gridshell.fabrication.splice",
    "fabrication.strip": "gridshell.fabrication.strip",
    "fabrication.strips": "gridshell.fabrication.strips",
    "fabrication.svg": "gridshell.fabrication.svg",
    "gridshell.aside": "gridshell.core.aside",
    "gridshell.atomic": "gridshell.core.atomic",
    "gridshell.bspline": "gridshell.geometry.bspline",
    "gridshell.bundle": "gridshell.design.bundle",
    "gridshell.diffgeo": "gridshell.geometry.diffgeo",
    "gridshell.errors": "gridshell.core.errors",
    "gridshell.export.units": "gridshell.core.units",
    "gridshell.finite": "gridshell.core.finite",
    "gridshell.gg.simulate": "gridshell.gg.alignment",
    "gridshell.grid": "gridshell.geometry.grid",
    "gridshell.igl_adapter": "gridshell.geometry.igl_adapter",
    "gridshell.io.units": "gridshell.core.units",
    "gridshell.manifest": "gridshell.core.manifest",
    "gridshell.meshfile": "gridshell.geometry.meshfile",
    "gridshell.metrics": "gridshell.measure.metrics",
    "gridshell.ncp.phlw_checks": "gridshell.ncp.phlw.checks",
    "gridshell.ncp.phlw_figures": "gridshell.ncp.phlw.figures",
    "gridshell.ncp.phlw_gates": "gridshell.ncp.phlw.gates",
    "gridshell.ncp.phlw_output": "gridshell.ncp.phlw.output",
    "gridshell.ncp.phlw_problem": "gridshell.ncp.phlw.problem",
    "gridshell.ncp.phlw_rounds": "gridshell.ncp.phlw.rounds",
    "gridshell.ncp.phlw_terms": "gridshell.ncp.phlw.terms",
    "gridshell.ncp.simulate": "gridshell.ncp.alignment",
    "gridshell.net": "gridshell.geometry.net",
    "gridshell.objplain": "gridshell.geometry.objplain",
    "gridshell.outputs": "gridshell.workflow.outputs",
    "gridshell.quadmesh": "gridshell.geometry.quadmesh",
    "gridshell.quality": "gridshell.measure.quality",
    "gridshell.recent": "gridshell.core.recent",
    "gridshell.render.section": "gridshell.design.section",
    "gridshell.render.states": "gridshell.render.state_sheet",
    "gridshell.render.structure": "gridshell.render.utilisation",
    "gridshell.spline_batch": "gridshell.geometry.spline_batch",
    "gridshell.strips3d": "gridshell.geometry.strips3d",
    "gridshell.vectors": "gridshell.geometry.vectors",
    "gridshell.verification": "gridshell.design.verification",
}


class _MovedFinder(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Finds an old path of :data:`MOVED` and loads it as the module at the new path."""

    def find_spec(self, fullname, path=None, target=None):
        if fullname not in MOVED:
            return None
        return importlib.util.spec_from_loader(fullname, self)

    def create_module(self, spec):
        new = MOVED[spec.name]
        warnings.warn(f"{spec.name} is now {new}; the old path will be removed in the next "
                      f"release: import {new}", DeprecationWarning, stacklevel=2)
        return importlib.import_module(new)

    def exec_module(self, module):  # the module at the new path is executed already
        return None


def install() -> None:
    """Put the finder of old paths on ``sys.meta_path`` (once)."""
    if not any(isinstance(f, _MovedFinder) for f in sys.meta_path):
        sys.meta_path.insert(0, _MovedFinder())
