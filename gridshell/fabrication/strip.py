"""The Strip: one flat piece of one lamella to be cut (the data type, nothing else).

A strip is the region ``s0 <= s <= s1``, ``t_lo <= t <= t_hi`` of the strip coordinates of its
planar axis (see :mod:`gridshell.fabrication.axis`), in millimetres. ``s`` is the lamella's own arc
length, so joint ``k`` sits at ``s = joint_s[k]`` and consecutive joints are exactly the
design's arc length apart.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from gridshell.fabrication.axis import ArcAxis, CurveAxis, LineAxis

Axis = LineAxis | ArcAxis | CurveAxis


@dataclass
class Strip:
    """One piece of one lamella, flat, in mm.

    Attributes
    ----------
    lamella : int
        Lamella id (design.json).
    family : int
        1 or 3.
    orientation : str
        ``"tangent"`` (GG: width in the surface) or ``"orthogonal"`` (AA, CNC, NCP).
    axis : LineAxis | ArcAxis | CurveAxis
        Planar axis; ``axis.kind`` is ``"line"``, ``"arc"`` or ``"curve"``.
    s0, s1 : float
        Extent along the axis, end margins included.
    t_lo, t_hi : float
        Extent across the axis (``t_hi - t_lo`` = strip width).
    joint_s : (k,) float
        Positions of the joints on this piece along the axis.
    joint_index : (k,) int
        Net joint index of each joint.
    neighbours : list of list of int
        Ids of the other lamellae through each joint.
    piece, n_pieces : int
        1-based piece number and piece count of the lamella (1, 1 when not split).
    splices : list of dict
        For split lamellae, one note per splice of this piece (:mod:`gridshell.fabrication.splice`):
        ``{"kind": "joint" | "span", "with": other piece, "overlap": mm, "from": s, "to": s,
        ...}``.
    splice_s : (m,) float
        Positions of the fasteners (holes or marks) of span splices on this piece.
    """

    lamella: int
    family: int
    orientation: str
    axis: Axis
    s0: float
    s1: float
    t_lo: float
    t_hi: float
    joint_s: np.ndarray
    joint_index: np.ndarray
    neighbours: list[list[int]]
    piece: int = 1
    n_pieces: int = 1
    splices: list[dict] = field(default_factory=list)
    splice_s: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def __post_init__(self) -> None:
        self.splice_s = np.asarray(self.splice_s, float).reshape(-1)
        self.joint_s = np.asarray(self.joint_s, float).reshape(-1)
        self.joint_index = np.asarray(self.joint_index, np.int64).reshape(-1)

    @property
    def length(self) -> float:
        """Flat length along the axis, mm."""
        return float(self.s1 - self.s0)

    @property
    def width(self) -> float:
        return float(self.t_hi - self.t_lo)

    @property
    def t_mid(self) -> float:
        """Centre line of the width."""
        return 0.5 * (self.t_lo + self.t_hi)

    @property
    def name(self) -> str:
        """Label text: ``L12`` or ``L12-2/3`` for piece 2 of 3."""
        return f"L{self.lamella}" + (f"-{self.piece}/{self.n_pieces}" if self.n_pieces > 1 else "")

    def sub(self, s0: float, s1: float, **changes) -> "Strip":
        """The piece ``[s0, s1]`` of this strip with the joints (and splice fasteners) that
        lie on it."""
        m = (self.joint_s >= s0 - 1e-9) & (self.joint_s <= s1 + 1e-9)
        f = self.splice_s[(self.splice_s >= s0 - 1e-9) & (self.splice_s <= s1 + 1e-9)]
        changes.setdefault("splice_s", f)
        return dataclasses.replace(self, s0=float(s0), s1=float(s1), joint_s=self.joint_s[m],
                                   joint_index=self.joint_index[m],
                                   neighbours=[n for n, k in zip(self.neighbours, m) if k],
                                   **changes)
