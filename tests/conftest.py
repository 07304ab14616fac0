import os
import sys

sys.path.insert(0, os.path.dirname(__file__))  # for fd_cases
os.environ.setdefault("MPLBACKEND", "Agg")
