"""The PHLW step (paper 3.4, 4.2.1): a B-spline surface optimized towards a PHLW, CNC or PK
surface, on which the NCP net exists.

Modules: :mod:`.terms` (eqs. 4.2-4.8 as solver terms), :mod:`.checks` (row fits, net checks),
:mod:`.problem` (the problem, guards, boundary gliding), :mod:`.rounds` (sampling levels, one
judged round), :mod:`.figures` (acceptance figures), :mod:`.gates` (pass / fail figures),
:mod:`.result` (PHLWResult), :mod:`.optimize` (the driver, :func:`optimize_phlw`),
:mod:`.output` (report.json and the PHLW design directory).

May import: :mod:`gridshell.core`, :mod:`gridshell.solver`, :mod:`gridshell.geometry`,
:mod:`gridshell.measure`, :mod:`gridshell.design`, :mod:`gridshell.render`, and
:mod:`gridshell.ncp.reference` / :mod:`gridshell.ncp.principal_frame`.
"""
from gridshell.ncp.phlw.checks import (_grid_geometry, fit_rows, net_direction_check,  # noqa: F401
                          principal_angle_error, row_relation_residual, start_rows)
from gridshell.ncp.phlw.figures import (ANGLE_TOL_DEG, COVERAGE_TOL, DEVIATION_TOL,  # noqa: F401
                           E_PHLW_FLOOR, RELATION_TOL, acceptance_figures, coverage_percent,
                           deviation_percent)
from gridshell.ncp.phlw.output import result_summary, write_phlw  # noqa: F401
from gridshell.ncp.phlw.problem import (REGULAR_FLOOR, UMBILIC_MARGIN, boundary_gliding,  # noqa: F401
                           phlw_problem, umbilic_margin)
from gridshell.ncp.phlw.rounds import STOP_MARGIN  # noqa: F401
from gridshell.ncp.phlw.terms import (MODES, Regularity, SampleGliding, UmbilicMargin,  # noqa: F401
                         curvature_eq, delta_eq, first_form_eq, init_auxiliary, make_layout,
                         make_samples, normal_eq, parametrization_guard, second_form_eq,
                         sqrt_delta_eq)
from gridshell.ncp.phlw.optimize import (DEFAULT_WEIGHTS, optimize_phlw,  # noqa: F401
                                         principal_range_notes)
from gridshell.ncp.phlw.result import PHLWResult  # noqa: F401
