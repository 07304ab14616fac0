"""What every subcommand leaves on stdout and stderr, whatever it does (:func:`run_command`).

* ``--json``: stdout holds exactly one JSON object, failure included. What the command prints
  is held back until it ends: its own JSON object is printed as it is (``"ok": false`` added
  when the exit code is not 0); a failure (:class:`~gridshell.core.errors.GridshellError`,
  an interruption, a bug) prints ``{"ok": false, "error": CLASS, "message": ..., "exit_code":
  N}``, over the command's own object if it printed one; text that is not one JSON object is
  kept as ``"output"``.
* ``-q`` silences progress, never the error: a command that ends with an exit code other
  than 0 leaves one line ``gridshell COMMAND: error: REASON`` on stderr - its own, else one
  made here from its JSON (``message``, ``problems``, the failing checks, ``verdict``).
"""
from __future__ import annotations

import contextlib
import io
import json
import sys
from typing import Any, Callable

from gridshell.core.errors import GridshellError


class _Watch(io.TextIOBase):
    """A text stream passing everything to ``target`` (None: nowhere) that keeps it
    (``text()``) and remembers whether a line starting with ``prefix`` went through (the
    command's own error line)."""

    def __init__(self, target: Any, prefix: str = "\0") -> None:
        self.target, self.prefix, self.said = target, prefix, False
        self._parts: list[str] = []
        self._line = ""

    def write(self, s: str) -> int:
        self._parts.append(s)
        self._line += s
        *done, self._line = self._line.split("\n")
        self.said = self.said or any(ln.startswith(self.prefix) for ln in done + [self._line])
        self._line = self._line[:len(self.prefix)]   # a line's start is all the check needs
        return self.target.write(s) if self.target is not None else len(s)

    def text(self) -> str:
        return "".join(self._parts)

    def flush(self) -> None:
        if self.target is not None:
            self.target.flush()

    def isatty(self) -> bool:
        return bool(getattr(self.target, "isatty", lambda: False)())


def _payload(text: str) -> dict[str, Any]:
    """The one JSON object of ``text`` (what the command printed), ``{}`` when empty; other
    text around it kept as ``"output"``."""
    text = text.strip()
    if not text:
        return {}
    try:
        obj, end = json.JSONDecoder().raw_decode(text)
    except ValueError:
        return {"output": text}
    if not isinstance(obj, dict):
        return {"output": text}
    rest = text[end:].strip()
    return {**obj, "output": rest} if rest else obj


def _reason(payload: dict[str, Any], code: int) -> str:
    """One line on why a command that printed ``payload`` ended with exit code ``code``."""
    if payload.get("message"):
        return str(payload["message"])
    problems = [str(p) for p in payload.get("problems") or []]
    failing = [str(c).strip() for c in payload.get("checks") or [] if "FAIL" in str(c)]
    if problems or failing:
        return "; ".join(problems + failing)
    verdict, util = payload.get("verdict"), payload.get("max_utilisation")
    if isinstance(verdict, str) and verdict:
        return verdict + (f" (max utilisation {util:.3g})" if isinstance(util, (int, float))
                          else "")
    printed = [ln.strip() for ln in str(payload.get("output", "")).splitlines() if ln.strip()]
    return printed[-1] if printed else f"exit code {code}"


def _dump(payload: dict[str, Any]) -> str:
    from gridshell.cli.common import _default
    from gridshell.design.bundle import finite_json

    return json.dumps(finite_json(payload), indent=1, default=_default, allow_nan=False)


def run_command(command: str, run: Callable[[], int], as_json: bool) -> int:
    """Run ``run()`` (a subcommand's ``run(args)``), keep the stdout / stderr contract of the
    module docstring and return the exit code (:data:`gridshell.core.errors.EXIT_CODES`;
    130 interrupted). A bug's traceback still goes to stderr after the JSON."""
    out = _Watch(None if as_json else sys.stdout)  # held back with --json
    err = _Watch(sys.stderr, f"gridshell {command}: ")
    failure: BaseException | None = None
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(out):
        try:
            code = int(run() or 0)
        except GridshellError as exc:
            failure, code = exc, exc.exit_code
        except KeyboardInterrupt as exc:
            failure, code = exc, 130
        except Exception as exc:  # a bug: the JSON first, then the traceback
            failure, code = exc, 1
    payload = _payload(out.text())
    if failure is not None:
        payload.update(ok=False, error=type(failure).__name__,
                       message=str(failure) or ("interrupted" if code == 130 else
                                                 type(failure).__name__), exit_code=code)
    elif code:
        payload.update(ok=False, exit_code=code)
    elif as_json:
        payload.setdefault("ok", True)
    if as_json:
        _emit(_dump(payload))
    if isinstance(failure, KeyboardInterrupt):
        print("interrupted", file=sys.stderr)
    elif isinstance(failure, GridshellError):
        print(f"gridshell {command}: error: {failure}", file=sys.stderr)
    elif failure is not None:
        raise failure
    elif code and not err.said:
        print(f"gridshell {command}: error: {_reason(payload, code)}", file=sys.stderr)
    return code


def _emit(text: str) -> None:
    """``text`` on stdout; a reader that went away (``| head``) is not an error."""
    try:
        print(text, flush=True)
    except BrokenPipeError:
        pass


def parse_or_explain(parse: Callable[[], Any], argv: list[str]) -> Any:
    """``parse()`` (the parser's ``parse_args``); with ``--json`` in ``argv`` a usage error
    (an unknown option, a bad value: argparse's exit 2) also prints ``{"ok": false, "error":
    "UsageError", "message": ...}`` on stdout before the exit."""
    err = _Watch(sys.stderr)
    try:
        with contextlib.redirect_stderr(err):
            return parse()
    except SystemExit as exc:
        if exc.code not in (0, None) and "--json" in argv:
            lines = [ln for ln in err.text().splitlines() if ln.strip()]
            message = lines[-1].split(": error: ", 1)[-1] if lines else "bad command line"
            _emit(_dump({"ok": False, "error": "UsageError", "message": message,
                         "exit_code": exc.code}))
        raise
