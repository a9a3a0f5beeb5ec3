"""Fig. 6 at each GPS loss rate, in the sensed wiring beside the paper's.

The paper's model feeds the controller the TRUE distance (``MyDistanceMonitor``), so losing
the leader's GPS fixes only steers the bearing and Fig. 6 barely moves: 0 to 90 % loss
changes its plateau by ~0.01 m. ``worlds/mde_challenge_sensed.yaml`` feeds it the distance
between the two GPS fixes instead; there a lost fix is a stale distance, and the loss rate
shows. One panel per wiring, one line per loss rate (the paper's 10 % drawn strongest), and
each line's plateau (mean distance from 50 s after the Kv switch) written beside it.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from .paper import FIG6, PaperRun, draw_notes, seed_band
from .save import save_png

#: The loss rates drawn (percent of the leader's fixes lost); 10 is the paper's Fig. 6.
LOSS_RATES = (0, 10, 50, 90)
PAPER_LOSS = 10
COLOURS = {0: "#1f77b4", 10: "#000000", 50: "#ff7f0e", 90: "#d62728"}


def plateau(run: PaperRun) -> float:
    """Mean distance from 50 s after the last Kv switch to the end (the paper's "18 m")."""
    switch = run.metrics["phases"][-1]["start"] if len(run.metrics["phases"]) > 1 else 0.0
    late = run.d[run.t >= switch + 50]
    return float(late.mean()) if late.size else float("nan")


def fig6_losses(panels: list[tuple[str, list[tuple[int, PaperRun]]]], out: Path) -> Path:
    """One panel per wiring (title, [(loss %, run), ...]): distance against time per loss."""
    fig, axes = plt.subplots(len(panels), 1, figsize=(13, 4.2 * len(panels)), squeeze=False)
    for ax, (title, runs) in zip(axes[:, 0], panels, strict=True):
        seed_band(ax, runs[0][1])
        top = FIG6["peak"]
        lines = []
        base = plateau(runs[0][1])
        for loss, run in runs:
            paper = loss == PAPER_LOSS
            ax.plot(
                run.t,
                run.d,
                color=COLOURS.get(loss, "0.5"),
                lw=1.5 if paper else 0.9,
                alpha=1.0 if paper else 0.8,
                label=f"{loss} % lost" + (" (the paper's)" if paper else ""),
            )
            if run.d.size:
                top = max(top, float(np.nanmax(run.d)))
            value = plateau(run)
            lines.append(
                (f"{loss} % lost: plateau {value:.2f} m ({value - base:+.3f} m)", COLOURS[loss])
            )
        ax.axhline(FIG6["plateau"], color="0.45", lw=0.8, ls=":")
        ax.set_ylim(0, top * 1.3)
        ax.set_xlabel("time (s)")
        ax.set_ylabel("distance (m)")
        ax.set_title(title, fontsize=11, loc="left")
        ax.legend(loc="lower right", fontsize=8)
        draw_notes(ax, lines)
    fig.suptitle(
        "Fig. 6 at each GPS loss rate: the controller's distance from the GPS fixes (sensed) "
        "vs the true distance (the paper's wiring)"
    )
    return save_png(fig, out)
