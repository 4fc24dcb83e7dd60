"""The report's HTML page: plotly.js, the studies as JSON and the page's own script, inline.

:func:`render` needs plotly (a dependency of suspopt) for its JavaScript only: the
figures are drawn in the browser by the page's script from the data, so that the drop-downs
can redraw them. The script and the style are package data, ``suspopt/report/assets/``
(``page.js``, ``charts.js``: :mod:`suspopt.report.charts`, ``page.css``), read when a page
is rendered. The data are JSON in a ``<script type="application/json">`` element with every
``<``, ``>`` and ``&`` escaped, and every name from a file is shown with ``textContent``,
never as markup.
"""

from __future__ import annotations

import html
import json
from typing import Any

from ..errors import ConfigError
from .charts import settings

__all__ = ["render", "asset"]


def asset(name: str) -> str:
    """The text of the page's file ``name`` (``page.js``, ``charts.js``, ``page.css``) in
    ``suspopt/report/assets/``."""
    from importlib.resources import files

    return files(__package__).joinpath("assets", name).read_text(encoding="utf-8")


def _plotly_js() -> str:
    try:
        from plotly.offline import get_plotlyjs
    except ImportError:
        raise ConfigError(
            "report: needs plotly for its page's plots, a dependency of suspopt that cannot be "
            "imported here: pip install plotly"
        ) from None
    return get_plotlyjs()


def _json(value: Any) -> str:
    """JSON safe inside a ``<script>`` element: no ``<``, ``>`` or ``&`` left as such."""
    text = json.dumps(value, allow_nan=False, separators=(",", ":"))
    return text.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")


def data_bytes(study) -> int:
    """The bytes ``study``'s data take in the page (:func:`render`) [bytes]."""
    return len(_json(study.data).encode())


def _section(i: int, study) -> str:
    d = study.data
    e = html.escape
    three = (
        f'<label><input type="checkbox" id="d3-{i}"> 3D ({", ".join(e(n) for n in d["objectives"])})</label>'
        if len(d["objectives"]) == 3
        else ""
    )
    parts = [
        f"<h2>{e(study.label)} <span class='note'>({e(study.kind)}, {d['rows']} designs)</span></h2>",
        f"<div class='controls'><label>x <select id='x-{i}'></select></label>"
        f"<label>y <select id='y-{i}'></select></label>"
        f"<label>colour <select id='c-{i}'></select></label>{three}</div>",
        f"<div class='row'><div id='front-{i}' class='plot'></div>"
        f"<div id='design-{i}' class='design'></div></div>",
        f"<h3>Objectives and variables <span id='brush-{i}' class='note'></span></h3>"
        f"<div id='brush-command-{i}' class='onward'></div><div id='parallel-{i}' class='wide'></div>",
    ]
    if d["signals"]["signals"]:
        parts.append(
            f"<h3>Signals of the picks</h3><div class='controls'><label>signal "
            f"<select id='s-{i}'></select></label></div><div class='row'>"
            f"<div id='signal-{i}' class='plot'></div><div id='psd-{i}' class='plot'></div></div>"
        )
    if d["signals"].get("transmissibility"):
        parts.append(
            f"<h3>Seat transmissibility of the picks (floor to seat; to head: STHT, Eq 2.86;"
            f" the seat linearised)</h3><div id='tr-{i}' class='wide'></div>"
        )
    if "history" in d:
        parts.append(f"<h3>History</h3><div id='history-{i}' class='wide'></div>")
    for note in study.notes:
        parts.append(f"<p class='note'>{e(note)}</p>")
    prov = d["provenance"]
    config = prov.get("config", "")
    rest = "\n".join(f"{k}: {v}" for k, v in prov.items() if k != "config")
    parts.append(
        f"<details><summary>Provenance</summary><pre>{e(rest)}</pre>"
        f"<pre>{e(config)}</pre></details>"
    )
    return "\n".join(parts)


#: The most designs the page's command for the brushed designs lists (``simulate --pick``):
#: more make a command line too long to read, and a batch better chosen by narrower ranges.
BRUSH_COMMAND_ROWS = 100


def render(studies, title: str) -> str:
    """The whole page of ``studies`` (:class:`suspopt.report.Study`)."""
    from .._version import __version__

    payload = {
        "studies": [{"label": s.label, "kind": s.kind, "data": s.data} for s in studies],
        "brush_command_rows": BRUSH_COMMAND_ROWS,
    }
    e = html.escape
    return "\n".join(
        [
            "<!DOCTYPE html>",
            "<html lang='en'><head><meta charset='utf-8'>",
            f"<meta name='generator' content='suspopt {e(__version__)}'>",
            f"<title>{e(title)}</title><style>{asset('page.css')}</style></head><body>",
            f"<h1>{e(title)}</h1>",
            "<p class='note'>Click a design to see its row; drag along an axis of the "
            "parallel coordinates to select those designs in the front. Written by suspopt "
            "report; it needs no network.</p>",
            *(_section(i, s) for i, s in enumerate(studies)),
            f"<script type='application/json' id='suspopt-data'>{_json(payload)}</script>",
            f"<script>{_plotly_js()}</script>",
            f"<script>window.suspoptSettings = {_json(settings())};</script>",
            f"<script>{asset('charts.js')}</script>",
            f"<script>{asset('page.js')}</script>",
            "</body></html>",
        ]
    )
