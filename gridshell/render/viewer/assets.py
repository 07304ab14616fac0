"""The viewer's scripts: the bundled three.js (r170) and OrbitControls as one classic script.

``vendor/three.module.min.js`` and ``vendor/OrbitControls.js`` are the unmodified files of the
npm package ``three@0.170.0`` (``vendor/README.md``). They are ES modules; an inline
``<script type="module">`` cannot import another inline module, so each module's body is
wrapped in a function whose ``export {a as B, ...}`` becomes ``return {B: a, ...}`` and whose
``import {...} from 'three'`` becomes ``const {...} = THREE``. The result runs as a classic
inline script from ``file://`` with no network: the page stays one self-contained file.

One literal changes: three.js creates its canvas with ``document.createElementNS`` and the
XHTML namespace written out as a URL; the page passes ``document.documentElement.namespaceURI``
instead (the same string in an HTML page), so the report holds no ``http(s)://`` text at all.
"""
from __future__ import annotations

import re
from functools import lru_cache
from importlib import resources

from gridshell.core.errors import GridshellError

__all__ = ["THREE_VERSION", "asset_text", "three_script", "viewer_script", "viewer_css"]

THREE_VERSION = "0.170.0"

_EXPORT = re.compile(r"export\s*\{([^}]*)\}\s*;?\s*$")
_XHTML = '"http://www.w3.org/1999/xhtml"'
_IMPORT = re.compile(r"import\s*\{([^}]*)\}\s*from\s*['\"]three['\"]\s*;")


def asset_text(name: str) -> str:
    """Text of a file of this package (``"viewer.js"``, ``"vendor/OrbitControls.js"``)."""
    try:
        return resources.files(__package__).joinpath(name).read_text(encoding="utf-8")
    except (OSError, FileNotFoundError) as exc:
        raise GridshellError(f"the viewer's file {name} is missing from the installed package "
                             f"({exc}); reinstall gridshell") from None


def _safe(text: str, name: str) -> str:
    """``text`` unless it would end an inline ``<script>`` early."""
    if re.search(r"</script|<!--", text, flags=re.I):
        raise GridshellError(f"{name} contains '</script' or '<!--' and cannot be inlined; "
                             "this is a bug, please report it")
    return text


def _pairs(spec: str) -> list[tuple[str, str]]:
    """``"a as B, c"`` -> ``[("a", "B"), ("c", "c")]`` (local, exported)."""
    out = []
    for item in spec.split(","):
        item = item.strip()
        if not item:
            continue
        local, _, public = item.partition(" as ")
        out.append((local.strip(), (public or local).strip()))
    return out


def module_to_function(src: str, name: str) -> tuple[str, list[tuple[str, str]]]:
    """The body of an ES module ``src`` without its final ``export {...}`` statement, and the
    exported ``(local, public)`` names. The module must have exactly that one export."""
    m = _EXPORT.search(src)
    if m is None or src.count("export{") + src.count("export {") != 1:
        raise GridshellError(f"{name}: expected one final 'export {{...}}' statement; the "
                             "bundled three.js is not the release this code was written for")
    return src[:m.start()], _pairs(m.group(1))


@lru_cache(maxsize=1)
def three_script() -> str:
    """A classic script defining ``THREE`` (three.js r170 with ``THREE.OrbitControls``)."""
    body, names = module_to_function(asset_text("vendor/three.module.min.js"),
                                     "three.module.min.js")
    if body.count(_XHTML) != 1:
        raise GridshellError("three.module.min.js: the XHTML namespace literal is not where "
                             "this code expects it; the bundled file is not r170")
    body = body.replace(_XHTML, "document.documentElement.namespaceURI")
    obj = ",".join(f"{pub}:{loc}" for loc, pub in names)
    three = f"var THREE=(function(){{\"use strict\";\n{body}\nreturn {{{obj}}};}})();\n"
    src = asset_text("vendor/OrbitControls.js")
    imp = _IMPORT.search(src)
    if imp is None:
        raise GridshellError("OrbitControls.js: no import from 'three'; the bundled file is "
                             "not the release this code was written for")
    names_in = ",".join(f"{pub}:{loc}" if loc != pub else loc
                        for pub, loc in _pairs(imp.group(1)))
    src = src[:imp.start()] + f"const {{{names_in}}}=THREE;" + src[imp.end():]
    obody, onames = module_to_function(src, "OrbitControls.js")
    oobj = ",".join(f"{pub}:{loc}" for loc, pub in onames)
    orbit = (f"THREE=Object.assign({{}},THREE,(function(THREE){{\"use strict\";\n{obody}\n"
             f"return {{{oobj}}};}})(THREE));\n")
    return _safe(three + orbit, "three.js")


def viewer_script() -> str:
    """The viewer's own script (``viewer.js``): reads the scene JSON, builds the page's view."""
    return _safe(asset_text("viewer.js"), "viewer.js")


def viewer_css() -> str:
    """The viewer's style sheet (``viewer.css``)."""
    return _safe(asset_text("viewer.css"), "viewer.css")
