"""Wall time and peak memory of one call, for the benchmark scripts.

Time is wall-clock seconds (``time.perf_counter``). Memory is the process's peak resident set
size while the call ran, in MB (2^20 bytes), above the resident size just before it: on Linux
the high-water mark ``VmHWM`` is reset through ``/proc/self/clear_refs`` before the call, so
earlier peaks (imports, building the inputs) do not count. It includes memory that Python does
not see (SuperLU, libigl, BLAS). Where the reset is not available the figure falls back to
``ru_maxrss`` minus the resident size before the call, an upper bound. ``traced=True`` measures
Python-side allocations with ``tracemalloc`` instead (numpy arrays included, C libraries'
buffers not), which slows allocation-heavy code: time and memory then come from separate runs.
"""
from __future__ import annotations

import resource
import time
import tracemalloc
from pathlib import Path
from typing import Any, Callable, NamedTuple

MB = float(2 ** 20)


class Measured(NamedTuple):
    """Outcome of :func:`measure`: seconds, peak MB above the start, absolute peak MB, the
    value, and the CPU seconds of the process (all threads) and of the processes it started
    and waited for within the call (the .3dm export's cut-sheet process): under load,
    wall >> CPU; with work in a second process, CPU > wall."""

    seconds: float
    peak_mb: float
    rss_peak_mb: float
    value: Any
    cpu_seconds: float = float("nan")


def _status_kb(key: str) -> float | None:
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith(key + ":"):
                return float(line.split()[1])
    except OSError:
        return None
    return None


def _reset_peak() -> bool:
    try:
        Path("/proc/self/clear_refs").write_text("5")
        return True
    except OSError:
        return False


def rss_mb() -> float:
    """Current resident set size, MB (0 where /proc is missing)."""
    kb = _status_kb("VmRSS")
    return kb / 1024 if kb is not None else 0.0


def _cpu() -> float:
    """CPU seconds of this process and of its children reaped so far."""
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return time.process_time() + kids.ru_utime + kids.ru_stime


def measure(fn: Callable[[], Any]) -> Measured:
    """Run ``fn()`` once; its wall time and peak resident memory above the start (MB). The
    garbage left by building the inputs is collected first, so that its collection is not
    timed as part of ``fn`` (the set-up's cyclic garbage made a full collection of ~0.1-0.2 s
    fall inside some rows, by chance)."""
    import gc

    gc.collect()
    reset = _reset_peak()
    base = rss_mb()
    t0, c0 = time.perf_counter(), _cpu()
    value = fn()
    seconds, cpu = time.perf_counter() - t0, _cpu() - c0
    hwm = _status_kb("VmHWM") if reset else None
    peak = hwm / 1024 if hwm is not None else resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    return Measured(seconds, max(peak - base, 0.0), peak, value, cpu)


def measure_traced(fn: Callable[[], Any]) -> Measured:
    """Run ``fn()`` under ``tracemalloc``; ``peak_mb`` is the peak of Python-side allocations
    (slower: the time is not representative)."""
    tracemalloc.start()
    t0 = time.perf_counter()
    try:
        value = fn()
        seconds = time.perf_counter() - t0
        peak = tracemalloc.get_traced_memory()[1] / MB
    finally:
        tracemalloc.stop()
    return Measured(seconds, peak, peak, value)


def run_worker(script: str | Path, args: list[str], timeout: float) -> dict | None:
    """Run ``python script --worker args...`` in a fresh process (clean memory figures); the
    dict it prints as its last stdout line (JSON), or ``None`` on timeout. A worker that fails
    returns ``{"error": last line of stderr}``."""
    import json
    import subprocess
    import sys

    try:
        p = subprocess.run([sys.executable, str(script), "--worker", *args], capture_output=True,
                           text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return None
    lines = [ln for ln in p.stdout.splitlines() if ln.startswith("{")]
    if p.returncode != 0 or not lines:
        err = (p.stderr.strip().splitlines() or ["exit code %d" % p.returncode])[-1]
        return {"error": err}
    return json.loads(lines[-1])


def compile_tree(root: Path) -> None:
    """Compile the bytecode of ``root``'s packages (``gridshell``, ``fabrication``), as ``pip
    install`` does: with ``PYTHONDONTWRITEBYTECODE`` set and no ``__pycache__``, a module
    imported lazily inside a timed call would be compiled from source inside it (~0.05-0.2 s
    a row), a cost an installed package does not have."""
    import compileall

    for pkg in ("gridshell", "fabrication"):
        if (Path(root) / pkg).is_dir():
            compileall.compile_dir(str(Path(root) / pkg), quiet=1)


def gridshell_env() -> dict[str, str]:
    """The environment of a ``python -m gridshell`` child process of a benchmark: this
    checkout first on ``PYTHONPATH``, matplotlib without a display."""
    import os

    root = str(Path(__file__).resolve().parent.parent)
    env = dict(os.environ, MPLBACKEND="Agg")
    env["PYTHONPATH"] = os.pathsep.join([root] + [p for p in
                                                  env.get("PYTHONPATH", "").split(os.pathsep)
                                                  if p])
    return env
