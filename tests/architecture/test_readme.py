"""The documentation's code runs: every ```python block of the README (and of the other
documents listed) is executed in a temporary directory that holds the samples' meshes at
``samples/``; every ``gridshell ...`` line of the other blocks parses with the command's own
parser; the README's table of options names only options the commands have."""
from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

from gridshell.cli.main import SUBCOMMANDS, build_parser

ROOT = Path(__file__).resolve().parents[2]
DOCUMENTS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md")),
             ROOT / "samples" / "README.md"]
FENCE = re.compile(r"^```(\w*)[ \t]*\n(.*?)^```", re.M | re.S)
SYNOPSIS = re.compile(r"[\[\]|]|\.\.\.")   # [optional], a|b, N ...: a synopsis, not a command


def code_blocks(path: Path) -> list[tuple[str, str, int]]:
    """``(language, code, line)`` of every fenced block of ``path`` (line: 1-based, of the
    opening fence)."""
    text = path.read_text(encoding="utf-8")
    return [(m.group(1).lower(), m.group(2), text.count("\n", 0, m.start()) + 1)
            for m in FENCE.finditer(text)]


def _blocks(lang: str) -> list:
    out = []
    for doc in DOCUMENTS:
        for kind, code, line in code_blocks(doc):
            if (kind == "python") == (lang == "python"):
                out.append(pytest.param(code, id=f"{doc.relative_to(ROOT)}:{line}"))
    return out


def _commands() -> list:
    """Every ``gridshell ...`` line of the non-Python blocks, without its trailing comment."""
    out = []
    for p in _blocks("shell"):
        code, = p.values
        for k, raw in enumerate(code.splitlines()):
            line = raw.split(" #", 1)[0].strip()
            if line.startswith("gridshell "):
                out.append(pytest.param(line, id=f"{p.id}+{k + 1}"))
    return out


@pytest.fixture(scope="module")
def parser():
    return build_parser()


def _options(parser, command: str) -> set[str]:
    sub = next(a for a in parser._actions if a.dest == "command")
    return set(sub.choices[command]._option_string_actions)


def test_the_readme_has_python_examples_and_commands():
    """The README shows the API (design, write, verify, fabricate, export for GG and NCP) as
    code that runs, not as prose; it imports no deprecated writer."""
    py = [p.values[0] for p in _blocks("python") if p.id.startswith("README.md")]
    assert len(py) >= 2
    text = "\n".join(py)
    for call in ("design_gg(", "design_ncp(", "write(", "verify(", "fabricate(", "export_3dm("):
        assert call in text, call
    assert "write_gg" not in text and "write_ncp" not in text
    assert len([c for c in _commands() if c.id.startswith("README.md")]) >= 8


@pytest.mark.parametrize("code", _blocks("python"))
def test_python_block_runs(code, tmp_path, monkeypatch):
    (tmp_path / "samples").symlink_to(ROOT / "samples", target_is_directory=True)
    monkeypatch.chdir(tmp_path)
    exec(compile(code, "README", "exec"), {"__name__": "__readme__"})


@pytest.mark.parametrize("line", _commands())
def test_command_line_parses(line, parser):
    argv = shlex.split(line)[1:]
    assert argv and argv[0] in SUBCOMMANDS, f"unknown command in {line!r}"
    if SYNOPSIS.search(line):       # only the option names can be checked
        unknown = {a for a in argv if a.startswith("-")} - _options(parser, argv[0])
        assert not unknown, f"{line!r}: {argv[0]} has no option {', '.join(sorted(unknown))}"
        return
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:       # argparse printed why on stderr
        pytest.fail(f"{line!r} does not parse (exit {exc.code})")
    assert args.command == argv[0]


def test_option_table_names_real_options(parser):
    """The README's table of the options each command has besides those shown."""
    rows = re.findall(r"^\| `([a-z]+)` \| (.*) \|$", (ROOT / "README.md").read_text(), re.M)
    rows = [(c, opts) for c, opts in rows if c in SUBCOMMANDS]
    assert {c for c, _ in rows} >= {"gg", "phlw", "ncp", "fabricate", "render", "export"}
    for command, cell in rows:
        named = set(re.findall(r"(?<![\w-])--[a-z0-9][a-z0-9-]*", cell))
        assert named, command
        unknown = named - _options(parser, command)
        assert not unknown, f"README option table: {command} has no {', '.join(sorted(unknown))}"


def test_the_checks_can_fail(parser):
    """A misspelt option or command is caught (the tests above are not vacuous)."""
    with pytest.raises(SystemExit):
        parser.parse_args(shlex.split("gg samples/dome.obj -o gg/ --lamelae 8"))
    assert "--lamelae" not in _options(parser, "gg")
    assert [b for b in code_blocks(ROOT / "README.md") if b[0] == "python"]
