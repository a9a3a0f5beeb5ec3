"""A sweep says its best point at the end, and its one-axis summary is readable."""

from __future__ import annotations

import statistics
from collections import defaultdict
from pathlib import Path

import pytest
from figcapture import keep_figures
from matplotlib.figure import Figure

from amsa_phys.cli.main import main
from amsa_phys.plots import summary
from amsa_phys.runs.sweep import read_results
from amsa_phys.runs.sweepbest import best_line, best_point

ROOT = Path(__file__).resolve().parents[2]
SCENARIO = ROOT / "scenarios" / "falsify_resonance.yaml"
AXIS = "Leader.changePeriod"


def test_sweep_prints_its_best_point(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The last line names the grid point with the lowest seed mean and that mean, as
    results.csv has them (the summary's star, without opening summary.png)."""
    out = tmp_path / "sw"
    argv = [
        "sweep",
        str(SCENARIO),
        "--grid",
        f"{AXIS}=7,14,30",
        "--grid",
        "LeaderGPS.lostDataGPS=10",
    ]
    assert main([*argv, "--seeds", "2", "--duration", "40", "--out", str(out), "-j", "1"]) == 0
    last = capsys.readouterr().out.splitlines()[-1]
    rows, _ = read_results(out / "results.csv")
    means: dict[float, list[float]] = defaultdict(list)
    for r in rows:
        means[r[AXIS]].append(r["rms_error"])
    x = min(means, key=lambda k: statistics.fmean(means[k]))
    assert last.startswith(f"best (lowest mean rms_error): {AXIS}={x:g}, ")
    assert last.endswith(f"-> {statistics.fmean(means[x]):.6g} (2 seeds)")


def test_best_point_ties_and_nothing() -> None:
    rows = [
        {"a": 1, "error": "", "m": 2.0},
        {"a": 2, "error": "", "m": 1.0},
        {"a": 3, "error": "", "m": 1.0},
        {"a": 4, "error": "boom", "m": 0.1},
        {"a": 5, "error": "", "m": None},
    ]
    assert best_point(rows, ["a"], "m") == ((("a", 2),), 1.0, 1, 1)
    assert best_point(rows[3:], ["a"], "m") is None


@pytest.fixture
def figures(monkeypatch: pytest.MonkeyPatch) -> list[Figure]:
    return keep_figures(monkeypatch, summary)


ROWS = [  # two seeds a point, spreads far below a marker at this scale
    {AXIS: x, "seed_index": s, "error": "", "rms_error": v}
    for x, pair in ((7, (0.6685, 0.6705)), (14, (0.7758, 0.7794)), (30, (0.4161, 0.4145)))
    for s, v in enumerate(pair)
]


def test_one_axis_summary_legend_says_what_its_marks_are(
    tmp_path: Path, figures: list[Figure]
) -> None:
    """The legend of a one-line summary names the best point and what a bar is, not just
    the metric's name again."""
    summary.plot_summary(ROWS, [AXIS], "rms_error", tmp_path / "s.png", "s: rms_error")
    ax = figures[0].axes[0]
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    assert texts != ["rms_error"]
    assert f"best: {AXIS}=30 (0.4153)" in texts
    assert "mean of 2 seeds, min–max bar" in texts


def test_two_seed_spread_is_shown_and_said(tmp_path: Path, figures: list[Figure]) -> None:
    """Each seed is drawn (a dot at its value) and the title says the largest spread, so
    bars too small to see are not read as "no spread"."""
    summary.plot_summary(ROWS, [AXIS], "rms_error", tmp_path / "s.png", "s: rms_error")
    ax = figures[0].axes[0]
    ticks = sorted(float(y) for ln in ax.lines if ln.get_gid() == "seed" for y in ln.get_ydata())
    assert ticks == sorted(r["rms_error"] for r in ROWS)
    assert "largest seed spread (min–max) 0.0036" in ax.get_title()


def test_a_requirements_robustness_is_best_at_its_highest(
    tmp_path: Path, figures: list[Figure]
) -> None:
    """A robustness is a margin (higher is better, as ``tune`` and ``falsify`` read it): the
    best point is its highest mean, in the last line and in the summary's star alike."""
    rows = [{**r, "robustness.band": -r["rms_error"]} for r in ROWS]
    point, mean, _, _ = best_point(rows, [AXIS], "robustness.band")  # type: ignore[misc]
    assert point == ((AXIS, 30),)  # the lowest mean would be 14's -0.7776
    assert mean == pytest.approx(-0.4153)
    assert best_line(rows, [AXIS], "robustness.band").startswith(  # type: ignore[union-attr]
        f"best (highest mean robustness.band): {AXIS}=30 -> "
    )
    summary.plot_summary(rows, [AXIS], "robustness.band", tmp_path / "s.png", "s")
    texts = [t.get_text() for t in figures[0].axes[0].get_legend().get_texts()]
    assert f"best: {AXIS}=30 (-0.4153)" in texts


def test_a_two_axis_robustness_heatmap_frames_the_highest_cell(
    tmp_path: Path, figures: list[Figure]
) -> None:
    rows = [
        {AXIS: x, "K": k, "seed_index": 0, "error": "", "robustness.band": x * k}
        for x in (1.0, 2.0)
        for k in (1.0, 3.0)
    ]
    summary.plot_summary(rows, [AXIS, "K"], "robustness.band", tmp_path / "s.png", "s")
    assert f"★ best: {AXIS}=2, K=3" in figures[0].axes[0].get_title()
