"""Errors the tool raises on purpose: each names the problem and what to do about it.

The CLI catches :class:`GridshellError` and prints its message with a non-zero exit code
(``exit_code``); anything else is a bug.
"""
from __future__ import annotations


class GridshellError(Exception):
    """Base class of every error the tool raises deliberately."""

    exit_code = 1


class InputError(GridshellError, ValueError):
    """The input (file, mesh, parameter) is unusable; the message says why and what to do."""

    exit_code = 2


class MeshError(InputError):
    """A mesh is empty, not quad where quads are needed, non-manifold, degenerate, or not finite."""


class NoNetError(GridshellError):
    """The surface admits no net of the requested kind (e.g. n outside [kappa_I, kappa_II])."""

    exit_code = 3


class ConvergenceError(GridshellError):
    """An optimizer stopped without meeting its tolerances."""

    exit_code = 4


class OutputError(GridshellError, OSError):
    """An output location cannot be written."""

    exit_code = 5


#: exit code -> category, the one table of the CLI's exit codes (README "Exit codes"); each
#: error class above carries its code
EXIT_CODES: dict[int, str] = {
    0: "success",
    GridshellError.exit_code: "a bug of the tool (please report it)",
    InputError.exit_code: "bad input: unreadable, degenerate or inconsistent files, "
                          "out-of-range coordinates, nonsensical parameters",
    NoNetError.exit_code: "no net of the requested kind exists on the surface",
    ConvergenceError.exit_code: "not converged: the design misses the paper's figures",
    OutputError.exit_code: "output refused or not writable",
}
