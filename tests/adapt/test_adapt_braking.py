"""`adapt`'s braking rule: the damping point the instant a higher gain brakes harder than a
right one, its level read from the sweep's catch-ups.

A catch-up (a cell's context plus a parameter no estimator watches: the follower started
behind) is not a cell: it must leave the cells, the robust point and the other rules alone.
The level is the hardest a cell's chosen higher point brakes in its cell or its catch-up; a
higher point swinging on a cell that keeps the robust point must brake harder, or there is no
rule. The rule fires on both wheels braking past the level while the motor estimate is unsure
and holds a worn level, and on nothing else.
"""

from __future__ import annotations

import csv
import shutil
from fractions import Fraction
from pathlib import Path

import pytest

from amsa_phys.adapt.braking import catch_ups
from amsa_phys.adapt.derive import derive
from amsa_phys.engine.adapt import AdaptRules
from amsa_phys.model.adaptrules import parse_rules
from amsa_phys.model.scenario import load_scenario
from amsa_phys.model.yamlio import YamlDoc

ROOT = Path(__file__).resolve().parents[2]
FIXTURE = ROOT / "tests" / "fixtures" / "adapt"
#: the fixture's cells choose nominal 0.2 (robust), worn 0.4, speed changes 0.1, and random
#: (its 0.4 made worse here) the robust 0.2: the higher gain is set on worn motors alone
RANDOM = {("random", "0.4"): "0.6"}
CATCH_UPS = (
    "    worn, behind: {MyNormalizePower.motorCoef: 50, Follower.x: -2.0}\n"
    "    nominal, behind: {Leader.behavior: 1, Follower.x: -2.0}\n"
)
#: rms error of the catch-ups (worst of all at the robust point: were they cells, the
#: robust point would move)
RMS = {
    ("worn, behind", "0.1"): 9.0,
    ("worn, behind", "0.2"): 9.0,
    ("worn, behind", "0.4"): 1.0,
    ("nominal, behind", "0.1"): 9.0,
    ("nominal, behind", "0.2"): 9.0,
    ("nominal, behind", "0.4"): 9.5,
}
#: each (context, Kv)'s hardest braking on both wheels, %
BRAKING = {
    ("worn", "0.4"): 20.0,  # the right gain from the reference
    ("worn, behind", "0.4"): 45.0,  # ... catching up: the right braking
    ("random", "0.4"): 10.0,
    ("nominal", "0.4"): 90.0,  # a higher gain swinging on nominal motors: the wrong braking
    ("nominal, behind", "0.4"): 120.0,
    ("nominal", "0.1"): 0.0,  # a lower point far worse there: it lags, it does not swing
}
LEVEL = 45.0
REQUIREMENTS = (
    "expect:\n"
    "  - {stl: 'always(MotorMonitor.pathSpeed <= 5)', name: path_speed}\n"
    "  - {stl: 'always(MyFollowerController.LeftPower >= -1000 or "
    "MyFollowerController.RightPower >= -1000)', name: braking}\n"
)


def _sweep(
    tmp_path: Path, behind: bool = True, braking: dict | None = None, measured: bool = True
) -> tuple[Path, Path]:
    """The fixture sweep (with its catch-ups, or not) beside a copy of its world."""
    braking = BRAKING if braking is None else braking
    (tmp_path / "worlds").mkdir(parents=True)
    shutil.copy(ROOT / "worlds" / "mde_adaptive.yaml", tmp_path / "worlds")
    sweep = tmp_path / "sweep" / "sweep.yaml"
    sweep.parent.mkdir()
    text = (FIXTURE / "sweep.yaml").read_text().replace("../../../worlds", "../worlds")
    requirements = REQUIREMENTS if measured else REQUIREMENTS.rsplit("  - ", 1)[0]
    sweep.write_text(text + (CATCH_UPS if behind else "") + requirements)
    rows = list(csv.reader((FIXTURE / "results.csv").open()))
    extra = [
        [str(len(rows) - 1 + i), ctx, kv, str(s), str(s + 1), "", f"{RMS[(ctx, kv)]:g}", "20"]
        for i, ((ctx, kv), s) in enumerate((k, s) for k in RMS for s in (0, 1))
    ]
    results = sweep.parent / "results.csv"
    with results.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow([*rows[0], "robustness.path_speed", "robustness.braking"])
        for r in rows[1:] + (extra if behind else []):
            r[6] = RANDOM.get((r[1], r[2]), r[6])
            hardest = braking.get((r[1], r[2]), 5.0)
            w.writerow([*r, "4.7", f"{1000 - hardest:g}"])
    return sweep, results


def _derive(sweep: Path, results: Path):
    return derive(results, load_scenario(sweep), "rms_error", 5, float("inf"), 0.0)


def test_a_catch_up_repeats_a_cell_with_parameters_no_estimator_watches() -> None:
    contexts = {
        "worn": {"P.coef": 50},
        "worn, behind": {"P.coef": 50, "F.x": -2.0},
        "worn, watched": {"P.coef": 50, "L.behavior": 4},  # a cell: the leader is watched
        "other": {"P.coef": 40, "F.x": -2.0},  # repeats no context
    }
    assert catch_ups(contexts, {"P.coef", "L.behavior"}) == {"worn, behind": "worn"}


def test_catch_ups_are_not_cells_and_move_no_other_rule(tmp_path: Path) -> None:
    plain = _derive(*_sweep(tmp_path / "a", behind=False))
    found = _derive(*_sweep(tmp_path / "b"))
    assert [c.name for c in found.cells] == [c.name for c in plain.cells]
    assert found.robust == plain.robust == {"MyFollowerController.Kv": 0.2}
    assert found.catch_ups == {"worn, behind": "worn", "nominal, behind": "nominal"}
    assert plain.braking is None  # no catch-up: no right gain seen braking as it arrives
    assert found.braking is not None
    assert found.rules[0] == found.braking.rule
    assert found.rules[1:] == plain.rules


def test_without_the_braking_measurement_a_repeating_context_stays_a_cell(
    tmp_path: Path,
) -> None:
    found = _derive(*_sweep(tmp_path, measured=False))
    assert found.catch_ups == {}
    assert found.braking is None
    assert "worn, behind" in [c.name for c in found.cells]  # placed, or reported, as before


def test_the_level_is_the_hardest_right_braking_and_the_rule_reads_both_wheels(
    tmp_path: Path,
) -> None:
    b = _derive(*_sweep(tmp_path)).braking
    assert b is not None
    assert (b.right, b.wrong, b.level) == (45.0, 90.0, LEVEL)  # the catch-up, not the cell's 20
    assert b.rule["when"] == {
        "MotorMonitor.valid": {"below": 0.5},
        "MotorMonitor.delivered": {"below": pytest.approx(0.7)},  # where a higher gain is set
        "MyFollowerController.LeftPower": {"below": -LEVEL},
        "MyFollowerController.RightPower": {"below": -LEVEL},
    }
    assert b.rule["set"] == {"MyFollowerController.Kv": 0.1}  # the damping point
    assert b.rule["hold"] == b.rule["dwell"] == 0.25  # one step of the 4 Hz controller


def test_no_rule_when_a_wrong_gain_brakes_no_harder_than_a_right_one(tmp_path: Path) -> None:
    soft = {**BRAKING, ("nominal", "0.4"): 40.0}
    assert _derive(*_sweep(tmp_path, braking=soft)).braking is None


def _fires(tmp_path: Path, frames: list[dict[str, float]]) -> list[float]:
    """The instants the derived braking rule fires on ``frames`` at 4 Hz (Kv 0.4 in force)."""
    sweep, results = _sweep(tmp_path)
    scenario = load_scenario(sweep)
    rule = _derive(sweep, results).braking.rule
    rules = parse_rules(YamlDoc(path=sweep, data={}), [rule], scenario.world)
    kv = {"Kv": 0.4}
    engine = AdaptRules(rules, lambda leaf, p: kv[p])
    out = []
    for k, values in enumerate(frames):
        firing = engine.due(Fraction(k, 4), values)
        if firing is not None:
            out.append(float(firing.t))
            kv.update({c.param: c.value for c in firing.rule.changes})
    return out


def _frame(left: float, right: float, valid: float = 0.0, held: float = 0.25) -> dict:
    return {
        "MotorMonitor.valid": valid,
        "MotorMonitor.delivered": held,
        "MyFollowerController.LeftPower": left,
        "MyFollowerController.RightPower": right,
    }


def test_the_rule_fires_on_a_wrong_gains_braking_and_on_nothing_else(tmp_path: Path) -> None:
    # a worn motors' gain on motors that recovered: it brakes to -80 % at 1 s
    swing = [_frame(30, 30)] * 4 + [_frame(-80, -78)] * 8
    assert _fires(tmp_path / "a", swing) == [1.25]  # held for one 0.25 s step
    # a right gain catching up brakes no harder than the level: nothing
    right = [_frame(30, 30)] * 4 + [_frame(-44, -44)] * 8
    assert _fires(tmp_path / "b", right) == []
    # one wheel braking (a turn), a sure estimate, healthy motors: nothing
    for case, frames in {
        "c": [_frame(-80, 10)] * 8,
        "d": [_frame(-80, -80, valid=1.0)] * 8,
        "e": [_frame(-80, -80, held=1.0)] * 8,
    }.items():
        assert _fires(tmp_path / case, frames) == [], case


def _all_rules_fire(tmp_path: Path, guard: bool, frame: dict[str, float], seconds: int) -> list:
    """(instant, label) of every derived rule that fires on ``frame`` held for ``seconds``."""
    sweep, results = _sweep(tmp_path)
    scenario = load_scenario(sweep)
    found = derive(results, scenario, "rms_error", 5, float("inf"), 0.0, guard=guard)
    rules = parse_rules(YamlDoc(path=sweep, data={}), found.rules, scenario.world)
    kv = {"Kv": 0.4}
    engine = AdaptRules(rules, lambda leaf, p: kv[p])
    out = []
    for k in range(4 * seconds):
        firing = engine.due(Fraction(k, 4), frame)
        if firing is not None:
            out.append((float(firing.t), firing.rule.label))
            kv.update({c.param: c.value for c in firing.rule.changes})
    return out


#: a worn motors' gain swinging on motors that recovered before the estimate turned unsure:
#: its held value above the switched band, the path speed far above the fallback's release
DEADLOCK = {
    "MotorMonitor.valid": 0.0,
    "MotorMonitor.delivered": 0.75,
    "MotorMonitor.pathSpeed": 1.2,
    "LeaderMonitor.valid": 1.0,
    "LeaderMonitor.turning": 0.0,
    "MyFollowerController.LeftPower": 150.0,
    "MyFollowerController.RightPower": 150.0,
}


def test_the_guard_sets_the_robust_point_where_no_other_rule_can_fire(tmp_path: Path) -> None:
    # without the guard the swing goes on: the damping and braking rules read a held value
    # in the band only, the fallback waits for the path speed to fall
    assert _all_rules_fire(tmp_path / "a", False, DEADLOCK, 60) == []
    fired = _all_rules_fire(tmp_path / "b", True, DEADLOCK, 60)
    assert fired == [(5.0, "robust, MotorMonitor unsure above the switched band")]  # the hold
    # inside the band the damping rule acts, and the guard stays out of it
    inside = {**DEADLOCK, "MotorMonitor.delivered": 0.5}
    labels = [label for _, label in _all_rules_fire(tmp_path / "c", True, inside, 60)]
    assert labels == ["damp, MotorMonitor swinging"]


def test_the_guard_is_the_motor_fallback_without_its_release(tmp_path: Path) -> None:
    sweep, results = _sweep(tmp_path)
    plain = derive(results, load_scenario(sweep), "rms_error", 5, float("inf"), 0.0, guard=False)
    found = derive(results, load_scenario(sweep), "rms_error", 5, float("inf"), 0.0)
    i = next(k for k, r in enumerate(found.rules) if r["label"] == "robust, MotorMonitor unsure")
    fallback, guard = found.rules[i], found.rules[i + 1]
    assert guard["when"] == {
        "MotorMonitor.valid": {"below": 0.5},
        "MotorMonitor.delivered": {"above": pytest.approx(0.7)},
    }
    assert (guard["set"], guard["hold"], guard.get("dwell")) == (
        fallback["set"],
        fallback["hold"],
        fallback.get("dwell"),
    )
    assert found.rules[: i + 1] + found.rules[i + 2 :] == plain.rules
