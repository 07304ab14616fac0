"""rhino3dm has one door: :mod:`gridshell.geometry.rhino_adapter` is the only module of the
package that imports it (every import counts: top level, inside functions, ``importlib`` and
``__import__`` by name), so that one Rhino object gives one set of arrays whichever door - the
.3dm reader, the Grasshopper server, the export - it comes in by."""
import ast
import pathlib

ROOT = pathlib.Path(__file__).resolve().parents[2]
ADAPTER = "gridshell/geometry/rhino_adapter.py"


def rhino3dm_imports(source: str) -> list[int]:
    """The line numbers at which ``source`` imports rhino3dm (or one of its submodules)."""
    lines = []
    for node in ast.walk(ast.parse(source)):
        names: list[str] = []
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom) and not node.level:
            names = [node.module or ""]
        elif isinstance(node, ast.Call) and node.args and isinstance(node.args[0], ast.Constant):
            f = node.func
            fname = f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", "")
            if fname in ("import_module", "__import__") and isinstance(node.args[0].value, str):
                names = [node.args[0].value]
        if any(n.split(".")[0] == "rhino3dm" for n in names):
            lines.append(node.lineno)
    return lines


def test_the_detector_finds_every_kind_of_import():
    src = ("import os\nimport rhino3dm\ndef f():\n    from rhino3dm import Mesh\n"
           "    import rhino3dm as r\n    importlib.import_module('rhino3dm')\n"
           "    __import__('rhino3dm')\n    import rhino3dmx\n    'rhino3dm'\n")
    assert rhino3dm_imports(src) == [2, 4, 5, 6, 7]
    assert rhino3dm_imports("from gridshell.geometry import rhino_adapter as rh\n") == []


def test_only_the_adapter_imports_rhino3dm():
    files = [f for top in ("gridshell", "fabrication") for f in sorted((ROOT / top).rglob("*.py"))]
    assert (ROOT / ADAPTER) in files
    found = {}
    for f in files:
        rel = f.relative_to(ROOT).as_posix()
        hits = rhino3dm_imports(f.read_text())
        if hits:
            found[rel] = hits
    assert ADAPTER in found, "the adapter itself no longer imports rhino3dm"
    others = {k: v for k, v in found.items() if k != ADAPTER}
    assert not others, ("rhino3dm imported outside gridshell.geometry.rhino_adapter (go through "
                        f"the adapter): {others}")
