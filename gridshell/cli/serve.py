"""``gridshell serve``: the Grasshopper components through a local Hops server."""
from __future__ import annotations

import argparse
import sys
from typing import Any

HELP = ("start a Hops server with the Grasshopper components GG design, NCP design, verify and "
        "fabricate (point a Hops component at http://localhost:PORT/gg, /ncp, /verify, "
        "/fabricate)")


def add_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--port", type=int, default=5000, help="TCP port (default 5000)")
    p.add_argument("--host", default="127.0.0.1",
                   help="address to listen on (default 127.0.0.1: this computer only)")
    p.add_argument("--workdir", metavar="DIR",
                   help="folder for the design bundles the components write (default: a new "
                        "temporary folder)")


def run(args: Any) -> int:
    from gridshell.core.errors import InputError

    if not 0 < args.port < 65536:
        raise InputError(f"--port {args.port} is not a TCP port; give 1..65535")
    try:
        from gridshell.server.components import make_app
    except ModuleNotFoundError as exc:
        raise InputError(f"the Hops server needs {exc.name}; install it with "
                         "pip install 'gridshell[server]'") from None
    app = make_app(args.workdir)
    if not args.quiet:  # with --json stdout keeps its one JSON object, printed at the end
        print(f"gridshell Hops server on http://{args.host}:{args.port}/ (components: /gg, /ncp, "
              f"/verify, /fabricate; bundles in {app.config['GRIDSHELL_WORKDIR']}); Ctrl+C stops",
              file=sys.stderr if args.json else sys.stdout)
    app.run(host=args.host, port=args.port, debug=False)
    return 0
