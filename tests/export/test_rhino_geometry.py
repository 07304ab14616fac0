"""The export's cut paths as Rhino curves: straight spans and DXF bulge arcs (included angle
4 atan(b)), every curve of a sheet at the sheet's height."""
from __future__ import annotations

import numpy as np
import pytest

rhino3dm = pytest.importorskip("rhino3dm")

from gridshell.export.rhino_geometry import bulge_curve  # noqa: E402


def xyz(p):
    return np.array([p.X, p.Y, p.Z])


def test_a_bulge_of_one_is_a_half_circle_counter_clockwise():
    # (0,0) -> (2,0) with b = 1: the half circle about (1,0) below the chord (counter-clockwise)
    c = bulge_curve(np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 3.0]]), np.array([1.0, 0.0, 0.0]),
                    closed=False, z=0.5)
    assert isinstance(c, rhino3dm.PolyCurve) and c.SegmentCount == 2
    arc = c.SegmentCurve(0)
    d = arc.Domain
    mid = xyz(arc.PointAt(0.5 * (d.T0 + d.T1)))
    assert np.allclose(mid, [1.0, -1.0, 0.5], atol=1e-12)
    q = xyz(arc.PointAt(d.T0 + 0.25 * (d.T1 - d.T0)))          # on the circle, below the chord
    assert np.linalg.norm(q - [1.0, 0.0, 0.5]) == pytest.approx(1.0, abs=1e-12) and q[1] < 0
    assert np.allclose(xyz(arc.PointAtStart), [0.0, 0.0, 0.5])
    assert np.allclose(xyz(c.PointAtEnd), [2.0, 3.0, 0.5])


def test_a_path_without_arcs_is_a_polyline_at_the_given_height():
    V = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]])
    c = bulge_curve(V, None, closed=True, z=2.0)
    assert isinstance(c, rhino3dm.PolylineCurve) and c.PointCount == 4
    P = np.array([xyz(c.Point(i)) for i in range(c.PointCount)])
    assert np.array_equal(P[:, :2], np.vstack([V, V[:1]])) and np.all(P[:, 2] == 2.0)
