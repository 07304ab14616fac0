"""Finite-difference cases of solver terms, one module per area.

Each module defines ``CASES: dict[str, Callable[[np.random.Generator], (layout, x, data)]]``
keyed by the term's qualified name (``module.function``, as in ``gridshell.solver.TERMS``).
``tests/test_jacobians.py`` runs every case and fails if a registered term has none.
"""
