"""Sparse least-squares solver shared by every optimization of the project.

May import: :mod:`gridshell.core` only (numpy, scipy, scikit-sparse).
"""
from gridshell.solver.layout import Layout
from gridshell.solver.problem import Assembled, Entry, Problem
from gridshell.solver.solve import SolveResult, solve
from gridshell.solver.terms import TERMS, TermResult, concat, linear_result, result, term

__all__ = ["Layout", "Problem", "Entry", "Assembled", "SolveResult", "solve", "TERMS",
           "TermResult", "term", "result", "concat", "linear_result"]
