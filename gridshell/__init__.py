"""Inverse design of alignable lamella gridshells.

The Python API (:mod:`gridshell.api`), loaded on first use so that ``import gridshell`` stays
cheap: ``design_gg``, ``design_ncp``, ``optimize_phlw``, ``write``, ``read``, ``verify``,
``fabricate``, ``check_structure``, ``simulate``, ``export_3dm``, ``write_outputs``,
``Design``, ``DesignBundle``.
"""
from gridshell.core import moved as _moved
from gridshell.core.version import __version__  # noqa: F401

_moved.install()

__all__ = ["Design", "DesignBundle", "check_structure", "design_gg", "design_ncp", "export_3dm",
           "fabricate", "optimize_phlw", "read", "simulate", "verify", "write", "write_outputs"]


def __getattr__(name: str):
    if name in __all__:
        from gridshell import api

        return getattr(api, name)
    raise AttributeError(f"module 'gridshell' has no attribute {name!r}")


def __dir__():
    return sorted(list(globals()) + __all__)
