"""The ``gridshell`` command: a thin layer over the Python API, one module per subcommand."""
from __future__ import annotations

import argparse
import importlib
import os
import sys

# One BLAS thread unless the user asks for more (before numpy / CHOLMOD load OpenBLAS): the
# command's problems are small to mid-sized, where OpenBLAS's second thread spins more than it
# helps (measured: the 12 x 8 m hill gg 10.1 -> 5.4 s, 200k triangles 12.5 -> 9.9 s, the demo
# 39 -> 35 s on 2 cores; benchmarks/README.md "Big input").
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
from typing import Iterable, Sequence

from gridshell.core.version import __version__
from gridshell.core.errors import GridshellError

#: subcommand name -> module in gridshell.cli with ``HELP``, ``add_args(parser)`` and ``run(args)``
SUBCOMMANDS: dict[str, str] = {
    "build": "build",
    "analyze": "analyze",
    "gg": "gg",
    "phlw": "phlw",
    "ncp": "ncp",
    "verify": "verify",
    "fabricate": "fabricate",
    "render": "render",
    "export": "export",
    "demo": "demo",
    "check": "check",
    "serve": "serve",
    "simulate": "simulate",
    "sweep": "sweep",
}


def _available() -> dict[str, object]:
    mods = {}
    for name, modname in SUBCOMMANDS.items():
        try:
            mods[name] = importlib.import_module(f"{__package__}.{modname}")
        except ModuleNotFoundError as exc:
            if exc.name != f"{__package__}.{modname}":
                raise
    return mods


class _Version(argparse.Action):
    """``--version``: the package's version and the linear solver in use (looked up when asked)."""

    def __init__(self, option_strings: Sequence[str], dest: str = argparse.SUPPRESS,
                 default: str = argparse.SUPPRESS,
                 help: str = "show the version and the linear solver in use, and exit") -> None:
        super().__init__(option_strings, dest=dest, default=default, nargs=0, help=help)

    def __call__(self, parser, namespace, values, option_string=None):  # noqa: ANN001
        from gridshell.solver.linear import describe

        try:
            lin = describe()
        except GridshellError as exc:
            lin = f"unavailable: {exc}"
        sys.stdout.write(f"gridshell {__version__}\nlinear solver: {lin}\n")
        parser.exit()


class _Parser(argparse.ArgumentParser):
    """argparse with a one-line error: what is wrong and where the options are described
    (argparse's own prints the whole usage block first)."""

    def error(self, message: str):  # noqa: D102 - argparse's hook
        self.exit(2, f"{self.prog}: error: {message} ({self.prog} --help lists the options)\n")


def build_parser(commands: Iterable[str] | None = None) -> argparse.ArgumentParser:
    """The argument parser of the ``gridshell`` command.

    ``commands``: the subcommands whose options are added (None: all). Every subcommand is
    listed either way; :func:`main` adds the options of the one it runs only, because some
    take their choices from registries whose modules are slow to import (``fabricate``).
    """
    parser = _Parser(
        prog="gridshell",
        description="Design alignable lamella gridshells: from a target surface to cut files.")
    parser.add_argument("--version", action=_Version)
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    wanted = None if commands is None else set(commands)
    for name, mod in _available().items():
        p = sub.add_parser(name, help=getattr(mod, "HELP", None),
                           description=getattr(mod, "HELP", None))
        if wanted is not None and name not in wanted:
            continue
        g = p.add_mutually_exclusive_group()
        g.add_argument("-v", "--verbose", action="count", default=0, help="more progress output")
        g.add_argument("-q", "--quiet", action="store_true", help="no progress output")
        p.add_argument("--json", action="store_true", help="print the summary as JSON on stdout")
        mod.add_args(p)
        p.set_defaults(_run=mod.run)
    return parser


def _requested(argv: Sequence[str]) -> list[str]:
    """The subcommand named in ``argv`` (its first word that is not an option), if any."""
    first = next((a for a in argv if not a.startswith("-")), None)
    return [first] if first in SUBCOMMANDS else []


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI; returns the exit code (:data:`gridshell.core.errors.EXIT_CODES`: 0 success,
    2 bad input or no command, 3 no net, 4 not converged, 5 output refused or not writable,
    1 other tool error; argparse exits with 2 on an unknown option)."""
    argv = sys.argv[1:] if argv is None else list(argv)
    from gridshell.cli.outcome import parse_or_explain, run_command

    parser = build_parser(_requested(argv))
    try:  # a bad option or value: one line and exit 2, before any work; --help: exit 0
        args = parse_or_explain(lambda: parser.parse_args(argv), argv)
    except SystemExit as exc:
        return exc.code if isinstance(exc.code, int) else 2
    if not getattr(args, "command", None):
        parser.print_help(sys.stderr)
        print(f"\ngridshell: error: give a command, one of {', '.join(SUBCOMMANDS)} "
              "(gridshell COMMAND --help describes its options)", file=sys.stderr)
        return 2
    from gridshell.core.manifest import set_command

    set_command(args.command, ["gridshell", *argv])
    try:  # --json: one JSON object on stdout; -q: never without the error line
        return run_command(args.command, lambda: args._run(args), bool(args.json))
    finally:
        set_command(None)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
