"""`adapt`'s swing rule: the robust point once the loop swings farther than any right gain
makes it swing, its level from the sweep.

The sweep's own runs say how far the distance swings under the points the rules choose;
a swing well beyond that is a wrong gain. The level must come from the chosen points only
(a swinging point no cell chose must not raise it), the rule must set the robust point,
every rule setting another point must wait for the swing to fall below the level, the rule
must not fight the damping rule, and nothing changes when the sweep did not measure the
swing or the factor is 0.
"""

from __future__ import annotations

import csv
import shutil
from pathlib import Path

import pytest
import yaml
from adapt_speeds import SPEEDS

from amsa_phys.adapt.derive import derive
from amsa_phys.cli.main import main
from amsa_phys.model.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[2]
FIXTURE = ROOT / "tests" / "fixtures" / "adapt"
SWING = "  - {stl: 'always[5:10](SwingMonitor.amplitude <= 100)', name: swing}\n"
SPEED = "  - {stl: 'always(MotorMonitor.pathSpeed <= 5)', name: path_speed}\n"
#: each run's largest half swing (m) by (context, Kv, seed index): the cells choose nominal
#: 0.2, worn 0.4, random 0.4 and speed changes 0.1 (tests/adapt_speeds.py); nominal 0.4 and
#: speed changes 0.4 swing by metres and are not chosen
SWINGS = {
    ("nominal", "0.1"): (0.2, 0.2),
    ("nominal", "0.2"): (0.5, 0.7),
    ("nominal", "0.4"): (6.0, 6.2),
    ("worn", "0.1"): (0.1, 0.1),
    ("worn", "0.2"): (0.2, 0.2),
    ("worn", "0.4"): (0.3, 0.3),
    ("random", "0.1"): (0.3, 0.3),
    ("random", "0.2"): (0.3, 0.3),
    ("random", "0.4"): (0.4, 0.4),
    ("speed changes", "0.1"): (0.2, 0.2),
    ("speed changes", "0.2"): (1.0, 1.0),
    ("speed changes", "0.4"): (5.0, 5.0),
}


def _sweep(tmp_path: Path, swing: bool = True, speed: bool = False) -> tuple[Path, Path]:
    """The fixture sweep on the world with a SwingMonitor, with its measurements (or not)."""
    (tmp_path / "worlds").mkdir(parents=True)
    shutil.copy(ROOT / "worlds" / "mde_adaptive_swing.yaml", tmp_path / "worlds")
    sweep = tmp_path / "sweep" / "sweep.yaml"
    sweep.parent.mkdir()
    text = (FIXTURE / "sweep.yaml").read_text().replace("../../../worlds", "../worlds")
    text = text.replace("mde_adaptive.yaml", "mde_adaptive_swing.yaml")
    if swing or speed:
        text += "expect:\n" + (SWING if swing else "") + (SPEED if speed else "")
    sweep.write_text(text)
    rows = list(csv.reader((FIXTURE / "results.csv").open()))
    results = sweep.parent / "results.csv"
    with results.open("w", newline="") as f:
        w = csv.writer(f)
        extra = (["robustness.swing"] if swing else []) + (
            ["robustness.path_speed"] if speed else []
        )
        w.writerow([*rows[0], *extra])
        for r in rows[1:]:
            values = []
            if swing:
                values.append(f"{100 - SWINGS[(r[1], r[2])][int(r[3])]:.6g}")
            if speed:
                values.append(f"{5 - SPEEDS[(r[1], r[2])]:.6g}")
            w.writerow([*r, *values])
    return sweep, results


def _derive(sweep: Path, results: Path, **kw):
    return derive(results, load_scenario(sweep), "rms_error", 5, float("inf"), 0.0, **kw)


def test_the_level_is_the_chosen_points_largest_swing_times_the_factor(tmp_path: Path) -> None:
    found = _derive(*_sweep(tmp_path))
    s = found.swing
    assert s is not None
    # nominal at the robust 0.2: seeds 0.5 and 0.7, mean 0.6; the unchosen swings (6.1, 5.0,
    # 1.0) do not count
    assert s.largest == pytest.approx(0.6)
    assert s.level == pytest.approx(1.5 * 0.6, abs=1e-3)
    first = found.rules[0]
    assert first["set"] == {"MyFollowerController.Kv": 0.2}  # the robust point
    assert first["when"] == {
        "SwingMonitor.valid": {"above": 0.5},
        "SwingMonitor.amplitude": {"above": s.level},
    }
    assert first["dwell"] == 60  # the SwingMonitor's window in the world
    assert _derive(*_sweep(tmp_path / "b"), swing_factor=2.0).swing.level == pytest.approx(1.2)


def test_higher_points_wait_for_the_swing_and_the_robust_point_does_not(tmp_path: Path) -> None:
    found = _derive(*_sweep(tmp_path))
    level = found.swing.level
    cells = [r for r in found.rules if not str(r.get("label", "")).startswith("robust")]
    away = [r for r in cells if r["set"] != found.robust]
    home = [r for r in cells if r["set"] == found.robust]
    assert away
    assert home
    assert all(r["when"]["SwingMonitor.amplitude"] == {"below": level} for r in away)
    assert all("SwingMonitor.amplitude" not in r["when"] for r in home)


def test_the_swing_rule_leaves_a_fast_swing_to_the_damping_rule(tmp_path: Path) -> None:
    found = _derive(*_sweep(tmp_path, speed=True))
    labels = [r.get("label") for r in found.rules]
    assert labels[:2] == ["damp, MotorMonitor swinging", "robust, SwingMonitor swinging"]
    rule = found.rules[1]
    assert rule["when"]["MotorMonitor.pathSpeed"] == {"below": found.damping.speed}


def test_without_the_measurement_or_with_swing_0_the_rules_are_as_before(tmp_path: Path) -> None:
    plain = _derive(*_sweep(tmp_path / "a", swing=False))
    assert plain.swing is None
    off = _derive(*_sweep(tmp_path / "b"), swing_factor=0.0)
    assert off.swing is None
    assert off.rules == plain.rules
    assert len(_derive(*_sweep(tmp_path / "c")).rules) == len(plain.rules) + 1


def test_the_rules_file_loads_and_says_what_takes_the_gain_back(tmp_path: Path, capsys) -> None:
    sweep, results = _sweep(tmp_path)
    out = tmp_path / "rules.yaml"
    args = ["--margin", "inf", "--min-gain", "0", "--hold", "5"]
    code = main(["adapt", str(results.parent), "--scenario", str(sweep), "-o", str(out), *args])
    assert code == 0
    text = out.read_text()
    assert "# swing: MyFollowerController.Kv=0.2 while SwingMonitor's amplitude is above 0.9" in (
        text
    )
    assert yaml.safe_load(text)["adapt"][0]["label"] == "robust, SwingMonitor swinging"
    bad = ["adapt", str(results.parent), "--scenario", str(sweep), "-o", str(out), "--force"]
    assert main([*bad, "--swing", "-1"]) == 2
    assert "--swing" in capsys.readouterr().err
