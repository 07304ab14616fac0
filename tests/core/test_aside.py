"""gridshell.core.aside: a computation in a forked process gives what it gives in this one (value,
exception), never leaves a process behind, and runs in this process where a fork is not safe;
the .3dm export that plans its cut sheets aside writes the same objects as one process does."""
from __future__ import annotations

import os
import signal
import sys
import threading

import numpy as np
import pytest
from tests.helpers.io_cases import rhino_objects
from tests.helpers.render_cases import make_bundle, write_case

from gridshell.core.aside import Aside, can_fork
from gridshell.design.bundle import write_bundle
from gridshell.core.errors import GridshellError, InputError
from gridshell.export.rhino import export_3dm as write_3dm

@pytest.fixture
def forking():
    """Skip where :class:`Aside` would not fork (checked when the test runs: another test may
    have left a thread running)."""
    if not can_fork():
        pytest.skip(f"no fork here ({sys.platform}, threads: "
                    f"{[t.name for t in threading.enumerate()]})")


forks = pytest.mark.usefixtures("forking")


def _values(n: int, seed: int) -> tuple[np.ndarray, int]:
    return np.random.default_rng(seed).normal(size=(n, 3)), os.getpid()


def _fails(msg: str) -> None:
    raise InputError(msg)


class _TwoArgs(Exception):
    def __init__(self, a, b):       # pickles as (a b,), cannot be rebuilt from its args
        super().__init__(f"{a} {b}")
        self.lock = threading.Lock()    # and holds a lock, which no reducer pickles (tblib's,
                                        # installed by dask, rebuilds the two-argument class)


def _fails_oddly() -> None:
    raise _TwoArgs("odd", "error")


def _dies() -> None:
    os.kill(os.getpid(), signal.SIGKILL)


def _gone(pid: int) -> bool:
    try:
        os.waitpid(pid, os.WNOHANG)
    except ChildProcessError:
        return True
    return False


@forks
def test_value_comes_from_another_process_and_equals_this_ones():
    with Aside(_values, 1000, seed=3) as a:
        assert a._pid is not None
        value, pid = a.result()
    assert pid != os.getpid()
    np.testing.assert_array_equal(value, _values(1000, 3)[0])     # bit for bit


@forks
def test_exception_comes_back_with_class_message_and_traceback_note():
    with pytest.raises(InputError, match="^bad mesh, fix it") as e, \
            Aside(_fails, "bad mesh, fix it") as a:
        pid = a._pid
        a.result()
    assert str(e.value) == "bad mesh, fix it"
    assert any("in a worker process" in n and "_fails" in n for n in e.value.__notes__)
    assert _gone(pid)


@forks
def test_exception_that_does_not_pickle_is_named():
    with pytest.raises(GridshellError, match="_TwoArgs: odd error"), Aside(_fails_oddly) as a:
        a.result()


@forks
def test_child_killed_is_a_clear_error_not_a_hang():
    with pytest.raises(GridshellError, match=r"ended without a result \(signal 9\)"), \
            Aside(_dies) as a:
        a.result()


@forks
def test_leaving_the_block_stops_the_child_and_reaps_it():
    with pytest.raises(RuntimeError), Aside(_values, 10, 0) as a:
        pid = a._pid
        raise RuntimeError("the caller's own work failed")
    assert _gone(pid)
    with Aside(_values, 10, 0) as a:
        pid = a._pid
        a.result()
    assert _gone(pid)


def test_serial_where_asked_or_with_other_threads(monkeypatch):
    monkeypatch.setenv("GRIDSHELL_SERIAL", "1")
    assert not can_fork()
    with Aside(_values, 5, 1) as a:
        assert a._pid is None
        assert a.result()[1] == os.getpid()
    monkeypatch.delenv("GRIDSHELL_SERIAL")
    stop = threading.Event()
    t = threading.Thread(target=stop.wait)
    t.start()
    try:
        assert not can_fork()
        with pytest.raises(InputError, match="in this process"), \
                Aside(_fails, "in this process") as a:
            assert a._pid is None
            a.result()
    finally:
        stop.set()
        t.join()


@forks
@pytest.mark.parametrize("kind, options", [
    ("GG", {"force": True}),                       # a design that fails: sheets forced
    ("GG", {}),                                     # ... and left out
    ("AA", {"force": True, "scale": 0.005}),       # joints too close for holes: marks
    ("CNC", {"force": True, "sheet": "300x200"}),
])
def test_export_forked_equals_one_process(tmp_path, monkeypatch, kind, options):
    if kind == "CNC":                   # as tests/export/test_export_rhino.py makes one
        b = make_bundle("CNC")
        b.params["n"] = b.metrics["n"] = 0.5
        d = write_bundle(tmp_path / "cnc", b)
    else:
        d = write_case(tmp_path / kind.lower(), kind)
    forked = write_3dm(d, tmp_path / "forked.3dm", **options)
    monkeypatch.setenv("GRIDSHELL_SERIAL", "1")
    serial = write_3dm(d, tmp_path / "serial.3dm", **options)
    assert {k: v for k, v in forked.items() if k != "path"} == \
        {k: v for k, v in serial.items() if k != "path"}
    assert rhino_objects(tmp_path / "forked.3dm") == rhino_objects(tmp_path / "serial.3dm")
    if options.get("scale") == 0.005:
        assert forked["params"]["joints"] == "marks" and "holes" not in forked["layers"]
