"""What a user's try-out found in the plots: the sweep title's name, the heatmap's text and
frame, the live-change label under the legend, fractional collision ticks."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
import pytest
from matplotlib.colors import to_rgba
from matplotlib.patches import Rectangle

from amsa_phys.cli.main import main
from amsa_phys.plots import distance, summary
from amsa_phys.plots.save import png_text

ROOT = Path(__file__).resolve().parent.parent.parent
SHORT = ROOT / "tests" / "fixtures" / "mde_short.yaml"


def caught_figure(module: Any, draw: Any, monkeypatch: pytest.MonkeyPatch) -> plt.Figure:
    caught: list[plt.Figure] = []
    monkeypatch.setattr(module, "save_png", lambda fig, out, **kw: caught.append(fig) or out)
    draw()
    return caught[0]


def grid_rows(metric: str, values: dict[tuple[float, float], float]) -> list[dict[str, Any]]:
    return [
        {"a": a, "b": b, metric: v, "error": "", "seed_index": 0} for (a, b), v in values.items()
    ]


def test_plot_of_a_renamed_sweep_folder_is_titled_with_the_scenario(tmp_path: Path) -> None:
    out = tmp_path / "sweep"
    args = ["sweep", str(SHORT), "--duration", "3", "--grid", "MyFollowerController.Kv=0.1,0.2"]
    assert main([*args, "-j", "1", "--out", str(out)]) == 0
    moved = out.rename(tmp_path / "whatever-I-called-it")
    assert main(["plot", str(moved), "--metric", "collisions"]) == 0
    title = png_text(moved / "summary.png")["Title"]
    assert title == "mde_short: collisions (1 seed); runs cut to 3 s of 500 s"


def test_an_old_sweep_without_the_record_falls_back_to_the_folder_name(
    tmp_path: Path,
) -> None:
    out = tmp_path / "old-sweep"
    args = ["sweep", str(SHORT), "--duration", "3", "--grid", "MyFollowerController.Kv=0.1,0.2"]
    assert main([*args, "-j", "1", "--out", str(out)]) == 0
    (out / "summary.png").unlink()
    assert main(["plot", str(out)]) == 0
    assert png_text(out / "summary.png")["Title"] == "old-sweep: rms_error (1 seed)"


def test_heatmap_text_contrasts_with_its_cell_and_the_best_frame_is_whole(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    values = {(a, b): a * 10 + b for a in (1.0, 2.0, 3.0) for b in (1.0, 2.0)}
    rows = grid_rows("rms_error", values)
    fig = caught_figure(
        summary,
        lambda: summary.plot_summary(rows, ["a", "b"], "rms_error", tmp_path / "s.png", "t"),
        monkeypatch,
    )
    try:
        ax = fig.axes[0]
        colour = {t.get_text(): t.get_color() for t in ax.texts}
        assert colour["32"] == "black"  # the highest value: viridis' yellow
        assert colour["11"] == "white"  # the lowest: its dark blue
        (frame,) = [p for p in ax.patches if isinstance(p, Rectangle) and not p.get_fill()]
        x, y = frame.get_xy()
        x0, x1 = sorted(ax.get_xlim())
        y0, y1 = sorted(ax.get_ylim())
        # the best cell (a=1, b=1) is the bottom-left corner: its frame lies inside the axes
        assert x0 < x < x + frame.get_width() < x1
        assert y0 < y < y + frame.get_height() < y1
    finally:
        plt.close(fig)


@pytest.mark.parametrize(
    ("rgba", "expected"),
    [((0.993, 0.906, 0.144, 1), "black"), ((0.267, 0.005, 0.329, 1), "white")],
)
def test_text_colour_follows_luminance(rgba: tuple[float, ...], expected: str) -> None:
    assert summary.text_colour_on(to_rgba(rgba)) == expected


@pytest.mark.parametrize("metric", ["collisions", "phase1.collisions"])
def test_count_metrics_get_integer_ticks(
    metric: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    rows = [
        {"Kv": kv, metric: n, "error": "", "seed_index": s}
        for kv, n in ((0.1, 0.0), (0.2, 1.0), (0.3, 3.0))
        for s in (0, 1)
    ]
    fig = caught_figure(
        summary,
        lambda: summary.plot_summary(rows, ["Kv"], metric, tmp_path / "s.png", "t"),
        monkeypatch,
    )
    try:
        ticks = [t for t in fig.axes[0].get_yticks() if -0.3 < t < 3.3]
        assert ticks
        assert all(float(t).is_integer() for t in ticks)
    finally:
        plt.close(fig)


def test_a_live_change_label_is_not_under_the_legend_and_has_an_entry(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    scen = tmp_path / "live.yaml"
    scen.write_text(
        SHORT.read_text().replace("../../worlds", str(ROOT / "worlds"))
        + "  - {at: 140, set: {MyFollowerController.Kv: 0.2}, new_phase: false, label: live}\n"
    )
    out = tmp_path / "run"
    args = ["run", str(scen), "--headless", "-q", "--duration", "150", "--no-plot"]
    assert main([*args, "--out", str(out)]) == 0
    metrics = json.loads((out / "metrics.json").read_text())
    fig = distance.distance_figure(out / "trace.csv", metrics)
    try:
        ax = fig.axes[0]
        legend = ax.get_legend()
        assert "change inside a phase" in [t.get_text() for t in legend.get_texts()]
        renderer = fig.canvas.get_renderer()
        (label,) = [t for t in ax.texts if t.get_text() == "live: Kv=0.2"]
        assert not label.get_window_extent(renderer).overlaps(legend.get_window_extent(renderer))
    finally:
        plt.close(fig)


@pytest.mark.parametrize(
    ("scenario", "title"),
    [
        ("paper_fig6.yaml", "paper_fig6: Kv = 0.35, then 0.05 from 100 s"),
        ("paper_fig5_kv01.yaml", "paper_fig5_kv01: Kv = 0.1"),
    ],
)
def test_a_paper_panel_title_names_every_kv_it_shows(scenario: str, title: str) -> None:
    from amsa_phys.cli.paperruns import run_label
    from amsa_phys.model.scenario import load_scenario

    path = ROOT / "scenarios" / scenario
    assert run_label(path, load_scenario(path)) == title


def test_a_rover_box_is_framed_in_its_trajectory_colour() -> None:
    from matplotlib.colors import to_hex
    from matplotlib.patches import FancyBboxPatch

    from amsa_phys.model.world import load_world
    from amsa_phys.plots.graph import LABEL_PT, diagram
    from amsa_phys.plots.trajectory import rover_styles

    fig, _, _ = diagram(load_world(ROOT / "worlds" / "mde_challenge.yaml"))
    try:
        ax = fig.axes[0]
        names = [t.get_text() for t in ax.texts if t.get_fontweight() == "bold"]
        boxes = [p for p in ax.patches if isinstance(p, FancyBboxPatch)]
        edge = {n: to_hex(b.get_edgecolor()) for n, b in zip(names, boxes, strict=True)}
        styles = rover_styles(["Leader", "Follower"])
        assert edge["Follower"] == styles["Follower"].colour  # blue, as its path
        assert edge["Leader"] == styles["Leader"].colour
        assert edge["LeaderGPS"] == to_hex("0.2")  # not a rover
        assert LABEL_PT >= 7
    finally:
        plt.close(fig)


def test_the_expanded_platoon_is_laid_out_a_bounded_number_of_times(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Moving the columns apart stops once it stops helping (it took 33 s, four layouts)."""
    from amsa_phys.model.world import load_world
    from amsa_phys.plots import graph

    calls = []
    layout = graph._layout

    def counted(*args: Any) -> Any:
        calls.append(args[2])
        return layout(*args)

    monkeypatch.setattr(graph, "_layout", counted)
    fig, boxes, _ = graph.diagram(load_world(ROOT / "worlds" / "platoon.yaml"), False)
    plt.close(fig)
    assert len(boxes) == 71
    assert len(calls) <= 2


def test_a_graph_too_big_to_draw_is_refused_at_once_and_a_big_one_says_it_is_working(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    import yaml

    world = yaml.safe_load((ROOT / "worlds" / "platoon.yaml").read_text())
    for cars in (199, 15):
        world["components"]["Car"]["count"] = cars
        (tmp_path / f"p{cars}.yaml").write_text(yaml.safe_dump(world, sort_keys=False))
    out = tmp_path / "g.png"
    assert main(["graph", str(tmp_path / "p199.yaml"), "--expand", "-o", str(out)]) == 2
    assert capsys.readouterr().err == (
        "error: --expand: 1394 components are too many to draw (at most 300): drop --expand "
        "(copies drawn once), or write a .dot file for Graphviz\n"
    )
    assert not out.exists()
    assert (
        main(["graph", str(tmp_path / "p199.yaml"), "--expand", "-o", str(tmp_path / "g.dot")]) == 0
    )
    assert main(["graph", str(tmp_path / "p15.yaml"), "--expand", "-o", str(out)]) == 0
    assert capsys.readouterr().err.startswith("laying out 106 components and ")
    assert out.stat().st_size > 10_000
