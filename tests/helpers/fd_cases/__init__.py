"""Finite-difference cases of solver terms, one module per area.

Each module defines ``CASES: dict[str, Callable[[np.random.Generator], (layout, x, data)]]``
keyed by the term's qualified name (``module.function``, as in ``gridshell.solver.TERMS``),
optionally followed by a variant in brackets, ``module.function[cnc]``, where one term is
checked in several configurations (e.g. once per PHLW mode, whose layouts and data differ).
``tests/solver/test_jacobians.py`` runs every case and fails if a registered term has none.
"""


def term_name(case: str) -> str:
    """The registered term a case key names: ``"m.f[cnc]" -> "m.f"``."""
    return case.split("[", 1)[0]
