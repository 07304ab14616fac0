"""Chains of stages over a design bundle, as the faces (API, CLI, server) run them.

- :mod:`.outputs`: render.png, alignment.gif, report.html and the .3dm of a bundle in one call
- :mod:`.structure`: the structural check (structure.json, structure.png) and the elastic
  equilibrium (DIR/equilibrium) of a bundle, each in one call

May import every folder below the API: the pipelines, export, render, structure, fabrication.
"""
