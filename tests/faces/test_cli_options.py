"""Every option of every command is checked before any work: a bad value ends the command
while the command line is parsed (exit 2, one line naming the option), before a file is read,
an output directory made or a stage started."""
from __future__ import annotations

import argparse

import pytest

from gridshell.cli import main as cli_main
from gridshell.cli.main import build_parser

ALWAYS_BAD = ["abc", "nan", "inf", "1e999"]


def _subparsers() -> dict[str, argparse.ArgumentParser]:
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return dict(sub.choices)


def _typed_options():
    for cmd, sp in _subparsers().items():
        for a in sp._actions:
            if a.option_strings and a.type is not None:
                yield cmd, a


def _cases():
    for cmd, a in _typed_options():
        bad = list(getattr(a.type, "refused", []))
        if a.type.__name__ not in ("scale", "sheet", "material"):
            bad = ALWAYS_BAD + bad
        for value in bad:
            yield pytest.param(cmd, a.option_strings[-1], value, a.nargs,
                               id=f"{cmd}{a.option_strings[-1]}={value}")


def test_no_option_takes_a_bare_int_or_float():
    """Every number option goes through gridshell.cli.values (ranges, finite values)."""
    bare = [f"{cmd} {a.option_strings[-1]}" for cmd, a in _typed_options()
            if a.type in (int, float)]
    assert bare == []


def _argv(cmd: str, option: str, value: str, nargs) -> list[str]:
    sp = _subparsers()[cmd]
    argv = [cmd]
    for a in sp._actions:
        if not a.option_strings and a.nargs != 0 and a.dest != "help":
            argv.append("missing-target.obj")
        elif a.required:
            argv += [a.option_strings[0], "missing-out"]
    n = nargs if isinstance(nargs, int) else 1
    return argv + [option, *([value] * n)]


@pytest.mark.parametrize("cmd,option,value,nargs", list(_cases()))
def test_bad_value_refused_before_any_work(cmd, option, value, nargs, monkeypatch, capsys,
                                           tmp_path):
    started = []
    monkeypatch.chdir(tmp_path)
    for mod in cli_main._available().values():
        monkeypatch.setattr(mod, "run", lambda args: started.append(args) or 0)
    code = cli_main.main(_argv(cmd, option, value, nargs))
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1, err
    err = err[0]
    assert started == []
    assert f"argument {option}" in err and ": error: " in err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("argv", [
    ["ncp", "missing.json", "-o", "out", "--frames", "0"],
    ["gg", "missing.obj", "-o", "out", "--rounds", "0"],
    ["gg", "missing.obj", "-o", "out", "--lamellae", "0"],
    ["ncp", "missing.json", "-o", "out", "--curves", "0"],
    ["fabricate", "missing", "--scale", "0"],
    ["check", "missing", "--material", "unobtainium"],
])
def test_the_reported_cases_name_the_option_not_the_file(argv, capsys, tmp_path, monkeypatch):
    """The target does not exist: the option is refused first, so the message is about it."""
    monkeypatch.chdir(tmp_path)
    code = cli_main.main(argv)
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "missing" not in err
    assert f"argument {argv[-2]}" in err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("argv", [
    ["gg", "t.obj", "-o", "out", "--frames", "0"],
    ["gg", "t.obj", "-o", "out", "--direction", "-30", "--offsets", "-0.5", "0", "0.5"],
    ["ncp", "s.json", "-o", "out", "--rounds", "0", "--n", "-2"],
    ["fabricate", "b", "--kerf", "0", "--scale", "1:10", "--sheet", "600x400"],
    ["check", "b", "--nu", "0.3", "--top", "0", "--material", "plywood"],
])
def test_values_in_range_parse(argv, monkeypatch):
    seen = []
    for mod in cli_main._available().values():
        monkeypatch.setattr(mod, "run", lambda args: seen.append(args) or 0)
    assert cli_main.main(argv) == 0
    assert len(seen) == 1
