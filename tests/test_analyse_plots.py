"""``suspopt.plots``: figures drawn from arrays, written atomically as PNG or SVG."""

from __future__ import annotations

import numpy as np
import pytest

from suspopt import plots


def test_a_figure_that_fails_to_write_leaves_nothing(tmp_path):
    fig, (ax,) = plots.new_figure(1)
    ax.plot([0, 1], [0, 1])
    path = tmp_path / "fig.png"

    def broken(target, **kwargs):
        target.write(b"half a figure")
        raise OSError("disk full")

    fig.savefig = broken
    with pytest.raises(OSError, match="disk full"):
        plots.save(fig, path)
    assert list(tmp_path.iterdir()) == []  # no figure, no temporary file, no lock


@pytest.mark.slow
def test_the_suffix_chooses_the_format(tmp_path):
    f = np.linspace(0.1, 30, 50)
    png = plots.transmissibilities(tmp_path / "t.png", "T", [("seat", f, 1 / f)])
    svg = plots.transmissibilities(tmp_path / "t.SVG", "T", [("seat", f, 1 / f)])
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert b"<svg" in svg.read_bytes()[:1000]
    with pytest.raises(ValueError, match="suffix must be one of .png, .svg"):
        plots.check_path(tmp_path / "t.jpg")


def test_pareto_fronts_draw_one_panel_per_objective_pair_and_variable(tmp_path):
    F = np.column_stack([np.linspace(0.1, 0.3, 8), np.linspace(0.09, 0.01, 8)])
    X = np.column_stack([np.linspace(1e4, 1e5, 8), np.full(8, 1000.0)])
    path = tmp_path / "front.svg"
    plots.pareto_fronts(
        path,
        "front",
        [("RC_se", "m/s^2"), ("X_ST", "m")],
        [("optimised", F), ("class B", 2 * F)],
        [("K_v", "N/m", X[:, 0]), ("C_v", "N s/m", X[:, 1])],
        marks={"knee": 3},
        comfort=[True, False],
    )
    text = path.read_text()
    # three panels (front, K_v, C_v) and the mark's label
    assert text.count('id="axes_') == 3 and "knee" in text


def test_a_cloud_of_builds_is_drawn_beneath_the_fronts(tmp_path, monkeypatch):
    """``cloud`` draws every point it is given (the builds of ``analyse builds``), on the
    panel's pair of objectives, beneath the fronts, under its label."""
    F = np.column_stack([np.linspace(0.1, 0.3, 8), np.linspace(0.09, 0.01, 8)])
    builds = np.repeat(F, 5, axis=0) * np.linspace(0.95, 1.05, 40)[:, None]
    drawn = []
    monkeypatch.setattr(plots.figures, "save", lambda fig, path: drawn.append(fig) or path)
    plots.pareto_fronts(
        tmp_path / "f.png", "f", [("RC_se", "m/s^2"), ("X_ST", "m")], [("optimised", F)],
        cloud=("builds (40)", builds),
    )  # fmt: skip
    ax = drawn[0].axes[0]
    cloud = next(c for c in ax.collections if c.get_label() == "builds (40)")
    np.testing.assert_array_equal(cloud.get_offsets(), builds)
    assert cloud.get_zorder() < min(c.get_zorder() for c in ax.collections if c is not cloud)
