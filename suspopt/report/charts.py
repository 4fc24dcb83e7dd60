"""The report's charts that need more than one ``Plotly.react``: the script
``assets/charts.js`` (package data, read by :func:`suspopt.report.page.render`) defines
``window.suspoptCharts``, which the page's own script (``assets/page.js``) calls with the data
and the labels it made:

- ``lines(x, curves, labels, prefix, extra)``: one line per *distinct* curve, named by the
  ``labels`` of every curve that shares it (``distinct``: curves equal to :data:`SAME` of
  their largest magnitude are one), so that a legend has one entry per curve drawn;
- ``history(div, h)``: the history per generation as one panel per series (each best
  objective, the hypervolume, the feasible share), each on its own y axis titled with its
  quantity and unit, so none lies flat on another's scale;
- ``placeLabels(div, labels)``: labels of points (the front's picks and the config's design)
  as annotations with a leader line, each placed at the first of a list of offsets where its
  box on screen overlaps no label placed before it and no labelled point, preferring offsets
  inside the plot; picks of one point share one label (the page joins their names). It
  places again after the axes move (the labels widen the autorange) and after a zoom, and
  marks the plot ``data-labelled`` when they are placed (what the browser test waits for).

This module holds the numbers the script takes (:func:`settings`, given to the page as
``window.suspoptSettings``).
"""

from __future__ import annotations

__all__ = ["SAME", "LABEL_GAP_PX", "settings"]

#: Curves whose values differ by no more than this share of their largest magnitude are drawn
#: as one, and named by all the designs that share it.
SAME = 1e-12
#: Fewest pixels between two label boxes.
LABEL_GAP_PX = 2


def settings() -> dict[str, float]:
    """The numbers ``assets/charts.js`` reads from ``window.suspoptSettings``."""
    return {"same": SAME, "labelGapPx": LABEL_GAP_PX}
