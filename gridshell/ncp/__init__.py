"""NCP pipeline (paper 4.2): normal-curvature-preserving alignable gridshells.

``phlw``: B-spline surface design towards PHLW, CNC and PK surfaces (paper 3.4, 4.2.1);
``reference``: the initial B-spline from a reference mesh;
``source``: the surface a design starts from (a B-spline as it is, or the PHLW step);
``pipeline``: design_ncp as the named stages ``NCP_STAGES``.

May import: the floors below (core, solver, geometry, measure, io, design) and render
(the maps a design writes); never gg, export or a face.
"""
