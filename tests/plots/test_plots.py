"""What the plots show is readable: notes above the data, labels clear of each other."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt

from amsa_phys.model.scenario import load_scenario
from amsa_phys.plots.distance import distance_figure
from amsa_phys.runs.single import run_scenario

ROOT = Path(__file__).resolve().parent.parent.parent


def test_phase_notes_sit_above_the_signal_and_apart(tmp_path: Path) -> None:
    # scenario1's opening phase sets four parameters and its signal swings to 20 m: the notes
    # used to run through the curve and the first one over the second phase's
    scenario = load_scenario(ROOT / "scenarios" / "scenario1.yaml", duration=260)
    metrics = run_scenario(scenario, tmp_path, plot=False, progress=False).metrics
    fig = distance_figure(tmp_path / "trace.csv", metrics)
    try:
        fig.canvas.draw()
        ax = fig.axes[0]
        renderer = fig.canvas.get_renderer()  # type: ignore[attr-defined]
        notes = [a for a in ax.texts if a.get_text()]
        assert [n.get_text() for n in notes] == [
            "behavior=1\nlostDataGPS=0\nmotorCoef=100\nKv=0.35",
            "Kv=0.15",
            "Kv=0.1",
        ]
        boxes = [n.get_window_extent(renderer) for n in notes]
        (line,) = [ln for ln in ax.lines if ln.get_label() == metrics["quality"]["signal"]]
        highest = ax.transData.transform(line.get_xydata()).max(axis=0)[1]
        for i, box in enumerate(boxes):
            assert box.y0 > highest, notes[i].get_text()
            assert box.y1 <= ax.get_window_extent(renderer).y1
            assert not any(box.overlaps(other) for other in boxes[:i])
    finally:
        plt.close(fig)
