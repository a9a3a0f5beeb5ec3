"""Fig. 6 in a street: consumer GNSS among buildings changes the Fig. 6 metrics by a fifth or
more against the RTK receivers of the open sensed world (docs/sensors.md, "Fig. 6 in a
street"), and the buildings themselves, not only the receiver, move the Kv 0.35 overshoot."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from amsa_phys.engine.runner import Simulation
from amsa_phys.model.metrics import block_metrics
from amsa_phys.model.scenario import load_scenario

SCENARIOS = Path(__file__).resolve().parent.parent.parent / "scenarios"


def phase_metrics(name: str, *overrides: str) -> list[dict[str, Any]]:
    """Metrics of phase 1 (Kv 0.35, 0-100 s) and phase 2 (Kv 0.05, 100-200 s)."""
    r = Simulation.from_scenario(load_scenario(SCENARIOS / name, overrides=list(overrides))).run()
    ev = [e.t for e in r.events]
    return [
        block_metrics(r.samples_t, r.samples_s, 0.0, 100.0, 15.0, 1.5, ev),
        block_metrics(r.samples_t, r.samples_s, 100.0, 200.0, 15.0, 1.5, ev, include_end=True),
    ]


def test_urban_gnss_changes_fig6_by_a_fifth() -> None:
    sensed = phase_metrics("paper_fig6_sensed.yaml")
    urban = phase_metrics("paper_fig6_urban.yaml")
    # Kv 0.35 overshoot: 23.9 m in the open, 19.5 m in the street (-18 %: more than 15 %)
    assert urban[0]["max_distance"] < 0.85 * sensed[0]["max_distance"]
    # Kv 0.05 settles 2.5 m too far in the open, 0.4 m in the street (-84 %)
    assert abs(urban[1]["mean_error"] - sensed[1]["mean_error"]) > 0.2 * abs(
        sensed[1]["mean_error"]
    )
    # buildings 0 m tall: the consumer receiver alone leaves the overshoot where it was
    flat = phase_metrics(
        "paper_fig6_urban.yaml", "LeaderGPS.obstacleHeight=0", "FollowerGPS.obstacleHeight=0"
    )
    assert flat[0]["max_distance"] > 0.95 * sensed[0]["max_distance"]
