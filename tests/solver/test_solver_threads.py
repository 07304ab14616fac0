"""The solver runs with one BLAS thread unless the user set a count (gridshell.solver.threads)."""
from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import pytest


SCRIPT = textwrap.dedent("""
    import numpy as np
    from threadpoolctl import threadpool_info
    from gridshell.solver import threads
    from gridshell.solver.linear import available
    available("cholmod")
    seen = []
    with threads.limited_blas():
        seen = [i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"]
    after = [i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"]
    print(seen, after)
""")


def _run(env_extra: dict) -> tuple[list[int], list[int]]:
    env = {k: v for k, v in os.environ.items()
           if k not in ("OPENBLAS_NUM_THREADS", "GRIDSHELL_BLAS_THREADS", "OMP_NUM_THREADS")}
    env.update(env_extra)
    out = subprocess.run([sys.executable, "-c", SCRIPT], env=env, capture_output=True,
                         text=True, check=True).stdout.split("] [")
    inside = [int(v) for v in out[0].strip("[] \n").split(",") if v.strip()]
    after = [int(v) for v in out[1].strip("[] \n").split(",") if v.strip()]
    return inside, after


def test_one_thread_inside_and_restored_after():
    inside, after = _run({})
    assert len(inside) >= 1 and all(n == 1 for n in inside)
    # the limit is scoped: the libraries return to their own count (all cores) after the block
    if (os.cpu_count() or 1) > 1:
        assert max(after) > 1


def test_user_thread_count_wins():
    if (os.cpu_count() or 1) < 2:
        pytest.skip("one core: a count of 2 is not distinguishable from the default")
    inside, _ = _run({"GRIDSHELL_BLAS_THREADS": "2"})
    assert all(n == 2 for n in inside)
    inside, _ = _run({"OPENBLAS_NUM_THREADS": "2"})
    assert all(n == 2 for n in inside)


def test_solve_keeps_its_answer_under_the_limit():
    """A linear least-squares problem solved inside the limit equals numpy's lstsq answer."""
    import numpy as np
    import scipy.sparse as sp

    from gridshell.solver import Layout, Problem, solve
    from gridshell.solver import terms as T

    rng = np.random.default_rng(3)
    A = sp.random(60, 20, density=0.3, random_state=4, format="csr") + sp.eye(60, 20)
    b = rng.normal(size=(60, 1))
    lay = Layout({"x": (20, 1)})
    pb = Problem(lay).add("fit", 1.0, T.linear, T.Linear("x", A, b))
    res = solve(pb, np.zeros(20), method="gn", max_iter=5)
    ref = np.linalg.lstsq(A.toarray(), b[:, 0], rcond=None)[0]
    assert np.allclose(res.x, ref, rtol=0, atol=1e-9 * np.abs(ref).max())
