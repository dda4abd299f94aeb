"""ambseal.report: figures (:mod:`ambseal.report.figures`, matplotlib Agg) and the
self-contained HTML page (:mod:`ambseal.report.html`).

Import the submodules directly; this package imports nothing, so ``import ambseal.report``
does not load matplotlib.
"""
