"""The timings the README quotes, measured on this machine (``make bench`` runs it after
``run_all.py``): each command its own process, as a user runs it, wall clock around it.

Writes ``benchmarks/readme_timings.json`` (the machine, the date and every figure);
``--update-readme`` copies the figures into README.md, where each quoted timing carries the
marker ``<!--bench:KEY-->`` right before its number (``tests/architecture/test_readme_timings.py``
checks every marked figure is within 25 % of this file's and that no timing is unmarked).

    .venv/bin/python benchmarks/readme.py [--only KEY ...] [--update-readme]   # ~6 min, 2 cores

``make_test`` is the duration of the last whole-suite run of this checkout
(``out/make-test.json``, written by ``tests/conftest.py`` when ``make test`` finishes); the
script runs no test suite itself.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import re
import subprocess
import sys
import tempfile
import time
from datetime import date
from pathlib import Path
from typing import Callable

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(ROOT))

from _measure import gridshell_env  # noqa: E402

RECORD = HERE / "readme_timings.json"
README = ROOT / "README.md"
TEST_RUN = ROOT / "out" / "make-test.json"
MARK = re.compile(r"<!--bench:([a-z0-9_]+)-->(~?)(\d+(?:\.\d+)?)( ?)(s|min)\b")
DOME = ROOT / "samples" / "dome.obj"


def gridshell(*args: str, cwd: Path) -> float:
    """Wall seconds of one ``python -m gridshell ARGS`` (RuntimeError unless it exits 0)."""
    t0 = time.perf_counter()
    p = subprocess.run([sys.executable, "-m", "gridshell", *args], cwd=cwd, env=gridshell_env(),
                       capture_output=True, text=True)
    sec = time.perf_counter() - t0
    if p.returncode:
        raise RuntimeError(f"gridshell {' '.join(args)} exited {p.returncode}: "
                           f"{p.stderr.strip()[-300:]}")
    return sec


def _demo(tmp: Path) -> dict[str, float]:
    return {"demo": gridshell("demo", "-o", str(tmp / "demo"), "-q", cwd=tmp),
            "demo_quick": gridshell("demo", "--quick", "-o", str(tmp / "quick"), "-q", cwd=tmp)}


def _build_dome(tmp: Path) -> dict[str, float]:
    out = str(tmp / "pack")
    return {"build_dome": gridshell("build", str(DOME), "-o", out, "-q", cwd=tmp),
            "build_dome_material": gridshell("build", str(DOME), "-o", out, "--material", "petg",
                                             "-q", cwd=tmp)}


def _build_models(tmp: Path) -> dict[str, float]:
    """The build benchmark's models (benchmarks/build.py): the slowest first run and material
    change of the user's models and the 200k-triangle PLY's."""
    import build as bench

    small, small_mat, big, big_mat = [], [], 0.0, 0.0
    for name, (make, extra) in bench.MODELS.items():
        folder = tmp / name
        folder.mkdir()
        model = make(folder)
        first = bench._build(model, folder / "pack", extra)
        again = bench._build(model, folder / "pack", [*extra, "--material", "petg"])
        if first["code"] or again["code"]:
            raise RuntimeError(f"build {name}: exit {first['code']} / {again['code']}")
        if "200k" in name:
            big, big_mat = first["seconds"], again["seconds"]
        else:
            small.append(first["seconds"])
            small_mat.append(again["seconds"])
    return {"build_models_min": min(small), "build_models_max": max(small),
            "build_200k": big, "material_models_min": min(small_mat),
            "material_models_max": max(small_mat), "material_200k": big_mat}


def _analyze(tmp: Path) -> dict[str, float]:
    """``gridshell analyze`` on the 12 x 8 m hill at ~200k triangles in mm (analyze.py)."""
    import analyze as bench
    from gridshell.geometry.meshfile import write_mesh
    from tests.helpers.io_cases import hill

    V, T = hill(355, 284, scale=1000.0)
    target = tmp / "hill_200k.obj"
    write_mesh(target, V, T)
    r = bench.run(target, tmp / "hill-analysis")
    if r["exit"]:
        raise RuntimeError(f"analyze exited {r['exit']}")
    return {"analyze_200k": r["wall"]}


def _make_test(tmp: Path) -> dict[str, float]:
    """The last whole-suite run's duration (out/make-test.json), if there is one."""
    if not TEST_RUN.is_file():
        print(f"  no {TEST_RUN.relative_to(ROOT)}: run `make test` first for make_test",
              flush=True)
        return {}
    rec = json.loads(TEST_RUN.read_text())
    return {"make_test": float(rec["seconds"])}


PARTS: dict[str, Callable[[Path], dict[str, float]]] = {
    "demo": _demo, "build_dome": _build_dome, "build_models": _build_models,
    "analyze": _analyze, "make_test": _make_test}


def machine() -> dict[str, object]:
    """What the figures were measured on."""
    cpu = ""
    try:
        cpu = next(ln.split(":", 1)[1].strip() for ln in open("/proc/cpuinfo")
                   if ln.startswith("model name"))
    except (OSError, StopIteration):
        cpu = platform.processor()
    return {"cores": os.cpu_count(), "cpu": cpu, "python": platform.python_version(),
            "system": platform.system()}


def _text(key: str, seconds: float, tilde: str, space: str, unit: str) -> str:
    """The figure as the README writes it, in the unit it had."""
    if unit == "min":
        return f"{tilde}{seconds / 60:.0f}{space}min"
    return f"{tilde}{seconds:.1f}{space}s" if seconds < 10 else f"{tilde}{seconds:.0f}{space}s"


def update_readme(figures: dict[str, float]) -> list[str]:
    """Copy ``figures`` into README.md's marked timings; returns the keys changed."""
    text = README.read_text(encoding="utf-8")
    changed = []

    def put(m: re.Match) -> str:
        key, tilde, _, space, unit = m.groups()
        if key not in figures:
            return m.group(0)
        new = f"<!--bench:{key}-->{_text(key, figures[key], tilde, space, unit)}"
        if new != m.group(0):
            changed.append(key)
        return new

    README.write_text(MARK.sub(put, text), encoding="utf-8")
    return changed


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", nargs="+", choices=tuple(PARTS), help="measure these only")
    ap.add_argument("--update-readme", action="store_true",
                    help="copy the figures into README.md's marked timings")
    args = ap.parse_args(argv)
    old = json.loads(RECORD.read_text()) if RECORD.is_file() else {}
    figures = dict(old.get("figures", {}))
    print(f"README timings; {os.cpu_count()} cores", flush=True)
    with tempfile.TemporaryDirectory(prefix="gridshell-readme-bench-") as tmp:
        for name in args.only or PARTS:
            folder = Path(tmp) / name
            folder.mkdir()
            got = PARTS[name](folder)
            for key, sec in got.items():
                print(f"  {key:22s} {sec:8.1f} s", flush=True)
            figures.update({k: round(v, 2) for k, v in got.items()})
    RECORD.write_text(json.dumps({"date": date.today().isoformat(), "machine": machine(),
                                  "figures": figures}, indent=1) + "\n")
    print(f"wrote {RECORD.relative_to(ROOT)}")
    if args.update_readme:
        changed = update_readme(figures)
        print(f"README.md: {len(changed)} figures updated {changed}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
