"""adapt: rules: the engine's semantics, replay, --no-adapt, loading errors, derivation."""

from __future__ import annotations

import re
from fractions import Fraction
from pathlib import Path

import pytest
import yaml

import amsa_phys as ap
from amsa_phys.adapt.derive import derive
from amsa_phys.cli.main import main
from amsa_phys.engine.adapt import AdaptRules
from amsa_phys.model.adaptrules import Condition, Rule
from amsa_phys.model.scenario import Change, load_scenario

ROOT = Path(__file__).resolve().parents[2]
WORLD = str(ROOT / "worlds" / "mde_adaptive.yaml")
FIXTURE = ROOT / "tests" / "fixtures" / "adapt"


def _rule(number: int, below: float, kv: float, hold: float) -> Rule:
    return Rule(
        number,
        (Condition("S.x", below=below),),
        (Change("C", "Kv", kv),),
        Fraction(str(hold)),
    )


def _drive(rules: AdaptRules, signal: list[float], params: dict | None = None):
    """Evaluate at 4 Hz; a firing's changes are applied to ``params`` (as the engine does)."""
    fired = []
    for k, x in enumerate(signal):
        f = rules.due(Fraction(k, 4), {"S.x": x})
        if f is not None:
            fired.append((f.t, f.rule.number))
            if params is not None:
                params.update({c.param: c.value for c in f.rule.changes})
    return fired


def test_a_rule_fires_once_at_the_instant_its_hold_ends() -> None:
    params = {"Kv": 0.1}
    rules = AdaptRules([_rule(1, 0.5, 0.3, 2)], lambda leaf, p: params[p])
    # true from t = 1 s (k = 4) on: fires at exactly t = 3 s, then never again
    fired = _drive(rules, [1.0] * 4 + [0.0] * 40, params)
    assert fired == [(Fraction(3), 1)]
    assert rules.fired[0].estimates == (("S.x", 0.0),)


def test_hysteresis_a_flicker_restarts_the_hold() -> None:
    params = {"Kv": 0.1}
    rules = AdaptRules([_rule(1, 0.5, 0.3, 2)], lambda leaf, p: params[p])
    # true 0..1.75 s, false at 2 s, true again from 2.25 s: fires at 4.25 s, not 2 s
    signal = [0.0] * 8 + [1.0] + [0.0] * 20
    assert _drive(rules, signal, params) == [(Fraction(17, 4), 1)]


def test_least_time_between_switches_and_values_in_force() -> None:
    params = {"Kv": 0.1}
    low = _rule(1, 0.5, 0.3, 2)
    high = Rule(2, (Condition("S.x", above=0.5),), (Change("C", "Kv", 0.1),), Fraction(3))
    rules = AdaptRules([low, high], lambda leaf, p: params[p])
    fired = []
    for k, x in enumerate([0.0] * 12 + [1.0] * 40):
        f = rules.due(Fraction(k, 4), {"S.x": x})
        if f is not None:
            params["Kv"] = f.rule.changes[0].value
            fired.append((f.t, f.rule.number))
    # rule 1 at 2 s; rule 2's condition holds from 3 s, 3 s of hold -> 6 s (>= 3 s after 2 s)
    assert fired == [(Fraction(2), 1), (Fraction(6), 2)]
    # Kv already 0.1 at the start: a rule setting it to 0.1 never fires
    quiet = AdaptRules([high], lambda leaf, p: 0.1)
    assert _drive(quiet, [1.0] * 40) == []


def _scenario(adapt: list | None, duration: float = 20) -> dict:
    out = {
        "world": WORLD,
        "duration": duration,
        "seed": 2,
        "quality": {"signal": "MyDistanceMonitor.distanceFollowerToLeader", "reference": 15},
        "set": {"MyFollowerController.Kv": 0.15},
    }
    if adapt is not None:
        out["adapt"] = adapt
    return out


ALWAYS = [
    {
        "when": {"MyDistanceMonitor.distanceFollowerToLeader": {"below": 1000}},
        "set": {"MyFollowerController.Kv": 0.3},
        "hold": 2,
        "label": "always",
    }
]


def test_the_engine_applies_a_rule_at_the_exact_instant_and_records_it() -> None:
    run = ap.run(_scenario(ALWAYS))
    events = [e for e in run.events if e.kind == "adapt"]
    assert [e.t for e in events] == [2.0]
    assert events[0].detail.startswith("rule 1 (always): MyFollowerController.Kv=0.3 (")
    assert run.metrics["events"][0]["kind"] == "adapt"
    t, rule = run.trace["t"], run.trace["adapt.rule"]
    assert rule[t < 2].max() == 0.0
    assert rule[t >= 2].min() == 1.0
    # the controller's command from t = 2 s uses Kv 0.3: the run differs from --no-adapt after
    fixed = ap.run(_scenario(ALWAYS), adapt=False)
    left = "MyFollowerController.LeftPower"
    assert (run.trace[left][t <= 2] == fixed.trace[left][t <= 2]).all()
    assert (run.trace[left][t > 4] != fixed.trace[left][t > 4]).any()


def test_replay_of_the_resolved_scenario_is_identical() -> None:
    run = ap.run(_scenario(ALWAYS))
    assert "adapt" in run.scenario
    again = ap.run(run.scenario)
    assert again.trace.tobytes() == run.trace.tobytes()
    assert [(e.t, e.detail) for e in again.events] == [(e.t, e.detail) for e in run.events]


def test_no_adapt_equals_the_scenario_without_rules_byte_for_byte(tmp_path: Path) -> None:
    (tmp_path / "1").mkdir()
    (tmp_path / "2").mkdir()
    with_rules = tmp_path / "1" / "s.yaml"
    without = tmp_path / "2" / "s.yaml"
    with_rules.write_text(yaml.safe_dump(_scenario(ALWAYS)))
    without.write_text(yaml.safe_dump(_scenario(None)))
    a, b = tmp_path / "a", tmp_path / "b"
    common = ["--headless", "--no-plot", "-q"]
    assert main(["run", str(with_rules), "--no-adapt", "--out", str(a), *common]) == 0
    assert main(["run", str(without), "--out", str(b), *common]) == 0
    for name in ("trace.csv", "scenario.yaml"):
        assert (a / name).read_bytes() == (b / name).read_bytes(), name


@pytest.mark.parametrize(
    ("adapt", "message"),
    [
        (
            [
                {
                    "when": {"MotorMonitor.delivred": {"below": 1}},
                    "set": {"MyFollowerController.Kv": 1},
                }
            ],
            "adapt[0].when.MotorMonitor.delivred: unknown Data 'MotorMonitor.delivred' "
            "(did you mean MotorMonitor.delivered?)",
        ),
        (
            [
                {
                    "when": {"MotorMonitor.delivered": {"below": 1}},
                    "set": {"MyFollowerController.Kv": 99},
                }
            ],
            "adapt[0].set.MyFollowerController.Kv: 99 is above the maximum 10",
        ),
        (
            [
                {
                    "when": {"MotorMonitor.delivered": {"below": 0.2, "above": 0.5}},
                    "set": {"MyFollowerController.Kv": 1},
                }
            ],
            "below 0.2 is not above above 0.5: the condition never holds",
        ),
        (
            [{"when": {"MotorMonitor.delivered": {}}, "set": {"MyFollowerController.Kv": 1}}],
            "adapt[0].when.MotorMonitor.delivered: needs 'below' or 'above'",
        ),
        ("missing_rules.yaml", "adapt: rules file not found"),
    ],
    ids=["unknown-data", "out-of-range", "empty-band", "no-bound", "missing-file"],
)
def test_bad_rules_are_one_line_errors_exit_2(tmp_path: Path, capsys, adapt, message) -> None:
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(_scenario(adapt), sort_keys=False))
    assert main(["validate", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert re.search(re.escape(message), err), err
    assert err.startswith(f"error: {path}:")


def test_describe_shows_the_rules(tmp_path: Path, capsys) -> None:
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump(_scenario(ALWAYS)))
    assert main(["describe", str(path)]) == 0
    out = capsys.readouterr().out
    assert (
        "rule 1 (always): when MyDistanceMonitor.distanceFollowerToLeader < 1000 for 2 s: "
        "set MyFollowerController.Kv=0.3" in out
    )


def test_derive_from_a_fixture_sweep_gives_the_expected_table() -> None:
    """Without a margin or a least gain (the fixture's grid is coarse), as told."""
    scenario = load_scenario(FIXTURE / "sweep.yaml")
    found = derive(FIXTURE / "results.csv", scenario, "rms_error", 5, float("inf"), 0.0)
    table = {
        c.name: (c.best["MyFollowerController.Kv"], round(c.score, 6), c.levels)
        for c in found.cells
    }
    turning, delivered = "LeaderMonitor.turning", "MotorMonitor.delivered"
    assert table == {
        "nominal": (0.2, 0.55, {delivered: 1.0, turning: 0.0}),
        "worn": (0.4, 0.6, {delivered: 0.5, turning: 0.0}),
        "random": (0.4, 0.35, {delivered: 1.0, turning: 0.2}),
        "speed changes": (0.1, 0.5, {delivered: 1.0, turning: 0.0}),
    }
    assert found.robust == {"MyFollowerController.Kv": 0.2}
    sure = {"MotorMonitor.valid": {"above": 0.5}, "LeaderMonitor.valid": {"above": 0.5}}
    robust = {"MyFollowerController.Kv": 0.2}
    assert found.rules == [
        {
            "when": {"MotorMonitor.valid": {"below": 0.5}},
            "set": robust,
            "hold": 5,
            "dwell": 30,  # the estimator's window: a switch's transient stays in it that long
            "label": "robust, MotorMonitor unsure",
        },
        {
            "when": {"LeaderMonitor.valid": {"below": 0.5}},
            "set": robust,
            "hold": 5,
            "dwell": 30,
            "label": "robust, LeaderMonitor unsure",
        },
        {
            "when": {turning: {"below": 0.08}, delivered: {"below": 0.7}, **sure},
            "set": {"MyFollowerController.Kv": 0.4},
            "hold": 5,
            "label": "worn",
        },
        {
            "when": {turning: {"above": 0.12}, delivered: {"above": 0.8}, **sure},
            "set": {"MyFollowerController.Kv": 0.4},
            "hold": 5,
            "label": "random",
        },
        {
            "when": {turning: {"below": 0.08}, delivered: {"above": 0.8}, **sure},
            "set": robust,
            "hold": 5,
            "label": "nominal, speed changes (alike: robust)",
        },
        {  # no cell is worn with a random leader: worn and random are as near, and agree
            "when": {turning: {"above": 0.12}, delivered: {"below": 0.7}, **sure},
            "set": {"MyFollowerController.Kv": 0.4},
            "hold": 5,
            "label": "nearest worn (no cell here)",
        },
    ]
    # straight at constant speed and with speed changes look alike: reported, robust rule
    assert sorted(u.split(":")[0] for u in found.unplaced) == ["nominal", "speed changes"]


def test_adapt_command_writes_a_rules_file_a_scenario_can_name(tmp_path: Path) -> None:
    rules = tmp_path / "rules.yaml"
    argv = ["adapt", str(FIXTURE), "--scenario", str(FIXTURE / "sweep.yaml"), "-o", str(rules)]
    argv += ["--margin", "inf", "--min-gain", "0"]
    assert main(argv) == 0
    assert main(argv) == 2  # exists: refused without --force
    scenario = tmp_path / "s.yaml"
    scenario.write_text(yaml.safe_dump({**_scenario(None), "adapt": "rules.yaml"}))
    loaded = load_scenario(scenario)
    assert [r.label for r in loaded.adapt][2:4] == ["worn", "random"]
    # a file people read and edit: every rule says its own set: and when:, no YAML anchors
    # (rules share those objects; the dumper would write &id001 and then *id001)
    text = rules.read_text()
    assert "&id" not in text
    assert "*id" not in text
    sets = [line for line in text.splitlines() if line.strip().startswith("set:")]
    assert len(sets) == len(loaded.adapt)


def test_the_shipped_rules_files_hold_no_anchors() -> None:
    for path in sorted(
        (Path(__file__).resolve().parents[2] / "scenarios" / "rules").glob("*.yaml")
    ):
        text = path.read_text()
        assert "&id" not in text, path
        assert "*id" not in text, path


def test_sweeps_of_adaptive_runs_batched_equal_pool(tmp_path: Path) -> None:
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump(_scenario(ALWAYS, duration=10)))
    rows = []
    for executor in ("local", "batch"):
        out = tmp_path / executor
        argv = ["sweep", str(path), "--grid", "MyFollowerController.Kv=0.1,0.2", "--seeds", "2"]
        assert main([*argv, "-j", "1", "--executor", executor, "--out", str(out)]) == 0
        rows.append((out / "results.csv").read_text())
    assert rows[0] == rows[1]


def test_adapt_on_a_sweep_without_a_context_axis_is_refused(tmp_path: Path, capsys) -> None:
    """A Kv-only sweep has one context: nothing for a rule to tell apart. The command says so
    in one line (exit 2) instead of printing an empty cell and writing ``adapt: []``."""
    sweep = tmp_path / "sweep"
    sweep.mkdir()
    rows = (FIXTURE / "results.csv").read_text().splitlines()
    header = rows[0].split(",")
    keep = [i for i, name in enumerate(header) if name != "context"]
    nominal = [r for r in rows[1:] if "nominal" in r.split(",")]
    sweep.joinpath("results.csv").write_text(
        "\n".join(",".join(r.split(",")[i] for i in keep) for r in [rows[0], *nominal]) + "\n"
    )
    out = tmp_path / "rules.yaml"
    argv = ["adapt", str(sweep), "--scenario", str(FIXTURE / "sweep.yaml"), "-o", str(out)]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "results.csv" in err
    assert "no context axis" in err
    assert not out.exists()


def test_run_prints_the_rules_that_fired(tmp_path: Path, capsys) -> None:
    """The terminal summary names each adapt switch, as the table names live changes."""
    scenario = ROOT / "scenarios" / "adaptive.yaml"
    argv = ["run", str(scenario), "--headless", "--no-plot", "--duration", "100"]
    assert main([*argv, "--out", str(tmp_path / "run")]) == 0
    out = capsys.readouterr().out
    line = next(x for x in out.splitlines() if x.startswith("adapt:"))
    # the motor estimator is unsure until its window is full: the robust gain meanwhile
    assert line == "adapt: 1 switch: at 10 s rule 2 (robust, MotorMonitor unsure): Kv=0.2"
    assert main([*argv, "--no-adapt", "--out", str(tmp_path / "off")]) == 0
    assert "adapt:" not in capsys.readouterr().out


def test_the_adapt_line_counts_what_it_does_not_show() -> None:
    from amsa_phys.cli.report import adapt_line

    events = [{"t": float(i), "detail": f"rule {i} (r): Leaf.Kv={i} (Est.x=1)"} for i in range(7)]
    line = adapt_line(events)
    assert line.startswith("adapt: 7 switches: at 0 s rule 0 (r): Kv=0; at 1 s")
    assert line.endswith("; 2 more in metrics.json's events")
