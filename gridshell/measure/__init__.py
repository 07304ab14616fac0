"""The paper's figures of a design and the thresholds they are judged by.

- :mod:`.metrics`: alignability error (5.1), Delta_l, Delta_n, deviation from the target
- :mod:`.quality`: THRESHOLDS and the gates a design must pass on its figures

May import: :mod:`gridshell.core`, :mod:`gridshell.solver`, :mod:`gridshell.geometry`.
"""
