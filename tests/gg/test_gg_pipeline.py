"""Tests of gridshell.gg.pipeline: net from a GG mesh, collapse, metrics, the whole pipeline."""
from __future__ import annotations

import json

import numpy as np
import pytest
from tests.helpers.gg_cases import catenoid, helicoid_grid, hill_grid, revolution_grid

from gridshell.core.errors import ConvergenceError, InputError
from gridshell.geometry.grid import grid_quads
from gridshell.api import write
from gridshell.gg.pipeline import collapse_gg, design_gg, gg_metrics, gg_net_from_mesh


def _mesh(P):
    R, C = P.shape[:2]
    return P.reshape(-1, 3), grid_quads(R, C)


def test_exact_surface_of_revolution_gives_an_alignable_net():
    P = revolution_grid(catenoid(1.0), np.linspace(-1.0, 1.0, 25), np.linspace(0.0, 2.0, 25))
    st = gg_net_from_mesh(P, n_lamellae=8, crossing_angle=90.0)
    V, F = _mesh(P)
    m = gg_metrics(st["net"], V, F, net_rev=st["net_rev"], target=(V, F))
    assert m["alignability"]["mean"] < 0.1 and m["alignability_arc"]["max"] < 0.1
    assert m["alignability_revolution"]["max"] < 1e-6
    assert m["geodesic_turning"] < 2.0
    assert m["deviation_joints"]["max"] < 0.1


def test_helicoid_net_meets_the_paper_bounds():
    P = helicoid_grid(25, 25, c=0.5)
    st = gg_net_from_mesh(P, n_lamellae=8, crossing_angle=70.0, at_parallel=0.3)
    V, F = _mesh(P)
    m = gg_metrics(st["net"], V, F, target=(V, F))
    assert m["alignability"]["mean"] < 1.0 and m["alignability"]["max"] < 3.0
    assert m["geodesic_turning"] < 2.0
    assert m["deviation_joints"]["max"] < 1.0


def test_collapse_keeps_lamella_lengths_between_joints():
    P = helicoid_grid(21, 21, c=0.5)
    net = gg_net_from_mesh(P, n_lamellae=6, crossing_angle=90.0)["net"]
    aligned, info = collapse_gg(net)
    assert info["mismatch_max"] < 1e-4 and info["components"] == 1
    np.testing.assert_allclose(aligned[:, 1:], 0.0)
    for lam in net.lamellae:
        x = aligned[lam.joints, 0]
        np.testing.assert_allclose(np.diff(x), np.diff(lam.joint_s), atol=2e-4)
    # a net-loop closes on the line: A -> B -> C and A -> D -> C end at the same x
    A, B, C, D = (aligned[net.loops[:, i], 0] for i in range(4))
    assert np.all(B > A) and np.all(D > A) and np.all(C > B) and np.all(C > D)


def test_offsets_in_metres_place_curves_on_the_reference_parallel():
    P = revolution_grid(catenoid(1.0), np.linspace(-1.0, 1.0, 21), np.linspace(0.0, 2.0, 21))
    st = gg_net_from_mesh(P, offsets=([0.3, 0.5, 1.2], [0.1, 0.9, 1.8]), crossing_angle=90.0)
    r_star = 1.0  # the catenoid's neck is the middle parallel
    np.testing.assert_allclose(st["inet"].offsets1 * r_star, [0.3, 0.5, 1.2], rtol=1e-6)
    with pytest.raises(InputError, match="pair"):
        gg_net_from_mesh(P, offsets=([0.3],), crossing_angle=90.0)


def test_write_gg_bundle(tmp_path):
    P = helicoid_grid(15, 15, c=0.5)
    st = gg_net_from_mesh(P, n_lamellae=5, crossing_angle=90.0)
    from gridshell.design.bundle import DesignBundle, read_design_json
    V, F = _mesh(P)
    aligned, _ = collapse_gg(st["net"])
    b = DesignBundle(kind="GG", net=st["net"], aligned=aligned, surface_V=V, surface_F=F,
                     metrics=gg_metrics(st["net"], V, F))
    out = write(tmp_path / "b", b, frames=3)
    assert (out / "preview.png").stat().st_size > 1000
    d = read_design_json(out)
    assert d["kind"] == "GG" and len(d["lamellae"]) == len(st["net"].lamellae)
    # the alignment sequence: net.obj first, aligned.obj last, pictures and a GIF
    from gridshell.geometry.meshfile import read_configuration
    from gridshell.render.sequence import read_sequence
    frames, loops = read_sequence(out)
    assert len(frames) == 4
    np.testing.assert_array_equal(loops, st["net"].loops)
    np.testing.assert_array_equal(frames[0], read_configuration(out / "net.obj")[0])
    np.testing.assert_array_equal(frames[-1], read_configuration(out / "aligned.obj")[0])
    assert len(list((out / "sequence").glob("frame_*.png"))) == 4
    assert (out / "alignment.gif").read_bytes()[:6] in (b"GIF89a", b"GIF87a")
    from PIL import Image
    with Image.open(out / "states.png") as im:
        assert im.width >= 1600                    # two states per row, each >= 800 px
    assert not (write(tmp_path / "c", b, render=False, frames=0) / "sequence").exists()


# ----------------------------------------------------------------------------- whole pipeline


def test_design_gg_on_an_exact_surface_of_revolution():
    P = revolution_grid(catenoid(1.0), np.linspace(-0.8, 0.8, 12), np.linspace(0.0, 1.5, 12))
    bundle, report = design_gg(_mesh(P), grid=(12, 12), n_lamellae=6, crossing_angle=90.0)
    m = bundle.metrics
    assert bundle.kind == "GG"
    assert m["alignability"]["mean"] < 0.1
    assert m["deviation"]["max"] < 1.0


def test_design_gg_on_a_helicoid():
    # a triangle mesh of the helicoid: the grid comes from its parameterization, so its lines
    # are neither rulings nor helices and the optimization has real work to do
    V, Q = _mesh(helicoid_grid(25, 25, c=0.5))
    T = np.concatenate([Q[:, [0, 1, 2]], Q[:, [0, 2, 3]]])
    bundle, report = design_gg((V, T), grid=(20, 20), direction=0.0, n_lamellae=6,
                               crossing_angle=80.0)
    assert bundle.params["quality"]["ok"]
    m = bundle.metrics
    assert m["deviation"]["max"] < 1.0
    assert m["alignability"]["mean"] < 1.0 and m["alignability"]["max"] < 3.0
    assert m["geodesic_turning"] < 2.0
    # the initial grid spans the whole target (the rectangle inside the LSCM domain of the
    # helicoid covered 65 % of it): the design reaches the target's boundary
    assert m["coverage"] > 98.0 and m["deviation_target"]["max"] < 1.0


def test_two_way_deviation_and_coverage_on_a_helicoid_grid():
    # an exact GG target given as a structured grid (rulings = meridians): the design is the
    # target itself, in both directions and in area (closed form of the helicoid's area)
    c = 0.5
    V, F = _mesh(helicoid_grid(25, 25, c=c))
    bundle, _ = design_gg((V, F), n_lamellae=6, crossing_angle=80.0, frames=0)
    m = bundle.metrics
    assert m["deviation"]["max"] < 0.01 and m["deviation_target"]["max"] < 0.2
    assert m["coverage"] == pytest.approx(100.0, abs=0.5)
    area = 2.0 * (np.sqrt(1 + c * c) + c * c * np.arcsinh(1 / c))   # int int sqrt(u^2+c^2)
    from gridshell.measure.metrics import surface_area
    assert surface_area(bundle.surface_V, bundle.surface_F) == pytest.approx(area, rel=2e-3)
    # the same design measured against a wider target (u in [-1.5, 1.5]) covers less of it
    # and is far from its outer rulings: 0.5 m along a ruling
    W, G = _mesh(helicoid_grid(37, 25, c=c, u=(-1.5, 1.5)))
    wide = gg_metrics(bundle.net, bundle.surface_V, bundle.surface_F, target=(W, G))
    area_w = 2.0 * (1.5 * np.sqrt(2.25 + c * c) + c * c * np.arcsinh(1.5 / c))
    assert wide["coverage"] == pytest.approx(100 * area / area_w, rel=3e-3)
    diag = np.linalg.norm(W.max(0) - W.min(0))
    assert wide["deviation_target"]["max"] == pytest.approx(100 * 0.5 / diag, rel=5e-3)
    assert wide["deviation"]["max"] < 0.01     # the one-way figure cannot see it


def test_design_gg_on_a_dome_triangle_mesh():
    # elliptic paraboloid z = -(x^2/a + y^2/b): no exact geodesic alignable net exists on it
    x, y = np.meshgrid(np.linspace(-1, 1, 11), np.linspace(-0.8, 0.8, 9), indexing="ij")
    V = np.stack([x.ravel(), y.ravel(), -(x.ravel() ** 2 / 2.0 + y.ravel() ** 2 / 1.2)], 1)
    Q = grid_quads(11, 9)
    T = np.concatenate([Q[:, [0, 1, 2]], Q[:, [0, 2, 3]]])
    bundle, _ = design_gg((V, T), grid=(10, 10), n_lamellae=5, crossing_angle=90.0)
    m = bundle.metrics
    assert np.isfinite(m["deviation"]["max"]) and m["deviation"]["max"] >= 0.0
    # on the designed surface the net is alignable up to the paper's bounds
    assert m["alignability"]["mean"] < 1.0 and m["alignability"]["max"] < 3.0
    assert m["alignability_revolution"]["max"] < 1e-3
    assert len(bundle.net.loops) > 0


# ----------------------------------------------------------------------------- acceptance


def _score(bundle):
    """Largest figure / threshold over the design's gates (below 1: all pass)."""
    return max(g["value"] / g["limit"] for g in bundle.params["quality"]["gates"]
               if g.get("limit") is not None)


def test_a_freeform_hill_is_accepted_on_its_figures_at_every_scale():
    # regression (issue 13): a rotated 24 x 16 freeform hill met the paper's figures (Delta_a
    # max 0.52 %) and was refused for an edge-length spread of 1.67e-6 > 1e-6. Accepted now on
    # its figures, identically for a 0.5 m model and a 60 m hall 500 m off the origin (the
    # net's joints on the phi boundaries used to come and go with round-off: 261 / 262 / 263 /
    # 255 loops at 0.5 m / 12 m / 60 m / shifted)
    out = []
    for size, shift in ((0.5, (0.0, 0.0, 0.0)), (60.0, (500.0, -300.0, 20.0))):
        bundle, report = design_gg(_mesh(hill_grid(24, 16, size=size, shift=shift)), frames=0)
        q = bundle.params["quality"]
        paper = [g for g in q["gates"] if not g["name"].startswith("fair_")]
        assert q["ok"] and len(paper) == 4 and all(g["ok"] for g in q["gates"])
        assert bundle.params["converged"] and q["summary"].startswith("all ")
        # (with the orthogonality constraint the constraint energy keeps falling by more than
        # POLISH_STALL per iteration here, so the polish may run its 20 iterations)
        assert report["design"]["stop"] in ("figures", "stagnation", "tolerance",
                                            "iteration limit")
        out.append(bundle.metrics)
    a, b = out
    assert a["n_loops"] == b["n_loops"] and a["n_joints"] == b["n_joints"]
    for key in ("alignability", "alignability_arc"):
        for stat in ("mean", "max"):
            assert b[key][stat] == pytest.approx(a[key][stat], rel=1e-4)
    assert b["deviation"]["max"] == pytest.approx(a["deviation"]["max"], rel=1e-4)


@pytest.mark.slow
def test_a_longer_polish_never_worsens_the_design():
    # regression (issue 13): the polish's elastic metric halved every iteration until nothing
    # was left, and the projection put its correction into odd-even zig-zags: 20 polish
    # iterations took a 30 x 20 hill from Delta_a max 0.88 % to 2.53 % (a 36 x 24 one from
    # 0.92 % to 3.7 %, failing). Now every iteration descends, the metric is kept, and the
    # best checkpoint is returned
    V, F = _mesh(hill_grid(30, 20))
    b0, _ = design_gg((V, F), frames=0, polish_iter=0, allow_unconverged=True)
    b20, rep = design_gg((V, F), frames=0, polish_iter=20)
    assert _score(b20) <= _score(b0)
    # (0.72 % -> 0.38 % with the orthogonality constraint, the zig-zag projection went up)
    assert b20.metrics["alignability"]["max"] < 0.6 * b0.metrics["alignability"]["max"]
    ec = [h["constraint_energy"] for h in rep["design"]["history"] if h["round"] == "polish"]
    assert ec and all(y <= x for x, y in zip(ec, ec[1:]))


def test_a_design_missing_the_figures_is_refused_naming_them():
    # one round and no polish on the hill: Delta_a max 5.6 %; refused unless allowed, and then
    # the bundle says so
    V, F = _mesh(hill_grid(24, 16))
    with pytest.raises(ConvergenceError, match=r"misses the paper's figures.*Delta_a max"):
        design_gg((V, F), frames=0, rounds=1, polish_iter=0)
    bundle, _ = design_gg((V, F), frames=0, rounds=1, polish_iter=0, allow_unconverged=True)
    q = bundle.params["quality"]
    assert q["ok"] is False and bundle.params["converged"] is False
    bad = [g for g in q["gates"] if not g["ok"]]
    assert bad and all(g["value"] >= g["limit"] for g in bad)
    assert bundle.metrics["alignability"]["max"] == pytest.approx(
        next(g["value"] for g in q["gates"] if g["name"] == "delta_a_max"))


def _same_direction_edges(F):
    F = np.asarray(F)
    e = np.stack([F.ravel(), np.roll(F, -1, axis=1).ravel()], axis=1)
    _, count = np.unique(e, axis=0, return_counts=True)
    return int(np.sum(count - 1))


@pytest.mark.parametrize("meridians, triangles", [("cols", False), ("rows", False),
                                                  ("cols", True)])
def test_every_obj_of_a_gg_bundle_is_consistently_oriented(tmp_path, meridians, triangles):
    # regression (issue 13): on a surface-of-revolution quad grid with meridians = columns the
    # bundle's net.obj had edges run in the same direction by both faces; verify and
    # fabricate refused it
    from tests.helpers.gg_cases import sphere

    from gridshell.geometry.meshfile import read_mesh

    P = revolution_grid(sphere(1.0), np.linspace(0.3, 1.6, 14), np.linspace(0.0, 1.2, 12))
    V, F = _mesh(P)
    if triangles:
        F = np.concatenate([F[:, [0, 1, 2]], F[:, [0, 2, 3]]])
    design = design_gg((V, F), meridians=meridians, frames=2,
                       grid=(14, 12) if triangles else None)
    bundle, report = design
    assert bundle.params["quality"]["ok"]
    out = write(tmp_path / "b", design, render=False)
    assert json.loads((out / "report.json").read_text())["revolution"]["method"] == \
        report["revolution"]["method"]
    objs = [out / n for n in ("net.obj", "aligned.obj", "surface.obj", "revolution.obj")]
    objs += sorted((out / "sequence").glob("frame_*.obj"))
    assert len(objs) == 7
    for path in objs:
        # the faces as written (aligned.obj is a collapsed, degenerate mesh: read it raw)
        F = [[int(t.split("/")[0]) for t in ln.split()[1:]]
             for ln in path.read_text().splitlines() if ln.startswith("f ")]
        assert len(F) > 0 and _same_direction_edges(F) == 0, path.name
    assert len(read_mesh(out / "net.obj", kind="any").F) == len(bundle.net.loops)


def test_offsets_off_the_surface_are_an_input_error_in_metres():
    """``gg --offsets -5 99`` on a ~2 m wide surface: no lamella reaches it. The user's
    positions are wrong, not the surface (exit 2, not 3), and the message is in metres."""
    from gridshell.core.errors import InputError

    P = helicoid_grid(14, 14)
    with pytest.raises(InputError, match=r"-5, 99 m.*0 to [0-9.]+ m of arc length"):
        gg_net_from_mesh(P, offsets=([-5.0, 99.0], [-5.0, 99.0]))
    # positions on the parallel still make a net
    st = gg_net_from_mesh(P, offsets=([0.3, 0.6, 0.9], [0.3, 0.6, 0.9]))
    assert len(st["net"].family(1)) == 3
