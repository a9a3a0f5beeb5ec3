"""Runs that never settled are visible in a sweep's summary itself, not only in its title.

A grid point where no run settled has no line point; the "never" note was placed at its x
all the same, outside the autoscaled axes: invisible, and ``tight_layout`` then warned on
the terminal that it could not fit the figure (issue 30, item 8).
"""

from __future__ import annotations

import itertools
import warnings
from pathlib import Path

import matplotlib.pyplot as plt
import pytest

from amsa_phys.plots import summary
from amsa_phys.runs.sweep import read_results

#: Kv = 0.35 never settles in either seed; Kv = 0.1 in one of its two
ONE_AXIS = """\
run,MyFollowerController.Kv,seed_index,seed,error,rms_error,settling_time
0,0.1,0,1,,0.30,4.0
1,0.1,1,2,,0.25,
2,0.2,0,1,,0.40,6.0
3,0.2,1,2,,0.40,7.0
4,0.35,0,1,,3.0,
5,0.35,1,2,,2.9,
"""


def three_axes() -> str:
    """Kv x Kw x motorCoef, one seed; Kv = 0.35 never settles."""
    lines = [
        "run,MyFollowerController.Kv,MyFollowerController.Kw,MyNormalizePower.motorCoef,"
        "seed_index,seed,error,rms_error,settling_time"
    ]
    grid = itertools.product((0.1, 0.2, 0.35), (0.02, 0.04), (60, 80, 100))
    for i, (kv, kw, coef) in enumerate(grid):
        settle = "" if kv == 0.35 else f"{kv * 10 + kw * 100 + coef / 100:.2f}"
        lines.append(f"{i},{kv},{kw},{coef},0,1,,{kv},{settle}")
    return "\n".join(lines) + "\n"


def draw(tmp_path: Path, csv: str, monkeypatch: pytest.MonkeyPatch) -> plt.Figure:
    (tmp_path / "results.csv").write_text(csv)
    rows, axes = read_results(tmp_path / "results.csv")
    caught: list[plt.Figure] = []
    real_save = summary.save_png

    def keep(fig: plt.Figure, out: Path, **kw: object) -> Path:
        caught.append(fig)
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # "Tight layout not applied" was one
            return real_save(fig, out, **kw)  # type: ignore[arg-type]

    monkeypatch.setattr(summary, "save_png", keep)
    if len(axes) > 2:
        from amsa_phys.plots import facets

        monkeypatch.setattr(facets, "save_png", keep, raising=False)
    summary.plot_summary(rows, axes, "settling_time", tmp_path / "s.png", "sweep")
    (fig,) = caught
    return fig


def never_marks(ax: plt.Axes) -> list[tuple[float, str]]:
    """(x, text) of each "N never" note drawn on the axes' top edge."""
    return sorted(
        (float(t.get_position()[0]), t.get_text()) for t in ax.texts if "never" in t.get_text()
    )


def test_a_grid_point_where_no_run_settled_is_inside_the_line_plot(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    fig = draw(tmp_path, ONE_AXIS, monkeypatch)
    try:
        ax = fig.axes[0]
        assert never_marks(ax) == [(0.1, "1 never"), (0.35, "2 never")]
        low, high = ax.get_xlim()
        assert low < 0.1  # both inside the axes: nothing drawn off the edge
        assert high > 0.35
        assert (tmp_path / "s.png").is_file()
    finally:
        plt.close(fig)


def test_small_multiples_mark_never_settled_runs_inside_each_panel(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    fig = draw(tmp_path, three_axes(), monkeypatch)
    try:
        panels = [ax for ax in fig.axes if never_marks(ax) or ax.images]
        assert panels
        shown = 0
        for ax in panels:
            low, high = ax.get_xlim()
            for x, text in never_marks(ax):
                assert min(low, high) < x < max(low, high), text
                shown += 1
        assert shown >= 1  # every Kv = 0.35 run is said somewhere in the panels
    finally:
        plt.close(fig)


def test_a_figure_too_wide_to_lay_out_is_saved_without_a_library_warning(tmp_path: Path) -> None:
    from amsa_phys.plots.save import save_png

    fig, ax = plt.subplots(figsize=(4, 3))
    ax.plot([0, 1], [0, 1])
    ax.set_ylabel("a label far too long to fit " * 40, rotation=0)  # tight_layout gives up
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = save_png(fig, tmp_path / "wide.png")
    assert [str(w.message) for w in caught] == []
    assert out.stat().st_size > 0
