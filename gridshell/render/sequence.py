"""The alignment sequence of a bundle as PNG frames and an animated GIF (paper Fig. 16).

A bundle's ``sequence/frame_000.obj, frame_001.obj, ...`` hold the joints of every state from
deployed to aligned, all with the net-loops as faces. The drawing itself is
:func:`gridshell.render.ncp_maps.sequence_frames` (fixed limits over all frames) and
:func:`gridshell.render.ncp_maps.gif`; this module reads the frames, fixes the camera from the
principal axes of the deployed state (as :mod:`.ribbons` does) and writes the files atomically.
"""
from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Callable, Sequence

import numpy as np

from gridshell.core.atomic import write_bytes
from gridshell.core.errors import InputError, MeshError

__all__ = ["sequence_files", "read_sequence", "render_sequence", "render_bundle_sequence"]

_FRAME = re.compile(r"^frame_(\d+)\.obj$")


def sequence_files(bundle_dir: str | os.PathLike) -> list[Path]:
    """The frame OBJ files of ``bundle_dir/sequence`` in numeric order (empty if none)."""
    d = Path(bundle_dir) / "sequence"
    if not d.is_dir():
        return []
    found = [(int(m.group(1)), p) for p in d.iterdir() if (m := _FRAME.match(p.name))]
    return [p for _, p in sorted(found)]


def read_sequence(bundle_dir: str | os.PathLike) -> tuple[list[np.ndarray], np.ndarray]:
    """Frames ``[(n,3) float]`` and faces ``(m,4) int`` of the alignment sequence of a bundle.

    The faces come from the first frame; every frame must have the same vertex count. The
    collapsed frames are degenerate meshes by design, so the files are read without the mesh
    checks of :func:`gridshell.geometry.meshfile.read_mesh`.

    Raises
    ------
    InputError
        No ``sequence/frame_*.obj`` in the bundle, or frames of different sizes.
    """
    from gridshell.geometry.meshfile import read_configuration

    files = sequence_files(bundle_dir)
    if not files:
        raise InputError(f"{bundle_dir} has no sequence/frame_*.obj; an alignment sequence is "
                         "written by 'gridshell gg' and 'gridshell ncp'")
    frames, F = [], None
    for p in files:
        V, P, sizes = read_configuration(p)
        V = np.asarray(V, float).reshape(-1, 3)
        if F is None:
            if not len(P) or np.any(sizes != 4):
                raise MeshError(f"{p}: the frames must have the net-loops (quads) as faces")
            F = np.asarray(P[:, :4], np.int64)
        if frames and len(V) != len(frames[0]):
            raise InputError(f"{p} has {len(V)} vertices, {files[0].name} {len(frames[0])}; "
                             "all frames of a sequence must have the same joints")
        frames.append(V)
    return frames, F


def render_sequence(frames: Sequence[np.ndarray], F: np.ndarray, *,
                    frames_dir: str | os.PathLike | None = None,
                    gif_path: str | os.PathLike | None = None, title: str = "",
                    dpi: int = 80, duration_ms: int = 200, hold_ms: int = 800,
                    view: tuple[float, float] | None = None,
                    progress: Callable[[str], None] | None = None) -> dict[str, object]:
    """PNG frames with a fixed camera and limits, and an animated GIF, of an alignment sequence.

    Parameters
    ----------
    frames : list of (n,3) float
        Joint positions of each state, metres, deployed first.
    F : (m,4) int
        Net-loops; their edges are drawn.
    frames_dir : path-like, optional
        Directory receiving ``frame_000.png ...`` (each written atomically).
    gif_path : path-like, optional
        The animated GIF (written atomically); the first and last frames are held ``hold_ms``.
    title, dpi, duration_ms : picture title, resolution, time per frame
    view : (elev, azim) degrees, optional
        Camera (default :func:`gridshell.render.ribbons.view_angles` of the first frame).

    Returns
    -------
    dict
        ``frames``: list of written PNG paths, ``gif``: the GIF path or None, ``pngs``: the
        PNG bytes of every frame.
    """
    from gridshell.geometry.quadmesh import mesh_edges
    from gridshell.render import ncp_maps
    from gridshell.render.ribbons import view_angles

    frames = [np.asarray(V, float).reshape(-1, 3) for V in frames]
    if not frames:
        raise InputError("render_sequence: no frames given")
    F = np.asarray(F, np.int64).reshape(-1, 4)
    E = mesh_edges(F, len(frames[0]))
    elev, azim = view if view is not None else view_angles(frames[0])
    if progress is not None:
        progress(f"rendering {len(frames)} alignment frames")
    pngs = ncp_maps.sequence_frames(frames, E, title=title, dpi=dpi, elev=elev, azim=azim)
    written: list[Path] = []
    if frames_dir is not None:
        d = Path(frames_dir)
        width = max(3, len(str(len(pngs) - 1)))
        for k, b in enumerate(pngs):
            p = d / f"frame_{k:0{width}d}.png"
            write_bytes(p, b)
            written.append(p)
    gif = None
    if gif_path is not None:
        hold = max(1, int(round(hold_ms / max(duration_ms, 1))))
        seq = [pngs[0]] * hold + list(pngs) + [pngs[-1]] * hold
        write_bytes(gif_path, ncp_maps.gif(seq, duration_ms=duration_ms))
        gif = Path(gif_path)
    return {"frames": written, "gif": gif, "pngs": pngs}


def render_bundle_sequence(bundle_dir: str | os.PathLike, *, gif_name: str = "alignment.gif",
                           frames: bool = True, dpi: int = 80,
                           progress: Callable[[str], None] | None = None) -> dict[str, object]:
    """Render ``bundle_dir/sequence/frame_*.obj`` to ``sequence/frame_*.png`` (with
    ``frames``) and ``bundle_dir/<gif_name>``; see :func:`render_sequence`."""
    import json

    bundle_dir = Path(bundle_dir)
    V, F = read_sequence(bundle_dir)
    kind = ""
    try:
        kind = json.loads((bundle_dir / "design.json").read_text(encoding="utf-8"))["kind"]
    except (OSError, ValueError, KeyError):
        pass
    return render_sequence(V, F, frames_dir=bundle_dir / "sequence" if frames else None,
                           gif_path=bundle_dir / gif_name, dpi=dpi,
                           title=f"{kind} alignment".strip(), progress=progress)
