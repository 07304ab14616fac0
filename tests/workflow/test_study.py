"""The study of a sweep: --vary values and ranges, Latin hypercube samples, variant keys, files."""
from __future__ import annotations

import json

import numpy as np
import pytest

from gridshell.core.errors import InputError
from gridshell.workflow.study import Study, parse_vary, read_study, variant_key


def test_vary_values_and_ranges():
    values, ranges = parse_vary(["lamellae=8,12,16", "material=pp,petg", "angle=60:120",
                                 "scale=1:10,1:20"])
    assert values == {"lamellae": [8, 12, 16], "material": ["pp", "petg"],
                      "scale": ["1:10", "1:20"]}
    assert ranges == {"angle": (60.0, 120.0)}


@pytest.mark.parametrize("item,word", [
    ("lamellae", "NAME=V1"), ("colour=red", "unknown sweep parameter"),
    ("lamellae=1", "fewer than 2"), ("lamellae=8,8", "twice"), ("angle=120:60", "empty"),
    ("material=unobtainium", "unobtainium"), ("kind=ggg", "kind"), ("width=-1", "positive"),
    ("spacing=nan", "finite"), ("material=pp:petg", "unknown material"), ("sheet=600", "sheet"),
])
def test_bad_vary_names_the_problem(item, word):
    with pytest.raises(InputError, match=word):
        parse_vary([item])


def test_factorial_study_makes_every_combination_once():
    st = Study("t.obj", {"lamellae": [8, 12], "material": ["pp", "petg"], "kind": ["gg", "cnc"]})
    v = st.variants()
    assert len(st) == len(v) == 8
    assert len({json.dumps(x, sort_keys=True) for x in v}) == 8


def test_latin_hypercube_puts_one_sample_in_each_stratum():
    n = 16
    st = Study("t.obj", {"material": ["pp", "petg"]},
               {"angle": (60.0, 120.0), "spacing": (0.1, 0.5)}, samples=n, sampling="lhs", seed=3)
    v = st.variants()
    assert len(v) == 2 * n
    for name, (lo, hi) in st.ranges.items():
        x = np.array([p[name] for p in v[:n]])
        strata = np.floor((x - lo) / (hi - lo) * n).clip(0, n - 1).astype(int)
        assert sorted(strata) == list(range(n))        # one sample per stratum
    assert [p["angle"] for p in v[:n]] == [p["angle"] for p in v[n:]]  # same points per combo
    again = Study("t.obj", {"material": ["pp", "petg"]},
                  {"angle": (60.0, 120.0), "spacing": (0.1, 0.5)}, samples=n, seed=3).variants()
    assert again == v                                   # seeded: the same study twice


def test_a_range_needs_samples_and_studies_are_bounded():
    with pytest.raises(InputError, match="--samples"):
        Study("t.obj", {}, {"angle": (60.0, 120.0)})
    with pytest.raises(InputError, match="more than"):
        Study("t.obj", {"lamellae": list(range(2, 200)), "angle": [float(a) for a in
                                                                   range(1, 100)]})


def test_variant_key_is_the_content_of_target_parameters_and_version():
    k = variant_key("a" * 64, {"lamellae": 8, "kind": "gg"}, "1.0")
    assert k == variant_key("a" * 64, {"kind": "gg", "lamellae": 8}, "1.0")  # order-free
    others = {variant_key("b" * 64, {"lamellae": 8, "kind": "gg"}, "1.0"),
              variant_key("a" * 64, {"lamellae": 9, "kind": "gg"}, "1.0"),
              variant_key("a" * 64, {"lamellae": 8, "kind": "gg"}, "1.1"),
              variant_key("a" * 64, {"lamellae": 8, "kind": "gg"}, "1.0", "mm")}
    assert k not in others and len(others) == 4


def test_study_file_json_and_yaml(tmp_path):
    (tmp_path / "hill.obj").write_text("v 0 0 0\n")
    spec = {"target": "hill.obj", "parameters": {"lamellae": [8, 12], "angle": {"range": [70, 110]}},
            "samples": 4, "seed": 1, "fixed": {"material": "petg"}}
    (tmp_path / "s.json").write_text(json.dumps(spec))
    st = read_study(tmp_path / "s.json")
    assert st.target == str(tmp_path / "hill.obj") and len(st) == 8
    assert all(v["material"] == "petg" for v in st.variants())
    yaml = pytest.importorskip("yaml")
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(spec))
    assert read_study(tmp_path / "s.yaml").variants() == st.variants()
    (tmp_path / "bad.json").write_text("{")
    with pytest.raises(InputError, match="not valid JSON"):
        read_study(tmp_path / "bad.json")
    (tmp_path / "odd.json").write_text(json.dumps({**spec, "colour": 1}))
    with pytest.raises(InputError, match="unknown study keys colour"):
        read_study(tmp_path / "odd.json")
