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
