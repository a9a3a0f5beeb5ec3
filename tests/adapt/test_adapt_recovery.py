"""`adapt`'s recovery rule: the robust gain as soon as motors a high gain was set for recover.

Its thresholds must come from the cell rules alone: the recent share above every band where
a cell sets another point than the robust one, the held estimate still below the next
switching cell's band, the lowest switching cell's bands on the other estimators (never
their confidence), after one step of the estimator. No rule without a recent share, or when
a high gain is set for strong motors too (a band without an upper edge).
"""

from __future__ import annotations

from pathlib import Path

import yaml

from amsa_phys.adapt.recovery import recovery
from amsa_phys.model.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[2]
SWEEP = ROOT / "scenarios" / "adaptive_sweep.yaml"
ROBUST = {"MyFollowerController.Kv": 0.2}
SURE = {"MotorMonitor.valid": {"above": 0.5}, "LeaderMonitor.valid": {"above": 0.5}}


def _rule(turning: dict, delivered: dict, kv: float) -> dict:
    when = {"LeaderMonitor.turning": turning, "MotorMonitor.delivered": delivered, **SURE}
    return {"when": when, "set": {"MyFollowerController.Kv": kv}, "hold": 10}


#: the shipped cells' rules: healthy and tired keep the robust gain, worn and very worn not
CELLS = [
    _rule({"below": 0.08}, {"above": 0.9}, 0.2),
    _rule({"below": 0.08}, {"above": 0.4, "below": 0.6}, 0.3),
    _rule({"below": 0.08}, {"below": 0.35}, 0.6),
    _rule({"above": 0.12}, {"above": 0.4, "below": 0.6}, 0.35),
    _rule({"below": 0.08}, {"above": 0.65, "below": 0.85}, 0.2),
    _rule({"above": 0.12}, {"below": 0.35}, 0.35),
]


def _sweep(tmp_path: Path, window: float):
    """The shipped sweep, its motor estimator's recent share over ``window`` s (0: off)."""
    data = yaml.safe_load(SWEEP.read_text())
    data["world"] = str(ROOT / "worlds" / "mde_adaptive.yaml")
    data["set"] = {"MotorMonitor.recentWindow": window}
    path = tmp_path / "sweep.yaml"
    path.write_text(yaml.safe_dump(data))
    return load_scenario(path)


def test_the_thresholds_are_the_switching_cells_bands(tmp_path: Path) -> None:
    rule = recovery(_sweep(tmp_path, 5), CELLS, ROBUST, "MotorMonitor.delivered")
    assert rule == {
        "when": {
            "MotorMonitor.recent": {"above": 0.6},  # above every band a higher gain is for
            "MotorMonitor.delivered": {"below": 0.4},  # not yet in the worn motors' band
            "LeaderMonitor.turning": {"below": 0.08},  # the very worn cell's leader
        },
        "set": ROBUST,
        "hold": 0.25,  # one step of the 4 Hz estimator
        "dwell": 0.25,
        "label": "robust, MotorMonitor recovered",
    }


def test_the_next_band_up_sets_how_far_the_held_estimate_may_have_caught_up(
    tmp_path: Path,
) -> None:
    cells = [c for c in CELLS if c["set"]["MyFollowerController.Kv"] != 0.3]
    cells = [c for c in cells if c["set"]["MyFollowerController.Kv"] != 0.35]
    rule = recovery(_sweep(tmp_path, 5), cells, ROBUST, "MotorMonitor.delivered")
    # only the very worn cell switches: its own band is the top, and the held estimate
    # may rise to it
    assert rule is not None
    assert rule["when"]["MotorMonitor.recent"] == {"above": 0.35}
    assert rule["when"]["MotorMonitor.delivered"] == {"below": 0.35}


def test_no_rule_when_a_high_gain_is_also_set_for_strong_motors(tmp_path: Path) -> None:
    cells = [*CELLS, _rule({"above": 0.12}, {"above": 0.9}, 0.25)]
    assert recovery(_sweep(tmp_path, 5), cells, ROBUST, "MotorMonitor.delivered") is None


def test_no_rule_without_a_recent_share(tmp_path: Path) -> None:
    """The shipped world leaves the recent share off: no recovery rule, the rules as before."""
    assert recovery(_sweep(tmp_path, 0), CELLS, ROBUST, "MotorMonitor.delivered") is None
    assert recovery(load_scenario(SWEEP), CELLS, ROBUST, "MotorMonitor.delivered") is None
