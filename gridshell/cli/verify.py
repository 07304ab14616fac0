"""``gridshell verify``: recompute a bundle's metrics (paper 5.1) from its files alone."""
from __future__ import annotations

import argparse
import json
from typing import Any

from ..verification import verify_bundle

HELP = "recompute the alignability metrics of a design bundle from its files and print JSON"


def add_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("bundle", help="design bundle directory (output of 'gridshell gg' / 'ncp')")
    p.add_argument("--per-loop", action="store_true",
                   help="also list Delta_a of every net-loop")


def run(args: Any) -> int:
    res = verify_bundle(args.bundle)
    if not args.per_loop:
        res.pop("per_loop")
    print(json.dumps({"ok": True, **res}, indent=1, default=float))
    return 0
