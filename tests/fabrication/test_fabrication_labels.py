"""Engraved labels (issue item 3): single-line Hershey strokes, inside the material."""
from __future__ import annotations

import numpy as np
import pytest
import shapely
from tests.helpers.fab_cases import make_bundle

from gridshell.fabrication.labels import text_strokes
from gridshell.fabrication.params import FabParams
from gridshell.fabrication.part import build_part
from gridshell.fabrication.strips import strips_from_bundle


def test_text_strokes_have_the_cap_height_and_start_at_zero():
    lines, length = text_strokes("L12", 6.0)
    P = np.concatenate(lines)
    assert P[:, 1].min() == pytest.approx(0.0, abs=1e-9)
    assert P[:, 1].max() == pytest.approx(6.0)
    assert P[:, 0].min() == pytest.approx(0.0) and P[:, 0].max() == pytest.approx(length)
    assert all(len(L) >= 2 for L in lines)


@pytest.mark.parametrize("kind,joints", [("GG", "hole"), ("CNC", "hole"), ("NCP", "slots")])
def test_labels_name_the_lamella_and_its_neighbours_inside_the_material(kind, joints):
    b = make_bundle(kind, nr=4, nc=4)
    params = FabParams(joints=joints)
    for s in strips_from_bundle(b, params):
        part = build_part(s, params)
        assert part.labels_dropped == 0
        material = shapely.Polygon(part.outline.flatten())
        for c, r in zip(part.holes, part.radii):
            material = material.difference(shapely.Point(c).buffer(r))
        strokes = shapely.MultiLineString(part.engrave)
        assert material.buffer(-0.4).contains(strokes)
        # one text per neighbour plus the strip's name: the strokes form that many clusters
        n_texts = sum(1 for nb in s.neighbours if nb) + 1
        clusters = shapely.unary_union([shapely.LineString(L).buffer(0.8) for L in part.engrave])
        assert len(getattr(clusters, "geoms", [clusters])) >= n_texts


def test_no_labels_option():
    b = make_bundle("GG")
    params = FabParams(labels=False)
    assert build_part(strips_from_bundle(b, params)[0], params).engrave == []


def test_neighbours_are_the_crossing_lamellae():
    b = make_bundle("GG", nr=3, nc=4)
    strips = strips_from_bundle(b, FabParams())
    assert strips[0].neighbours == [[3], [4], [5], [6]]     # row 0 crosses columns 3..6
    assert strips[3].neighbours == [[0], [1], [2]]
