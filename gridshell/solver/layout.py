"""Named variable blocks of one optimization vector ``x``."""
from __future__ import annotations

from typing import Iterable, Mapping

import numpy as np

from gridshell.core.errors import InputError


class Layout:
    """Maps block names (``"V"``, ``"N"``, ``"n_u"``) to slices of one vector ``x``.

    Nobody writes an offset by hand: ``layout.view(x, "V")`` is the ``(nv, 3)`` view of the
    vertex block and ``layout.indices("V")`` the matching global indices.

    Parameters
    ----------
    blocks : mapping or iterable of (name, shape)
        Block names and their shapes, in the order they are laid out in ``x``.
    """

    def __init__(self, blocks: Mapping[str, tuple[int, ...] | int]
                 | Iterable[tuple[str, tuple[int, ...] | int]] = ()) -> None:
        self._slices: dict[str, slice] = {}
        self._shapes: dict[str, tuple[int, ...]] = {}
        self.size = 0
        items = blocks.items() if isinstance(blocks, Mapping) else blocks
        for name, shape in items:
            self.add(name, shape)

    def add(self, name: str, shape: tuple[int, ...] | int) -> "Layout":
        """Append block ``name`` of ``shape``; returns ``self``."""
        if name in self._slices:
            raise InputError(f"variable block {name!r} is defined twice")
        shape = (int(shape),) if np.isscalar(shape) else tuple(int(s) for s in shape)
        n = int(np.prod(shape)) if shape else 1
        self._slices[name] = slice(self.size, self.size + n)
        self._shapes[name] = shape
        self.size += n
        return self

    @property
    def names(self) -> list[str]:
        """Block names in layout order."""
        return list(self._slices)

    def __contains__(self, name: str) -> bool:
        return name in self._slices

    def slice(self, name: str) -> slice:
        """Slice of block ``name`` in ``x``."""
        try:
            return self._slices[name]
        except KeyError:
            raise InputError(f"no variable block {name!r}; blocks are {self.names}") from None

    def shape(self, name: str) -> tuple[int, ...]:
        """Shape of block ``name``."""
        self.slice(name)
        return self._shapes[name]

    def view(self, x: np.ndarray, name: str) -> np.ndarray:
        """View of block ``name`` of ``x`` in its shape (writes go through to ``x``)."""
        return x[self.slice(name)].reshape(self._shapes[name])

    def indices(self, name: str) -> np.ndarray:
        """Global indices of block ``name``, in its shape."""
        s = self.slice(name)
        return np.arange(s.start, s.stop).reshape(self._shapes[name])

    def pack(self, values: Mapping[str, np.ndarray], default: float = 0.0) -> np.ndarray:
        """Vector ``x`` from block values; blocks not given are filled with ``default``."""
        x = np.full(self.size, float(default))
        for name, val in values.items():
            val = np.asarray(val, dtype=float)
            if val.size != self.slice(name).stop - self.slice(name).start:
                raise InputError(f"block {name!r} has shape {self._shapes[name]}, "
                                 f"got an array of shape {val.shape}")
            x[self.slice(name)] = val.reshape(-1)
        return x

    def unpack(self, x: np.ndarray) -> dict[str, np.ndarray]:
        """Copies of every block of ``x`` in its shape."""
        return {n: self.view(x, n).copy() for n in self.names}

    def mask(self, names: Iterable[str]) -> np.ndarray:
        """Boolean mask over ``x`` selecting the blocks ``names``."""
        m = np.zeros(self.size, dtype=bool)
        for n in names:
            m[self.slice(n)] = True
        return m

    def __repr__(self) -> str:
        parts = ", ".join(f"{n}{self._shapes[n]}" for n in self.names)
        return f"Layout({parts}; size={self.size})"
