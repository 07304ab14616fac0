"""Helpers shared by the subcommands: progress reporting and summaries."""
from __future__ import annotations

import json
import sys
import time
from typing import Any, Callable, Iterable, Mapping

from gridshell.measure.quality import Gate


class Progress:
    """Progress messages on stderr, with the elapsed time; silent with ``-q``."""

    def __init__(self, args: Any) -> None:
        self.quiet = bool(getattr(args, "quiet", False))
        self.verbose = int(getattr(args, "verbose", 0) or 0)
        self.t0 = time.perf_counter()

    def __call__(self, msg: str) -> None:
        if not self.quiet:
            print(f"[{time.perf_counter() - self.t0:7.1f}s] {msg}", file=sys.stderr, flush=True)

    def detail(self, msg: str) -> None:
        """A message shown only with ``-v``."""
        if self.verbose and not self.quiet:
            self(msg)

    @property
    def callback(self) -> Callable[[str], None]:
        return self


def choice_help(descriptions: Mapping[str, str], choices: Iterable[str], default: str,
                describe: Callable[[str], str] | None = None) -> str:
    """Help text of an option whose ``choices`` come from a registry: ``"a: what a does; b:
    ...; default a"``, with ``describe(choice)`` or ``descriptions[choice]``. A choice the
    registry gained but ``descriptions`` lacks is still listed, by name."""
    describe = describe or (lambda c: descriptions.get(c, ""))
    parts = [f"{c}: {describe(c)}" if describe(c) else str(c) for c in choices]
    return "; ".join(parts) + f" (default {default})"


def add_bundle_arg(p: Any, note: str = "") -> None:
    """The positional design bundle ``DIR`` of a command that reads one (``note``: what the
    command puts into it)."""
    p.add_argument("bundle", metavar="DIR",
                   help="design bundle (output of 'gridshell gg' or 'ncp')" + note)


def add_input_args(p: Any) -> None:
    """``--units``, ``--no-clean`` and ``--object``: how a command reads the user's geometry
    (:func:`gridshell.io.read.read_input`)."""
    from gridshell.core.units import UNITS

    p.add_argument("--units", choices=tuple(UNITS), metavar="|".join(UNITS),
                   help="the unit the input is drawn in (default: a .3dm's own unit system, "
                        "else metres; a model whose size reads as another unit is refused "
                        "until this is given). Everything inside is metres; the bundle records "
                        "the unit")
    p.add_argument("--no-clean", action="store_true",
                   help="do not weld coincident vertices, drop duplicate faces and unreferenced "
                        "vertices, or orient the faces consistently before the checks "
                        "(pymeshlab; default: clean, and say what was done)")
    p.add_argument("--object", metavar="NAME|ID|LAYER",
                   help=".3dm input: the object to read (a mesh, NURBS surface or single-face "
                        "Brep) by name, id or layer, when the file holds several")


def input_options(args: Any) -> dict[str, Any]:
    """The keyword arguments of :func:`gridshell.io.read.read_input` given on the command
    line (:func:`add_input_args`)."""
    return {"units": getattr(args, "units", None), "clean": not getattr(args, "no_clean", False),
            "obj": getattr(args, "object", None)}


def input_line(info: dict | None) -> str:
    """The summary's input line from ``params["input"]`` (:meth:`gridshell.io.read.
    InputGeometry.info`): the object, the unit, what cleaning did, notes."""
    if not info:
        return "-"
    units = (info.get("units") or {}).get("name", "m")
    if info.get("surface"):
        clean = "NURBS surface"
    elif info.get("clean"):
        clean = info["clean"].get("summary", "-")
    else:
        clean = "not cleaned (--no-clean)"
    parts = [f"units {units}" + (" (the file's)" if info.get("units_source") == "file" else ""),
             clean, *(info.get("notes") or [])]
    if info.get("object"):
        parts.insert(0, str(info["object"]))
    return "; ".join(parts)


def print_summary(args: Any, title: str, summary: dict[str, Any]) -> None:
    """One-screen summary on stdout, or JSON with ``--json``."""
    if getattr(args, "json", False):  # strict JSON: a figure not measured is null, not NaN
        from gridshell.design.bundle import finite_json

        print(json.dumps(finite_json({"ok": True, **summary}), indent=1, default=_default,
                         allow_nan=False))
        return
    print(title)
    width = max((len(k) for k in summary), default=0)
    for k, v in summary.items():
        print(f"  {k:<{width}}  {_fmt(v)}")


def print_gates(args: Any, summary: dict, title: str, quality: dict) -> None:
    """The summary, ending with one pass / FAIL line per figure of ``quality`` (``{"ok",
    "gates": [Gate.as_dict()]}``); with ``--json`` as ``summary["quality"]``."""
    if getattr(args, "json", False):
        print_summary(args, title, {**summary, "quality": quality})
        return
    print_summary(args, title, {**summary, "quality": "pass" if quality["ok"] else "FAIL"})
    for line in quality_lines(quality["gates"]):
        print(f"    {line}")


def quality_lines(gates: list[dict]) -> list[str]:
    """The pass / FAIL lines of a design's gates (``Gate.as_dict()`` records): the lamella
    fairness first (the checks that hold on one line, each failing one on its own), then one
    line per figure of the paper."""
    fair = [g for g in gates if str(g.get("name", "")).startswith("fair_")]
    line = (lambda g: g.get("line") or Gate.from_dict(g).line())
    out = []
    held = [g for g in fair if g.get("ok", False)]
    if held:
        radius = next((g["detail"].split(" (")[0] for g in held if g["name"] == "fair_radius"
                       and g.get("detail")), None)
        out.append(f"pass  lamella fairness: {len(held)} of {len(fair)} checks hold (radius, "
                   "corners, hairpins, loops, distance from the surface, folds"
                   + (f"; smallest in-plane radius {radius}" if radius else "") + ")")
    out += [line(g) for g in fair if not g.get("ok", False)]
    return out + [line(g) for g in gates if g not in fair]


def _fmt(v: Any) -> str:
    if isinstance(v, float):
        return f"{v:.4g}"
    if isinstance(v, dict):
        return ", ".join(f"{k}={_fmt(x)}" for k, x in v.items())
    return str(v)


def _default(o: Any) -> Any:
    try:
        import numpy as np
        if isinstance(o, np.generic):
            return o.item()
        if isinstance(o, np.ndarray):
            return o.tolist()
    except ImportError:  # pragma: no cover
        pass
    return str(o)
