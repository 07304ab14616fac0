import os

os.environ.setdefault("MPLBACKEND", "Agg")


def pytest_terminal_summary(terminalreporter):
    """Print how many hostile-input cases ran (issue 14: the count is shown by ``make test``)."""
    n = {k: 0 for k in ("passed", "failed")}
    for k in n:
        n[k] = sum(1 for r in terminalreporter.stats.get(k, [])
                   if getattr(r, "when", "call") == "call" and "test_hostile_inputs.py" in r.nodeid)
    if sum(n.values()):
        terminalreporter.write_line(f"hostile-input suite: {sum(n.values())} cases "
                                    f"({n['passed']} passed, {n['failed']} failed)")


_START: list[float] = []
#: where a whole-suite run leaves its duration (benchmarks/readme.py copies it to the README)
TEST_RUN = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "out",
                        "make-test.json")


def pytest_sessionstart(session):
    import time

    _START.append(time.perf_counter())


def pytest_sessionfinish(session, exitstatus):
    """After a run of the whole suite to its end (no paths, -k, -m, --deselect or -x given:
    ``make test``), write its duration, test and failure counts and the machine's cores to
    ``out/make-test.json``."""
    import json
    import time

    cfg = session.config
    paths = sorted(os.path.abspath(a) for a in cfg.args)
    default = sorted(os.path.abspath(os.path.join(str(cfg.rootpath), t))
                     for t in (cfg.getini("testpaths") or ["."]))
    whole = (not cfg.args or paths == default or paths == [str(cfg.rootpath)]) \
        and not cfg.getoption("keyword") and not cfg.getoption("markexpr") \
        and not cfg.getoption("deselect") and not cfg.getoption("maxfail")
    if not (whole and exitstatus in (0, 1) and _START and session.testscollected):
        return
    os.makedirs(os.path.dirname(TEST_RUN), exist_ok=True)
    with open(TEST_RUN, "w", encoding="utf-8") as f:
        json.dump({"seconds": round(time.perf_counter() - _START[0], 1),
                   "tests": session.testscollected, "failed": session.testsfailed,
                   "cores": os.cpu_count(), "date": time.strftime("%Y-%m-%d")}, f)
