"""A design study: the parameters a sweep varies, their values, and the variants they make.

A study is a target model and, per parameter, either a list of values (every combination is
a variant: a full factorial) or a range ``{"range": [lo, hi]}`` sampled ``samples`` times,
at random or by Latin hypercube (``sampling``). From the command line::

    --vary lamellae=8,12,16 --vary material=pp,petg --vary kind=gg,cnc
    --vary angle=60:120 --samples 10 --sampling lhs

or a study file (JSON, or YAML where PyYAML is installed)::

    {"target": "hill.3dm", "units": "mm",
     "parameters": {"lamellae": [8, 12, 16], "kind": ["gg", "cnc"], "angle": {"range": [60, 120]}},
     "sampling": "lhs", "samples": 10, "seed": 0}

Each variant is a dict of parameter values (units: lamellae per family, spacing metres,
angle and direction degrees, width and thickness mm of the cut strip, scale ``"1:10"``,
sheet ``"600x400"`` mm) and is keyed by the content hash of the target file's bytes, the
variant's parameters and the tool's version (:func:`variant_key`): the name of its directory
under ``variants/`` and what makes a re-run skip it.
"""
from __future__ import annotations

import hashlib
import itertools
import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

from gridshell.core.errors import InputError

__all__ = ["PARAMETERS", "KINDS", "Study", "parse_vary", "read_study", "variant_key"]

#: the design kinds a variant can be: GG, or an NCP mode
KINDS = ("gg", "phlw", "cnc", "aa")
#: parameter name -> (what it is, the type of one value)
PARAMETERS: dict[str, tuple[str, type]] = {
    "kind": ("the pipeline and mode: " + ", ".join(KINDS), str),
    "lamellae": ("lamellae per family (GG --lamellae, NCP --curves)", int),
    "spacing": ("spacing of the lamellae, metres (instead of lamellae)", float),
    "angle": ("GG crossing angle on the reference parallel, degrees", float),
    "direction": ("GG meridian direction on a triangle mesh, degrees", float),
    "material": ("strip material preset (gridshell check --help lists them)", str),
    "width": ("strip width as cut, mm", float),
    "thickness": ("strip thickness as cut, mm", float),
    "scale": ("model scale, e.g. 1:10 (1:1 full size)", str),
    "sheet": ("sheet size in mm, e.g. 600x400", str),
}
SAMPLINGS = ("grid", "random", "lhs")
#: the most variants one study may hold (a typo in a range must not start a million designs)
MAX_VARIANTS = 10000


@dataclass(frozen=True)
class Study:
    """A target and the parameter axes of a sweep.

    ``values``: parameter -> list of values (a factorial axis); ``ranges``: parameter ->
    (lo, hi) sampled ``samples`` times (``sampling`` "random" or "lhs", ``seed``); ``fixed``:
    parameters every variant shares.
    """

    target: str
    values: dict[str, list[Any]] = field(default_factory=dict)
    ranges: dict[str, tuple[float, float]] = field(default_factory=dict)
    samples: int = 0
    sampling: str = "grid"
    seed: int = 0
    units: str | None = None
    fixed: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        for name in [*self.values, *self.ranges, *self.fixed]:
            _known(name)
        if self.sampling not in SAMPLINGS:
            raise InputError(f"sampling {self.sampling!r} is not one of {', '.join(SAMPLINGS)}")
        if self.ranges and self.samples < 1:
            raise InputError(f"the ranges of {', '.join(self.ranges)} need a sample count: "
                             "give --samples N (N >= 1)")
        if self.ranges and self.sampling == "grid":
            object.__setattr__(self, "sampling", "lhs")
        if len(self) > MAX_VARIANTS:
            raise InputError(f"the study has {len(self)} variants, more than {MAX_VARIANTS}: "
                             "give fewer values or samples")

    def __len__(self) -> int:
        n = math.prod(len(v) for v in self.values.values()) if self.values else 1
        return n * (self.samples if self.ranges else 1)

    def variants(self) -> list[dict[str, Any]]:
        """Every variant of the study, in a fixed order: the factorial combinations of
        ``values``, each with the ``samples`` points of ``ranges`` (the same points for every
        combination, so a parameter's effect is seen on the same samples)."""
        names = list(self.values)
        combos = [dict(zip(names, c)) for c in itertools.product(*self.values.values())]
        points = self._sample() if self.ranges else [{}]
        return [{**self.fixed, **c, **p} for c in combos for p in points]

    def _sample(self) -> list[dict[str, float]]:
        import numpy as np

        rng = np.random.default_rng(self.seed)
        k, n = len(self.ranges), self.samples
        if self.sampling == "lhs":  # one sample in each of n strata per axis, strata shuffled
            u = (np.argsort(rng.random((n, k)), axis=0) + rng.random((n, k))) / n
        else:
            u = rng.random((n, k))
        out = []
        for row in u:
            p = {}
            for (name, (lo, hi)), t in zip(self.ranges.items(), row):
                v = lo + float(t) * (hi - lo)
                p[name] = int(round(v)) if PARAMETERS[name][1] is int else round(v, 9)
            out.append(p)
        return out

    def as_dict(self) -> dict[str, Any]:
        """The study as its file holds it (``study.json`` of a sweep's directory)."""
        d: dict[str, Any] = {"target": self.target, "parameters": {
            **{k: list(v) for k, v in self.values.items()},
            **{k: {"range": list(v)} for k, v in self.ranges.items()}}}
        if self.fixed:
            d["fixed"] = dict(self.fixed)
        if self.ranges:
            d.update(sampling=self.sampling, samples=self.samples, seed=self.seed)
        if self.units:
            d["units"] = self.units
        return d


def _known(name: str) -> None:
    if name not in PARAMETERS:
        raise InputError(f"unknown sweep parameter {name!r}; choose from "
                         f"{', '.join(PARAMETERS)}")


def _value(name: str, text: Any) -> Any:
    """One value of parameter ``name`` checked and converted (``text`` a string or a number)."""
    kind = PARAMETERS[name][1]
    try:
        v = kind(float(text)) if kind is int and not isinstance(text, str) else kind(text)
    except (TypeError, ValueError):
        raise InputError(f"sweep parameter {name}: {text!r} is not a valid "
                         f"{'integer' if kind is int else 'number' if kind is float else 'value'}"
                         f" ({PARAMETERS[name][0]})") from None
    if kind is float and not math.isfinite(v):
        raise InputError(f"sweep parameter {name}: {text!r} is not a finite number")
    if name == "kind" and v not in KINDS:
        raise InputError(f"sweep parameter kind: {v!r} is not one of {', '.join(KINDS)}")
    if name == "lamellae" and v < 2:
        raise InputError(f"sweep parameter lamellae: {v} is fewer than 2 per family")
    if name in ("spacing", "width", "thickness") and v <= 0:
        raise InputError(f"sweep parameter {name}: {v!r} must be positive")
    if name == "angle" and not 0 < v < 180:
        raise InputError(f"sweep parameter angle: {v!r} must lie in (0, 180) degrees")
    if name == "material":
        from gridshell.structure.materials import get_material

        get_material(v)
    if name == "scale":
        from gridshell.design.section import parse_scale

        parse_scale(v)
    if name == "sheet":
        from gridshell.fabrication.params import parse_sheet

        parse_sheet(v)
    return v


def parse_vary(items: list[str]) -> tuple[dict[str, list[Any]], dict[str, tuple[float, float]]]:
    """``["lamellae=8,12", "angle=60:120"]`` -> (values, ranges); one line of error naming
    the item and the fix otherwise."""
    values: dict[str, list[Any]] = {}
    ranges: dict[str, tuple[float, float]] = {}
    for item in items:
        name, sep, rest = item.partition("=")
        name = name.strip()
        if not sep or not rest.strip():
            raise InputError(f"--vary {item!r}: write NAME=V1,V2,... or NAME=LO:HI, e.g. "
                             "lamellae=8,12,16")
        _known(name)
        if name in values or name in ranges:
            raise InputError(f"--vary {name} is given twice; give its values once")
        if ":" in rest and PARAMETERS[name][1] is not str:  # a scale 1:10 is a value
            ranges[name] = _range(name, rest.split(":"))
        else:
            values[name] = _values(name, [v.strip() for v in rest.split(",")])
    return values, ranges


def _values(name: str, raw: list[Any]) -> list[Any]:
    if not raw or any(v == "" for v in raw):
        raise InputError(f"sweep parameter {name}: an empty value in {raw!r}")
    vals = [_value(name, v) for v in raw]
    if len(set(map(str, vals))) != len(vals):
        raise InputError(f"sweep parameter {name}: a value is given twice in {raw!r}")
    return vals


def _range(name: str, bounds: list[Any]) -> tuple[float, float]:
    if PARAMETERS[name][1] is str:
        raise InputError(f"sweep parameter {name} takes a list of values, not a range: "
                         f"{name}=A,B")
    if len(bounds) != 2:
        raise InputError(f"sweep parameter {name}: a range is LO:HI, got {':'.join(bounds)}")
    lo, hi = (float(_value(name, b)) for b in bounds)
    if not lo < hi:
        raise InputError(f"sweep parameter {name}: the range {lo:g}:{hi:g} is empty (LO < HI)")
    return lo, hi


def read_study(path: str | os.PathLike) -> Study:
    """The study of a JSON (or YAML) file; its target path relative to the file."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except OSError as exc:
        raise InputError(f"cannot read the study file {p}: {exc.strerror or exc}") from None
    try:
        if p.suffix.lower() in (".yaml", ".yml"):
            try:
                import yaml
            except ImportError:
                raise InputError("a YAML study needs PyYAML: pip install pyyaml (or write "
                                 "the study as JSON)") from None
            data = yaml.safe_load(text)
        else:
            data = json.loads(text)
    except ValueError as exc:
        raise InputError(f"the study file {p} is not valid {p.suffix[1:].upper() or 'JSON'}: "
                         f"{str(exc).splitlines()[0]}") from None
    return study_from_dict(data, base=p.parent)


def study_from_dict(data: Any, base: str | os.PathLike = ".") -> Study:
    """A :class:`Study` from its dict (the file's content; ``target`` relative to ``base``)."""
    if not isinstance(data, Mapping) or "target" not in data:
        raise InputError("a study names its 'target' (a model file) and its 'parameters'")
    unknown = set(data) - {"target", "parameters", "fixed", "sampling", "samples", "seed", "units"}
    if unknown:
        raise InputError(f"unknown study keys {', '.join(sorted(unknown))}; the keys are "
                         "target, parameters, fixed, sampling, samples, seed, units")
    params = data.get("parameters") or {}
    if not isinstance(params, Mapping):
        raise InputError("the study's 'parameters' map names to lists of values or ranges")
    values, ranges = {}, {}
    for name, spec in params.items():
        _known(name)
        if isinstance(spec, Mapping) and "range" in spec:
            ranges[name] = _range(name, [str(b) for b in spec["range"]])
        else:
            values[name] = _values(name, spec if isinstance(spec, list) else [spec])
    fixed = {}
    for name, v in (data.get("fixed") or {}).items():
        _known(name)
        fixed[name] = _value(name, v)
    target = Path(str(data["target"]))
    target = target if target.is_absolute() else Path(base) / target
    return Study(str(target), values, ranges, samples=int(data.get("samples", 0) or 0),
                 sampling=str(data.get("sampling", "grid")), seed=int(data.get("seed", 0)),
                 units=data.get("units"), fixed=fixed)


def variant_key(target_sha256: str, params: Mapping[str, Any], version: str,
                units: str | None = None) -> str:
    """The variant's content hash (16 hex digits): target bytes, parameters, tool version."""
    blob = json.dumps({"target": target_sha256, "params": dict(sorted(params.items())),
                       "version": version, "units": units}, sort_keys=True, default=str)
    return hashlib.sha256(blob.encode()).hexdigest()[:16]


def file_sha256(path: str | os.PathLike) -> str:
    """sha256 of a file's bytes (the target's part of every variant's key)."""
    from gridshell.core.manifest import sha256_of

    try:
        return sha256_of(path)
    except OSError as exc:
        raise InputError(f"cannot read the target {path}: {exc.strerror or exc}") from None
