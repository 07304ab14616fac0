"""report.html's interactive 3D view (WebGL, three.js r170 bundled; no network at view time).

:mod:`.scene` turns a design bundle into compact arrays (surface, strips of their real section
per state of the alignment sequence, joints, net-loops, Delta_a and utilisation);
:mod:`.assets` makes the bundled three.js and ``viewer.js`` inline scripts; :mod:`.page` writes
the report's section. Importing this package imports nothing heavy.
"""
