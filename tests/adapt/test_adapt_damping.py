"""`adapt`'s damping rule: a lower gain while the follower swings, its threshold from the sweep.

A high gain left in force when the context changes under it starts a swing the robust gain
does not damp; the sweep's own runs say how fast a follower travels under the gains the
rules choose, and anything well above that is a swing. The rule must come from the sweep's
cells only (a swinging point that no cell chose must not raise the threshold), set the grid
point below the robust one, make the motor fallback wait for the swing to end, and be absent
when the sweep did not measure the path speed.
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
REQUIREMENT = "  - {stl: 'always(MotorMonitor.pathSpeed <= 5)', name: path_speed}\n"


def _sweep(tmp_path: Path, measured: bool = True) -> tuple[Path, Path]:
    """The fixture sweep beside a copy of its world, with the path speed column (or not)."""
    (tmp_path / "worlds").mkdir(parents=True)
    shutil.copy(ROOT / "worlds" / "mde_adaptive.yaml", tmp_path / "worlds")
    sweep = tmp_path / "sweep" / "sweep.yaml"
    sweep.parent.mkdir()
    text = (FIXTURE / "sweep.yaml").read_text().replace("../../../worlds", "../worlds")
    if measured:
        text += "expect:\n" + REQUIREMENT
    sweep.write_text(text)
    rows = list(csv.reader((FIXTURE / "results.csv").open()))
    results = sweep.parent / "results.csv"
    with results.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow([*rows[0], "robustness.path_speed"] if measured else rows[0])
        for r in rows[1:]:
            w.writerow([*r, f"{5 - SPEEDS[(r[1], r[2])]:.6g}"] if measured else r)
    return sweep, results


def _derive(sweep: Path, results: Path, **kw):
    return derive(results, load_scenario(sweep), "rms_error", 5, float("inf"), 0.0, **kw)


def test_the_threshold_is_the_chosen_points_fastest_times_the_factor(tmp_path: Path) -> None:
    found = _derive(*_sweep(tmp_path))
    d = found.damping
    assert d is not None
    # worn at 0.4: seeds' mean 0.31; the unchosen swings (1.5, 1.4, 0.9) do not count
    assert d.fastest == pytest.approx(0.31)
    assert d.speed == pytest.approx(1.5 * 0.31, abs=1e-3)
    first = found.rules[0]
    assert first["set"] == {"MyFollowerController.Kv": 0.1}  # below the robust 0.2
    assert first["when"] == {
        "MotorMonitor.valid": {"below": 0.5},
        "MotorMonitor.pathSpeed": {"above": d.speed},
    }
    assert _derive(*_sweep(tmp_path / "b"), damp=2.0).damping.speed == pytest.approx(0.62)


def test_the_motor_fallback_waits_for_the_swing_and_cell_rules_do_not(tmp_path: Path) -> None:
    found = _derive(*_sweep(tmp_path))
    motor = next(r for r in found.rules if r.get("label") == "robust, MotorMonitor unsure")
    # released below 1.25 times the fastest: the robust gain set on a swing carries it on
    assert motor["when"]["MotorMonitor.pathSpeed"] == {"below": pytest.approx(0.3875, abs=1e-3)}
    leader = next(r for r in found.rules if r.get("label") == "robust, LeaderMonitor unsure")
    assert "MotorMonitor.pathSpeed" not in leader["when"]
    cells = [r for r in found.rules if not str(r.get("label", "")).startswith(("robust", "damp"))]
    assert cells
    assert all("MotorMonitor.pathSpeed" not in r["when"] for r in cells)


def test_without_the_measurement_or_with_damp_0_the_rules_are_as_before(tmp_path: Path) -> None:
    plain = _derive(*_sweep(tmp_path / "a", measured=False))
    assert plain.damping is None
    off = _derive(*_sweep(tmp_path / "b"), damp=0.0)
    assert off.damping is None
    assert off.rules == plain.rules
    assert len(_derive(*_sweep(tmp_path / "c")).rules) == len(plain.rules) + 1


def test_the_rules_file_loads_and_says_what_damps(tmp_path: Path, capsys) -> None:
    sweep, results = _sweep(tmp_path)
    shutil.copy(sweep, results.parent / "scenario.yaml")
    out = tmp_path / "rules.yaml"
    args = ["--margin", "inf", "--min-gain", "0", "--hold", "5"]
    code = main(["adapt", str(results.parent), "--scenario", str(sweep), "-o", str(out), *args])
    assert code == 0
    text = out.read_text()
    assert "# damping: MyFollowerController.Kv=0.1 while MotorMonitor is unsure" in text
    assert yaml.safe_load(text)["adapt"][0]["label"] == "damp, MotorMonitor swinging"
    assert main(["adapt", str(results.parent), "-o", str(out), "--force", "--damp", "-1"]) == 2
    assert "--damp" in capsys.readouterr().err


def test_the_damping_rule_reads_only_where_a_cell_rule_leaves_the_robust_point() -> None:
    """A swing starts where a higher gain was set: worn bands, not healthy motors."""
    from amsa_phys.adapt.derive import _switched_band
    from amsa_phys.control.estimators.watches import Watch

    robust = {"K": 0.2}
    rules = [
        {"when": {"M.delivered": {"above": 0.9}}, "set": robust},
        {"when": {"M.delivered": {"above": 0.4, "below": 0.6}}, "set": {"K": 0.3}},
        {"when": {"M.delivered": {"below": 0.35}}, "set": {"K": 0.6}},
    ]
    watch = Watch("M.delivered", "P.coef", None)  # type: ignore[arg-type]
    assert _switched_band(rules, robust, "M", [watch]) == {"M.delivered": {"below": 0.6}}
    # a rule leaving the robust point on healthy motors too: no band to read
    rules.append({"when": {"M.delivered": {"above": 0.9}}, "set": {"K": 0.1}})
    assert _switched_band(rules, robust, "M", [watch]) == {}
