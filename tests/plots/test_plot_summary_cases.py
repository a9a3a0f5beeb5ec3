"""Summary cases found trying sweeps as a user: a sweep in which no run settled still draws
its grid, every point saying "never"; a tied best says it is tied.

Found trying the small multiples as a user: a 30 s sweep of three axes (nothing settles in
30 s), ``amsa-phys plot DIR --metric settling_time`` printed "drawn as 'never'" and the
picture said "no completed runs to plot" on empty axes, at every number of axes.
"""

from __future__ import annotations

import itertools
import warnings
from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
import pytest

from amsa_phys.plots import facets, summary


def _never_rows(axes: dict[str, list[Any]]) -> list[dict[str, Any]]:
    """Every grid point, one seed, completed (no error) with no settling time."""
    return [
        {**dict(zip(axes, values, strict=True)), "seed": 0, "error": "", "settling_time": None}
        for values in itertools.product(*axes.values())
    ]


def _draw(axes: dict[str, list[Any]], tmp_path: Path, monkeypatch: Any) -> Any:
    caught: list[Any] = []
    keep = lambda fig, out, **kw: caught.append(fig) or out  # noqa: E731
    monkeypatch.setattr(summary, "save_png", keep)
    monkeypatch.setattr(facets, "save_png", keep)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no library warning reaches the user
        summary.plot_summary(
            _never_rows(axes), list(axes), "settling_time", tmp_path / "s.png", "sweep"
        )
    return caught[0]


def _texts(fig: Any) -> list[str]:
    return [t.get_text() for ax in fig.axes for t in ax.texts]


@pytest.mark.parametrize(
    "axes",
    [
        {"K": [0.1, 0.2, 0.3]},
        {"K": [0.1, 0.2, 0.3], "m": [40, 70]},
        {"K": [0.1, 0.2, 0.3], "m": [40, 70], "c": [1, 2]},
        {"K": [0.1, 0.2, 0.3], "ctx": ["a", "b"], "leader": ["x", "y"]},  # line panels
    ],
    ids=["one axis", "two axes", "three axes", "one numeric of three"],
)
def test_every_grid_point_says_never(
    axes: dict[str, list[Any]], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    fig = _draw(axes, tmp_path, monkeypatch)
    try:
        texts = _texts(fig)
        assert not any("no completed runs" in t for t in texts)
        points = len(list(itertools.product(*axes.values())))
        if len(axes) == 1 or (len(axes) >= 3 and "ctx" in axes):  # lines: "k never" per x
            shown = sum(int(t.split()[0]) for t in texts if t.endswith(" never"))
        else:  # heatmap cells
            shown = texts.count("never")
        assert shown == points
        assert not [ax for ax in fig.axes if ax.get_label() == "<colorbar>"]  # no scale
    finally:
        plt.close(fig)


def test_a_two_axis_heatmap_says_when_its_best_is_tied(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """An axis that did not matter ties the best across its values: the title says so."""
    rows = [
        {"K": k, "m": m, "seed": 0, "error": "", "rms_error": abs(k - 0.2) + 1.0}
        for k in (0.1, 0.2, 0.3)
        for m in (40, 70)
    ]
    caught: list[Any] = []
    monkeypatch.setattr(summary, "save_png", lambda fig, out, **kw: caught.append(fig) or out)
    summary.plot_summary(rows, ["K", "m"], "rms_error", tmp_path / "s.png", "sweep")
    try:
        title = caught[0].axes[0].get_title()
        assert "★ best: K=0.2, m=40 (tied with 1 other grid point)" in title
    finally:
        plt.close(caught[0])


@pytest.mark.parametrize(
    ("metric", "word"), [("rms_error", "lowest"), ("robustness.band", "highest")]
)
def test_lines_of_one_axis_say_which_mean_is_starred(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, metric: str, word: str
) -> None:
    """Three lines (a context axis beside Kv), two seeds: the star's legend entry says the
    sense of the best ("lowest mean of each line"), never the seed count ("2 mean ...")."""
    rows = [
        {"K": k, "ctx": c, "seed": s, "error": "", metric: k * (1 + i) + 0.01 * s}
        for k in (0.1, 0.2, 0.3)
        for i, c in enumerate(("a", "b", "c"))
        for s in (0, 1)
    ]
    caught: list[Any] = []
    monkeypatch.setattr(summary, "save_png", lambda fig, out, **kw: caught.append(fig) or out)
    summary.plot_summary(rows, ["K", "ctx"], metric, tmp_path / "s.png", "sweep")
    try:
        labels = [
            t.get_text()
            for ax in caught[0].axes
            if ax.get_legend()
            for t in ax.get_legend().get_texts()
        ]
        assert f"{word} mean of each line" in labels, labels
    finally:
        plt.close(caught[0])


def test_a_tiny_seed_spread_is_never_said_as_zero_percent() -> None:
    """A spread of 3e-6 of the axis read "0.0% of the axis", as if there were none."""
    assert summary.axis_share(0.009) == "0.9% of the axis"
    assert summary.axis_share(3e-6) == "under 0.1% of the axis"
    assert summary.axis_share(0.0) == "none (the seeds agree exactly)"
