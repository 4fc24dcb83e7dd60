"""Figures of the analyses, drawn from arrays (matplotlib).

The analyses compute and write HDF5; this module draws what they hand it, so a figure can be
redrawn from a file (the simulation figure computes the Welch PSDs and ISO 2631-1 weighted
r.m.s. of the signals it is handed, with :mod:`suspopt.metrics`). Panel functions (``draw_*``) draw on one matplotlib ``Axes``; figure
functions lay panels out and :func:`save` writes the file, atomically (a temporary name, then
a rename), as PNG or SVG by its suffix. No pyplot: figures are ``matplotlib.figure.Figure``
objects, so nothing depends on a display or on global state; matplotlib is imported inside
the functions only (importing this module costs nothing). Each ``plot_*`` figure has a
``*_figure`` twin that returns the ``Figure`` unsaved.

Several curves on one panel (models, designs) get :func:`curve_styles`: colour, line style,
line width (the first curve widest and drawn underneath, the last narrowest on top) and a
marker shape at staggered positions (:func:`mark_indices`), so that curves which coincide
stay distinguishable; the data are never offset. A figure has one legend, below its panels,
never on the data; layouts are constrained (labels never overlap) and titles wrap.

Figures of the thesis they correspond to:

- :func:`model_comparison`: time responses and body-acceleration PSD of several models
  (Figs. 3.2-3.8, 3.9-3.15, 3.17-3.24);
- :func:`pareto_fronts`: a Pareto front and its pseudo-fronts (Figs. 7.4b, 8.22-8.24) with
  chosen designs marked, and the design variables along the front (Figs. 8.11-8.20);
- :func:`sensitivity`: the CDF threshold sweep (Figs. 4.7, 4.10);
- :func:`scenario_spread`: a robust front's picks under each scenario (ours);
- :func:`transmissibilities`: seat transmissibility and STHT (Eq 2.86, Figs. 2.18b, 8.26);
- :func:`plot_kesort`: the k-ε levels over a front (Figs. 6.7, 7.5, 7.6), from a
  :class:`suspopt.choosing.selection.Selection`;
- :func:`plot_simulation`: a :class:`suspopt.simulation.Result`'s signals over time, their
  Welch PSD and the ISO 2631-1 weighted r.m.s. of its accelerations against the comfort
  reactions (Annex C.2.3), one or several designs (``suspopt simulate --plot``; the figure
  :func:`result_figure`, which ``Result.plot()`` returns);
- :func:`plot_optimisation`: an :class:`suspopt.optimisation.OptimisationResult`'s front (or
  best value) and its history per generation (``suspopt optimise --plot``; the figure
  :func:`optimisation_result_figure`, which ``OptimisationResult.plot()`` returns).
"""

from __future__ import annotations

from ..metrics.spectral import PSD_SEGMENT
from .figures import (
    model_comparison,
    model_figure,
    pareto_fronts,
    plot_kesort,
    scenario_spread,
    sensitivity,
    transmissibilities,
)
from .panels import (
    draw_comfort_levels,
    draw_design_variable,
    draw_front,
    draw_history,
    draw_spectra,
    draw_time_responses,
    draw_weighted_rms,
)
from .runs import (
    chosen_designs,
    default_signals,
    design_labels,
    optimisation_figure,
    optimisation_result_figure,
    pareto_set_figure,
    plot_optimisation,
    plot_simulation,
    result_figure,
    simulation_figure,
)
from .style import (
    FORMATS,
    MAX_DESIGNS,
    check_path,
    curve_styles,
    mark_indices,
    new_figure,
    save,
)

__all__ = [
    "FORMATS",
    "MAX_DESIGNS",
    "PSD_SEGMENT",
    "check_path",
    "new_figure",
    "save",
    "curve_styles",
    "mark_indices",
    "draw_time_responses",
    "draw_spectra",
    "draw_front",
    "draw_design_variable",
    "draw_comfort_levels",
    "draw_weighted_rms",
    "draw_history",
    "model_comparison",
    "model_figure",
    "pareto_fronts",
    "sensitivity",
    "scenario_spread",
    "transmissibilities",
    "plot_kesort",
    "simulation_figure",
    "plot_simulation",
    "result_figure",
    "default_signals",
    "optimisation_figure",
    "plot_optimisation",
    "optimisation_result_figure",
    "pareto_set_figure",
    "chosen_designs",
    "design_labels",
]
