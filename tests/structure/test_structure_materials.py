"""Materials and sections: presets, user values, section properties against closed forms and
Timoshenko & Goodier's table of rectangular torsion coefficients."""
import math

import numpy as np
import pytest

from gridshell.fabrication.params import FabParams
from gridshell.core.errors import InputError
from gridshell.structure import MATERIALS, Section, get_material, material_names, user_material
from gridshell.structure.section import torsion_beta, torsion_stress_factor


def test_presets_complete_and_sourced():
    for name in ("pp", "petg", "birch-plywood", "spruce", "gfrp", "aluminium"):
        m = get_material(name)
        assert m.E > m.G > 0 and m.allowable > 0 and m.density > 0
        assert len(m.source) > 20
        assert 1e-3 < m.elastic_strain < 0.1
    assert material_names() == list(MATERIALS)
    assert get_material("Polypropylene") is MATERIALS["pp"]
    assert get_material("aluminum") is MATERIALS["aluminium"]


def test_isotropic_presets_consistent():
    for m in MATERIALS.values():
        if m.nu is not None:
            assert m.G == pytest.approx(m.E / (2 * (1 + m.nu)), rel=0.02)


def test_unknown_material_names_choices():
    with pytest.raises(InputError, match="pp, petg"):
        get_material("steel-ish")


def test_user_values():
    pp = get_material("pp")
    m = user_material("pp", E=2.0e9)
    assert m.E == 2.0e9 and m.G == pytest.approx(2.0e9 / (2 * 1.42))
    assert m.allowable == pp.allowable
    sp = user_material("spruce", E=12e9)
    assert sp.G == MATERIALS["spruce"].G  # orthotropic: measured G kept
    g = user_material("gfrp", allowable_stress=100e6)
    assert g.allowable == 100e6  # the user's stress governs, not the preset's 1 % strain
    own = user_material(None, E=3e9, allowable_stress=40e6)
    assert own.G == pytest.approx(3e9 / 2.7) and own.allowable == 40e6
    with pytest.raises(InputError):
        user_material(None, E=3e9)
    with pytest.raises(InputError):
        user_material("pp", E=-1.0)
    with pytest.raises(InputError):
        user_material("pp", E=float("nan"))


def test_strain_limit_governs():
    g = get_material("gfrp")
    assert g.allowable == pytest.approx(min(g.allowable_stress, g.E * g.allowable_strain))


def test_section_closed_forms():
    s = Section(20.0, 1.0, 0.1)
    w, t = 0.020, 0.001
    assert s.area == pytest.approx(w * t)
    assert s.I_weak == pytest.approx(w * t ** 3 / 12)
    assert s.I_strong == pytest.approx(t * w ** 3 / 12)
    assert s.W_weak == pytest.approx(w * t ** 2 / 6)
    assert s.W_strong == pytest.approx(t * w ** 2 / 6)
    # thin strip: J -> w t^3 / 3 (1 - 0.630 t / w) to first order
    assert s.J == pytest.approx(w * t ** 3 / 3 * (1 - 0.630 * t / w), rel=1e-3)
    assert s.J < w * t ** 3 / 3
    assert s.strip_curvature(1.0) == pytest.approx(10.0)
    assert s.strip_length(2.0) == pytest.approx(0.2)
    assert s.edge_ratio == 20.0


@pytest.mark.parametrize("ab, alpha, beta", [
    (1, 0.208, 0.141), (1.5, 0.231, 0.196), (2, 0.246, 0.229), (3, 0.267, 0.263),
    (4, 0.282, 0.281), (6, 0.299, 0.299), (10, 0.312, 0.312)])
def test_torsion_coefficients_match_timoshenko(ab, alpha, beta):
    """Timoshenko & Goodier table (sec. 109): J = beta a b^3, tau_max = T / (alpha a b^2)."""
    r = 1 / ab
    assert torsion_beta(r) == pytest.approx(beta, rel=4e-3)
    assert torsion_beta(r) / torsion_stress_factor(r) == pytest.approx(alpha, rel=4e-3)


def test_torsion_thin_limit_and_modulus():
    assert torsion_beta(1e-5) == pytest.approx(1 / 3, rel=1e-4)
    assert torsion_stress_factor(1e-5) == pytest.approx(1.0, rel=1e-4)
    s = Section(30.0, 3.0)
    a, b = 0.03, 0.003
    # tau_max = T / W_t with T = G J theta' equals k G b theta'
    assert s.W_torsion == pytest.approx(s.J / (torsion_stress_factor(b / a) * b))
    sq = Section(10.0, 10.0)
    assert sq.J == pytest.approx(0.1406 * 0.01 ** 4, rel=2e-3)
    assert np.allclose(torsion_beta(np.array([0.1, 0.2])),
                       [torsion_beta(0.1), torsion_beta(0.2)])


def test_section_from_fabrication_params():
    p = FabParams(width=25.0, thickness=1.5, scale="1:20")
    s = Section.from_params(p)
    assert (s.width_mm, s.thickness_mm, s.scale) == (25.0, 1.5, 0.05)
    assert s.to_json()["scale_text"] == "1:20"
    for bad in (0.0, -1.0, math.nan):
        with pytest.raises(InputError):
            Section(20.0, bad)
