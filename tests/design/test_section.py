"""One resolver of the strip section: caller > the bundle's fabrication report > defaults, one
error policy for a broken report, and the same strip for check, simulate, render and export."""
import json

import pytest
from tests.helpers.render_cases import write_case

from gridshell.cli.main import main
from gridshell.core.errors import InputError
from gridshell.design.section import (DEFAULTS, FABRICATION_REPORT, parse_scale,
                                      resolve_section, scale_text)


def _report(d, params):
    f = d / FABRICATION_REPORT
    f.parent.mkdir(exist_ok=True)
    f.write_text(json.dumps({"params": params}) if isinstance(params, dict) else params)
    return f


def test_defaults_without_a_report_and_their_sources(tmp_path):
    d = write_case(tmp_path / "gg", "GG")
    s = resolve_section(d)
    assert (s.width_mm, s.thickness_mm, s.scale, s.material) == (20.0, 1.0, 0.1, "pp")
    assert dict(s.sources) == dict.fromkeys(("width", "thickness", "scale", "material"),
                                            "defaults")
    # real size = cut size / scale, metres
    assert (s.width_m, s.thickness_m) == pytest.approx((0.2, 0.01))
    assert resolve_section(None) == s and s.source == "defaults"


def test_caller_then_report_then_defaults_field_by_field(tmp_path):
    d = write_case(tmp_path / "gg", "GG")
    f = _report(d, {"width": 12.0, "scale": 0.05, "hole": 2.0})
    s = resolve_section(d, thickness=2, scale="1:4")
    assert (s.width_mm, s.thickness_mm, s.scale) == (12.0, 2.0, 0.25)
    assert s.sources == {"width": str(f), "thickness": "given", "scale": "given",
                         "material": "defaults"}
    assert s.given("thickness") and not s.given("width")
    assert s.source == f"{f} (width), given (thickness, scale)"
    t = resolve_section(d, material="spruce")
    assert (t.width_mm, t.thickness_mm, t.scale, t.material) == (12.0, 1.0, 0.05, "spruce")
    assert t.sources["thickness"] == "defaults" and t.given("material")
    # stored=False (what fabricate uses): the report is not read at all
    assert resolve_section(d, stored=False).source == "defaults"


@pytest.mark.parametrize("content, why", [
    ("{not json", "not JSON"),
    ("[1, 2]", "not a JSON object"),
    (json.dumps({"params": [20, 1]}), "'params' is not an object"),
    (json.dumps({"params": {"width": -3}}), "params.width is -3"),
    (json.dumps({"params": {"scale": "1:10"}}), "params.scale is '1:10'"),
])
def test_a_broken_report_is_an_error_naming_it_and_the_fix(tmp_path, content, why):
    d = write_case(tmp_path / "gg", "GG")
    f = _report(d, content)
    with pytest.raises(InputError) as e:
        resolve_section(d)
    msg = str(e.value)
    assert str(f) in msg and why in msg and "gridshell fabricate" in msg and "\n" not in msg
    # the caller's values do not hide a broken report: every command says the same
    with pytest.raises(InputError, match="not a readable fabrication report"):
        resolve_section(d, width=10, thickness=1, scale=0.1)


def test_undecodable_bytes_are_an_unreadable_report(tmp_path):
    d = write_case(tmp_path / "gg", "GG")
    f = d / FABRICATION_REPORT
    f.parent.mkdir()
    f.write_bytes(b"\xff\xfe\x00{")
    with pytest.raises(InputError, match="cannot be read"):
        resolve_section(d)


@pytest.mark.parametrize("argv", [["check", "--no-picture"], ["simulate"], ["export"],
                                  ["render", "--no-sequence"]])
def test_every_command_exits_2_with_one_line_on_a_broken_report(tmp_path, capsys, argv):
    d = write_case(tmp_path / "gg", "GG")
    f = _report(d, "{broken")
    before = sorted(p.name for p in d.iterdir())
    assert main([argv[0], str(d), *argv[1:], "-q"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and str(f) in err and "Traceback" not in err
    assert sorted(p.name for p in d.iterdir()) == before     # nothing written


@pytest.mark.parametrize("bad, what", [({"width": 0}, "--width"), ({"thickness": float("nan")},
                                       "--thickness"), ({"scale": "ten"}, "scale"),
                                      ({"material": ""}, "material")])
def test_bad_caller_values_are_refused(bad, what):
    with pytest.raises(InputError, match=what):
        resolve_section(None, **bad)


def test_scale_text_and_parse_scale_are_inverse():
    for s in (0.1, 0.05, 1.0, 2.0, 0.125):
        assert parse_scale(scale_text(s)) == pytest.approx(s)
    assert parse_scale("1:10") == 0.1 and scale_text(0.1) == "1:10"


def test_fabparams_defaults_are_the_resolvers():
    from gridshell.fabrication.params import FabParams

    p = FabParams()
    assert (p.width, p.thickness, p.scale) == (DEFAULTS["width"], DEFAULTS["thickness"],
                                               DEFAULTS["scale"])


@pytest.mark.parametrize("stored", [None, {"width": 14.0, "thickness": 0.8, "scale": 0.05}])
def test_check_simulate_render_and_export_see_the_same_strip(tmp_path, stored):
    """The bundle's strip as each command receives it: the structural check's structure.json,
    the equilibrium's record, the viewer's scene and the .3dm's strips."""
    pytest.importorskip("rhino3dm")
    from gridshell import api
    from gridshell.render.viewer.scene import build_scene

    d = write_case(tmp_path / "gg", "GG")
    if stored:
        _report(d, stored)
    want = stored or {k: DEFAULTS[k] for k in ("width", "thickness", "scale")}
    w_m = 1e-3 * want["width"] / want["scale"]
    t_m = 1e-3 * want["thickness"] / want["scale"]

    chk = api.check_structure(d, states=False, write=False, picture=False)
    sec = chk.result["section"]
    assert (sec["width_mm"], sec["thickness_mm"], sec["scale"]) == tuple(want.values())
    assert chk.section.source == ("defaults" if stored is None else str(d / FABRICATION_REPORT))

    sim = api.simulate(d, per_bay=1, max_iter=3, write=False)
    rec = sim.record["section"]
    assert (rec["width_mm"], rec["thickness_mm"], rec["scale"]) == tuple(want.values())

    scene = build_scene(d)["section"]
    assert (scene["width_m"], scene["thickness_m"]) == pytest.approx((w_m, t_m), rel=1e-12)

    info = api.export_3dm(d, tmp_path / "gg.3dm", sheets=False)
    assert (info["strip_width_m"], info["strip_thickness_m"]) == pytest.approx((w_m, t_m),
                                                                                rel=1e-12)
    assert (info["params"]["width"], info["params"]["thickness"],
            info["params"]["scale"]) == tuple(want.values())
