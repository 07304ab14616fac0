"""Where each kind of net can exist on a target, before any design (``gridshell analyze``).

``maps`` (the target's fitted surface sampled: K, principal curvatures, umbilics, which samples
lie on the target), ``regions`` (connected regions of a class, the largest parameter rectangle
a mode admits), ``trial`` (a quick coarse GG design: how far the nearest GG surface is),
``recommend`` (the pipeline and mode to use, with the expected deviation and coverage),
``analyze`` (the whole analysis and its files: analysis.json, analysis.png).

May import: :mod:`gridshell.core`, :mod:`gridshell.geometry`, :mod:`gridshell.measure`,
:mod:`gridshell.io`, :mod:`gridshell.design`, :mod:`gridshell.render` and the pipelines
:mod:`gridshell.gg`, :mod:`gridshell.ncp` (the floor above them).
"""
