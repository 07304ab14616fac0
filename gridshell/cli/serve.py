"""``gridshell serve``: the Grasshopper components through a local Hops server."""
from __future__ import annotations

import argparse
import sys
from typing import Any

from gridshell.cli.values import port

HELP = ("start a Hops server with the Grasshopper components GG design, NCP design, verify and "
        "fabricate (point a Hops component at http://localhost:PORT/gg, /ncp, /verify, "
        "/fabricate)")


def add_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--port", type=port, default=5000, help="TCP port (default 5000)")
    p.add_argument("--host", default="127.0.0.1",
                   help="address to listen on (default 127.0.0.1: this computer only)")
    p.add_argument("--workdir", metavar="DIR",
                   help="folder for the design bundles the components write (default: a new "
                        "temporary folder)")
    p.add_argument("--allow", metavar="DIR", action="append", default=[],
                   help="a further folder whose design bundles /verify and /fabricate may read "
                        "and write (repeatable; default: the work directory only)")
    p.add_argument("--max-body", metavar="BYTES", type=_size, default=None,
                   help="largest request body, bytes or with K, M, G (default 64M: eight times "
                        "the request of a 200k-triangle mesh); larger ones are refused (413)")


def _size(text: str) -> int:
    """``--max-body``: bytes, or a number with K, M or G (binary multiples)."""
    t = text.strip().upper().removesuffix("B")
    mult = {"K": 2 ** 10, "M": 2 ** 20, "G": 2 ** 30}.get(t[-1:], 1)
    try:
        n = float(t[:-1] if mult > 1 else t) * mult
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a size; give bytes or e.g. 64M") \
            from None
    if not 0 < n < 2 ** 40:
        raise argparse.ArgumentTypeError(f"{text!r}: give a positive size below 1T, e.g. 64M")
    return int(n)


def run(args: Any) -> int:
    from gridshell.core.errors import InputError

    if not 0 < args.port < 65536:
        raise InputError(f"--port {args.port} is not a TCP port; give 1..65535")
    try:
        from gridshell.server.components import make_app
    except ModuleNotFoundError as exc:
        raise InputError(f"the Hops server needs {exc.name}; install it with "
                         "pip install 'gridshell[server]'") from None
    app = make_app(args.workdir, allow=tuple(args.allow), host=args.host, port=args.port,
                   max_body=args.max_body)
    if not args.quiet:  # with --json stdout keeps its one JSON object, printed at the end
        print(f"gridshell Hops server on http://{args.host}:{args.port}/ (components: /gg, /ncp, "
              f"/verify, /fabricate; bundles in {app.config['GRIDSHELL_WORKDIR']}); Ctrl+C stops",
              file=sys.stderr if args.json else sys.stdout)
    app.run(host=args.host, port=args.port, debug=False)
    return 0
