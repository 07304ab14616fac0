"""A corpus of analytic reference surfaces the project was not tuned to, for tests and
benchmarks (issue 13): surfaces of revolution with random profiles, catenoid-helicoid
associates, height-field hills, domes, ridges, saddles and monkey saddles, constant-K and
near-constant-K patches, and the domes and hills architects draw (single bumps, round domes
with an umbilic crown, asymmetric hills, 3:2 pavilion hills) written as users bring them
(Rhino .3dm meshes, OBJ, PLY, OFF in metres, centimetres or millimetres); at several
resolutions, sizes (a 0.5 m model to a 60 m hall), orientations and offsets, as quad grids
and triangle meshes.

    from gridshell.corpus import REFERENCES, get, select
    ref = get("saddle-03")
    V, F = ref.mesh_arrays()          # metres
    ref.write_obj("saddle-03.obj")
    get("pavilion-02").write_target("dir")   # dir/target.3dm, a Rhino mesh in millimetres
    ref.modes                         # ('gg', 'ncp-phlw', 'ncp-cnc', 'ncp-aa')

``benchmarks/corpus.py`` runs every applicable pipeline on every reference.

May import: :mod:`gridshell.core`, :mod:`gridshell.geometry`.
"""
from gridshell.corpus.registry import (COUNTS, FAST, MODES, REFERENCES, Reference, build_reference, get, names,
                       select)
from gridshell.corpus.surfaces import FAMILIES, Shape

__all__ = ["COUNTS", "FAMILIES", "FAST", "MODES", "REFERENCES", "Reference", "Shape",
           "build_reference", "get", "names", "select"]
