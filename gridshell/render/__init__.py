"""Headless pictures (matplotlib Agg) and the self-contained ``report.html`` of a design bundle.

One module per picture: :mod:`.net_preview`, :mod:`.ncp_maps`, :mod:`.curvature_diagram`,
:mod:`.ribbons` (the lamellae as ribbons), :mod:`.sequence` (alignment frames and GIF),
:mod:`.report` (one HTML page of everything). Importing this package imports nothing heavy.

May import: :mod:`gridshell.core`, :mod:`gridshell.geometry`, :mod:`gridshell.measure`,
:mod:`gridshell.design` (the bundle); never a pipeline, structure or fabrication.
"""
