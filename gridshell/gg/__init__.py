"""The GG pipeline (paper 4.1): surface design, surface of revolution, geodesic net, map back.

May import: the floors below (core, solver, geometry, measure, io, design) and render
(the previews a design writes); never ncp, export or a face.
"""
