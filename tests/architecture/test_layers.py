"""The package's import rule: no circle, no import from a lower floor to a higher one.

The floors are read from ARCHITECTURE.md (the fenced ``layers`` block: top floor first, peers on
one line), so the order is written once. Every import counts, those inside functions too.
"""
import ast
import pathlib
import re

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
PKG = ROOT / "gridshell"


def floors() -> list[list[str]]:
    """The ``layers`` block of ARCHITECTURE.md, bottom floor first."""
    text = (ROOT / "ARCHITECTURE.md").read_text()
    m = re.search(r"```layers\n(.*?)```", text, re.S)
    assert m, "ARCHITECTURE.md has no ```layers block"
    rows = [line.split("#")[0].split() for line in m.group(1).splitlines()]
    return [r for r in rows if r][::-1]


def modules() -> dict[str, pathlib.Path]:
    out = {}
    for f in PKG.rglob("*.py"):
        rel = f.relative_to(ROOT).with_suffix("")
        name = ".".join(rel.parts)
        out[name[: -len(".__init__")] if name.endswith(".__init__") else name] = f
    return out


def imports(mods: dict[str, pathlib.Path]) -> dict[str, set[str]]:
    """module -> the gridshell modules (or packages) it imports, resolved to known names."""
    out = {}
    for name, f in mods.items():
        base = name if f.name == "__init__.py" else name.rsplit(".", 1)[0]
        got = set()
        for node in ast.walk(ast.parse(f.read_text())):
            targets = []
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                mod = node.module or ""
                if node.level:
                    parts = base.split(".")[: len(base.split(".")) - node.level + 1]
                    mod = ".".join(parts + ([mod] if mod else []))
                targets = [f"{mod}.{a.name}" if f"{mod}.{a.name}" in mods else mod for a in node.names]
            got |= {t for t in targets if t.split(".")[0] == "gridshell" and t != name}
        out[name] = got
    return out


def folder(module: str) -> str:
    """The folder (first level below gridshell) a module belongs to; ``__main__`` is the CLI's."""
    key = module.split(".")[1]
    return "cli" if key == "__main__" else key


def floor_of(module: str, index: dict[str, int]) -> int | None:
    if "." not in module:
        return None  # the package's own door (gridshell/__init__)
    key = folder(module)
    assert key in index, f"{module}: folder {key!r} is on no floor of ARCHITECTURE.md"
    return index[key]


def test_every_folder_is_on_a_floor_and_the_top_level_is_small():
    index = {k: i for i, row in enumerate(floors()) for k in row}
    loose = sorted(p.name for p in PKG.glob("*.py") if p.name not in ("__init__.py", "__main__.py"))
    assert len(loose) <= 6, loose
    for p in PKG.iterdir():
        if p.is_dir() and (p / "__init__.py").exists():
            assert p.name in index, f"gridshell/{p.name}/ is on no floor of ARCHITECTURE.md"
            doc = ast.get_docstring(ast.parse((p / "__init__.py").read_text()))
            assert doc and "import" in doc.lower(), f"gridshell/{p.name}/__init__ must say what it may import"


def test_no_import_runs_up_or_sideways():
    index = {k: i for i, row in enumerate(floors()) for k in row}
    mods = modules()
    bad = []
    for name, targets in imports(mods).items():
        lo = floor_of(name, index)
        if lo is None:
            continue
        for t in targets:
            hi = floor_of(t, index)
            if hi is None:
                bad.append(f"{name} imports the package root")
            elif folder(t) != folder(name) and hi >= lo:
                bad.append(f"{name} -> {t}")
    assert not bad, "imports from a lower floor to a higher one (or between peers):\n" + "\n".join(sorted(bad))


def test_no_import_circle():
    mods = modules()
    # a package's door re-exporting its own modules is not a circle: those edges are left out
    graph = {m: {t for t in ts if not t.startswith(m + ".")} for m, ts in imports(mods).items()}
    # Tarjan's strongly connected components over modules
    index, low, stack, on, sccs, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
            if w not in graph:
                continue
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                sccs.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    assert not sccs, f"import circles: {sccs}"


@pytest.mark.parametrize("text", ["ghost -> core", "core -> cli"])
def test_the_rule_catches_a_violation(text, tmp_path):
    """The check itself: a made-up upward import is found by the same functions."""
    index = {k: i for i, row in enumerate(floors()) for k in row}
    src, dst = text.split(" -> ")
    if src == "ghost":
        with pytest.raises(AssertionError):
            floor_of("gridshell.ghost.x", index)
    else:
        assert floor_of(f"gridshell.{src}.x", index) < floor_of(f"gridshell.{dst}.y", index)
