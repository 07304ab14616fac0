"""Grasshopper components through Hops (``gridshell serve``): a thin layer over the Python API.

:mod:`.rhino` converts between Rhino geometry (what Hops sends and receives) and our arrays
through :mod:`gridshell.geometry.rhino_adapter`, a target read by :mod:`gridshell.io` exactly
as the CLI reads the same object from a .3dm;
:mod:`.components` registers the components (GG design, NCP design, verify, fabricate) on a
``ghhops-server`` Flask app; errors reach the component as its message, never a dead
component; :mod:`.guard` is what the server trusts (the folders it reads and writes, the
Host and Origin it answers, the body size, one solve at a time).

May import: :mod:`gridshell.api` and every floor below; never the CLI.
"""
