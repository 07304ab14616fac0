"""The design bundle (the directory every pipeline writes) and its verification.

- :mod:`.bundle`: write_bundle / read_bundle; DesignBundle, Design
- :mod:`.verification`: every figure of a bundle recomputed from its files and gated
- :mod:`.section`: the strip's section, scale and material (caller, else the bundle's
  fabrication report, else the defaults; one error policy)

May import: :mod:`gridshell.core`, :mod:`gridshell.solver`, :mod:`gridshell.geometry`,
:mod:`gridshell.measure`, :mod:`gridshell.io`; never a pipeline (gg, ncp) nor an output.
"""
