"""Deprecated: the fabrication package is now :mod:`gridshell.fabrication`.

``import fabrication`` and ``from fabrication.nesting import ...`` keep working for one release
(with a :class:`DeprecationWarning`); write ``from gridshell.fabrication import ...`` instead.
"""
import warnings

import gridshell  # noqa: F401  (installs the finder of old module paths)
from gridshell.fabrication import FabParams, Strip, parse_scale, parse_sheet  # noqa: F401

warnings.warn("the top-level package 'fabrication' is now 'gridshell.fabrication'; the old name "
              "will be removed in the next release", DeprecationWarning, stacklevel=2)

__all__ = ["FabParams", "Strip", "fabricate", "parse_scale", "parse_sheet"]


def __getattr__(name: str):
    if name == "fabricate":
        from gridshell.fabrication.pipeline import fabricate

        return fabricate
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
