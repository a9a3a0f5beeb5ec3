"""The paper's Fig. 5 and Fig. 6 redrawn from the project's runs, beside the paper's numbers.

The paper (section 4.1) gives its results as a few numbers read off its plots: for each Kv
of the nominal context a maximal distance and a time to reach the reference, and for the
degraded context a band and a plateau. :data:`FIG5` and :data:`FIG6` hold them; each panel
shows a run's leader-follower distance with the reference and its tolerance band, marks the
project's own figures (the maximum after the first approach, the settling time) and writes
paper and project side by side, green within ±15 % of the paper, red outside.

The figures take plain arrays (:class:`PaperRun`): running the scenarios is the caller's
job (``amsa-phys plot --paper``), so this module only draws.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from ..palette import ALERT, REFERENCE, SIGNAL, hex_colour
from .save import save_png

#: How close a project number must be to the paper's to count as reached.
SHARE = 0.15

#: Fig. 5, nominal context: per Kv, the paper's maximal distance (m) and time to reach the
#: reference distance (s); None where the paper gives no number.
FIG5: dict[float, dict[str, Any]] = {
    0.35: {"max": None, "settle": None, "says": "could not catch up with the leader"},
    0.15: {"max": 32.0, "settle": 150.0, "says": "max 32 m, ~150 s to the reference, oscillations"},
    0.1: {"max": 29.0, "settle": None, "says": "max 29 m, fewer oscillations"},
    0.05: {"max": 25.0, "settle": 120.0, "says": "max 25 m, 120 s to a safe distance (best)"},
}
#: Fig. 6, degraded context: Kv = 0.35 around 15 m with peaks up to 22 m (after the start),
#: Kv = 0.05 from t = 100 s practically stable at 18 m.
FIG6 = {"peak": 22.0, "plateau": 18.0, "switch": 100.0}

#: the measured distance: palette.SIGNAL, the colour of the quality signal in distance.png
#: (it was the follower's blue here and black there)
FOLLOWER = hex_colour(SIGNAL)
GOOD, BAD, MUTED = hex_colour(REFERENCE), hex_colour(ALERT), "0.45"


@dataclass
class PaperRun:
    """One run as the figures need it: the quality signal and the metrics document."""

    label: str
    kv: float | None  # the controller's Kv at t = 0 (None: unknown)
    t: np.ndarray
    d: np.ndarray
    metrics: dict[str, Any]

    @property
    def reference(self) -> float:
        """The quality's reference distance."""
        return float(self.metrics["quality"]["reference"])

    @property
    def tolerance(self) -> float:
        """The quality's tolerance."""
        return float(self.metrics["quality"]["tolerance"])


def reached(value: float | None, paper: float) -> bool:
    """Whether ``value`` is within :data:`SHARE` of the paper's number."""
    return value is not None and abs(value - paper) <= SHARE * paper


def _verdict(value: float | None, paper: float, unit: str) -> tuple[str, str]:
    """``("26.0 m (-19 %)", red)``: the project's number, its gap to the paper's, a colour."""
    if value is None:
        return "none", BAD
    gap = 100 * (value - paper) / paper
    return f"{value:.1f} {unit} ({gap:+.0f} %)", GOOD if reached(value, paper) else BAD


def seed_band(ax: plt.Axes, run: PaperRun) -> None:
    ref, tol = run.reference, run.tolerance
    ax.axhspan(ref - tol, ref + tol, color=GOOD, alpha=0.12, lw=0)
    ax.axhline(ref, color=GOOD, lw=1, ls="--")
    ax.set_xlim(0, float(run.t[-1]) if run.t.size else 1)
    ax.grid(alpha=0.3)


def fig5(runs: list[PaperRun], out: Path, title: str = "") -> Path:
    """Fig. 5: one panel per run (the paper's four gains, each from t = 0)."""
    n = len(runs)
    cols = 2 if n > 1 else 1
    rows = (n + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(13, 3.9 * rows + 0.6), squeeze=False)
    top = max([float(np.nanmax(r.d)) for r in runs if r.d.size] + [20.0])
    for ax, run in zip(axes.flat, runs, strict=False):
        seed_band(ax, run)
        ax.plot(run.t, run.d, color=FOLLOWER, lw=1.3)
        ax.set_ylim(0, top * 1.18)
        m = run.metrics["overall"]
        peak, settle = m.get("max_after_approach"), m.get("settling_time")
        paper = FIG5.get(run.kv) if run.kv is not None else None
        if peak is not None:
            i = int(np.argmax(np.where(_after_approach(run), run.d, -np.inf)))
            ax.plot(run.t[i], run.d[i], "o", color=FOLLOWER, ms=6)
        if settle is not None:
            ax.axvline(settle, color=MUTED, lw=1, ls=":")
        ax.set_title(run.label, fontsize=11, loc="left")
        ax.set_ylabel("distance (m)")
        ax.set_xlabel("time (s)")
        lines: list[tuple[str, str]] = []
        if paper is not None:
            lines.append((f"paper: {paper['says']}", "0.1"))
            if paper["max"] is not None:
                text, colour = _verdict(peak, paper["max"], "m")
                lines.append((f"max after approach: paper {paper['max']:g} m, here {text}", colour))
            if paper["settle"] is not None:
                text, colour = _verdict(settle, paper["settle"], "s")
                lines.append(
                    (f"in the band after: paper {paper['settle']:g} s, here {text}", colour)
                )
            if paper["max"] is None:
                ok = settle is None
                lines.append(
                    (
                        "here: never holds 15 ± 1.5 m"
                        if ok
                        else f"here: settles at {settle:.0f} s",
                        GOOD if ok else BAD,
                    )
                )
        else:
            lines.append((f"max after approach {_num(peak)} m, settled {_num(settle)} s", "0.1"))
        draw_notes(ax, lines)
    for ax in list(axes.flat)[n:]:
        ax.set_visible(False)
    fig.suptitle(title or "Fig. 5, nominal context: each Kv alone from the same start", y=0.995)
    return save_png(fig, out)


def fig6(run: PaperRun, out: Path, title: str = "") -> Path:
    """Fig. 6: one run, Kv = 0.35 then 0.05 from t = 100 s, with the paper's two claims."""
    fig, ax = plt.subplots(figsize=(13, 4.6))
    seed_band(ax, run)
    ax.plot(run.t, run.d, color=FOLLOWER, lw=1.3)
    top = max(float(np.nanmax(run.d)) if run.d.size else 20.0, FIG6["peak"])
    ax.set_ylim(0, top * 1.25)
    switch = FIG6["switch"]
    for phase in run.metrics["phases"][1:]:
        ax.axvline(phase["start"], color="0.3", lw=1)
        switch = phase["start"]
    for y, colour, what in (
        (FIG6["peak"], BAD, "paper: peaks up to 22 m"),
        (FIG6["plateau"], MUTED, "paper: plateau 18 m"),
    ):
        ax.axhline(y, color=colour, lw=0.8, ls=":")
        ax.text(1, y + 0.2, what, color=colour, fontsize=8, va="bottom")
    t, d = run.t, run.d
    early = d[(t >= 50) & (t < switch)]
    late = d[t >= switch + 50]
    lines = [("paper: Kv 0.35 around 15 m, peaks up to 22 m apart from the beginning", "0.1")]
    if early.size:
        ok = abs(early.mean() - run.reference) < run.tolerance and early.max() <= FIG6["peak"]
        lines.append(
            (
                f"here (t = 50-{switch:g} s): mean {early.mean():.1f} m, max {early.max():.1f} m",
                GOOD if ok else BAD,
            )
        )
    lines.append((f"paper: Kv 0.05 from t = {switch:g} s practically stable at 18 m", "0.1"))
    if late.size:
        text, colour = _verdict(float(late.mean()), FIG6["plateau"], "m")
        lines.append((f"here (t > {switch + 50:g} s): mean {text}, std {late.std():.2f} m", colour))
    draw_notes(ax, lines)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("distance (m)")
    ax.set_title(run.label, fontsize=11, loc="left")
    fig.suptitle(title or "Fig. 6, degraded context: Kv 0.35, then 0.05 from t = 100 s")
    return save_png(fig, out)


def _after_approach(run: PaperRun) -> np.ndarray:
    """The samples from the first one within tolerance on (the paper's max is over these)."""
    inside = np.abs(run.d - run.reference) <= run.tolerance
    mask = np.zeros_like(inside)
    if inside.any():
        mask[int(np.argmax(inside)) :] = True
    return mask


def draw_notes(ax: plt.Axes, lines: list[tuple[str, str]]) -> None:
    """Lines of text at the top right of a panel, each in its colour."""
    for k, (text, colour) in enumerate(lines):
        ax.text(
            0.99,
            0.97 - 0.085 * k,
            text,
            transform=ax.transAxes,
            ha="right",
            va="top",
            fontsize=8.5,
            color=colour,
            bbox={"fc": "white", "ec": "none", "alpha": 0.8, "pad": 1.0},
        )


def _num(value: float | None) -> str:
    return "-" if value is None else f"{value:.1f}"
