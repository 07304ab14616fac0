"""Option values checked while the command line is parsed, before any work.

Each function here is an argparse ``type=``: it turns the text into the value or raises
``argparse.ArgumentTypeError`` with what is allowed (its ``refused`` attribute lists texts just
outside the range, for the tests), so a bad value stops the command at once
with argparse's one line (``gridshell gg: error: argument --frames: ...``, exit 2), before a
file is read or a stage starts. Counts are integers, lengths and weights finite floats; the
unit of a length is the option's own (its help says which).
"""
from __future__ import annotations

import argparse
import math
from typing import Callable

__all__ = ["checked", "count", "number", "positive", "nonnegative", "angle_between", "fraction",
           "percent", "port"]


def _parse(text: str, kind: type, what: str) -> float | int:
    try:
        value = kind(text)
    except (TypeError, ValueError):
        raise argparse.ArgumentTypeError(f"expected {what}, got {text!r}") from None
    if isinstance(value, float) and not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"expected {what} (finite), got {text!r}")
    return value


def count(minimum: int = 1, meaning: str = "", *,
          maximum: int | None = None) -> Callable[[str], int]:
    """An integer option from ``minimum`` to ``maximum`` (None: no bound); ``meaning`` (e.g.
    "0: none") goes into the message so that the user learns what the smallest values do."""
    def parse(text: str) -> int:
        value = int(_parse(text, int, "a whole number"))
        if value < minimum or (maximum is not None and value > maximum):
            extra = f" ({meaning})" if meaning else ""
            top = f" and <= {maximum}" if maximum is not None else ""
            raise argparse.ArgumentTypeError(f"must be a whole number >= {minimum}{top}{extra}, "
                                             f"got {text}")
        return value
    parse.__name__ = f"count>={minimum}"
    parse.refused = ["1.5", str(minimum - 1)] + ([] if maximum is None else [str(maximum + 1)])
    return parse


def number(minimum: float | None = None, *, strict: bool = False,
           maximum: float | None = None) -> Callable[[str], float]:
    """A finite float option, at least ``minimum`` (above it with ``strict``), at most
    ``maximum``; None: no bound."""
    def parse(text: str) -> float:
        value = float(_parse(text, float, "a number"))
        low = minimum is not None and (value <= minimum if strict else value < minimum)
        if low or (maximum is not None and value > maximum):
            raise argparse.ArgumentTypeError(f"must be {_range(minimum, strict, maximum)}, "
                                             f"got {text}")
        return value
    parse.__name__ = "number"
    parse.refused = ([] if minimum is None else [f"{minimum:g}" if strict else f"{minimum - 1:g}"]
                     + ([] if maximum is None else [f"{maximum + 1:g}"]))
    return parse


def _range(minimum: float | None, strict: bool, maximum: float | None) -> str:
    parts = []
    if minimum is not None:
        parts.append(f"{'>' if strict else '>='} {minimum:g}")
    if maximum is not None:
        parts.append(f"<= {maximum:g}")
    return " and ".join(parts) if parts else "a finite number"


def angle_between(low: float, high: float) -> Callable[[str], float]:
    """An angle in degrees strictly between ``low`` and ``high``."""
    def parse(text: str) -> float:
        value = float(_parse(text, float, "an angle in degrees"))
        if not low < value < high:
            raise argparse.ArgumentTypeError(f"must be an angle between {low:g} and {high:g} "
                                             f"degrees (exclusive), got {text}")
        return value
    parse.__name__ = "angle"
    parse.refused = [f"{low:g}", f"{high:g}"]
    return parse


def fraction(text: str) -> float:
    """A fraction strictly between 0 and 1."""
    value = float(_parse(text, float, "a fraction"))
    if not 0.0 < value < 1.0:
        raise argparse.ArgumentTypeError(f"must be a fraction between 0 and 1 (exclusive), "
                                         f"got {text}")
    return value


def percent(text: str) -> float:
    """A share in per cent, above 0 and at most 100."""
    value = float(_parse(text, float, "a percentage"))
    if not 0.0 < value <= 100.0:
        raise argparse.ArgumentTypeError(f"must be a percentage above 0 and at most 100, "
                                         f"got {text}")
    return value


def port(text: str) -> int:
    """A TCP port, 1-65535."""
    value = int(_parse(text, int, "a port number"))
    if not 1 <= value <= 65535:
        raise argparse.ArgumentTypeError(f"must be a port number from 1 to 65535, got {text}")
    return value


#: a finite number above 0 (lengths, moduli, densities)
positive = number(0.0, strict=True)
#: a finite number of at least 0 (clearances, gaps, weights)
nonnegative = number(0.0)


def checked(parse: Callable[[str], object], name: str) -> Callable[[str], str]:
    """A text option checked by ``parse`` (the library's own reader of it, e.g.
    :func:`gridshell.design.section.parse_scale`) while the command line is parsed; the text is
    kept as given, so the command reads it as before. The reader's one-line message is the
    error."""
    from gridshell.core.errors import GridshellError

    def check(text: str) -> str:
        try:
            parse(text)
        except (GridshellError, ValueError, KeyError) as exc:
            raise argparse.ArgumentTypeError(str(exc).strip("'\"")) from None
        return text
    check.__name__ = name
    check.refused = ["-1:0"]
    return check


fraction.refused = ["0", "1"]  # type: ignore[attr-defined]
percent.refused = ["0", "101"]  # type: ignore[attr-defined]
port.refused = ["0", "65536"]  # type: ignore[attr-defined]
