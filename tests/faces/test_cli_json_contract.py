"""The ``--json`` and ``-q`` contracts of every subcommand (:mod:`gridshell.cli.outcome`):
with ``--json`` stdout is exactly one JSON object, failure included; ``-q`` silences progress,
never the one error line on stderr. Each command is run on a failure of its own (bad input,
an incomplete bundle, an overstressed strip, a usage error, a bug, an interruption) and on a
success where one is quick."""
from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from tests.helpers.fab_cases import make_bundle

from gridshell.cli import main as cli_main
from gridshell.cli.main import SUBCOMMANDS, main
from gridshell.design.bundle import write_bundle

FLAT = {"c": 0.0, "twist": 0.0, "stretch": 0.0}
MODES = {"json": ["--json"], "json-quiet": ["--json", "-q"], "quiet": ["-q"]}


@pytest.fixture(scope="module")
def bundles(tmp_path_factory):
    """A flat GG bundle that passes verify, a curved one (overstressed at 10 mm), and the
    flat one with aligned.obj removed and with n_joints tampered."""
    root = tmp_path_factory.mktemp("bundles")
    good = write_bundle(root / "good", make_bundle("GG", **FLAT))
    curved = write_bundle(root / "curved", make_bundle("GG"))
    missing = Path(shutil.copytree(good, root / "missing"))
    (missing / "aligned.obj").unlink()
    tampered = Path(shutil.copytree(good, root / "tampered"))
    d = json.loads((tampered / "design.json").read_text())
    d["n_joints"] += 3
    (tampered / "design.json").write_text(json.dumps(d))
    (root / "points.obj").write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n")
    foreign = root / "foreign"
    foreign.mkdir()
    (foreign / "mine.txt").write_text("not the tool's")
    return {"good": good, "curved": curved, "missing": missing, "tampered": tampered,
            "points": root / "points.obj", "foreign": foreign, "nowhere": root / "nowhere"}


def _failures(b: dict, tmp: Path) -> dict[str, tuple[list[str], int, str]]:
    """command -> (argv, exit code, a word of the error line) of a failure of each command."""
    return {
        "gg": (["gg", str(b["points"]), "-o", str(tmp / "o")], 2, "no faces"),
        "phlw": (["phlw", str(b["points"]), "-o", str(tmp / "o")], 2, "no faces"),
        "ncp": (["ncp", str(b["points"]), "-o", str(tmp / "o")], 2, "no faces"),
        "verify": (["verify", str(b["missing"])], 2, "aligned.obj"),
        "analyze": (["analyze", str(b["points"]), "--no-files"], 2, "no faces"),
        "fabricate": (["fabricate", str(b["nowhere"]), "-o", str(tmp / "o")], 2, "nowhere"),
        "render": (["render", str(b["nowhere"])], 2, "nowhere"),
        "export": (["export", str(b["nowhere"])], 2, "nowhere"),
        "demo": (["demo", "-o", str(b["foreign"])], 5, "foreign"),
        "check": (["check", str(b["curved"]), "--thickness", "10", "--no-picture",
                   "--no-states"], 4, "overstressed"),
        "serve": (["serve", "--port", "0"], 2, "--port"),
        "simulate": (["simulate", str(b["nowhere"])], 2, "nowhere"),
        "build": (["build", str(b["points"]), "-o", str(tmp / "p")], 2, "no faces"),
        "sweep": (["sweep", str(b["nowhere"]), "-o", str(tmp / "s"), "--vary",
                   "lamellae=6,8"], 2, "nowhere"),
    }


def _run(capsys, argv):
    code = main(argv)
    cap = capsys.readouterr()
    return code, cap.out, [ln for ln in cap.err.splitlines() if ln.strip()]


def test_every_command_is_covered(bundles, tmp_path):
    assert set(_failures(bundles, tmp_path)) == set(SUBCOMMANDS)


@pytest.mark.parametrize("mode", sorted(MODES))
@pytest.mark.parametrize("command", sorted(SUBCOMMANDS))
def test_a_failure_is_one_json_object_and_one_error_line(bundles, tmp_path, capsys, command,
                                                         mode):
    argv, want, word = _failures(bundles, tmp_path)[command]
    code, out, err = _run(capsys, [*argv, *MODES[mode]])
    assert code == want, err
    if "json" in mode:
        payload = json.loads(out)            # exactly one object: extra text fails to parse
        assert isinstance(payload, dict) and payload["ok"] is False
        assert payload["exit_code"] == want
    assert any(ln.startswith(f"gridshell {command}: ") for ln in err), err
    assert word.lower() in " ".join(err).lower() and "Traceback" not in " ".join(err), err
    if "quiet" in mode:
        assert len(err) == 1 and err[0].startswith(f"gridshell {command}: error: "), err
        assert word.lower() in err[0].lower()
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("which", ["missing", "tampered"])
def test_verify_quiet_json_of_an_incomplete_bundle_prints_the_verdict(bundles, capsys, which):
    code, out, err = _run(capsys, ["verify", str(bundles[which]), "-q", "--json"])
    verdict = json.loads(out)
    assert code == 2 and verdict["ok"] is False and verdict["problems"]
    reason = "aligned.obj" if which == "missing" else "n_joints"
    assert any(reason in p for p in verdict["problems"])
    assert len(err) == 1 and err[0].startswith("gridshell verify: error: ") and reason in err[0]


@pytest.mark.parametrize("command", ["verify", "check"])
def test_a_success_is_one_json_object_and_quiet(bundles, capsys, command):
    argv = [command, str(bundles["good"])] + (["--no-picture", "--no-states"]
                                               if command == "check" else [])
    code, out, err = _run(capsys, [*argv, "--json", "-q"])
    assert code == 0 and json.loads(out)["ok"] is True and err == []


@pytest.mark.parametrize("command", sorted(SUBCOMMANDS))
def test_a_usage_error_with_json_is_one_json_object(capsys, command):
    code = main([command, "--json", "-v", "-q"])
    cap = capsys.readouterr()
    payload = json.loads(cap.out)
    assert code == 2 and payload["ok"] is False and payload["error"] == "UsageError"
    assert "not allowed with" in payload["message"] and "not allowed with" in cap.err


@pytest.mark.parametrize("raised, code", [(RuntimeError("a bug"), None),
                                          (KeyboardInterrupt(), 130)])
def test_a_bug_or_an_interruption_still_prints_one_json_object(bundles, capsys, monkeypatch,
                                                               raised, code):
    def broken(args):
        print("half a summary")
        raise raised

    monkeypatch.setattr(cli_main.importlib.import_module("gridshell.cli.verify"), "run", broken)
    argv = ["verify", str(bundles["good"]), "--json", "-q"]
    if code is None:
        with pytest.raises(RuntimeError, match="a bug"):
            main(argv)
        got = 1
    else:
        got = main(argv)
    cap = capsys.readouterr()
    payload = json.loads(cap.out)
    assert payload["ok"] is False and payload["error"] == type(raised).__name__
    assert payload["exit_code"] == got and payload["output"] == "half a summary"
