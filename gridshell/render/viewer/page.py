"""The viewer's part of ``report.html``: a section with the scene data and the scripts inline.

:func:`viewer_section` returns one ``<section id="viewer">`` holding the view's container,
the scene (:func:`gridshell.render.viewer.scene.scene_json`) and three.js r170 with
OrbitControls, each gzip-compressed and base64-encoded in a ``<script type="application/gzip">``
element (:func:`packed`: the demo's scene and library shrink from 2.5 MB to 0.7 MB), and
``viewer.js`` inline, which unpacks them in the browser (``DecompressionStream``) and runs them:
the report stays one file that works offline.
"""
from __future__ import annotations

import base64
import gzip
import os
from functools import lru_cache

from gridshell.render.viewer.assets import THREE_VERSION, three_script, viewer_css, viewer_script
from gridshell.render.viewer.scene import scene_json

__all__ = ["packed", "unpacked", "viewer_section", "viewer_css"]


def packed(text: str) -> str:
    """``text`` gzip-compressed and base64-encoded (safe inside an HTML element)."""
    return base64.b64encode(gzip.compress(text.encode("utf-8"), 9, mtime=0)).decode("ascii")


def unpacked(b64: str) -> str:
    """The inverse of :func:`packed`."""
    return gzip.decompress(base64.b64decode(b64)).decode("utf-8")


def viewer_section(bundle_dir: str | os.PathLike) -> str:
    """The HTML of the viewer's section of the report of ``bundle_dir``."""
    return (
        '<section id="viewer"><h2>3D view</h2>'
        '<div id="gridshell-viewer"><div class="gv-view"></div><div class="gv-panel"></div>'
        "<noscript><p>The 3D view needs JavaScript; the pictures below show the design."
        "</p></noscript></div>"
        f'<script type="application/gzip" id="gridshell-scene">{packed(scene_json(bundle_dir, faces=False))}'
        "</script>"
        f'<script type="application/gzip" id="gridshell-three" data-library="three.js '
        f'r{THREE_VERSION.split(".")[1]} (MIT, bundled)">{_three_packed()}</script>'
        f"<script>\n{viewer_script()}</script></section>"
    )



@lru_cache(maxsize=1)
def _three_packed() -> str:
    """:func:`packed` three.js, computed once per process."""
    return packed(three_script())
