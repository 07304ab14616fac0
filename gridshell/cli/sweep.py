"""``gridshell sweep``: a design study on Dask - every variant designed, verified, checked and
cut as one task, one results table (:func:`gridshell.api.sweep`)."""
from __future__ import annotations

import argparse
import sys
from typing import Any

from gridshell.cli.values import count

HELP = ("explore the design space: every combination of --vary values (or samples of ranges) "
        "designed, verified, checked and cut on Dask (a local cluster or --scheduler); "
        "results.parquet, sweep.html")


def _vary(text: str) -> str:
    """One ``--vary NAME=V1,V2`` / ``NAME=LO:HI``, checked while parsing (kept as text)."""
    from gridshell.core.errors import InputError
    from gridshell.workflow.study import parse_vary

    try:
        parse_vary([text])
    except InputError as exc:
        raise argparse.ArgumentTypeError(str(exc).replace(f"--vary {text!r}: ", "")) from None
    return text


_vary.refused = ["lamellae=1", "colour=red", "material=unobtainium", "angle=120:60",
                 "lamellae=", "scale=0"]  # type: ignore[attr-defined]


def add_args(p: argparse.ArgumentParser) -> None:
    from gridshell.workflow.study import PARAMETERS, SAMPLINGS

    p.add_argument("target", nargs="?", help="the model every variant is designed on (mesh or "
                                             ".3dm); or give --study")
    p.add_argument("-o", "--output", required=True, metavar="DIR",
                   help="study directory: results.parquet, sweep.html, sweep.png, variants/; "
                        "a re-run skips the variants already done")
    p.add_argument("--vary", action="append", type=_vary, default=[], metavar="NAME=VALUES",
                   help="a parameter and its values, V1,V2,... (every combination is a variant) "
                        "or a range LO:HI (sampled --samples times); repeat for more. NAME: "
                        + "; ".join(f"{k} ({v[0]})" for k, v in PARAMETERS.items()))
    p.add_argument("--study", metavar="FILE",
                   help="a study file (JSON or YAML): target, parameters, sampling, samples, "
                        "seed, units; --vary adds to its parameters")
    p.add_argument("--samples", type=count(1), metavar="N",
                   help="samples of the ranges (default 8 when a range is given)")
    p.add_argument("--sampling", choices=SAMPLINGS[1:], default=None,
                   help="how ranges are sampled: lhs (Latin hypercube, default) or random")
    p.add_argument("--seed", type=count(0), default=None, metavar="N",
                   help="seed of the sampling (default 0)")
    from gridshell.core.units import UNITS

    p.add_argument("--units", choices=tuple(UNITS), metavar="|".join(UNITS),
                   help="the unit the target is drawn in, when the file does not say")
    p.add_argument("--workers", type=count(1, maximum=512), metavar="N",
                   help="processes of the local Dask cluster (default: the cores)")
    p.add_argument("--scheduler", metavar="tcp://HOST:8786",
                   help="run on a running Dask cluster instead (dask scheduler + dask worker; "
                        "the workers need DIR on a shared filesystem)")
    p.add_argument("--no-page", action="store_true", help="do not write sweep.html / sweep.png")


def study_of(args: Any) -> Any:
    """The :class:`~gridshell.workflow.study.Study` of the command line."""
    from gridshell.core.errors import InputError
    from gridshell.workflow.study import Study, parse_vary, read_study

    values, ranges = parse_vary(args.vary)
    if args.study:
        base = read_study(args.study)
        target = args.target or base.target
        values, ranges = {**base.values, **values}, {**base.ranges, **ranges}
        samples, sampling, seed = base.samples, base.sampling, base.seed
        units, fixed = args.units or base.units, base.fixed
    else:
        if not args.target:
            raise InputError("give the TARGET model (or a --study file)")
        target, samples, sampling, seed, units, fixed = args.target, 0, "grid", 0, args.units, {}
    if not values and not ranges:
        raise InputError("nothing varies: give --vary NAME=V1,V2 (e.g. --vary lamellae=8,12,16)")
    if ranges:  # a study with ranges samples them by Latin hypercube unless told (Study)
        samples, sampling = args.samples or samples or 8, args.sampling or sampling
    return Study(str(target), values, ranges, samples=samples, sampling=sampling,
                 seed=seed if args.seed is None else args.seed, units=units, fixed=fixed)


def run(args: Any) -> int:
    from gridshell.api import sweep
    from gridshell.cli.common import Progress, print_summary

    study = study_of(args)
    progress = Progress(args)
    res = sweep(study, args.output, workers=args.workers, scheduler=args.scheduler,
                progress=progress.callback, bar=sys.stderr.isatty() and not args.quiet,
                page=not args.no_page)
    t = res.table
    codes = t["code"].value_counts().sort_index()
    summary = {
        "study": f"{len(t)} variants of {study.target}: "
                 + ", ".join(f"{k} x{len(v)}" for k, v in study.values.items())
                 + "".join(f", {k} {lo:g}..{hi:g}" for k, (lo, hi) in study.ranges.items())
                 + (f" ({study.samples} {study.sampling} samples)" if study.ranges else ""),
        "ran / done before": f"{res.ran} / {res.reused} in {res.seconds:.1f} s",
        "exit codes": ", ".join(f"{int(c)}: {n}" for c, n in codes.items()),
        "results": str(res.results),
    }
    cut = t[t["code"] == 0]
    if len(cut):
        best = cut.sort_values(["max_utilisation", "sheets"]).iloc[0]
        summary["lowest utilisation"] = (f"{best['max_utilisation']:.3g} ({best['key']}: "
                                         + ", ".join(f"{k}={best[k]}" for k in
                                                     [*study.values, *study.ranges]) + ")")
    if res.page is not None:
        summary["open"] = str(res.page)
    print_summary(args, "gridshell sweep", summary)
    return 0
