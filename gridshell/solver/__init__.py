"""Sparse least-squares solver shared by every optimization of the project."""
from .layout import Layout
from .problem import Assembled, Entry, Problem
from .solve import SolveResult, solve
from .terms import TERMS, TermResult, concat, linear_result, result, term

__all__ = ["Layout", "Problem", "Entry", "Assembled", "SolveResult", "solve", "TERMS",
           "TermResult", "term", "result", "concat", "linear_result"]
