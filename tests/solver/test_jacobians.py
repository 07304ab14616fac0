"""One finite-difference check over every registered solver term (relative error < 1e-6)."""
import importlib
import pkgutil
import zlib

import numpy as np
import pytest

import gridshell
from gridshell.solver import TERMS
from gridshell.solver.fdcheck import jacobian_error

from tests.helpers import fd_cases
from tests.helpers.fd_cases import term_name


def _import_all_gridshell_modules():
    """Import every module of the package so that every @term is registered."""
    for mod in pkgutil.walk_packages(gridshell.__path__, "gridshell."):
        if ".cli" in mod.name:
            continue
        importlib.import_module(mod.name)


def _all_cases():
    cases = {}
    for mod in pkgutil.iter_modules(fd_cases.__path__):
        m = importlib.import_module(f"tests.helpers.fd_cases.{mod.name}")
        cases.update(m.CASES)
    return cases


_import_all_gridshell_modules()
CASES = _all_cases()


def test_every_registered_term_has_a_case():
    missing = sorted(set(TERMS) - {term_name(c) for c in CASES})
    assert not missing, f"terms without a finite-difference case: {missing}"


def test_case_keys_name_a_term_and_a_variant():
    assert term_name("a.b.f[cnc]") == "a.b.f" and term_name("a.b.f") == "a.b.f"
    bad = [c for c in CASES if "[" in c and (not c.endswith("]") or c.endswith("[]"))]
    assert not bad, f"malformed case keys (use module.function[variant]): {bad}"


@pytest.mark.parametrize("case", sorted(CASES))
def test_jacobian_matches_finite_differences(case):
    name = term_name(case)
    assert name in TERMS, f"case {case} names no registered term"
    rng = np.random.default_rng(zlib.crc32(case.encode()))
    layout, x, data = CASES[case](rng)
    err = jacobian_error(TERMS[name], x, layout, data)
    assert err < 1e-6, f"{case}: relative Jacobian error {err:.2e}"
