"""Meshes shipped with the package: the inputs of ``gridshell demo``.

``dome.obj`` (a freeform dome, the GG target) and ``torus_patch.obj`` (a torus zone, the
reference of the CNC pavilion) are copies of ``samples/dome.obj`` and
``samples/torus_patch.obj``, written by ``samples/make_meshes.py`` (origin and formulas:
``samples/README.md``). Metres.

May import: :mod:`gridshell.core`.
"""
from __future__ import annotations

from importlib import resources
from pathlib import Path

__all__ = ["DEMO_MESHES", "path"]

#: the meshes of this package
DEMO_MESHES = ("dome.obj", "torus_patch.obj")


def path(name: str) -> Path:
    """The file system path of the shipped mesh ``name`` (one of :data:`DEMO_MESHES`)."""
    from gridshell.core.errors import InputError

    if name not in DEMO_MESHES:
        raise InputError(f"no bundled mesh {name!r}; the package ships {', '.join(DEMO_MESHES)}")
    p = Path(str(resources.files(__name__) / name))
    if not p.is_file():
        raise InputError(f"the bundled mesh {p} is missing; reinstall gridshell")
    return p
