"""The ground floor: errors, safe output and the plumbing every other folder stands on.

- :mod:`.errors`: GridshellError > InputError > MeshError; NoNetError; ConvergenceError; OutputError
- :mod:`.atomic`: temporary name + rename, never a half-written output nor a lost user file
- :mod:`.manifest`: manifest.json of an output directory (files, sizes, sha256, the command)
- :mod:`.finite`: finite or nothing, the last check of every output file
- :mod:`.units`: length units at the edges (``--units``, to metres, a bundle's unit)
- :mod:`.aside`: a pure computation in a forked process while the caller goes on
- :mod:`.recent`: a small LRU of recent results by content key
- :mod:`.moved`: old module paths (before the 0.2 layout) kept importable for one release

May import: numpy and the standard library only; nothing else of gridshell.
"""
