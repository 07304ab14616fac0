"""Read a design bundle for display and export, tolerating a collapsed ``aligned.obj``.

The aligned configuration puts the joints of a loop on one line by design (AA and GG strips
are straight), which :func:`gridshell.quadmesh.read_mesh` rejects as degenerate faces; pictures
and exports only need its vertices, so this reader takes them unchecked.
"""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from ..bundle import DesignBundle, read_bundle
from ..errors import MeshError


def load_bundle(path: str | Path) -> DesignBundle:
    """:func:`gridshell.bundle.read_bundle`, falling back to the unchecked vertices of
    ``aligned.obj`` when only that file fails the mesh checks."""
    from ..quadmesh import _read_raw

    path = Path(path)
    try:
        return read_bundle(path)
    except MeshError as exc:
        if not str(exc).startswith("aligned.obj"):
            raise
    aligned = np.asarray(_read_raw(path / "aligned.obj")[0], float).reshape(-1, 3)
    b = _read_bundle_without_aligned(path)
    if aligned.shape != b.net.joints.shape:
        raise MeshError(f"{path / 'aligned.obj'} has {len(aligned)} vertices but net.obj "
                        f"{len(b.net.joints)}; re-run the design command")
    return replace(b, aligned=aligned)


def _read_bundle_without_aligned(path: Path) -> DesignBundle:
    """read_bundle with net.obj standing in for aligned.obj (the caller replaces it)."""
    import shutil
    import tempfile

    with tempfile.TemporaryDirectory(prefix="gridshell-bundle-") as tmp:
        t = Path(tmp)
        for name in ("design.json", "net.obj", "axes.obj", "surface.obj", "revolution.obj"):
            if (path / name).is_file():
                shutil.copyfile(path / name, t / name)
        shutil.copyfile(path / "net.obj", t / "aligned.obj")
        return read_bundle(t)
