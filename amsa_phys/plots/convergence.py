"""A falsification's convergence: every run's value and the worst so far against runs."""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.colors import BoundaryNorm
from matplotlib.ticker import MaxNLocator

from .save import save_png


def plot_convergence(
    values: list[float | None],
    generations: list[int],
    label: str,
    maximise: bool,
    out: Path,
    title: str,
    threshold: float | None = None,
    reference: tuple[float, str] | None = None,
) -> Path:
    """Draw ``values`` (in run order) as dots coloured by generation, and the worst so far
    as a step line (the maximum of a metric, the minimum of a robustness). A value of
    ``None`` is a run without one (its settings broke a rule): left out.

    ``threshold`` draws the line a violation crosses (robustness 0, an ``expect`` bound);
    ``reference`` a value to compare with (e.g. a grid's worst) and its caption. A run
    without a value (a fault: the worst there is) is marked on the axis's edge.
    """
    fig, ax = plt.subplots(figsize=(8, 4.5), dpi=100)
    runs = list(range(len(values)))  # numbered from 0, as results.csv's `run` and the headline
    finite = [v for v in values if v is not None and math.isfinite(v)]
    xs = [r for r, v in zip(runs, values, strict=True) if v is not None and math.isfinite(v)]
    gens = [
        g for g, v in zip(generations, values, strict=True) if v is not None and math.isfinite(v)
    ]
    if finite:
        last = max(generations, default=0)
        # generations are whole numbers: one colour each, a tick on each (not a 0.0-1.0 ramp)
        norm = BoundaryNorm([g - 0.5 for g in range(last + 2)], plt.get_cmap("viridis").N)
        dots = ax.scatter(
            xs, finite, c=gens, cmap="viridis", norm=norm, s=14, zorder=4, label="run"
        )  # above the worst-so-far line: the dot that set it was hidden under the step
        if last > 0:
            bar = fig.colorbar(dots, ax=ax, label="generation")
            bar.set_ticks(list(range(0, last + 1, max(1, (last + 1) // 10))))
    worst: list[float] = []
    current = math.nan
    for v in values:
        if v is None:
            worst.append(current)
            continue
        if math.isnan(current) or (v > current if maximise else v < current):
            current = v
        worst.append(current)
    shown = [w if math.isfinite(w) else math.nan for w in worst]
    ax.step(runs, shown, where="post", color="crimson", lw=2, zorder=3, label="worst so far")
    faults = [r for r, v in zip(runs, values, strict=True) if v is not None and math.isinf(v)]
    if faults:
        edge = max(finite) if maximise and finite else (min(finite) if finite else 0.0)
        ax.plot(faults, [edge] * len(faults), "kx", label="fault or no value")
    if threshold is not None and not maximise:  # a robustness: below the bound falsifies
        bad = [(r, v) for r, v in zip(xs, finite, strict=True) if v < threshold]
        if bad:
            ax.scatter(
                [r for r, _ in bad],
                [v for _, v in bad],
                s=90,
                facecolors="none",
                edgecolors="#c0392b",
                linewidths=1.8,
                zorder=5,
                label=f"falsifying ({len(bad)})",
            )
    if threshold is not None:
        ax.axhline(threshold, color="black", ls="--", lw=1, label=f"bound {threshold:g}")
    if reference is not None:
        ax.axhline(reference[0], color="tab:blue", ls=":", lw=1.5, label=reference[1])
    ax.set_xlabel("run (as numbered in results.csv)")
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))  # runs are whole: no run 2.5
    # values as they are, never "1e-5 + 1.004e-1" above the axis when they lie close together
    ax.ticklabel_format(axis="y", useOffset=False)
    ax.set_ylabel(label)
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    # below the axes: inside, "best" still covered a run's dot
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=5, fontsize=8, frameon=False)
    fig.set_size_inches(8, 5)
    return save_png(fig, out)
