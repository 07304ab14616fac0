"""gridshell.core.recent.Recent: least recently used dropped first, byte limit, copies in and out."""
import numpy as np

from gridshell.core.recent import Recent


def test_oldest_unused_is_dropped_and_copies_are_returned():
    r = Recent(2, copy=lambda a: a.copy())
    a, b, c = np.zeros(3), np.ones(3), np.full(3, 2.0)
    r.put("a", a)
    r.put("b", b)
    got = r.get("a")                     # a is now the newest
    got[:] = 7.0
    a[:] = 5.0
    assert np.array_equal(r.get("a"), np.zeros(3))   # neither change reached the store
    r.put("c", c)
    assert r.get("b") is None and r.get("c") is not None and r.get("a") is not None
    assert r.get(None) is None


def test_byte_limit():
    r = Recent(10, copy=lambda a: a.copy(), nbytes=lambda a: a.nbytes, max_bytes=200)
    r.put("big", np.zeros(30))           # 240 bytes: over the limit alone, not stored
    assert r.get("big") is None
    for k in range(3):
        r.put(k, np.zeros(10))           # 80 bytes each: the third pushes out the first
    assert r.get(0) is None and r.get(1) is not None and r.get(2) is not None
