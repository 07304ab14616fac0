"""NCP pipeline (paper 4.2): normal-curvature-preserving alignable gridshells.

``phlw``: B-spline surface design towards PHLW, CNC and PK surfaces (paper 3.4, 4.2.1);
``reference``: the initial B-spline from a reference mesh.
"""
