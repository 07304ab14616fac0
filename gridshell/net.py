"""Curve nets of a gridshell: joints, net-loops and lamellae (the data type, nothing else)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .errors import InputError


def polyline_length(P: np.ndarray) -> float:
    """Arc length of a polyline ``P (k,3)`` (same units as ``P``)."""
    P = np.asarray(P, dtype=float)
    if len(P) < 2:
        return 0.0
    return float(np.linalg.norm(np.diff(P, axis=0), axis=1).sum())


def polyline_arclength(P: np.ndarray) -> np.ndarray:
    """Cumulative arc length ``s (k,)`` at the vertices of a polyline ``P (k,3)``, ``s[0] = 0``."""
    P = np.asarray(P, dtype=float)
    seg = np.linalg.norm(np.diff(P, axis=0), axis=1)
    return np.concatenate([[0.0], np.cumsum(seg)])


@dataclass
class Lamella:
    """One lamella: its axis and the joints along it.

    Attributes
    ----------
    id : int
        Identifier, unique in the net.
    family : int
        1 or 3 (the paper's C^1 and C^3).
    joints : (k,) int
        Indices into ``Net.joints`` in order along the lamella.
    joint_s : (k,) float
        Arc length of each joint along the axis, metres, increasing.
    axis : (p,3) float
        Dense polyline of the lamella axis, metres.
    """

    id: int
    family: int
    joints: np.ndarray
    joint_s: np.ndarray
    axis: np.ndarray

    def __post_init__(self) -> None:
        self.joints = np.asarray(self.joints, dtype=np.int64).reshape(-1)
        self.joint_s = np.asarray(self.joint_s, dtype=float).reshape(-1)
        self.axis = np.asarray(self.axis, dtype=float).reshape(-1, 3)
        if self.family not in (1, 3):
            raise InputError(f"lamella {self.id}: family must be 1 or 3, got {self.family}")
        if len(self.joints) != len(self.joint_s):
            raise InputError(f"lamella {self.id}: {len(self.joints)} joints but "
                             f"{len(self.joint_s)} joint_s values; they must match")
        if len(self.joint_s) > 1 and np.any(np.diff(self.joint_s) < 0):
            raise InputError(f"lamella {self.id}: joint_s must increase along the lamella")

    @property
    def length(self) -> float:
        """Arc length of the axis, metres."""
        return polyline_length(self.axis)


@dataclass
class Net:
    """A gridshell net: joints (vertices), net-loops (quad faces) and lamellae.

    Attributes
    ----------
    joints : (n,3) float
        Joint positions, metres.
    loops : (m,4) int
        Net-loops as quads of joint indices, ordered A, B, C, D around the loop.
    lamellae : list of Lamella
    """

    joints: np.ndarray
    loops: np.ndarray
    lamellae: list[Lamella] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.joints = np.asarray(self.joints, dtype=float).reshape(-1, 3)
        self.loops = np.asarray(self.loops, dtype=np.int64).reshape(-1, 4)
        n = len(self.joints)
        if self.loops.size and (self.loops.min() < 0 or self.loops.max() >= n):
            raise InputError(f"net: loop indices must lie in [0, {n}); got "
                             f"[{self.loops.min()}, {self.loops.max()}]")
        for lam in self.lamellae:
            if lam.joints.size and (lam.joints.min() < 0 or lam.joints.max() >= n):
                raise InputError(f"net: lamella {lam.id} names joints outside [0, {n})")

    def family(self, f: int) -> list[Lamella]:
        """The lamellae of family ``f`` (1 or 3), in order."""
        return [lam for lam in self.lamellae if lam.family == f]

    def edges(self) -> np.ndarray:
        """Joint-to-joint edges along lamellae, ``(E,2)`` int, each once."""
        pairs = [np.stack([lam.joints[:-1], lam.joints[1:]], axis=1)
                 for lam in self.lamellae if len(lam.joints) > 1]
        if not pairs:
            return np.zeros((0, 2), dtype=np.int64)
        e = np.sort(np.concatenate(pairs), axis=1)
        return np.unique(e, axis=0)
