"""Nesting that earns its sheets (issue 16): on the demo's two designs and five corpus designs,
sheets <= ceil(1.15 x part area / sheet area) wherever the parts fit at all, every part placed
exactly once, inside its sheet's gap-wide margin, no two parts closer than the gap.

"Fit at all": the parts grown by half the gap are disjoint and lie in the sheet shrunk by half
the gap, so no layout needs fewer than :func:`gridshell.fabrication.nesting.gap_bound` sheets. At the
default 2 mm gap every case meets the 15 % bound itself; where a larger gap puts that floor
above the bound (20 mm strips with 5 mm gaps lose 25 % of their area to the gap), the layout
must reach the floor. The hyperbolic paraboloid (a corpus saddle) CNC
design goes on one sheet when its grown parts fit one, else the test states the measured
reason.

Designs are small (few curves and frames) and made once per module; the demo's two are made
with the demo's own sizes and cut-file parameters (:mod:`gridshell.cli.demo`).
"""
from __future__ import annotations

import functools

import pytest
import shapely

from gridshell.fabrication import FabParams
from gridshell.fabrication.nesting import FLAT_TOL, SLACK, gap_bound, sheet_bound
from gridshell.fabrication.pipeline import plan_parts

GG_SMALL = ["--frames", "2", "--no-preview"]
NCP_SMALL = ["--samples", "24", "24", "--collapse-samples", "200", "200", "--frames", "2",
             "--rounds", "1", "--no-render", "--phlw-samples", "12", "12", "--phlw-outer", "2"]

#: corpus designs (reference, CLI words), and "hypar-cnc": a CNC gridshell on the hyperbolic
#: paraboloid z = x y / 4.5 m over a 4.5 x 4.5 m square, 12 curves per family (24 arcs,
#: 43 % of one sheet)
CORPUS = {
    "associate-03-gg": ("associate-03", ["gg", *GG_SMALL]),
    "hill-06-gg": ("hill-06", ["gg", *GG_SMALL]),
    "dome-05-ncp": ("dome-05", ["ncp", "--mode", "phlw", "--curves", "6", *NCP_SMALL]),
    "pseudosphere-03-aa": ("pseudosphere-03", ["ncp", "--mode", "aa", "--curves", "6",
                                               *NCP_SMALL]),
    "saddle-04-cnc": ("saddle-04", ["ncp", "--mode", "cnc", "--curves", "6", *NCP_SMALL]),
    "hypar-cnc": (None, ["ncp", "--mode", "cnc", "--curves", "12", *NCP_SMALL]),
}
#: the demo's CNC pavilion: 24 arcs (radius 231 mm, 4 each of six lengths, the longest over
#: 100 degrees) take 49.8 % of one 600 x 400 sheet and 64.8 % grown by half the gap: one sheet
#: (translation-nested arcs sit 25 mm / cos(half angle) apart and the drop nesting needed two;
#: the raster passes turn parts freely)
CASES = ["demo-gg", "demo-cnc", *CORPUS]


@pytest.fixture(scope="module")
def designs(tmp_path_factory):
    """Bundles made on first use, one per case, for the whole module."""
    root = tmp_path_factory.mktemp("nesting_bound")

    @functools.lru_cache(maxsize=None)
    def make(case: str):
        return _design(case, root)

    return make


def _design(case: str, root) -> tuple:
    from gridshell.cli.demo import FABRICATION, SIZES

    if case == "demo-gg":
        from gridshell import data
        from gridshell.api import design_gg

        s = SIZES["full"]["gg"]
        bundle, _ = design_gg(data.path("dome.obj"), grid=s["grid"],
                              n_lamellae=s["n_lamellae"], frames=2)
        return bundle, FabParams(**FABRICATION)
    if case == "demo-cnc":
        from gridshell import data
        from gridshell.api import design_ncp
        from gridshell.geometry.meshfile import read_mesh
        from gridshell.ncp.phlw import optimize_phlw
        from gridshell.ncp.reference import initial_surface

        ph, nc = SIZES["full"]["phlw"], SIZES["full"]["ncp"]
        mesh = read_mesh(data.path("torus_patch.obj"), kind="any")
        res = optimize_phlw(initial_surface(mesh.V, mesh.F).surface, (mesh.V, mesh.F),
                            mode="cnc", samples=ph["samples"], outer=ph["outer"],
                            max_iter=ph["max_iter"])
        bundle, _ = design_ncp(res, mode="cnc", curves=nc["curves"], samples=nc["samples"],
                               collapse_samples=nc["collapse_samples"], frames=2,
                               postopt_rounds=nc["postopt_rounds"])
        return bundle, FabParams(**FABRICATION)
    from gridshell.design.bundle import read_bundle
    from gridshell.cli.main import main
    from gridshell.corpus import get

    name, words = CORPUS[case]
    obj = get(name).write_obj(root / f"{name}.obj") if name else _hypar(root / "hypar.obj")
    out = root / case
    assert main([words[0], str(obj), "-o", str(out), *words[1:]]) == 0
    return read_bundle(out), FabParams()


def _hypar(path, side=4.5, c=4.5, n=13):
    """OBJ of the hyperbolic paraboloid ``z = x y / c`` over ``side x side`` m, n x n."""
    import numpy as np

    from gridshell.geometry.grid import grid_quads
    from gridshell.geometry.meshfile import write_mesh

    t = np.linspace(-side / 2, side / 2, n)
    X, Y = np.meshgrid(t, t, indexing="ij")
    write_mesh(path, np.stack([X.ravel(), Y.ravel(), (X * Y / c).ravel()], 1),
               grid_quads(n, n))
    return path


def _check_placed(parts, layout, gap):
    """Every part once, inside its sheet's margin, no two closer than ``gap`` (shapely)."""
    assert sorted(id(p.strip) for p in layout.parts) == sorted(id(p.strip) for p in parts)
    assert len(layout.parts) == len(parts) == len(layout.sheet_of)
    W, H = layout.sheet
    inner = shapely.box(gap, gap, W - gap, H - gap).buffer(SLACK + 1e-3, join_style="mitre")
    for k in range(layout.n_sheets):
        polys = [p.polygon(FLAT_TOL) for p in layout.on_sheet(k)]
        assert polys, f"sheet {k + 1} is empty"
        for P in polys:
            assert inner.contains(P), f"a part leaves sheet {k + 1} or its margin"
        tree = shapely.STRtree(polys)
        for i, P in enumerate(polys):
            for j in tree.query(P, predicate="dwithin", distance=gap):
                if j > i:
                    assert P.distance(polys[j]) >= gap - 1e-3, (k, i, j)
    # the material used is the part outlines over the sheets' area
    area = sum(p.polygon(FLAT_TOL).area for p in parts)
    assert layout.used() == pytest.approx(area / (layout.n_sheets * W * H))


@pytest.mark.slow
@pytest.mark.parametrize("case", CASES)
def test_sheets_within_the_area_bound(case, designs):
    bundle, params = designs(case)
    parts, layout, info = plan_parts(bundle, params)
    g = params.gap
    _check_placed(parts, layout, g)
    bound = sheet_bound(parts, params.sheet)
    floor = gap_bound(parts, params.sheet, g)
    assert layout.n_sheets >= floor                  # the floor is a true lower bound
    if g <= FabParams().gap:                         # at the default gap the bound itself holds
        assert layout.n_sheets <= bound, (case, layout.n_sheets, bound, floor)
    if floor <= bound:
        assert layout.n_sheets <= bound, (case, layout.n_sheets, bound)
    else:       # the parts grown by the gap do not fit the bound: the layout reaches the floor
        assert layout.n_sheets == floor, (case, layout.n_sheets, floor, bound)


def test_hypar_cnc_on_one_sheet_if_its_area_allows(designs):
    """The hyperbolic paraboloid CNC design: one sheet when its parts grown by half the gap
    fit the sheet shrunk by half the gap (their area allows), else that is the reason."""
    bundle, params = designs("hypar-cnc")
    parts, layout, info = plan_parts(bundle, params)
    assert info["strips"][0].axis.kind == "arc"
    W, H = params.sheet
    g = params.gap
    grown = sum(p.polygon(FLAT_TOL).buffer(g / 2, quad_segs=16).area for p in parts)
    if grown <= (W - g) * (H - g):
        assert layout.n_sheets == 1
    else:
        assert gap_bound(parts, params.sheet, g) > 1 and layout.n_sheets == gap_bound(
            parts, params.sheet, g), f"grown parts {grown:.0f} mm^2 > {(W - g) * (H - g):.0f}"


@pytest.mark.slow
def test_sheet_count_and_material_used_in_summary_cut_list_and_plan(tmp_path, capsys):
    """``gridshell fabricate``: the summary, the cut list and the plan's title give the sheet
    count and the material used (part outlines over sheet area) of fabrication.json."""
    import csv
    import json

    from tests.helpers.fab_cases import make_bundle

    from gridshell.design.bundle import write_bundle
    from gridshell.cli.main import main

    write_bundle(tmp_path / "b", make_bundle("CNC", nr=5, nc=6))
    out = tmp_path / "fab"
    assert main(["fabricate", "--force", str(tmp_path / "b"), "-o", str(out), "--sheet",
                 "300x200", "-q", "--json"]) == 0
    s = json.loads(capsys.readouterr().out)
    rep = json.loads((out / "fabrication.json").read_text())
    n, used, per = rep["n_sheets"], rep["material_used"], rep["material_used_per_sheet"]
    assert n >= 2 and sum(per) == pytest.approx(n * used)
    assert s["sheets"].startswith(f"{n} x 300 x 200 mm")
    assert s["material used [% of sheet area]"] == (
        ", ".join(f"{100 * u:.1f}" for u in per) + f" (all sheets {100 * used:.1f})")
    with open(out / "cutlist.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert {int(r["n_sheets"]) for r in rows} == {n}
    assert {r["material_used_pct"] for r in rows} == {f"{100 * used:.1f}"}
    assert all(r["sheet_used_pct"] == f"{100 * per[int(r['sheet']) - 1]:.1f}" for r in rows)
    title = f"{n} sheets 300 x 200 mm, {100 * used:.0f} % of their area used"
    assert title in (out / "plan.svg").read_text()
