"""Debug in the window, then replay: the session and its replay judge the same phases.

A live change is a change *inside* the phase it lands in (``new_phase: false`` in the
resolved scenario), never a phase of its own; a run cut short (``--duration``, the window
closed early) reports the phase it stopped in as partial and skips its checks, and its
resolved ``scenario.yaml`` replays without being refused.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml
from windowdrive import live_change, press

from amsa_phys.cli.main import main
from amsa_phys.engine.runner import Simulation
from amsa_phys.errors import ConfigError
from amsa_phys.model.scenario import Expectation, Scenario, load_scenario
from amsa_phys.runs.expect import check_expectations
from amsa_phys.runs.single import run_scenario
from amsa_phys.view.pg import pygame
from amsa_phys.view.video import Recorder
from amsa_phys.view.window import Window

ROOT = Path(__file__).resolve().parent.parent.parent
WORLD = ROOT / "worlds" / "mde_challenge.yaml"


def scenario_file(tmp_path: Path, extra: str = "") -> Path:
    """Twelve seconds of scenario 1 with a Kv step at 6 s and checks on both phases."""
    path = tmp_path / "two_phases.yaml"
    path.write_text(
        f"world: {WORLD}\n"
        "duration: 12\n"
        "seed: 1\n"
        "quality: {signal: MyDistanceMonitor.distanceFollowerToLeader, reference: 15}\n"
        "set: {MyFollowerController.Kv: 0.35}\n"
        "timeline:\n"
        "  - {at: 6, set: {MyFollowerController.Kv: 0.15}}\n"
        "expect:\n"
        "  - {metric: max_distance, phase: 0, below: 100}\n"
        "  - {metric: max_distance, phase: 1, below: 100}\n"
        "  - {metric: rms_error, below: 100}\n" + extra
    )
    return path


#: run to 2 s, set MyFollowerController.Kv = 0.2 in the panel, run at x8 to the end
live_change_at_two_seconds = live_change("MyFollowerController.Kv", "0.2", at=2, faster=3)


def phases_of(metrics: dict) -> list[tuple[float, float]]:
    return [(p["start"], p["end"]) for p in metrics["phases"]]


def verdicts(scenario: Scenario, metrics: dict, out: Path) -> list[tuple[str, object, str]]:
    return [
        (c.what, c.value, c.verdict)
        for c in check_expectations(scenario.expect, metrics, out / "trace.csv")
    ]


def test_a_live_change_stays_inside_its_phase_and_the_replay_judges_the_same(
    tmp_path: Path,
) -> None:
    path = scenario_file(tmp_path)
    session = tmp_path / "session"
    session.mkdir()
    scenario = load_scenario(path)
    outcome = run_scenario(scenario, session, window=live_change_at_two_seconds, plot=False)
    assert phases_of(outcome.metrics) == [(0.0, 6.0), (6.0, 12.0)]
    [live] = outcome.metrics["phases"][0]["changes"]
    assert live["label"] == "live"
    assert live["set"] == {"MyFollowerController.Kv": 0.2}
    assert 2.0 <= live["at"] < 2.2

    doc = yaml.safe_load((session / "scenario.yaml").read_text())
    assert [e.get("new_phase", True) for e in doc["timeline"]] == [False, True]

    replay = tmp_path / "replay"
    assert (
        main(["run", str(session / "scenario.yaml"), "--headless", "-q", "--out", str(replay)]) == 0
    )
    replayed = json.loads((replay / "metrics.json").read_text())
    assert phases_of(replayed) == phases_of(outcome.metrics)
    assert replayed["phases"][0]["changes"] == outcome.metrics["phases"][0]["changes"]
    again = load_scenario(session / "scenario.yaml")
    assert verdicts(again, replayed, replay) == verdicts(scenario, outcome.metrics, session)
    assert (replay / "trace.csv").read_bytes() == (session / "trace.csv").read_bytes()


def test_an_in_phase_timeline_entry_changes_the_run_but_not_the_phases(tmp_path: Path) -> None:
    inner = "  - {at: 3, set: {MyFollowerController.Kv: 0.05}, new_phase: false}\n"
    path = scenario_file(tmp_path)
    text = path.read_text().replace("timeline:\n", "timeline:\n" + inner)
    path.write_text(text)
    scenario = load_scenario(path)
    assert len(scenario.timeline.phases) == 2
    out = tmp_path / "run"
    assert main(["run", str(path), "--headless", "-q", "--out", str(out)]) == 0
    metrics = json.loads((out / "metrics.json").read_text())
    assert phases_of(metrics) == [(0.0, 6.0), (6.0, 12.0)]
    assert metrics["phases"][0]["changes"] == [
        {"at": 3.0, "set": {"MyFollowerController.Kv": 0.05}}
    ]
    plain = tmp_path / "plain"
    (tmp_path / "ref").mkdir()
    main(["run", str(scenario_file(tmp_path / "ref")), "--headless", "-q", "--out", str(plain)])
    rows = (out / "trace.csv").read_text().splitlines()
    ref = (plain / "trace.csv").read_text().splitlines()
    assert rows[:61] == ref[:61]  # identical up to t = 3 s (20 rows a second, header)
    assert rows[-1] != ref[-1]


def test_an_in_phase_entry_is_checked_with_its_own_line(tmp_path: Path) -> None:
    inner = "  - {at: 3, set: {Follower.mass: 40}, new_phase: false}\n"
    path = scenario_file(tmp_path)
    path.write_text(path.read_text().replace("timeline:\n", "timeline:\n" + inner))
    with pytest.raises(ConfigError) as err:
        load_scenario(path)
    assert str(err.value) == (
        f"{path}:7: timeline[0].set.Follower.mass: mass is read only when the run starts; "
        "set it in set: or in the world"
    )


def close_at_four(sim: Simulation, scenario: Scenario, rec: Recorder | None) -> None:
    """A window session closed with q at t = 4 s."""
    w = Window(sim, scenario.quality, size=(320, 240))
    while sim.now < 4:
        w.frame(0.1)
    press(pygame.K_q)
    w.frame(0.1)


def test_closing_the_window_early_skips_what_it_did_not_finish(tmp_path: Path) -> None:
    scenario = load_scenario(scenario_file(tmp_path))
    out = tmp_path / "early"
    out.mkdir()
    outcome = run_scenario(scenario, out, window=close_at_four, plot=False)
    assert phases_of(outcome.metrics) == [(0.0, 4.0)]
    assert outcome.metrics["phases"][0]["partial"] is True
    assert outcome.metrics["overall"]["partial"] is True
    checks = check_expectations(scenario.expect, outcome.metrics, out / "trace.csv")
    assert [(c.verdict, c.why) for c in checks] == [
        ("skipped", "phase 0 was cut short at t=4 s"),
        ("skipped", "phase 1 not reached: the run ended at t=4 s"),
        ("skipped", "the run was cut short at t=4 s"),
    ]
    text = (out / "scenario.yaml").read_text()
    assert text.startswith("# this run stopped at t=4 s, so these checks were not judged")
    assert "expect" not in yaml.safe_load(text)
    replay = tmp_path / "replay"
    assert main(["run", str(out / "scenario.yaml"), "--headless", "-q", "--out", str(replay)]) == 0


def test_a_run_cut_by_duration_passes_and_its_scenario_replays(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "cut"
    scenario1 = ROOT / "scenarios" / "scenario1.yaml"
    assert (
        main(["run", str(scenario1), "--headless", "-q", "--duration", "130", "--out", str(out)])
        == 0
    )
    printed = capsys.readouterr().out
    assert "expect rms_error (phase 0) = " in printed  # phase 0 (0-125 s) ran whole: judged
    assert "expect settling_time (phase 3): skipped (phase 3 not reached" in printed
    assert "expect collisions: skipped (the run was cut short at t=130 s)" in printed
    metrics = json.loads((out / "metrics.json").read_text())
    assert "partial" not in metrics["phases"][0]
    assert metrics["phases"][1]["partial"] is True
    doc = yaml.safe_load((out / "scenario.yaml").read_text())
    # what the cut run judged stays: phase 0's bound and the whole-run requirement
    assert doc["expect"] == [
        {"metric": "rms_error", "phase": 0, "above": 2.0},
        {"stl": "always(MyDistanceMonitor.distanceFollowerToLeader >= 3)", "name": "no_contact"},
    ]
    replay = tmp_path / "replay"
    assert main(["run", str(out / "scenario.yaml"), "--headless", "-q", "--out", str(replay)]) == 0
    assert capsys.readouterr().out.count("expect rms_error (phase 0) = ") == 1
    assert (replay / "trace.csv").read_bytes() == (out / "trace.csv").read_bytes()


def test_a_trace_window_the_cut_run_stopped_inside_is_judged_only_if_broken() -> None:
    """A cut run's [90, end] window that held until the cut is skipped (the rest might not
    have held), like a metric of a cut phase; a sample that broke the bound still fails."""
    t = np.arange(0, 100.5, 0.5)
    header, data = ["t", "Gap.d"], np.column_stack([t, np.full_like(t, 10.0)])
    cut = {"simulated": 100.0, "overall": {"partial": True}, "phases": []}
    whole = {"simulated": 100.0, "overall": {}, "phases": []}
    holds = Expectation(None, None, 13.5, None, 1, trace="Gap.d", after=90.0)
    inside = Expectation(None, None, 13.5, None, 2, trace="Gap.d", after=20.0, before=50.0)
    [c] = check_expectations([holds], cut, (header, data))
    assert (c.verdict, c.why) == (
        "skipped",
        "the run was cut short at t=100 s inside the window; held until then",
    )
    assert check_expectations([holds], whole, (header, data))[0].verdict == "pass"
    assert check_expectations([inside], cut, (header, data))[0].verdict == "pass"  # whole window
    data[-1, 1] = 14.0  # broke the bound before the cut: a real failure
    assert check_expectations([holds], cut, (header, data))[0].verdict == "FAIL"


def test_the_replays_note_names_every_check_it_leaves_out(tmp_path: Path) -> None:
    """An STL check reading past where the window was closed is left out of the replay
    (its loader would refuse it): the comment heading scenario.yaml names it too."""
    stl = "  - {stl: 'always[0:10](MyDistanceMonitor.distanceFollowerToLeader >= 0)', name: far}\n"

    scenario = load_scenario(scenario_file(tmp_path, stl))
    out = tmp_path / "early"
    out.mkdir()
    run_scenario(scenario, out, window=close_at_four, plot=False)
    text = (out / "scenario.yaml").read_text()
    note = text.splitlines()[0]
    assert "expect" not in yaml.safe_load(text)
    for what in ("max_distance (phase 0)", "max_distance (phase 1)", "rms_error", "far"):
        assert what in note, note
