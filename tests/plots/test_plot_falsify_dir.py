"""``amsa-phys plot`` on a falsification's directory: samples of a box, not a sweep's grid."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from figcapture import keep_figures
from matplotlib.collections import PathCollection
from matplotlib.figure import Figure

from amsa_phys.cli.main import main
from amsa_phys.falsify.outputs import write_results
from amsa_phys.plots import samples

KEYS = ["Leader.changePeriod", "Leader.cruisePower"]
#: (changePeriod, cruisePower, rms_error, robustness): run 2 and 3 falsify, 3 is the worst
POINTS = [
    (3.9449, 3.85542, 0.345, 0.9),
    (16.5453, 11.3361, 1.02, 0.2),
    (10.785, 10.5628, 0.916, -0.3),
    (14.088, 11.1556, 1.18, -0.87),
    (29.7523, 4.75378, 0.489, 0.6),
]


def _falsify_dir(folder: Path, objective: str = "robustness.band") -> Path:
    folder.mkdir(parents=True)
    rows = []
    for run, (cp, pw, rms, rob) in enumerate(POINTS):
        row = {"run": run, KEYS[0]: cp, KEYS[1]: pw, "seed_index": 0, "seed": 1, "error": ""}
        row |= {"rms_error": rms, "generation": run // 3}
        if objective.startswith("robustness"):
            row |= {"robustness.band": rob, "robustness": rob}
        rows.append(row)
    write_results(rows, KEYS, folder / "results.csv")
    record = {"scenario": "/somewhere/falsify_resonance.yaml", "objective": objective}
    (folder / "falsify.json").write_text(json.dumps(record))
    return folder


@pytest.fixture
def figures(monkeypatch: pytest.MonkeyPatch) -> list[Figure]:
    return keep_figures(monkeypatch, samples)


def _offsets(ax: object, label_start: str) -> np.ndarray:
    (coll,) = [
        c
        for c in ax.collections  # type: ignore[attr-defined]
        if isinstance(c, PathCollection) and str(c.get_label()).startswith(label_start)
    ]
    return np.asarray(coll.get_offsets())


def test_samples_are_dots_at_their_context_coloured_by_the_metric(
    tmp_path: Path, figures: list[Figure]
) -> None:
    """Every run is one dot at (changePeriod, cruisePower), its colour the metric: no grid
    cell per distinct value (the heatmap had 90 of 100 cells saying "none")."""
    folder = _falsify_dir(tmp_path / "fals")
    assert main(["plot", str(folder), "--metric", "rms_error"]) == 0
    ax = figures[0].axes[0]
    assert not ax.images  # no heatmap
    assert not [t for t in ax.texts if t.get_text() == "none"]
    dots = _offsets(ax, "run")
    assert sorted(map(tuple, dots.tolist())) == sorted((p[0], p[1]) for p in POINTS)
    (coll,) = [c for c in ax.collections if str(c.get_label()).startswith("run")]
    assert sorted(np.asarray(coll.get_array()).tolist()) == sorted(p[2] for p in POINTS)
    assert ax.get_xlabel() == KEYS[0]
    assert ax.get_ylabel() == KEYS[1]


def test_falsifying_runs_ringed_and_the_worst_starred_not_a_best(
    tmp_path: Path, figures: list[Figure]
) -> None:
    """The runs with robustness below 0 are marked as falsifying; the star is the search's
    worst (least robustness), never the lowest rms_error as a sweep's "best"."""
    folder = _falsify_dir(tmp_path / "fals")
    assert main(["plot", str(folder), "--metric", "rms_error"]) == 0
    ax = figures[0].axes[0]
    ringed = _offsets(ax, "falsifying")
    assert sorted(map(tuple, ringed.tolist())) == sorted((p[0], p[1]) for p in POINTS[2:4])
    (star,) = [ln for ln in ax.lines if str(ln.get_label()).startswith("worst")]
    assert (star.get_xdata()[0], star.get_ydata()[0]) == (POINTS[3][0], POINTS[3][1])
    texts = [ax.get_title(), *[t.get_text() for t in ax.get_legend().get_texts()]]
    assert not any("best" in t for t in texts)


def test_a_search_on_a_metric_stars_its_highest_value(
    tmp_path: Path, figures: list[Figure]
) -> None:
    """A search on rms_error maximised it: its worst run is the highest rms_error."""
    folder = _falsify_dir(tmp_path / "fals", objective="rms_error")
    assert main(["plot", str(folder)]) == 0
    ax = figures[0].axes[0]
    (star,) = [ln for ln in ax.lines if str(ln.get_label()).startswith("worst")]
    top = max(POINTS, key=lambda p: p[2])
    assert (star.get_xdata()[0], star.get_ydata()[0]) == (top[0], top[1])
    assert not [c for c in ax.collections if str(c.get_label()).startswith("falsifying")]


def test_titled_with_the_scenario_not_the_folder(tmp_path: Path, figures: list[Figure]) -> None:
    folder = _falsify_dir(tmp_path / "fals")
    assert main(["plot", str(folder)]) == 0
    title = figures[0].axes[0].get_title()
    assert title.startswith("falsify_resonance: robustness.band")
    assert "fals:" not in title


def test_a_trials_directory_points_at_its_trials(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``plot DIR`` on a ``--trials`` output names a trial to plot, and plotting that trial
    works (its falsify.json is one level up)."""
    top = tmp_path / "trials"
    top.mkdir()
    _falsify_dir(top / "trial-001")
    (top / "trial-001" / "falsify.json").rename(top / "falsify.json")
    _falsify_dir(top / "trial-002")
    assert main(["plot", str(top)]) == 2
    err = capsys.readouterr().err
    assert "trial-001" in err
    assert "2 trials" in err
    assert main(["plot", str(top / "trial-001")]) == 0
    assert (top / "trial-001" / "samples.png").is_file()


def test_one_axis_draws_the_value_against_it_with_the_bound(
    tmp_path: Path, figures: list[Figure]
) -> None:
    """A search over one parameter: robustness against it, the 0 it must fall below drawn."""
    folder = _falsify_dir(tmp_path / "fals")
    rows = (folder / "results.csv").read_text().splitlines()
    cut = [",".join(c for i, c in enumerate(r.split(",")) if i != 2) for r in rows]
    (folder / "results.csv").write_text("\n".join(cut) + "\n")  # KEYS[1] dropped
    assert main(["plot", str(folder)]) == 0
    ax = figures[0].axes[0]
    assert ax.get_ylabel() == "robustness.band"
    dots = _offsets(ax, "run")
    assert sorted(map(tuple, dots.tolist())) == sorted((p[0], p[3]) for p in POINTS)
    (bound,) = [ln for ln in ax.lines if ln.get_label() == "robustness 0"]
    assert list(bound.get_ydata()) == [0.0, 0.0]


def test_values_that_differ_in_the_sixth_digit_are_shown_as_values_not_an_offset(
    tmp_path: Path, figures: list[Figure]
) -> None:
    """A colour bar labelled ``1e-6 + 5.494e-1`` made near-equal runs look far apart."""
    folder = _falsify_dir(tmp_path / "fals", objective="rms_error")
    rows = (folder / "results.csv").read_text().splitlines()
    header = rows[0].split(",")
    at = header.index("rms_error")
    near = []
    for k, line in enumerate(rows[1:]):
        cells = line.split(",")
        cells[at] = f"{0.5494 + k * 1e-7:.7f}"
        near.append(",".join(cells))
    (folder / "results.csv").write_text("\n".join([rows[0], *near]) + "\n")
    assert main(["plot", str(folder)]) == 0
    fig = figures[0]
    fig.canvas.draw()
    (bar,) = [a for a in fig.axes if a.get_label() == "<colorbar>"]
    assert bar.yaxis.get_major_formatter().get_offset() == ""
    labels = [t.get_text() for t in bar.get_yticklabels() if t.get_text()]
    assert labels
    assert all(lab.startswith("0.5494") for lab in labels), labels
