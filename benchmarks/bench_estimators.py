"""How right the context estimators are, on contexts and seeds no rule was derived from.

``python benchmarks/bench_estimators.py`` runs ``worlds/mde_adaptive.yaml`` in known contexts
(held-out seeds 11-13, samples from t = 40 s, once every window is full) and prints, as
Markdown tables for docs/adaptation.md:

* ``LeaderMonitor``: a confusion table. True behaviour (straight at the MDE speed, a slow
  straight leader, speed changes, random; at the GPS's noise and at twice it, with the
  monitor's ``fixNoise`` told or not) against what
  the rules read: *straight* (``turning`` below 0.08), *turning* (above 0.12), *between*
  (neither: no rule fires) or *unsure* (``valid`` 0: the fallback).
* ``MotorMonitor``: error bands. For motors delivering 100 % down to 25 % (levels between
  the sweep's too), the share of valid samples and the 5th-95th percentile of the estimate.
* ``GPSLossMonitor``: the same for the GPS loss rate.
* Detection delay: seconds from a context change to the first sample in the new context's
  band (motors 100 -> 50 %; leader straight -> random).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
WORLD = ROOT / "worlds" / "mde_adaptive.yaml"
SEEDS = (11, 12, 13)
KV = 0.2  # the robust fixed gain of scenarios/adaptive_sweep.yaml


def _run(seed: int, duration: float, sets: dict[str, Any], timeline: list | None = None) -> Any:
    import amsa_phys as ap

    scenario: dict[str, Any] = {
        "world": str(WORLD),
        "duration": duration,
        "seed": seed,
        "trace_columns": ["*Monitor.*"],
    }
    if timeline:
        scenario["timeline"] = timeline
    return ap.run(scenario, set={"MyFollowerController.Kv": KV, **sets})


def leader_table() -> list[str]:
    """The LeaderMonitor confusion table (shares of samples, rows sum to 100 %)."""
    cases = {
        "straight (0.22 m/s)": {"Leader.behavior": 1},
        "slow straight (0.06 m/s)": {"Leader.behavior": 1, "Leader.cruisePower": 4.0},
        "speed changes": {"Leader.behavior": 3},
        "random": {"Leader.behavior": 4},
    }
    lines = [
        "| true behaviour | GPS noise / fixNoise | straight | turning | between | unsure |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for name, sets in cases.items():
        for noise, assumed in ((0.015, 0.015), (0.03, 0.015), (0.03, 0.03)):
            counts = np.zeros(4)
            for seed in SEEDS:
                noisy = {"LeaderGPS.stddev": noise, "LeaderMonitor.fixNoise": assumed}
                run = _run(seed, 300, {**sets, **noisy})
                t = run.trace["t"]
                keep = t >= 40
                turning = run.trace["LeaderMonitor.turning"][keep]
                valid = run.trace["LeaderMonitor.valid"][keep] > 0.5
                counts += [
                    np.sum(valid & (turning < 0.08)),
                    np.sum(valid & (turning > 0.12)),
                    np.sum(valid & (turning >= 0.08) & (turning <= 0.12)),
                    np.sum(~valid),
                ]
            shares = 100 * counts / counts.sum()
            lines.append(
                f"| {name} | {noise * 100:g} cm, {assumed * 100:g} cm | "
                + " | ".join(f"{s:.0f} %" for s in shares)
                + " |"
            )
    return lines


def motor_table() -> list[str]:
    """MotorMonitor: valid share and the estimate's 5-95 % band per true delivered share."""
    lines = [
        "| motors deliver | valid samples | estimate 5–95 % (valid) | median |",
        "| --- | --- | --- | --- |",
    ]
    for coef in (100, 80, 60, 50, 35, 25):
        values, valid_n, total = [], 0, 0
        for seed in SEEDS:
            run = _run(seed, 250, {"MyNormalizePower.motorCoef": coef})
            keep = run.trace["t"] >= 40
            valid = run.trace["MotorMonitor.valid"][keep] > 0.5
            values.append(run.trace["MotorMonitor.delivered"][keep][valid])
            valid_n += int(valid.sum())
            total += int(keep.sum())
        v = np.concatenate(values)
        band = f"{np.percentile(v, 5):.2f}–{np.percentile(v, 95):.2f}" if v.size else "-"
        median = f"{np.median(v):.2f}" if v.size else "-"
        lines.append(f"| {coef} % | {100 * valid_n / total:.0f} % | {band} | {median} |")
    return lines


def gps_table() -> list[str]:
    """GPSLossMonitor: the estimate's band per true loss rate."""
    lines = ["| GPS loses | estimate 5–95 % | mean |", "| --- | --- | --- |"]
    for loss in (0, 10, 20):
        values = []
        for seed in SEEDS:
            run = _run(seed, 200, {"LeaderGPS.lostDataGPS": loss})
            keep = run.trace["t"] >= 40
            values.append(run.trace["LeaderGPSMonitor.lossRate"][keep])
        v = np.concatenate(values)
        lines.append(
            f"| {loss} % | {np.percentile(v, 5):.3f}–{np.percentile(v, 95):.3f} | {v.mean():.3f} |"
        )
    return lines


def delay_table() -> list[str]:
    """Seconds from a change at 150 s to the first sample in the new context's band."""
    changes = {
        "motors 100 % -> 50 % (delivered below 0.7)": (
            {"MyNormalizePower.motorCoef": 50},
            "MotorMonitor.delivered",
            lambda x: x < 0.7,
        ),
        "leader straight -> random (turning above 0.12)": (
            {"Leader.behavior": 4},
            "LeaderMonitor.turning",
            lambda x: x > 0.12,
        ),
    }
    lines = ["| change at 150 s | delay, seeds 11 / 12 / 13 |", "| --- | --- |"]
    for name, (sets, signal, seen) in changes.items():
        delays = []
        for seed in SEEDS:
            run = _run(seed, 300, {}, [{"at": 150, "set": sets}])
            t = run.trace["t"]
            hit = t[(t > 150) & seen(run.trace[signal])]
            delays.append(f"{hit[0] - 150:.1f} s" if hit.size else "never")
        lines.append(f"| {name} | {' / '.join(delays)} |")
    return lines


def main() -> None:
    """Print every table."""
    for title, table in (
        ("LeaderMonitor", leader_table),
        ("MotorMonitor", motor_table),
        ("GPSLossMonitor", gps_table),
        ("detection delay", delay_table),
    ):
        print(f"\n{title}\n")
        for line in table():
            print(line, flush=True)


if __name__ == "__main__":
    main()
