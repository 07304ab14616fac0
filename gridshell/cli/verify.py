"""``gridshell verify``: recompute a bundle's metrics (paper 5.1) from its files alone and
check them against the paper's thresholds (:mod:`gridshell.measure.quality`).

Prints the JSON of :func:`gridshell.design.verification.verify_bundle` on stdout (``"ok"`` first) and
one pass / FAIL line per figure on stderr. Exit code (:func:`gridshell.design.verification.exit_code`):
0 every figure holds; 2 the bundle is incomplete or its files disagree with design.json;
4 a figure misses its threshold.
"""
from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from gridshell.design.bundle import finite_json
from gridshell.design.verification import exit_code

HELP = ("recompute the figures of a design bundle from its files, check them against the paper's "
        "thresholds and print JSON (exit 0 ok, 2 incomplete or inconsistent bundle, 4 a figure "
        "fails)")


def add_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("bundle", help="design bundle directory (output of 'gridshell gg' / 'ncp')")
    p.add_argument("--per-loop", action="store_true",
                   help="also list Delta_a of every net-loop")


def run(args: Any) -> int:
    from gridshell.api import verify

    res = verify(args.bundle)
    if not args.per_loop:
        res.pop("per_loop")
    ok = res.pop("ok")
    print(json.dumps(finite_json({"ok": ok, **res}), indent=1, allow_nan=False))
    if not getattr(args, "quiet", False):
        for line in res["checks"]:
            print(f"  {line}", file=sys.stderr)
        for p in res["problems"]:
            print(f"  problem: {p}", file=sys.stderr)
        verdict = "ok" if ok else "NOT ok"
        print(f"gridshell verify: {verdict}: {args.bundle}", file=sys.stderr)
    return exit_code({"ok": ok, **res})
