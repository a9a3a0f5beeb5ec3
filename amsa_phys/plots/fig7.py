"""Fig. 7 (the paper's future work, done): the adaptive run against the best fixed gains.

Top: the adaptive run's distance with its rule switches marked (``adaptmarks.py``), and the
runs of the two best fixed gains of the comparison drawn thin behind it; the context's
phases are marked and named. Bottom: the whole run's rms error of every fixed gain beside
the adaptive run's, the best fixed one and the adaptive one labelled. Like ``paper.py``
this module only draws: running the scenario is the caller's job.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from .adaptmarks import adapt_switches
from .save import save_png

ADAPTIVE = "0.1"
FIXED_COLOURS = ("tab:blue", "tab:orange")


@dataclass
class Fig7Run:
    """One run: its label, the tuned value (None: adaptive), distance samples, metrics."""

    label: str
    value: float | None
    t: np.ndarray
    d: np.ndarray
    metrics: dict[str, Any]

    @property
    def rms(self) -> float:
        """The whole run's rms error."""
        return float(self.metrics["overall"]["rms_error"])


def fig7(adaptive: Fig7Run, fixed: list[Fig7Run], out: Path, param: str = "Kv") -> Path:
    """Draw the figure into ``out``."""
    fig, (ax, bars) = plt.subplots(
        2, 1, figsize=(11, 7), dpi=100, gridspec_kw={"height_ratios": [2.2, 1]}
    )
    q = adaptive.metrics["quality"]
    ref, tol = float(q["reference"]), float(q["tolerance"])
    ax.axhspan(ref - tol, ref + tol, color="tab:green", alpha=0.12, label=f"tolerance ±{tol:g} m")
    ax.axhline(ref, color="tab:green", lw=1, ls="--")
    best = sorted(fixed, key=lambda r: r.rms)[:2]
    for run, colour in zip(best, FIXED_COLOURS, strict=False):
        ax.plot(
            run.t,
            run.d,
            color=colour,
            lw=0.9,
            alpha=0.75,
            label=f"fixed {param} = {run.value:g} (rms {run.rms:.2f} m)",
        )
    ax.plot(
        adaptive.t, adaptive.d, color=ADAPTIVE, lw=1.5, label=f"adaptive (rms {adaptive.rms:.2f} m)"
    )
    adapt_switches(ax, adaptive.metrics.get("events", []), adaptive.t, adaptive.d)
    for phase in adaptive.metrics["phases"]:
        if phase["start"] > 0:
            ax.axvline(phase["start"], color="0.4", lw=0.8, ls=":")
        name = phase.get("label") or ("nominal" if phase["start"] == 0 else "")
        ax.annotate(
            name,
            (phase["start"], 1.0),
            xycoords=("data", "axes fraction"),
            xytext=(3, -3),
            textcoords="offset points",
            va="top",
            fontsize=8,
            color="0.25",
        )
    lo = min(float(np.nanmin(r.d)) for r in [adaptive, *best])
    hi = max(float(np.nanmax(r.d)) for r in [adaptive, *best])
    ax.set_ylim(min(lo, ref - tol) - 0.5, max(hi, ref + tol) + 1.5)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("distance (m)")
    ax.grid(alpha=0.3)
    ax.legend(loc="lower right", fontsize=8, ncol=2)
    ax.set_title(
        f"{adaptive.label}: the best {param} depends on the context; rules derived from a "
        "context sweep switch it at run time",
        fontsize=10,
        loc="left",
    )
    names = [f"{r.value:g}" for r in fixed] + ["adaptive"]
    values = [r.rms for r in fixed] + [adaptive.rms]
    colours = ["0.75"] * len(fixed) + [ADAPTIVE]
    top = sorted(fixed, key=lambda r: r.rms)[0]
    colours[fixed.index(top)] = FIXED_COLOURS[0]
    bars.bar(names, values, color=colours)
    for x, v in enumerate(values):
        bars.text(x, v, f"{v:.2f}", ha="center", va="bottom", fontsize=8)
    bars.set_ylabel("rms error (m)")
    bars.set_xlabel(f"fixed {param} (--no-adapt), and the adaptive run")
    bars.set_ylim(0, max(values) * 1.2)
    bars.grid(alpha=0.3, axis="y")
    fig.suptitle(
        "Fig. 7: adaptive reconfiguration against every fixed gain (seed "
        f"{adaptive.metrics.get('seed')})"
    )
    fig.tight_layout()
    return save_png(fig, out)
