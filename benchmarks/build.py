"""``gridshell build`` on a user's models, no option given, then again with only
``--material`` changed (issue 30): wall time, exit code and what was chosen, per model.

The models are those of the issue, made here from the tests' own definitions
(``tests/helpers/io_cases.py``): the 12 x 8 m hill as a NURBS surface in a millimetre .3dm,
as a mesh in a millimetre .3dm, as an unwelded millimetre OBJ (``--units mm``: an OBJ does not
say its unit), as a rotated quad grid, as a 200k-triangle PLY soup, and a hypar. Each
``gridshell build`` is its own process (``python -m gridshell``), timed by the wall clock
around it; the second run of each (``--material petg``) reuses the design.

    .venv/bin/python benchmarks/build.py                  # ~4 min on 2 cores
    .venv/bin/python benchmarks/build.py --only hill-3dm-nurbs hypar --json out/build.json
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any, Callable

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from _measure import gridshell_env as _env  # noqa: E402

from tests.helpers.io_cases import (hill, hill_ctrl, rhino_mesh, rhino_nurbs,  # noqa: E402
                                    soup, write_3dm, write_obj_text, write_ply_soup)


def _quads(n: int, m: int) -> np.ndarray:
    idx = np.arange(n * m).reshape(n, m)
    return np.stack([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]], -1).reshape(-1, 4)


def _rotated_hill_quads(folder: Path) -> Path:
    n, m = 25, 17
    V, _ = hill(n, m)
    a = np.radians(35.0)
    R = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    return write_obj_text(folder / "hill_quads_rotated.obj", V @ R.T + [3.0, -2.0, 0.5],
                          _quads(n, m))


def _hypar(folder: Path, side: float = 6.0, n: int = 21) -> Path:
    t = np.linspace(-side / 2, side / 2, n)
    X, Y = np.meshgrid(t, t, indexing="ij")
    V = np.stack([X.ravel(), Y.ravel(), (X * Y / side).ravel()], 1)
    return write_obj_text(folder / "hypar.obj", V, _quads(n, n))


#: name -> (maker of the file in a folder, extra arguments the file needs)
MODELS: dict[str, tuple[Callable[[Path], Path], list[str]]] = {
    "hill-3dm-nurbs": (lambda d: write_3dm(d / "hill_nurbs.3dm", [
        (rhino_nurbs(hill_ctrl(scale=1000.0)), "hill", "model")], units="mm"), []),
    "hill-3dm-mesh": (lambda d: write_3dm(d / "hill_mesh.3dm", [
        (rhino_mesh(*hill(25, 17, scale=1000.0)), "hill", "model")], units="mm"), []),
    "hill-obj-unwelded-mm": (lambda d: write_obj_text(
        d / "hill_mm.obj", *soup(*hill(25, 17, scale=1000.0)), fmt="%.6f"), ["--units", "mm"]),
    "hill-quads-rotated": (_rotated_hill_quads, []),
    "hill-200k-ply": (lambda d: write_ply_soup(d / "hill_200k.ply", *hill(355, 284)), []),
    "hypar": (_hypar, []),
}


def _build(model: Path, out: Path, extra: list[str]) -> dict[str, Any]:
    env = _env()
    t0 = time.perf_counter()
    p = subprocess.run([sys.executable, "-m", "gridshell", "build", str(model), "-o", str(out),
                        "--json", *extra], env=env, capture_output=True, text=True)
    sec = time.perf_counter() - t0
    try:
        doc = json.loads(p.stdout)
    except ValueError:
        doc = {}
    return {"code": p.returncode, "seconds": sec, "summary": doc,
            "error": p.stderr.strip().splitlines()[-1] if p.returncode and p.stderr.strip()
            else ""}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", nargs="+", choices=tuple(MODELS), help="these models only")
    ap.add_argument("--json", metavar="OUT", help="also write the figures to OUT")
    args = ap.parse_args(argv)
    rows = []
    print(f"gridshell build, no option; then --material petg; {os.cpu_count()} cores",
          flush=True)
    print(f"{'model':22s} {'exit':>4s} {'first s':>8s} {'petg s':>7s}  chosen", flush=True)
    with tempfile.TemporaryDirectory(prefix="gridshell-build-bench-") as tmp:
        tmp = Path(tmp)
        for name in args.only or MODELS:
            make, extra = MODELS[name]
            folder = tmp / name
            folder.mkdir()
            model = make(folder)
            first = _build(model, folder / "pack", extra)
            again = _build(model, folder / "pack", [*extra, "--material", "petg"])
            s = first["summary"]
            chosen = (f"{s.get('kind', '')}; {s.get('section', '')}; {s.get('sheets', '')}"
                      if first["code"] == 0 else first["error"][:120])
            print(f"{name:22s} {first['code']:4d} {first['seconds']:8.1f} "
                  f"{again['seconds']:7.1f}  {chosen}", flush=True)
            rows.append({"model": name, "code": first["code"], "seconds": first["seconds"],
                         "material_code": again["code"], "material_seconds": again["seconds"],
                         "chosen": chosen})
    ok = [r for r in rows if r["code"] == 0]
    print(f"exit 0: {len(ok)} of {len(rows)}; slowest first run "
          f"{max((r['seconds'] for r in rows), default=0):.1f} s (goal < 60 s); slowest "
          f"material re-run {max((r['material_seconds'] for r in rows), default=0):.1f} s "
          "(goal < 10 s)")
    if args.json:
        Path(args.json).parent.mkdir(parents=True, exist_ok=True)
        Path(args.json).write_text(json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
