"""The window as a debugging tool: keys that cannot lose work, a HUD that tells the truth.

Driven headless (SDL dummy driver, injected keys, an exact clock) like test_window.py.
"""

from __future__ import annotations

import itertools
import json
from pathlib import Path

import pytest

from amsa_phys.engine.runner import Simulation
from amsa_phys.model.scenario import Scenario, load_scenario
from amsa_phys.runs.single import run_scenario
from amsa_phys.view.pg import pygame
from amsa_phys.view.video import Recorder
from amsa_phys.view.window import SPEEDS, Window

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO = ROOT / "tests" / "fixtures" / "mde_short.yaml"
SCENARIO1 = ROOT / "scenarios" / "scenario1.yaml"


def press(key: int, text: str = "") -> None:
    pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=key, mod=0, unicode=text))


def open_window(duration: float = 10, **kw: object) -> tuple[Window, Simulation]:
    scenario = load_scenario(SCENARIO, duration=duration, **kw)  # type: ignore[arg-type]
    sim = Simulation.from_scenario(scenario)
    sim.initialize()
    return Window(sim, scenario.quality, size=(640, 360)), sim


def queue_kv(w: Window, value: str) -> None:
    """Open the panel, select MyFollowerController.Kv, type ``value``, press Enter."""
    press(pygame.K_p)
    w.frame(0.0)
    while w.panel.row.key != "MyFollowerController.Kv":
        press(pygame.K_DOWN)
        w.frame(0.0)
    for ch in value:
        press(pygame.K_PERIOD if ch == "." else ord(ch), ch)
    press(pygame.K_RETURN)
    w.frame(0.0)


def test_esc_closes_the_panel_and_the_queued_change_survives() -> None:
    w, sim = open_window()
    for _ in range(10):
        w.frame(0.1)
    press(pygame.K_SPACE)  # paused: a change waits for the next instant
    w.frame(0.0)
    queue_kv(w, "0.2")
    assert [c.key for c in sim.pending_live] == ["MyFollowerController.Kv"]
    press(pygame.K_ESCAPE)  # no edit pending: closes the panel, does not quit
    assert w.frame(0.0)
    assert w.running
    assert not w.panel.visible
    press(pygame.K_q)  # quitting would drop the queued change: asked once more
    assert w.frame(0.0)
    assert "queued, not applied yet: q again quits without it" in w.notice
    press(pygame.K_SPACE)  # changed their mind: run on, the change lands
    w.frame(0.1)
    assert sim.pending_live == []
    assert sim.live_changes[-1][1].value == 0.2
    assert "queued" not in w.notice  # the warning went with the queue
    press(pygame.K_q)  # nothing queued any more: q quits at once
    assert not w.frame(0.0)


def test_q_twice_quits_without_the_queued_change() -> None:
    w, sim = open_window()
    w.frame(0.1)
    press(pygame.K_SPACE)
    w.frame(0.0)
    queue_kv(w, "0.2")
    press(pygame.K_q)
    assert w.frame(0.0)
    press(pygame.K_q)
    assert not w.frame(0.0)
    assert sim.live_changes == []


def test_esc_with_an_edit_drops_only_the_edit() -> None:
    w, _ = open_window()
    press(pygame.K_p)
    w.frame(0.0)
    press(pygame.K_RIGHT)  # a pending step
    w.frame(0.0)
    assert w.panel.pending is not None
    press(pygame.K_ESCAPE)
    w.frame(0.0)
    assert w.panel.visible
    assert w.panel.pending is None
    press(pygame.K_ESCAPE)
    w.frame(0.0)
    assert w.running
    assert not w.panel.visible


def test_hud_metrics_follow_simulated_instants_not_frames(tmp_path: Path) -> None:
    seen: dict[str, object] = {}

    def session(sim: Simulation, scenario: Scenario, rec: Recorder | None) -> float:
        w = Window(sim, scenario.quality, size=(640, 360))
        for _ in range(50):
            w.frame(0.1)
        press(pygame.K_SPACE)
        w.frame(0.1)
        frozen = (w.scene.metrics.rms_error, w.scene.metrics.count)
        for _ in range(30):  # three seconds paused, sixty frames drawn
            w.frame(0.05)
            w.frame(0.05)
        seen["paused"] = (frozen, (w.scene.metrics.rms_error, w.scene.metrics.count))
        press(pygame.K_SPACE)
        for _ in range(3):
            press(pygame.K_RIGHTBRACKET)
        while not w.finished:
            w.frame(0.1)
        seen["end"] = (w.scene.metrics.rms_error, w.scene.metrics.count, w.scene.metrics.max)
        seen["idle"] = getattr(w, "idle_s", None)
        return seen["idle"]  # type: ignore[return-value]

    out = tmp_path / "run"
    out.mkdir()
    outcome = run_scenario(load_scenario(SCENARIO, duration=20), out, window=session, plot=False)
    before, after = seen["paused"]  # type: ignore[misc]
    assert before == after  # paused: the HUD stands still
    rms, count, top = seen["end"]  # type: ignore[misc]
    overall = outcome.metrics["overall"]
    assert count == 20 * 20 + 1  # one sample per logged instant, t = 0 .. 20 s at 20 Hz
    assert rms == pytest.approx(overall["rms_error"], rel=1e-9)
    assert top == overall["max_distance"]
    assert seen["idle"] == pytest.approx(3.1)  # the paused frames, and the one after the end


def test_what_the_window_shows_does_not_depend_on_the_speed() -> None:
    """At x256 a 60 Hz frame spans 4.3 s: the history must still be per instant."""

    def history(speed: float, real_dt: float) -> tuple[object, ...]:
        w, _sim = open_window(duration=20, overrides=["LeaderGPS.lostDataGPS=50"])
        w.speed_index = SPEEDS.index(speed)
        while not w.finished:
            w.frame(real_dt)
        gps = {t.path: (list(t.fixes), list(t.lost), t.lost_total) for t in w.scene.gps}
        trails = {k: list(v) for k, v in w.scene.trails.items()}
        return trails, gps, w.scene.metrics.count

    slow = history(1, 0.05)  # one frame per logged instant
    fast = history(256, 1 / 60)
    assert fast == slow
    trails, gps, _ = fast
    assert gps["LeaderGPS"][2] > 20  # lost fixes marked, each where the leader was
    leader = trails["Leader"]
    steps = [abs(b[0] - a[0]) for a, b in itertools.pairwise(leader)]
    assert max(steps) < 0.5  # 20 samples a second at ~5 m/s: no chords across the run


@pytest.mark.parametrize("size", [(320, 240), (640, 360), (1280, 720)], ids=str)
def test_the_hud_fits_the_frame_and_nothing_overlaps(size: tuple[int, int]) -> None:
    scenario = load_scenario(SCENARIO1, duration=10)
    sim = Simulation.from_scenario(scenario)
    sim.initialize()
    w = Window(sim, scenario.quality, size=size)
    w.frame(0.5)
    w.notice = "camera: follow Follower"
    press(pygame.K_h)  # help open too
    w.frame(0.5)
    boxes = w.renderer.boxes
    screen = w.screen.get_rect()
    assert set(boxes) == {"hud", "status"}
    for name, box in boxes.items():
        assert screen.contains(box), f"{name} {box} leaves the {size} frame"
    assert not boxes["hud"].colliderect(boxes["status"])
    assert w.renderer.text_px >= 9


def test_paused_time_is_left_out_of_the_real_time_factor(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from types import SimpleNamespace

    from amsa_phys.runs import single

    def paused_eight_seconds(sim: Simulation, scenario: Scenario, rec: Recorder | None) -> float:
        w = Window(sim, scenario.quality, size=(320, 240))
        while not w.finished:
            w.frame(0.1)
        return 8.0

    clock = iter([100.0, 110.0])  # the run starts, then ends 10 s of wall clock later
    monkeypatch.setattr(single, "time", SimpleNamespace(perf_counter=lambda: next(clock)))
    out = tmp_path / "run"
    out.mkdir()
    outcome = run_scenario(
        load_scenario(SCENARIO, duration=2), out, window=paused_eight_seconds, plot=False
    )
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics == outcome.metrics
    assert (metrics["wall_time_s"], metrics["paused_s"]) == (10.0, 8.0)
    assert metrics["real_time_factor"] == 1.0  # 2 s simulated in 10 - 8 s of running
