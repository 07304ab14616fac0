"""The tests are laid out like the package: one folder per floor or pipeline, the shared cases
in ``tests/helpers`` imported as a package (``from tests.helpers.gg_cases import ...``), never
through ``sys.path``; the markers in use are the ones pyproject.toml registers."""
from __future__ import annotations

import re
import tomllib
from pathlib import Path

TESTS = Path(__file__).resolve().parents[1]
ROOT = TESTS.parent
SYS_PATH = re.compile(r"sys\.path\.(insert|append)")


def test_no_test_module_at_the_top_and_every_folder_a_package():
    assert not sorted(p.name for p in TESTS.glob("test_*.py"))
    folders = [p for p in TESTS.rglob("*") if p.is_dir() and "__pycache__" not in p.parts
               and p.name != "data" and "data" not in p.relative_to(TESTS).parts]
    assert folders
    missing = [str(p.relative_to(ROOT)) for p in folders if not (p / "__init__.py").exists()]
    assert not missing, f"test folders without __init__.py: {missing}"


def test_helpers_are_imported_as_a_package_not_through_sys_path():
    offenders = []
    for p in TESTS.rglob("*.py"):
        text = p.read_text()
        for m in SYS_PATH.finditer(text):
            line = text[text.rfind("\n", 0, m.start()) + 1:text.find("\n", m.start())]
            if "benchmarks" not in line:        # the benchmark scripts are not a package
                offenders.append(f"{p.relative_to(ROOT)}: {line.strip()}")
    assert not offenders, offenders


def test_the_markers_used_are_registered():
    ini = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["pytest"]["ini_options"]
    registered = {m.split(":", 1)[0].strip() for m in ini["markers"]}
    assert {"slow", "browser"} <= registered and "--strict-markers" in ini["addopts"]
    used = set()
    for p in TESTS.rglob("test_*.py"):
        used |= set(re.findall(r"@pytest\.mark\.(\w+)", p.read_text()))
    builtin = {"parametrize", "skipif", "skip", "xfail", "usefixtures", "filterwarnings"}
    assert used - builtin <= registered, used - builtin - registered
