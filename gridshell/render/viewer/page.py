"""The viewer's part of ``report.html``: a section with the scene data and the scripts inline.

:func:`viewer_section` returns one ``<section id="viewer">`` holding the view's container,
the scene (:func:`gridshell.render.viewer.scene.scene_json`) in a
``<script type="application/json">`` element, and the scripts (three.js r170 with
OrbitControls, then ``viewer.js``) inline: the report stays one file that works offline.
"""
from __future__ import annotations

import os

from gridshell.render.viewer.assets import THREE_VERSION, three_script, viewer_css, viewer_script
from gridshell.render.viewer.scene import scene_json

__all__ = ["viewer_section", "viewer_css"]


def viewer_section(bundle_dir: str | os.PathLike) -> str:
    """The HTML of the viewer's section of the report of ``bundle_dir``."""
    return (
        '<section id="viewer"><h2>3D view</h2>'
        '<div id="gridshell-viewer"><div class="gv-view"></div><div class="gv-panel"></div>'
        "<noscript><p>The 3D view needs JavaScript; the pictures below show the design."
        "</p></noscript></div>"
        f'<script type="application/json" id="gridshell-scene">{scene_json(bundle_dir)}'
        "</script>"
        f"<script>/* three.js r{THREE_VERSION.split('.')[1]} (MIT, bundled) */\n"
        f"{three_script()}</script>"
        f"<script>\n{viewer_script()}</script></section>"
    )
