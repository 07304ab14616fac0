"""A few recent results kept in this process, by key, newest last (least recently used
dropped first), safe to share between threads: what :func:`gridshell.design.bundle.read_bundle` read,
the closest-point queries asked again (:mod:`gridshell.geometry.igl_adapter`), a surface's normals and
search tree (:mod:`gridshell.geometry.strips3d`); :func:`array_key`, the key of arrays by content.
Every caller gets its own copy of a stored value, so no caller can change what another one
gets."""
from __future__ import annotations

import hashlib
import threading
from collections import OrderedDict
from typing import Any, Callable, Hashable

import numpy as np


def array_key(*arrays: np.ndarray) -> tuple:
    """A key equal for arrays of equal dtype, shape and bytes (BLAKE2b of the bytes), for the
    results kept by content."""
    out = []
    for a in arrays:
        a = np.ascontiguousarray(a)
        out.append((a.dtype.str, a.shape, hashlib.blake2b(a.data, digest_size=20).digest()))
    return tuple(out)


class Recent:
    """At most ``size`` values, of at most ``max_bytes`` together (``nbytes`` of each; no
    limit without it); ``copy`` makes the copies that go in and come out."""

    def __init__(self, size: int, copy: Callable[[Any], Any],
                 nbytes: Callable[[Any], int] | None = None, max_bytes: int | None = None):
        self.size, self.copy, self.nbytes, self.max_bytes = size, copy, nbytes, max_bytes
        self._items: OrderedDict[Hashable, Any] = OrderedDict()
        self._lock = threading.Lock()

    def get(self, key: Hashable | None) -> Any | None:
        """A copy of the value stored under ``key``, or None (also for ``key`` None)."""
        if key is None:
            return None
        with self._lock:
            hit = self._items.get(key)
            if hit is None:
                return None
            self._items.move_to_end(key)
        return self.copy(hit)

    def put(self, key: Hashable, value: Any) -> None:
        """Store a copy of ``value`` under ``key`` (not when it alone is over ``max_bytes``),
        dropping the oldest values beyond the limits."""
        limited = self.nbytes is not None and self.max_bytes is not None
        if limited and self.nbytes(value) > self.max_bytes:
            return
        value = self.copy(value)
        with self._lock:
            self._items[key] = value
            self._items.move_to_end(key)
            while len(self._items) > self.size or (
                    limited and sum(map(self.nbytes, self._items.values())) > self.max_bytes):
                self._items.popitem(last=False)
