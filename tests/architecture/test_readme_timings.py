"""The timings the documents quote are the benchmark's: every one in README.md carries the marker
``<!--bench:KEY-->`` and is within 25 % of what ``make bench`` measured last
(``benchmarks/readme.py`` -> ``benchmarks/readme_timings.json``, the machine and date with it);
the other documents quote no timing (theirs live in benchmarks/README.md). Limits and goals
("under 5 s", "more than 2 s") are not measurements and need no marker."""
from __future__ import annotations

import json
import re

import pytest

from tests.architecture.test_readme import DOCUMENTS, FENCE, ROOT

RECORD = ROOT / "benchmarks" / "readme_timings.json"
MARK = re.compile(r"<!--bench:([a-z0-9_]+)-->~?(\d+(?:\.\d+)?) ?(s|min)\b")
TIMING = re.compile(r"(?<![\w.-])~?(\d+(?:\.\d+)?)(?:-\d+(?:\.\d+)?)? ?(s|min)\b")
LIMIT = re.compile(r"(under|than|below|within|goal|<|>|at most|at least)\s*$")


def _prose(text: str) -> list[str]:
    """The lines of ``text`` outside code blocks and tables."""
    text = FENCE.sub(lambda m: "\n" * m.group(0).count("\n"), text)
    return [ln for ln in text.splitlines() if not ln.lstrip().startswith("|")]


def _unmarked(text: str) -> list[str]:
    """Timings of the prose of ``text`` without a marker that are not limits."""
    out = []
    for line in _prose(text):
        for m in TIMING.finditer(line):
            before = line[:m.start()]
            if before.endswith("-->") or LIMIT.search(before):
                continue
            out.append(line.strip()[:100])
    return out


def test_every_readme_timing_is_the_benchmarks():
    record = json.loads(RECORD.read_text())
    assert record["machine"]["cores"] and record["date"]
    figures = record["figures"]
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    marks = MARK.findall(text)
    assert len(marks) >= 10
    for key, number, unit in marks:
        assert key in figures, f"README quotes {key}, which benchmarks/readme.py does not measure"
        quoted = float(number) * (60.0 if unit == "min" else 1.0)
        assert abs(quoted - figures[key]) <= 0.25 * figures[key], (
            f"README: {key} {number} {unit}, the benchmark measured {figures[key]:.1f} s "
            "(run benchmarks/readme.py --update-readme)")


@pytest.mark.parametrize("doc", DOCUMENTS, ids=lambda p: str(p.relative_to(ROOT)))
def test_no_timing_without_its_measurement(doc):
    found = _unmarked(doc.read_text(encoding="utf-8"))
    assert not found, f"{doc.name}: timings that no benchmark copies in: {found}"


def test_the_checks_can_fail():
    assert _unmarked("the demo takes about 17 s on 2 cores") == \
        ["the demo takes about 17 s on 2 cores"]
    assert not _unmarked("it re-runs in under 5 s; <!--bench:demo-->17 s")
    assert not _unmarked("| table | 3.4 s |\n```\nx 2 s\n```")
    assert MARK.findall("<!--bench:demo-->~7 min") == [("demo", "7", "min")]
