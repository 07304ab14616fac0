"""BLAS threads while the solver runs: one unless the user chose otherwise.

The solver's matrices (1e3-1e5 unknowns) are factored and multiplied in many short BLAS calls;
a second OpenBLAS thread spins between them and costs more than it saves (the NCP simulation at
40 curves: 17.4 s with two threads, 4.0 s with one, measured 2026-12-02 on 2 cores). The
``gridshell`` command sets ``OPENBLAS_NUM_THREADS=1`` before numpy loads; a Python caller of the
API gets the same inside :func:`~gridshell.solver.solve.solve` through threadpoolctl, which
reaches both numpy's OpenBLAS and the one CHOLMOD links. ``OPENBLAS_NUM_THREADS`` or
``GRIDSHELL_BLAS_THREADS`` set by the user wins.
"""
from __future__ import annotations

import contextlib
import functools
import os
from typing import Any, Callable, Iterator, TypeVar

F = TypeVar("F", bound=Callable[..., Any])


def blas_limit() -> int | None:
    """The BLAS thread count to apply, or None when the user set one (env) already."""
    if "OPENBLAS_NUM_THREADS" in os.environ:
        return None
    text = os.environ.get("GRIDSHELL_BLAS_THREADS", "1")
    try:
        return max(1, int(text))
    except ValueError:
        return 1


@functools.lru_cache(maxsize=None)
def _controller() -> Any:
    """A threadpoolctl controller over the BLAS libraries loaded at the first solve (numpy's and,
    once :mod:`.linear` has imported it, CHOLMOD's)."""
    from threadpoolctl import ThreadpoolController

    from gridshell.solver.linear import available
    available("cholmod")  # loads CHOLMOD's BLAS (when installed) before the controller looks
    return ThreadpoolController()


@contextlib.contextmanager
def limited_blas() -> Iterator[None]:
    """Run the block with :func:`blas_limit` BLAS threads (no-op when the user set them)."""
    n = blas_limit()
    if n is None:
        yield
        return
    try:
        ctl = _controller()
    except ImportError:  # threadpoolctl missing: run as is
        yield
        return
    with ctl.limit(limits=n, user_api="blas"):
        yield


def one_blas_thread(fn: F) -> F:
    """Decorator: ``fn`` runs inside :func:`limited_blas`."""
    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        with limited_blas():
            return fn(*args, **kwargs)
    return wrapper  # type: ignore[return-value]
