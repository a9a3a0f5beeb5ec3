"""What a falsification's own plots show: trials.png, convergence.png, counterexample.png."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from figcapture import keep_figures
from matplotlib.collections import PathCollection, PolyCollection
from matplotlib.figure import Figure

from amsa_phys.falsify import counterexample
from amsa_phys.falsify.trials import Trial, plot_trials, summarize
from amsa_phys.plots import convergence, save


@pytest.fixture
def figures(monkeypatch: pytest.MonkeyPatch) -> list[Figure]:
    return keep_figures(monkeypatch, convergence, save, draw=True)


def test_trials_axis_counts_whole_trials(tmp_path: Path, figures: list[Figure]) -> None:
    """Three trials: ticks at 1, 2, 3 only (not 0.75, 1.25...)."""
    trials = [Trial(1, True, 3, 10, -0.4, 1.0), Trial(2, True, 11, 12, -0.1, 1.0)]
    trials.append(Trial(3, False, None, 12, 0.2, 1.0))
    plot_trials(summarize(trials, 12, "robustness.band"), tmp_path / "t.png", "s")
    ax = figures[0].axes[0]
    lo, hi = ax.get_xlim()
    ticks = [t for t in ax.get_xticks() if lo <= t <= hi]
    assert ticks
    assert all(float(t).is_integer() for t in ticks)
    assert {1.0, 2.0, 3.0} <= set(ticks)


VALUES = [0.54, 0.54, -0.38, 0.45, 1.0, 0.64, 0.78, 0.65, 0.25, -0.63]


def _convergence(tmp_path: Path, figures: list[Figure]) -> tuple[Figure, object]:
    convergence.plot_convergence(
        list(VALUES), [0] * len(VALUES), "robustness.band", False, tmp_path / "c.png", "t", 0.0
    )
    fig = figures[0]
    (ax,) = [a for a in fig.axes if a.get_label() != "<colorbar>"]
    return fig, ax


def test_convergence_falsifying_runs_marked_and_above_the_line(
    tmp_path: Path, figures: list[Figure]
) -> None:
    """The runs below the bound are ringed as falsifying, and every run's dot is drawn over
    the worst-so-far step line (the dot that set it was hidden under it)."""
    _, ax = _convergence(tmp_path, figures)
    colls = {str(c.get_label()): c for c in ax.collections if isinstance(c, PathCollection)}
    ringed = next(c for k, c in colls.items() if k.startswith("falsifying"))
    assert sorted(np.asarray(ringed.get_offsets())[:, 0].tolist()) == [2.0, 9.0]
    (step,) = [ln for ln in ax.lines if ln.get_label() == "worst so far"]
    assert colls["run"].get_zorder() > step.get_zorder()


def test_convergence_legend_covers_no_run(tmp_path: Path, figures: list[Figure]) -> None:
    fig, ax = _convergence(tmp_path, figures)
    box = ax.get_legend().get_window_extent(fig.canvas.get_renderer())
    dots = ax.transData.transform(np.column_stack([range(len(VALUES)), VALUES]))
    inside = [i for i, (x, y) in enumerate(dots) if box.contains(x, y)]
    assert inside == []


def _run_dir(folder: Path) -> Path:
    """A counterexample run: a signal dipping to 13.49 at t = 64.75 s against 15 ± 1.5
    required over [10:120] (before 10 s it is far outside the band, unjudged)."""
    folder.mkdir()
    t = np.arange(0.0, 120.25, 0.25)
    d = 15 - 1.51 * np.exp(-(((t - 64.75) / 6) ** 2))
    d[t < 5] = 16.7  # the approach: outside the band, before the requirement reads
    sig = "MyDistanceMonitor.distanceFollowerToLeader"
    rows = "\n".join(f"{a},{b}" for a, b in zip(t, d, strict=True))
    (folder / "trace.csv").write_text(f"t,{sig}\n{rows}\n")
    entry = {
        "formula": f"always[10:120](abs({sig} - 15) <= 1.5)",
        "robustness": -0.01,
        "instant": 64.75,
        "atom": f"(abs(({sig} - 15)) <= 1.5)",
    }
    (folder / "metrics.json").write_text(json.dumps({"requirements": {"band": entry}}))
    return folder


def test_counterexample_band_over_its_interval_with_room_around_it(
    tmp_path: Path, figures: list[Figure]
) -> None:
    """The band is drawn over [10, 120] s only, the y range extends past it on both sides
    (so it is not the background) and the broken sample is marked with its value."""
    counterexample.plot(_run_dir(tmp_path / "ce"), "band", tmp_path / "c.png", "s")
    ax = figures[0].axes[0]
    (band,) = [
        c for c in ax.collections if isinstance(c, PolyCollection) and "±" in str(c.get_label())
    ]
    xs = np.concatenate([p.vertices[:, 0] for p in band.get_paths()])
    ys = np.concatenate([p.vertices[:, 1] for p in band.get_paths()])
    assert (xs.min(), xs.max()) == (10.0, 120.0)
    lo, hi = ax.get_ylim()
    margin = 0.1 * (ys.max() - ys.min())  # a tenth of the band's height at least
    assert lo < ys.min() - margin
    assert hi > ys.max() + margin
    (broken,) = [ln for ln in ax.lines if str(ln.get_label()).startswith("broken")]
    assert broken.get_xdata()[0] == 64.75
    assert broken.get_ydata()[0] == pytest.approx(13.49, abs=0.005)
    assert "13.49" in broken.get_label()


def test_interval_of_a_formula() -> None:
    assert counterexample.interval("always[10:120](x <= 1)", 60.0) == (10.0, 60.0)
    assert counterexample.interval("always(x <= 1)", 60.0) == (0.0, 60.0)
    assert counterexample.interval("not a formula (", 60.0) == (0.0, 60.0)


def test_convergence_counts_whole_runs_and_says_values_as_they_are(
    tmp_path: Path, figures: list[Figure]
) -> None:
    """Eight runs: no tick at run 2.5; values 1e-5 apart: no "1e-5 + 1.004e-1" offset
    above the axis (found on a short search's convergence.png)."""
    values = [0.1004485, 0.1004485, 0.1004485, 0.1004485, 0.1004485, 0.1004418, 0.100435, 0.1004485]
    convergence.plot_convergence(values, [0] * 8, "rms_error", True, tmp_path / "c.png", "t")
    ax = figures[-1].axes[0]
    ticks = [t for t in ax.get_xticks() if -0.5 <= t <= 7.5]
    assert ticks
    assert all(float(t).is_integer() for t in ticks)
    assert ax.yaxis.get_offset_text().get_text() == ""
