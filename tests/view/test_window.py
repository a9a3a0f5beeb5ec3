"""The interactive window, driven headless (SDL dummy driver, injected keys, an exact clock)."""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path

import pytest
import yaml
from deadlines import HANG_S

from amsa_phys.cli.main import main
from amsa_phys.engine.runner import Simulation
from amsa_phys.model.scenario import Scenario, load_scenario
from amsa_phys.runs.single import run_scenario
from amsa_phys.view.pg import pygame
from amsa_phys.view.video import Recorder
from amsa_phys.view.window import Window

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO = ROOT / "tests" / "fixtures" / "mde_short.yaml"


def press(key: int, text: str = "", mod: int = 0) -> None:
    pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=key, mod=mod, unicode=text))


def type_text(text: str) -> None:
    for ch in text:
        press(pygame.K_PERIOD if ch == "." else ord(ch), ch)


class Session:
    """A scripted user: what they pressed and what the window showed."""

    def __init__(self) -> None:
        self.paused_at: tuple[float, float] | None = None
        self.applied_at: Fraction | None = None

    def __call__(self, sim: Simulation, scenario: Scenario, recorder: Recorder | None) -> None:
        w = Window(sim, scenario.quality, title="test", size=(640, 360), recorder=recorder)
        for _ in range(25):  # 2.5 s of wall clock at x1
            w.frame(0.1)
        assert abs(float(sim.now) - 2.5) < 0.02
        press(pygame.K_SPACE)
        w.frame(0.1)
        before = sim.now
        for _ in range(30):  # three seconds paused
            w.frame(0.1)
        self.paused_at = (float(before), float(sim.now))
        press(pygame.K_p)  # the panel: go to the controller's Kv and type 0.12
        w.frame(0.0)
        for _ in range(len(w.panel.rows)):
            if w.panel.row.key == "MyFollowerController.Kv":
                break
            press(pygame.K_DOWN)
            w.frame(0.0)
        type_text("0.12")
        press(pygame.K_RETURN)
        w.frame(0.0)
        assert "MyFollowerController.Kv = 0.12 at t = 2.51 s" in w.panel.message
        assert sim.now == before  # still paused: the change waits for the next instant
        assert sim.live_changes == []
        press(pygame.K_p)
        press(pygame.K_SPACE)
        press(pygame.K_RIGHTBRACKET)  # x2, x4, x8
        press(pygame.K_RIGHTBRACKET)
        press(pygame.K_RIGHTBRACKET)
        while not w.finished:
            w.frame(0.1)
        press(pygame.K_q)
        assert not w.frame(0.1)
        self.applied_at = sim.live_changes[-1][0] if sim.live_changes else None


@pytest.fixture(scope="module")
def session_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Session, Path, Scenario]:
    out = tmp_path_factory.mktemp("window")
    scenario = load_scenario(SCENARIO, duration=20)
    session = Session()
    run_scenario(scenario, out, window=session, plot=False)
    return session, out, scenario


def test_pause_stops_simulated_time(session_run: tuple[Session, Path, Scenario]) -> None:
    session, _, _ = session_run
    assert session.paused_at is not None
    before, after = session.paused_at
    assert before == after


def test_live_change_lands_in_the_resolved_scenario(
    session_run: tuple[Session, Path, Scenario],
) -> None:
    session, out, _ = session_run
    assert session.applied_at is not None
    # the next instant after the pause (every 1/100 s runs the physics)
    assert session.applied_at == Fraction(251, 100)
    doc = yaml.safe_load((out / "scenario.yaml").read_text())
    entries = [e for e in doc["timeline"] if e.get("label") == "live"]
    assert entries == [
        {"at": 2.51, "set": {"MyFollowerController.Kv": 0.12}, "label": "live", "new_phase": False}
    ]
    assert doc["duration"] == 20


def test_replaying_the_session_reproduces_the_trace(
    session_run: tuple[Session, Path, Scenario], tmp_path: Path
) -> None:
    _, out, _ = session_run
    replay = tmp_path / "replay"
    assert main(["run", str(out / "scenario.yaml"), "--headless", "--out", str(replay), "-q"]) == 0
    assert (replay / "trace.csv").read_bytes() == (out / "trace.csv").read_bytes()


def test_the_change_changed_the_run(session_run: tuple[Session, Path, Scenario], tmp_path: Path):
    _, out, _ = session_run
    plain = tmp_path / "plain"
    args = ["run", str(SCENARIO), "--headless", "--out", str(plain), "-q", "--duration", "20"]
    assert main(args) == 0
    a = (plain / "trace.csv").read_text().splitlines()
    b = (out / "trace.csv").read_text().splitlines()
    assert a[:50] == b[:50]  # identical before t = 2.5 s
    assert a[-1] != b[-1]


def test_closing_the_window_early_cuts_the_replayable_scenario(tmp_path: Path) -> None:
    def close_at_four_seconds(sim: Simulation, scenario: Scenario, rec: Recorder | None) -> None:
        w = Window(sim, scenario.quality, size=(320, 240))
        while sim.now < 4:
            w.frame(0.1)
        press(pygame.K_ESCAPE)
        w.frame(0.1)

    out = tmp_path / "early"
    out.mkdir()
    outcome = run_scenario(load_scenario(SCENARIO), out, window=close_at_four_seconds, plot=False)
    assert outcome.metrics["status"].startswith("closed in the window at t=4")
    doc = yaml.safe_load((out / "scenario.yaml").read_text())
    assert doc["duration"] == 4
    assert "timeline" not in doc  # the Kv steps at 125 s and later never happened
    replay = tmp_path / "replay"
    assert main(["run", str(out / "scenario.yaml"), "--headless", "--out", str(replay), "-q"]) == 0
    assert (replay / "trace.csv").read_bytes() == (out / "trace.csv").read_bytes()


def test_a_window_without_a_display_is_refused_clearly(tmp_path: Path) -> None:
    import os
    import subprocess
    import sys

    env = {k: v for k, v in os.environ.items() if k not in ("SDL_VIDEODRIVER", "DISPLAY")}
    env.pop("WAYLAND_DISPLAY", None)
    env.pop("XDG_RUNTIME_DIR", None)  # SDL's Wayland probe would complain about it
    proc = subprocess.run(
        [sys.executable, "-m", "amsa_phys", "run", str(SCENARIO), "--out", str(tmp_path / "w")],
        capture_output=True,
        text=True,
        env=env,
        check=False,
    )
    assert proc.returncode == 2
    assert proc.stderr == (  # one line: nothing printed by SDL or Wayland before it
        "error: run: no display to open a window on (no X11 or Wayland session); "
        "run with --headless\n"
    )
    assert not (tmp_path / "w").exists()


def test_a_display_that_refuses_the_connection_is_named(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``DISPLAY`` set, but SDL could not connect to it and fell back to its offscreen
    driver (an X server that is not running, or refuses this user): the line said "no X11
    or Wayland session", and a user looking at their ``DISPLAY`` could not tell why."""
    import pygame

    from amsa_phys.view import window

    monkeypatch.delenv("SDL_VIDEODRIVER", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.setenv("DISPLAY", ":93")
    monkeypatch.setattr(pygame.display, "init", lambda: None)
    monkeypatch.setattr(pygame.display, "quit", lambda: None)
    monkeypatch.setattr(pygame.display, "get_driver", lambda: "offscreen")
    with pytest.raises(RuntimeError) as refused:
        window.open_display(interactive=True)
    assert str(refused.value) == (
        "cannot open a window on DISPLAY=:93: SDL could not connect to that display (is its "
        "server running, and does it accept this user?)"
    )

    def no_video() -> None:
        raise pygame.error("windows not available")

    monkeypatch.setattr(pygame.display, "init", no_video)
    with pytest.raises(RuntimeError, match=r"^cannot open a window on DISPLAY=:93: windows "):
        window.open_display(interactive=True)


@pytest.mark.parametrize("driver", ["dummy", "offscreen", " Dummy "])
def test_a_window_on_an_invisible_driver_is_refused_not_waited_on(
    tmp_path: Path, driver: str
) -> None:
    """``SDL_VIDEODRIVER=dummy`` (a common headless setting) and ``run`` without
    ``--headless``: the window could never be closed, so the run would wait for ever after
    its end. Refused, one line, nothing written; ``view`` alike."""
    import os
    import subprocess
    import sys

    env = {**os.environ, "SDL_VIDEODRIVER": driver}
    out = tmp_path / "w"
    proc = subprocess.run(
        [sys.executable, "-m", "amsa_phys", "run", str(SCENARIO), "--out", str(out)],
        capture_output=True,
        text=True,
        env=env,
        check=False,
        timeout=HANG_S,  # a hang fails here instead of holding the suite
    )
    assert proc.returncode == 2
    assert proc.stderr == (
        f"error: run: SDL_VIDEODRIVER={driver.strip()} shows no window, and the session "
        "would wait for ever for it to be closed; run with --headless\n"
    )
    assert not out.exists()
    rundir = tmp_path / "r"
    assert (
        main(
            [
                "run",
                str(SCENARIO),
                "--headless",
                "--out",
                str(rundir),
                "-q",
                "--no-plot",
                "--duration",
                "2",
            ]
        )
        == 0
    )
    proc = subprocess.run(
        [sys.executable, "-m", "amsa_phys", "view", str(rundir)],
        capture_output=True,
        text=True,
        env=env,
        check=False,
        timeout=HANG_S,
    )
    assert proc.returncode == 2
    assert proc.stderr.startswith(f"error: view: SDL_VIDEODRIVER={driver.strip()} shows no window")
    assert proc.stderr.count("\n") == 1


@pytest.mark.usefixtures("python_sigint")
def test_ctrl_c_in_the_terminal_stops_a_paused_window(tmp_path: Path) -> None:
    import json
    import os
    import signal

    from amsa_phys.errors import Interrupted

    def ctrl_c_while_paused(sim: Simulation, scenario: Scenario, rec: Recorder | None) -> None:
        w = Window(sim, scenario.quality, size=(320, 240))
        while sim.now < 2:
            w.frame(0.1)
        press(pygame.K_SPACE)
        w.frame(0.1)
        os.kill(os.getpid(), signal.SIGINT)  # only noted: the state stays whole
        for _ in range(3):
            w.frame(0.1)  # paused: nothing advances, yet the next frame stops the session
        raise AssertionError("the window kept running after Ctrl-C")

    out = tmp_path / "w"
    out.mkdir()
    with pytest.raises(Interrupted, match=r"interrupted at t=2\.0"):
        run_scenario(load_scenario(SCENARIO), out, window=ctrl_c_while_paused, plot=False)
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["status"] == "interrupted"
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # handler restored
