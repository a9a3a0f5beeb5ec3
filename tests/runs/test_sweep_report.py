"""What a sweep tells its user: an axis the timeline overrides, heatmap values and the best
cell, runs left out of a summary (issue 17 items 12 and 13)."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import pytest
from matplotlib.patches import Rectangle

from amsa_phys.cli.main import main
from amsa_phys.plots import summary
from amsa_phys.runs.sweep import read_results

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO1 = ROOT / "scenarios" / "scenario1.yaml"

#: a 2 x 3 grid, one seed; Kv=0.35 never settles (empty settling_time), one run failed
RESULTS = """\
run,MyFollowerController.Kv,MyFollowerController.Kw,seed_index,seed,error,rms_error,settling_time
0,0.1,0.02,0,1,,0.30,4.0
1,0.1,0.04,0,1,,0.25,3.0
2,0.1,0.08,0,1,,0.40,6.0
3,0.35,0.02,0,1,,3.0,
4,0.35,0.04,0,1,,2.9,
5,0.35,0.08,0,1,run fault at t=1.000 s in X: boom,,
"""


def test_sweeping_what_the_timeline_changes_warns_once(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    args = ["sweep", str(SCENARIO1), "--grid", "MyFollowerController.Kv=0.1,0.2"]
    args += ["--grid", "MyFollowerController.Kw=0.04", "--duration", "130", "-j", "1"]
    assert main([*args, "--out", str(tmp_path / "s")]) == 0
    err = capsys.readouterr().err
    # Kv only: the timeline never sets Kw (the other warning: runs of 130 s cannot judge
    # the scenario's requirement read until 500 s)
    assert err.count("warning: MyFollowerController.") == 1
    assert err.count("warning:") == 2
    assert (
        "warning: MyFollowerController.Kv is swept, but the timeline also sets it (at 125 s): "
        "each run's value holds only until 125 s, so the axis affects phase 0 only; compare "
        "phase-0 metrics (--metric phase0.rms_error) or drop those entries\n"
    ) in err


def test_a_sweep_the_timeline_does_not_touch_does_not_warn(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    args = ["sweep", str(SCENARIO1), "--grid", "MyFollowerController.Kv=0.1,0.2"]
    assert main([*args, "--duration", "100", "-j", "1", "--out", str(tmp_path / "s")]) == 0
    err = capsys.readouterr().err
    assert "is swept, but the timeline" not in err  # cut at 100 s: no Kv step is reached
    assert err.count("warning:") == 1  # the requirement read until 500 s, said once


def test_heatmap_writes_each_value_and_frames_the_best(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "results.csv").write_text(RESULTS)
    rows, axes = read_results(tmp_path / "results.csv")
    caught: list[plt.Figure] = []
    monkeypatch.setattr(summary, "save_png", lambda fig, out, **kw: caught.append(fig) or out)
    summary.plot_summary(rows, axes, "rms_error", tmp_path / "s.png", "sweep")
    fig = caught[0]
    try:
        ax = fig.axes[0]
        cells = sorted(t.get_text() for t in ax.texts)
        assert cells == ["0.25", "0.3", "0.4", "2.9", "3", "none"]  # the failed run: none
        (frame,) = [p for p in ax.patches if isinstance(p, Rectangle)]
        x, y = frame.get_xy()  # framed inside the cell: its centre is the cell's
        centre = (x + frame.get_width() / 2, y + frame.get_height() / 2)
        assert centre == pytest.approx((0.0, 1.0))  # Kv = 0.1 (column 0), Kw = 0.04 (row 1)
        title = ax.get_title()
        assert "★ best: MyFollowerController.Kv=0.1, MyFollowerController.Kw=0.04" in title
        assert "1 of 6 runs have no rms_error and are left out" in title
    finally:
        plt.close(fig)


def test_plot_metric_says_how_many_runs_it_left_out(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "results.csv").write_text(RESULTS)
    assert main(["plot", str(tmp_path), "--metric", "settling_time"]) == 0
    assert capsys.readouterr().out == (
        f"wrote {tmp_path / 'summary.png'}\n"
        "2 of 6 runs never reached a settling_time: drawn as 'never'\n"
        "left out 1 of 6 runs: 0 with no settling_time value, 1 failed\n"
    )


def test_never_settled_runs_are_drawn_as_never_not_hidden(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "results.csv").write_text(RESULTS)
    rows, axes = read_results(tmp_path / "results.csv")
    caught: list[plt.Figure] = []
    monkeypatch.setattr(summary, "save_png", lambda fig, out, **kw: caught.append(fig) or out)
    summary.plot_summary(rows, axes, "settling_time", tmp_path / "s.png", "sweep")
    fig = caught[0]
    try:
        ax = fig.axes[0]
        texts = [t.get_text() for t in ax.texts]
        assert texts.count("never") + sum("never" in t and t != "never" for t in texts) == 2
        title = ax.get_title()
        assert "2 of 6 runs never reached a settling_time (drawn as 'never')" in title
        assert "1 of 6 runs have no settling_time and are left out" in title
    finally:
        plt.close(fig)


def test_sweep_executor_has_help(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        main(["sweep", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert (
        "--executor {batch,local,dask} where the runs go: batch (default): batches of runs as "
        "columns of one simulation, on -j local worker processes; local: one run per "
        "process; dask: batches on an existing Dask cluster (needs --scheduler and the "
        "cluster extra)"
    ) in text
