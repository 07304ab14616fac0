"""Every command example of the README and the other documents runs as a user runs it: each
shell block's ``gridshell ...`` lines one after the other in a fresh directory that holds the
samples at ``samples/``, each its own process (``python -m gridshell``); the exit code is 0 (or
the one the line's comment names, ``# exit N``) and what the command says it writes is there:
the ``-o`` directory with its manifest, every file listed in it as recorded (size and SHA-256),
the ``.3dm`` or the pictures named. The Dask block's scheduler and worker are started as shown
(on this machine's loopback and a free port instead of ``10.0.0.5:8786``), so the sweep on a
cluster runs too. (``tests/architecture/test_readme.py`` checks the lines against the parser.)"""
from __future__ import annotations

import os
import re
import shlex
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from gridshell.core import manifest
from tests.architecture.test_readme import DOCUMENTS, ROOT, SYNOPSIS, code_blocks

pytestmark = pytest.mark.slow
EXIT = re.compile(r"#\s*exit\s+(\d)\b")
CLUSTER = "10.0.0.5:8786"     # the address the README's Dask example uses


def _lines(code: str) -> list[tuple[list[str], int]]:
    """``(argv, expected exit)`` of every ``gridshell`` / ``dask`` line of a block."""
    out = []
    for raw in code.splitlines():
        line, _, comment = raw.partition(" #")
        line = line.strip()
        if line.split(" ", 1)[0] in ("gridshell", "dask") and not SYNOPSIS.search(line):
            m = EXIT.search("#" + comment)
            out.append((shlex.split(line), int(m.group(1)) if m else 0))
    return out


def _blocks() -> list:
    out = []
    for doc in DOCUMENTS:
        for kind, code, line in code_blocks(doc):
            lines = _lines(code)
            if kind != "python" and any(a[0] == "gridshell" for a, _ in lines):
                out.append(pytest.param(lines, id=f"{doc.relative_to(ROOT)}:{line}"))
    return out


def _option(argv: list[str], *names: str) -> str | None:
    for k, a in enumerate(argv[:-1]):
        if a in names:
            return argv[k + 1]
    return None


def _promised(argv: list[str]) -> list[tuple[str, bool]]:
    """``(path, is_output_directory)`` the command line says it writes."""
    command, rest = argv[1], argv[2:]
    out = _option(rest, "-o", "--output", "--out")
    if command == "verify":
        return []
    if command == "export":
        return [(out, False)]
    if command == "render":
        paths = [(str(Path(rest[0]) / "render.png"), False)]
        if "--report" in rest:
            paths.append((str(Path(rest[0]) / "report.html"), False))
        if _option(rest, "--3dm"):
            paths.append((_option(rest, "--3dm"), False))
        return paths
    if command == "fabricate":
        return [(out or str(Path(rest[0]) / "fabrication"), True)]
    return [(out, True)] if out else []


def _check_written(cwd: Path, argv: list[str]) -> None:
    for rel, is_dir in _promised(argv):
        path = cwd / rel
        assert path.exists(), f"{shlex.join(argv)}: {rel} was not written"
        if not is_dir:
            assert path.is_file() and path.stat().st_size > 0, rel
            continue
        m = manifest.read(path)
        assert m is not None and m["command"] == argv[1], f"{rel}: no manifest of {argv[1]}"
        assert m["files"], f"{rel}: the manifest lists no file"
        changed = [f for f in m["files"] if not manifest.unchanged(path, f)]
        assert not changed, f"{rel}: files not as the manifest records them: {changed[:3]}"


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _env() -> dict[str, str]:
    return {**os.environ, "PYTHONPATH": str(ROOT), "OPENBLAS_NUM_THREADS": "1",
            "MPLBACKEND": "Agg"}


def _dask(argv: list[str], address: str, cwd: Path, started: list) -> None:
    """Start the README's ``dask scheduler`` / ``dask worker`` line on ``address`` and wait
    until the scheduler answers."""
    host, port = address.rsplit(":", 1)
    argv = [a.replace(CLUSTER, address) for a in argv]
    if argv[1] == "scheduler":
        argv = [*argv[:2], "--host", host, "--port", port, "--no-dashboard"]
    exe = Path(sys.executable).with_name("dask")
    started.append(subprocess.Popen([str(exe), *argv[1:]], cwd=cwd, env=_env(),
                                    stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
    if argv[1] == "scheduler":
        deadline = time.monotonic() + 60
        while socket.socket().connect_ex((host, int(port))) and time.monotonic() < deadline:
            time.sleep(0.2)


def _cluster_lines() -> list[list[str]]:
    """The README's ``dask scheduler`` / ``dask worker`` lines (the cluster of the sweep on
    several machines)."""
    return [argv for p in [q for doc in DOCUMENTS for q in code_blocks(doc)]
            for argv, _ in _lines(p[1]) if argv[0] == "dask"]


@pytest.mark.parametrize("lines", _blocks())
def test_documented_commands_run(lines, tmp_path):
    (tmp_path / "samples").symlink_to(ROOT / "samples", target_is_directory=True)
    started: list[subprocess.Popen] = []
    address = f"127.0.0.1:{_free_port()}"
    try:
        for argv, code in lines:
            if argv[0] == "dask":
                continue
            if any(CLUSTER in a for a in argv) and not started:
                for dask_argv in _cluster_lines():
                    _dask(dask_argv, address, tmp_path, started)
            argv = [a.replace(CLUSTER, address) for a in argv]
            run = subprocess.run([sys.executable, "-m", "gridshell", *argv[1:]], cwd=tmp_path,
                                 env=_env(), capture_output=True, text=True, timeout=600)
            assert run.returncode == code, (f"{shlex.join(argv)} exited {run.returncode}, the "
                                            f"document says {code}:\n{run.stderr[-2000:]}")
            _check_written(tmp_path, argv)
    finally:
        for p in started:
            p.terminate()
            p.wait(timeout=30)


def test_every_document_with_commands_is_run():
    """The blocks run above are those of every document with gridshell lines (none is left
    out), and the promise check can fail: a line whose output is missing is caught."""
    ids = {p.id.split(":")[0] for p in _blocks()}
    assert ids == {str(d.relative_to(ROOT)) for d in DOCUMENTS
                   if any(a[0] == "gridshell" for k, c, _ in code_blocks(d) if k != "python"
                          for a, _ in _lines(c))}, ids
    assert _promised(["gridshell", "fabricate", "out/dome"]) == [("out/dome/fabrication", True)]
    with pytest.raises(AssertionError, match="was not written"):
        _check_written(ROOT, ["gridshell", "gg", "x.obj", "-o", "no/such/dir"])
