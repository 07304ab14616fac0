"""A pure computation run aside, in a forked process, while the caller goes on with other work
(the .3dm export plans its cut sheets there while it builds the strips: two cores, one wall
clock).

:class:`Aside` forks at once; :meth:`Aside.result` waits for the child and returns what the
function returned, or raises what it raised (its class and message; the child's traceback as a
note). The function's value travels back pickled; nothing else the child does reaches the
caller: it must not write files, print or change state the caller relies on (caches it fills
stay in the child). Where a fork is not safe or not available - not Linux, a process running
other Python threads (a fork copies only the calling thread, so a lock another thread holds
would stay held in the child), or ``GRIDSHELL_SERIAL=1`` in the environment - the function
runs in this process when its result is asked for: the same value either way.
"""
from __future__ import annotations

import os
import pickle
import signal
import sys
import threading
import traceback
from typing import Any, Callable

from gridshell.core.errors import GridshellError

__all__ = ["Aside", "can_fork"]


def can_fork() -> bool:
    """Whether :class:`Aside` forks here (Linux, no other Python thread, no
    ``GRIDSHELL_SERIAL=1``)."""
    return (sys.platform.startswith("linux") and hasattr(os, "fork")
            and os.environ.get("GRIDSHELL_SERIAL", "") != "1"
            and threading.active_count() == 1)


class Aside:
    """``fn(*args, **kwargs)`` started in a forked child (or, where :func:`can_fork` says no,
    deferred to :meth:`result`). Use as a context manager: leaving the block without asking for
    the result (an error in the caller's own work) stops the child."""

    def __init__(self, fn: Callable[..., Any], *args: Any, **kwargs: Any) -> None:
        self._call = (fn, args, kwargs)
        self._pid: int | None = None
        self._fd: int | None = None
        if can_fork():
            self._start()

    def _start(self) -> None:
        r, w = os.pipe()
        pid = os.fork()
        if pid == 0:                                    # the child: compute, send, vanish
            os.close(r)
            try:
                fn, args, kwargs = self._call
                try:
                    payload = pickle.dumps((True, fn(*args, **kwargs)), pickle.HIGHEST_PROTOCOL)
                except BaseException as exc:            # noqa: BLE001 - sent to the caller
                    payload = _pickled_error(exc)
                with os.fdopen(w, "wb") as f:
                    f.write(payload)
            finally:
                os._exit(0)                             # no atexit, no buffered output
        os.close(w)
        self._pid, self._fd = pid, r

    def result(self) -> Any:
        """The function's value (raising its exception). Waits for the child."""
        if self._pid is None:
            fn, args, kwargs = self._call
            return fn(*args, **kwargs)
        try:
            with os.fdopen(self._fd, "rb") as f:
                self._fd = None
                data = f.read()
            _, status = os.waitpid(self._pid, 0)
        finally:
            self.cancel()
        if not data:
            raise GridshellError(
                f"a worker process ended without a result ({_status_text(status)}), perhaps "
                "killed for lack of memory; run again with GRIDSHELL_SERIAL=1 to work in one "
                "process")
        ok, value = pickle.loads(data)
        if ok:
            return value
        raise value

    def cancel(self) -> None:
        """Stop the child (if still running) and release its pipe; no result afterwards."""
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None
        if self._pid is not None:
            pid, self._pid = self._pid, None
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            try:
                os.waitpid(pid, 0)
            except ChildProcessError:
                pass

    def __enter__(self) -> "Aside":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.cancel()


def _pickled_error(exc: BaseException) -> bytes:
    """``(False, exc)`` pickled with the child's traceback as a note; an exception that does not
    pickle becomes a :class:`GridshellError` naming it."""
    note = "in a worker process:\n" + "".join(traceback.format_exception(exc)).rstrip()
    try:
        exc.add_note(note)
        data = pickle.dumps((False, exc), pickle.HIGHEST_PROTOCOL)
        pickle.loads(data)          # an exception whose arguments do not rebuild it
        return data
    except Exception:                                   # noqa: BLE001 - any pickling failure
        err = GridshellError(f"{type(exc).__name__}: {exc}")
        err.add_note(note)
        return pickle.dumps((False, err), pickle.HIGHEST_PROTOCOL)


def _status_text(status: int) -> str:
    if os.WIFSIGNALED(status):
        return f"signal {os.WTERMSIG(status)}"
    return f"exit code {os.waitstatus_to_exitcode(status)}"
