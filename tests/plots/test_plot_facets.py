"""Sweeps of three axes or more draw small multiples, not a legend entry per line."""

from __future__ import annotations

import itertools
import warnings
from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
import pytest
from matplotlib.patches import Rectangle

from amsa_phys.plots import facets, summary
from amsa_phys.plots.save import png_text


def _rows(axes: dict[str, list[Any]], seeds: int = 2) -> list[dict[str, Any]]:
    """Every grid point × seed, the metric a known function of the point (lowest at K=0.3,
    m=70, c=2, seed-independent mean)."""
    rows = []
    for values in itertools.product(*axes.values()):
        point = dict(zip(axes, values, strict=True))
        for s in range(seeds):
            k, m = point.get("K", 0.3), point.get("m", 70)
            c = point.get("c", 2)
            value = (k - 0.3) ** 2 + ((m - 70) / 100) ** 2 + 0.01 * abs(c - 2) + 1.0
            rows.append({**point, "seed": s, "error": "", "rms_error": value + (s - 0.5) * 1e-3})
    return rows


def _draw(rows: list[dict[str, Any]], axes: list[str], tmp_path: Path, monkeypatch: Any) -> Any:
    caught: list[Any] = []
    monkeypatch.setattr(facets, "save_png", lambda fig, out, **kw: caught.append(fig) or out)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no library warning reaches the user
        summary.plot_summary(rows, axes, "rms_error", tmp_path / "s.png", "sweep: rms_error")
    return caught[0]


def test_three_numeric_axes_draw_a_heatmap_per_value_of_the_third(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    axes = {"K": [0.1, 0.2, 0.3, 0.4, 0.5], "m": [40, 55, 70, 85], "c": [1, 2, 3]}
    fig = _draw(_rows(axes), list(axes), tmp_path, monkeypatch)
    try:
        panels = [ax for ax in fig.axes if ax.get_visible() and ax.images]
        assert [ax.get_title() for ax in panels] == ["c=1", "c=2", "c=3"]  # fewest values
        assert all(ax.get_legend() is None for ax in fig.axes)
        assert {ax.images[0].get_array().shape for ax in panels} == {(4, 5)}  # m rows, K cols
        norms = {(ax.images[0].norm.vmin, ax.images[0].norm.vmax) for ax in panels}
        assert len(norms) == 1  # one colour scale for every panel
        framed = [ax for ax in panels if any(isinstance(p, Rectangle) for p in ax.patches)]
        assert [ax.get_title() for ax in framed] == ["c=2"]  # the best cell, in its panel
        assert "★ best: K=0.3, m=70, c=2" in fig._suptitle.get_text()
    finally:
        plt.close(fig)


def test_too_many_panels_follow_one_axis_and_say_what_was_averaged(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    axes = {
        "K": [0.1, 0.2, 0.3, 0.4],
        "m": [40, 55, 70, 85, 100],
        "c": [1, 2, 3, 4, 5, 6],
        "d": [0, 1, 2, 3, 4, 5, 6],
    }
    fig = _draw(_rows(axes, seeds=1), list(axes), tmp_path, monkeypatch)
    try:
        panels = [ax for ax in fig.axes if ax.get_visible() and ax.images]
        # the heatmaps take d and c (most values); K × m = 20 panels > 16: by K alone
        assert [ax.get_title() for ax in panels] == ["K=0.1", "K=0.2", "K=0.3", "K=0.4"]
        assert "cells are means over m too" in fig._suptitle.get_text()
    finally:
        plt.close(fig)


def test_one_numeric_axis_draws_a_line_per_panel(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    rows = _rows({"K": [0.1, 0.3, 0.5], "mode": ["a", "b"], "ctx": ["x", "y", "z"]})
    fig = _draw(rows, ["K", "mode", "ctx"], tmp_path, monkeypatch)
    try:
        panels = [ax for ax in fig.axes if ax.get_visible()]
        assert len(panels) == 6
        assert all(ax.get_legend() is None for ax in panels)
        assert "★ best: K=0.3" in fig._suptitle.get_text()
    finally:
        plt.close(fig)


def test_a_three_axis_summary_is_written_without_warnings(tmp_path: Path) -> None:
    axes = {"K": [0.1, 0.2, 0.3], "m": [40, 70], "c": [1, 2, 3]}
    rows = _rows(axes)
    rows[0]["error"] = "run fault"
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        out = summary.plot_summary(rows, list(axes), "rms_error", tmp_path / "s.png", "t: x")
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "1 of 36 runs have no rms_error" in png_text(out)["Title"]
    assert summary.scenario_of(out) == "t"


def test_a_tied_best_says_so(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """An axis that did not matter (every value gives the same metric) ties the best cell
    across its values: the title must not name one of them as the winner alone."""
    axes = {"K": [0.1, 0.3, 0.5], "m": [40, 70], "c": [1, 2]}
    rows = [
        {**r, "rms_error": round(r["rms_error"] - 0.01 * abs(r["c"] - 2), 6)}
        for r in _rows(axes, seeds=1)
    ]
    # now c does not matter: K=0.3, m=70 is best at c=1 and c=2 alike
    fig = _draw(rows, list(axes), tmp_path, monkeypatch)
    try:
        assert "★ best: K=0.3, m=70, c=1 (tied with 1 other grid point)" in fig._suptitle.get_text()
    finally:
        plt.close(fig)


def test_a_long_title_stays_inside_the_figure(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Three long axis names in the best point's line ran off both edges of the figure."""
    names = {
        "K": "MyFollowerController.Kv",
        "m": "MyFollowerController.Kw",
        "c": "physics.ground.friction",
    }
    rows = [
        {names[a]: v for a, v in r.items() if a in names}
        | {k: r[k] for k in ("seed", "error", "rms_error")}
        for r in _rows({"K": [0.1, 0.3], "m": [40, 70], "c": [2]})
    ]
    fig = _draw(rows, list(names.values()), tmp_path, monkeypatch)
    try:
        fig.canvas.draw()
        box = fig._suptitle.get_window_extent()
        assert box.x0 >= 0
        assert box.x1 <= fig.bbox.width
        assert "physics.ground.friction=2" in fig._suptitle.get_text()
    finally:
        plt.close(fig)
