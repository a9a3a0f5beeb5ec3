"""A counterexample a user can act on: the smallest change from nominal that still falsifies.

The worst run of a search is often far out in a corner of the box; what an engineer needs is
the *least* departure from the nominal context that still breaks the requirement. After the
search, the falsifying run closest to nominal (per axis, scaled by the box's width; a
categorical axis counts 1 when it differs) is pulled towards nominal by bisection along the
segment between them: each step runs one point and keeps it if it still falsifies. That point
becomes ``worst.yaml``; the raw worst stays as ``worst_raw.yaml``.

Then the counterexample is run once more with its trace (``counterexample/``, a run
directory) to say which comparison of the requirement broke and when, and
``counterexample.png`` draws the signals of that comparison with its bound and the instant.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path
from typing import Any

from ..model.scenario import Scenario
from ..runs.evaluate import evaluate
from .objective import Objective, Verdict
from .search import Progress, Settings
from .space import Space

#: Bisection steps towards nominal: the distance shrinks to 2**-8 of the segment's.
STEPS = 8

Point = tuple[tuple[str, Any], ...]


def nominal(space: Space, scenario: Scenario) -> dict[str, Any]:
    """The scenario's own value of each searched parameter at t = 0 (None if unknown)."""
    out: dict[str, Any] = {}
    for d in space.dims:
        leaf_path, _, name = d.key.rpartition(".")
        leaf = scenario.world.leaves.get(leaf_path)
        value: Any = None
        if leaf is not None:
            try:
                canon = leaf.template.canonical(name)
                value = leaf.params.get(canon, leaf.template.param(canon).default)
            except (KeyError, AttributeError):
                value = None
            for c in scenario.timeline.initial:
                if c.leaf == leaf_path and c.param in (name, canon):
                    value = c.value
        out[d.key] = value
    return out


def distance(point: Point, nom: dict[str, Any], space: Space) -> float:
    """Distance from nominal, each numeric axis in units of the box's width."""
    values = dict(point)
    total = 0.0
    for d in space.numeric:
        n = nom.get(d.key)
        ref = min(d.hi, max(d.lo, float(n))) if isinstance(n, int | float) else d.lo
        total += ((float(values[d.key]) - ref) / (d.hi - d.lo)) ** 2
    for d in space.categorical:
        total += 0.0 if values[d.key] == nom.get(d.key) else 1.0
    return math.sqrt(total)


def _toward(point: Point, nom: dict[str, Any], space: Space, s: float) -> Point:
    """``point`` moved a share ``s`` of the way to nominal on every numeric axis."""
    values = dict(point)
    out = []
    for d in space.numeric:
        n = nom.get(d.key)
        ref = min(d.hi, max(d.lo, float(n))) if isinstance(n, int | float) else float(values[d.key])
        x = float(values[d.key]) + s * (ref - float(values[d.key]))
        out.append((d.key, d.value((x - d.lo) / (d.hi - d.lo))))
    out += [(d.key, values[d.key]) for d in space.categorical]
    return tuple(out)


def minimise(
    space: Space,
    objective: Objective,
    settings: Settings,
    progress: Progress,
    nom: dict[str, Any],
) -> tuple[dict[str, Any], Verdict, Point] | None:
    """The falsifying point closest to nominal after :data:`STEPS` bisection runs (None if
    no run falsified). Runs of the bisection are not rows of the search."""
    keys = [d.key for d in space.dims]
    found = [
        (distance(tuple((k, r[k]) for k in keys), nom, space), r["run"], r, v)
        for r, v in zip(progress.rows, progress.verdicts, strict=True)
        if v.violated
    ]
    if not found:
        return None
    _, _, row, verdict = min(found, key=lambda x: (x[0], x[1]))
    best: Point = tuple((k, row[k]) for k in keys)
    lo, hi = 0.0, 1.0  # share of the way to nominal: lo still falsifies
    for _ in range(STEPS):
        mid = (lo + hi) / 2
        point = _toward(best, nom, space, mid)
        rows = list(
            evaluate(
                settings.scenario,
                [(point, settings.run_seed)],
                duration=settings.duration,
                executor="local",
                workers=1,
            )
        )
        v = objective.judge(rows[0])
        if v.violated:
            lo, row, verdict = mid, rows[0], v
        else:
            hi = mid
    final = _toward(best, nom, space, lo) if lo > 0 else best
    return row, verdict, final


_BOUND = re.compile(r"^\((.+) (<=|<|>=|>) (-?[\d.e+-]+)\)$")
_BAND = re.compile(r"^\(abs\(\((.+) - (-?[\d.e+-]+)\)\) (<=|<) (-?[\d.e+-]+)\)$")


def plot(run_dir: Path, requirement: str, out: Path, title: str) -> Path | None:
    """``counterexample.png``: the signal of the comparison that set the requirement's
    robustness, its bound (a band for ``abs(x - c) <= k``) and the instant marked."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from ..plots.save import save_png

    metrics = json.loads((run_dir / "metrics.json").read_text())
    entry = (metrics.get("requirements") or {}).get(requirement)
    if not entry or entry.get("instant") is None:
        return None
    atom = str(entry.get("atom", ""))
    header = (run_dir / "trace.csv").read_text().split("\n", 1)[0].split(",")
    band = _BAND.match(atom)
    bound = _BOUND.match(atom)
    signal = band.group(1) if band else bound.group(1) if bound else None
    if signal not in header:
        signal = next((c for c in header[1:] if c in atom), None)
    if signal is None:
        return None
    cols = [0, header.index(signal)]
    data = np.loadtxt(run_dir / "trace.csv", delimiter=",", skiprows=1, usecols=cols, ndmin=2)
    fig, ax = plt.subplots(figsize=(8, 4), dpi=100)
    ax.plot(data[:, 0], data[:, 1], color="#1f4e79", lw=1.2, label=signal)
    t0, t1 = interval(str(entry.get("formula", "")), float(data[-1, 0]))
    if t0 > float(data[0, 0]) or t1 < float(data[-1, 0]):  # what the requirement reads
        ax.axvspan(t0, t1, color="0.5", alpha=0.08, lw=0, label=f"judged: [{t0:g}, {t1:g}] s")
    lows, highs = [float(np.min(data[:, 1]))], [float(np.max(data[:, 1]))]
    if band:
        c, k = float(band.group(2)), float(band.group(4))
        # over the requirement's interval only: before it the band does not apply
        ax.fill_between(
            [t0, t1], c - k, c + k, color="#2e8b57", alpha=0.15, lw=0, label=f"{c:g} ± {k:g}"
        )
        for edge in (c - k, c + k):
            ax.plot([t0, t1], [edge, edge], color="#2e8b57", lw=1, ls="--")
        lows.append(c - k)
        highs.append(c + k)
    elif bound:
        level = float(bound.group(3))
        ax.plot([t0, t1], [level, level], color="#2e8b57", lw=1, ls="--", label="bound")
        lows.append(level)
        highs.append(level)
    # a margin beyond both the signal and the bound: a band as tall as the axes reads as
    # background, and a violation by 0.01 at its edge disappears into the frame
    lo, hi = min(lows), max(highs)
    pad = 0.15 * (hi - lo) if hi > lo else 1.0
    ax.set_ylim(lo - pad, hi + pad)
    t = float(entry["instant"])
    ax.axvline(t, color="#c0392b", lw=1, alpha=0.6)
    # the broken sample itself, with its value: a violation by 0.01 is invisible at the
    # band's scale, its number is not
    value = float(np.interp(t, data[:, 0], data[:, 1]))
    ax.plot(
        [t],
        [value],
        marker="o",
        ms=7,
        color="#c0392b",
        ls="none",
        zorder=5,
        label=f"broken: {value:.4g} at t = {t:g} s",
    )
    ax.annotate(
        f"{value:.4g}",
        (t, value),
        xytext=(8, -4),
        textcoords="offset points",
        color="#c0392b",
        fontsize=9,
        va="top",
    )
    ax.set_xlabel("t (s)")
    ax.set_ylabel(signal)
    rob = entry.get("robustness")
    ax.set_title(
        f"{title}: {requirement} robustness "
        + ("none" if rob is None else f"{rob:.4g}")
        + f" at t = {t:g} s"
    )
    # below the axes: inside, "best" still sat on the signal or the band's edge
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2, fontsize=8, frameon=False)
    fig.set_size_inches(8, 4.8)
    fig.tight_layout()
    return save_png(fig, out)


def interval(formula: str, end: float) -> tuple[float, float]:
    """The instants a requirement judges, as its outer ``always``/``eventually`` window
    reads them (``always[10:120]`` judges 10..120 s); the whole run otherwise."""
    from ..stl.syntax import FormulaError, parse

    try:
        node = parse(formula)
    except FormulaError:
        return 0.0, end
    if node.op in ("always", "eventually") and node.lo is not None:
        hi = end if node.hi is None else min(end, float(node.hi))
        return float(node.lo), hi
    return 0.0, end


def replay(settings: Settings, point: Point, out: Path) -> Path:
    """Run the counterexample once more with its trace: a run directory at ``out``."""
    from ..runs.rundir import prepare_run_dir
    from ..runs.single import run_scenario
    from ..runs.sweep import Job, prepare_job

    job = Job(0, str(settings.scenario), point, 0, settings.run_seed, (), settings.duration)
    prepare_run_dir(out, force=True)
    run_scenario(prepare_job(job), out, progress=False, plot=False)
    return out
