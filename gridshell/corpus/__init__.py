"""A corpus of analytic reference surfaces the project was not tuned to, for tests and
benchmarks (issue 13): surfaces of revolution with random profiles, catenoid-helicoid
associates, height-field hills, domes, ridges, saddles and monkey saddles, constant-K and
near-constant-K patches; at several resolutions, sizes (a 0.5 m model to a 60 m hall),
orientations and offsets, as quad grids and triangle meshes.

    from gridshell.corpus import REFERENCES, get, select
    ref = get("saddle-03")
    V, F = ref.mesh_arrays()          # metres
    ref.write_obj("saddle-03.obj")
    ref.modes                         # ('gg', 'ncp-phlw', 'ncp-cnc', 'ncp-aa')

``benchmarks/corpus.py`` runs every applicable pipeline on every reference.

May import: :mod:`gridshell.core`, :mod:`gridshell.geometry`.
"""
from gridshell.corpus.registry import (COUNTS, FAST, MODES, REFERENCES, Reference, build_reference, get, names,
                       select)
from gridshell.corpus.surfaces import FAMILIES, Shape

__all__ = ["COUNTS", "FAMILIES", "FAST", "MODES", "REFERENCES", "Reference", "Shape",
           "build_reference", "get", "names", "select"]
