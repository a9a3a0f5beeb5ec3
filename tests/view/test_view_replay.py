"""``amsa-phys view RUNDIR``: a finished run replayed, driven headless (SDL dummy driver,
injected keys and mouse, an exact clock), and checked against the run's own trace."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TypeVar

import numpy as np
import pytest
from deadlines import HANG_S

from amsa_phys.cli.main import main
from amsa_phys.cli.view import load_run
from amsa_phys.model.scenario import load_scenario
from amsa_phys.palette import ROVER_COLOURS, rover_colour
from amsa_phys.plots.distance import read_trace
from amsa_phys.runs.single import run_scenario
from amsa_phys.view.draw import INK
from amsa_phys.view.pg import pygame
from amsa_phys.view.player import BIG_STEP_S, SLIDER_H, Player
from amsa_phys.view.scene import Scene

T = TypeVar("T")
ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO = ROOT / "tests" / "fixtures" / "mde_short.yaml"
LOSSY = ["--set", "LeaderGPS.lostDataGPS=30", "--duration", "40"]


def press(key: int, mod: int = 0, text: str = "") -> None:
    pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=key, mod=mod, unicode=text))


def click(pos: tuple[int, int]) -> None:
    pygame.event.post(pygame.event.Event(pygame.MOUSEBUTTONDOWN, button=1, pos=pos))
    pygame.event.post(pygame.event.Event(pygame.MOUSEBUTTONUP, button=1, pos=pos))


@pytest.fixture(scope="module")
def rundir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("view") / "run"
    assert main(["run", str(SCENARIO), "--headless", *LOSSY, "--out", str(out)]) == 0
    return out


@pytest.fixture
def player(rundir: Path) -> Player:
    p = Player(load_run(rundir), title="test", size=(800, 480))
    p.frame(0.0)
    return p


def trace_row(rundir: Path, t: float) -> dict[str, float]:
    header, data = read_trace(rundir / "trace.csv")
    i = int(np.flatnonzero(np.isclose(data[:, 0], t))[0])
    return dict(zip(header, data[i].tolist(), strict=True))


def test_keys_scrub_to_an_event_and_the_picture_is_the_trace_there(
    player: Player, rundir: Path
) -> None:
    events = player.scene.events
    first = events[0]
    assert first.kind == "lost fix"  # 30 % of the leader's fixes are lost
    press(pygame.K_n)
    player.frame(0.0)
    assert player.t == pytest.approx(first.t)
    assert player.notice.startswith(f"{first.t:.2f} s: lost fix LeaderGPS")
    press(pygame.K_n)
    player.frame(0.0)
    assert player.t == pytest.approx(events[1].t)
    press(pygame.K_b)
    player.frame(0.0)
    assert player.t == pytest.approx(first.t)
    # the drawn rovers stand where the trace says, and are drawn there in their colour
    row = trace_row(rundir, player.t)
    frame = player.scene.frame(player.row)
    for r in frame.rovers:
        assert (r.x, r.y, r.heading) == (
            row[f"{r.name}.posX"],
            row[f"{r.name}.posY"],
            row[f"{r.name}.heading"],
        )
        px, py = player.camera.to_screen(r.x, r.y)
        assert tuple(player.screen.get_at((round(px), round(py))))[:3] == rover_colour(r.index)
    # shift+right: 5 s on; right: one logged instant; home and end
    t0 = player.t
    press(pygame.K_RIGHT, pygame.KMOD_SHIFT)
    player.frame(0.0)
    assert player.t == pytest.approx(t0 + BIG_STEP_S)
    press(pygame.K_RIGHT)
    player.frame(0.0)
    assert player.t == pytest.approx(t0 + BIG_STEP_S + 0.05)  # the 20 Hz log
    press(pygame.K_END)
    player.frame(0.0)
    assert player.t == pytest.approx(40.0)
    press(pygame.K_HOME)
    player.frame(0.0)
    assert player.t == 0.0


def test_play_runs_at_the_chosen_speed_and_the_slider_seeks(player: Player) -> None:
    press(pygame.K_SPACE)
    press(pygame.K_RIGHTBRACKET)  # x2
    for _ in range(10):
        player.frame(0.1)  # one wall-clock second
    assert player.t == pytest.approx(2.0)
    bar = player.slider
    click((bar.x + bar.width // 2, bar.centery))
    player.frame(0.1)
    assert not player.playing  # a seek pauses
    assert player.t == pytest.approx(20.0, abs=0.1)


def test_phase_keys_jump_to_phase_starts(tmp_path: Path) -> None:
    out = tmp_path / "run"
    assert main(["run", str(SCENARIO), "--headless", "--duration", "130", "--out", str(out)]) == 0
    p = Player(load_run(out), title="test", size=(640, 360))
    press(pygame.K_PAGEDOWN)
    p.frame(0.0)
    assert p.t == 125.0
    assert p.scene.frame(p.row).phase_text.startswith("phase 1 (of 0–1) from 125 s: Kv=0.15")
    press(pygame.K_PAGEUP)
    p.frame(0.0)
    assert p.notice == "no earlier event (Home: the start)"


def test_plot_pane_draws_a_picked_signal(player: Player) -> None:
    press(pygame.K_g)
    press(0, text="/")  # letters filter after /: without it they are the player's keys
    for ch in "distance":
        press(0, text=ch)
    press(pygame.K_RETURN)
    press(pygame.K_g)
    player.frame(0.0)
    assert player.picker.picked == ["MyDistanceMonitor.distanceFollowerToLeader"]
    assert not player.picker.visible
    press(pygame.K_END)
    player.frame(0.0)
    t, v = player.scene_series("MyDistanceMonitor.distanceFollowerToLeader", 30.0)
    assert t[0] == pytest.approx(10.0)
    assert t[-1] == pytest.approx(40.0)
    assert v[-1] == player.scene.frame(player.row).metrics.value


def test_lost_fixes_found_in_the_trace_are_the_live_runs(tmp_path: Path) -> None:
    """The replay and trajectory.png find lost fixes from the stale fix in the trace; the
    live window counts them in the running GPS. Both must agree, one by one."""
    scenario = load_scenario(SCENARIO, ["LeaderGPS.lostDataGPS=30"], duration=40)
    live: dict[str, int] = {}

    def drive(sim, scenario, recorder):  # type: ignore[no-untyped-def]
        scene = Scene(sim, scenario.quality)
        sim.advance(sim.grid.ticks(sim.duration))
        live.update({g.path: g.lost_total for g in scene.gps})

    out = tmp_path / "run"
    out.mkdir()
    run_scenario(scenario, out, window=drive, plot=False)
    replay = load_run(out)
    end = replay.frame(replay.rows - 1)
    assert live["LeaderGPS"] > 20
    assert {g.path: g.lost_total for g in end.gps} == live
    lost = [e for e in replay.events if e.kind == "lost fix"]
    assert len(lost) == live["LeaderGPS"]


def _bad(kind: str, run: Path, d: Path) -> Path:
    """A directory ``view`` must refuse: missing, not a run, a truncated trace, a sweep's."""
    if kind == "missing":
        return d / "nothing"
    out = d / kind
    if kind == "not-a-run":
        out.mkdir()
    elif kind == "truncated-trace":
        shutil.copytree(run, out)
        text = (out / "trace.csv").read_bytes()
        (out / "trace.csv").write_bytes(text[: len(text) // 2])  # a row cut short
    else:
        out.mkdir()
        (out / "results.csv").write_text("seed\n1\n")
    return out


@pytest.mark.parametrize(
    ("kind", "message"),
    [
        ("missing", "nothing: no such directory"),
        ("not-a-run", "not-a-run: not a run directory: trace.csv is missing"),
        ("truncated-trace", "trace.csv:"),
        ("sweep", "sweep: a sweep directory: view one of its kept runs"),
    ],
    ids=["missing", "not-a-run", "truncated-trace", "sweep"],
)
def test_bad_rundir_is_one_line_and_exit_2(
    rundir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], kind: str, message: str
) -> None:
    assert main(["view", str(_bad(kind, rundir, tmp_path))]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "Traceback" not in err
    assert message in err


def test_a_closed_run_says_where_it_was_cut(rundir: Path) -> None:
    scene = load_run(rundir)
    scene.metrics["status"] = "closed in the window at t=12.5 s"
    p = Player(scene, title="test", size=(640, 360))
    assert "run closed in the window at t=12.5 s" in p.status()


def test_colours_follow_the_world_not_the_trace_columns(tmp_path: Path) -> None:
    """A trace that keeps only the follower still draws it in the follower's blue."""
    out = tmp_path / "run"
    keep = "Follower.*,MyDistanceMonitor.*"
    argv = ["run", str(SCENARIO), "--headless", "--duration", "5", "--out", str(out)]
    assert main([*argv, "--trace-columns", keep]) == 0
    scene = load_run(out)
    assert [r.name for r in scene.rovers(0)] == ["Follower"]
    assert scene.rovers(0)[0].index == 1
    p = Player(scene, title="test", size=(640, 360))
    p.frame(0.0)
    r = scene.frame(p.row).rovers[0]
    px, py = p.camera.to_screen(r.x, r.y)
    assert tuple(p.screen.get_at((round(px), round(py))))[:3] == ROVER_COLOURS[1]
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["status"] == "completed"


# -- a real window: Xvfb, xdotool and ImageMagick's import ------------------------------------
X_TOOLS = ("Xvfb", "xdotool", "import")
X_TIMEOUT_S = 600.0  # a deadline for a failure, never a measured time: every wait polls


def _poll(what: str, check: Callable[[], T | None], state: Callable[[], str] = str) -> T:
    """``check()`` until it gives a value (the event waited for), or fail at the deadline
    saying ``state()`` (what the process under test said by then)."""
    deadline = time.monotonic() + X_TIMEOUT_S
    while time.monotonic() < deadline:
        found = check()
        if found is not None:
            return found
        time.sleep(0.1)
    raise AssertionError(f"waited {X_TIMEOUT_S:g} s for {what}; {state()}")


@pytest.fixture
def xdisplay() -> Iterator[str]:
    if missing := [tool for tool in X_TOOLS if shutil.which(tool) is None]:
        pytest.skip(f"no {', '.join(missing)} (apt-get install xvfb xdotool imagemagick)")
    read, write = os.pipe()
    server = subprocess.Popen(
        ["Xvfb", "-displayfd", str(write), "-screen", "0", "1024x768x24", "-nolisten", "tcp"],
        pass_fds=(write,),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    os.close(write)
    try:
        with os.fdopen(read) as fh:
            number = fh.readline().strip()  # Xvfb writes it once it accepts connections
        assert number.isdigit(), "Xvfb did not start"
        # and a client is served: a run started before that finds no display (seen once, on
        # a loaded machine: SDL fell back to its offscreen driver and the run refused)
        _poll(
            "Xvfb to serve a client",
            lambda: _x(f":{number}", "xdotool", "getdisplaygeometry") or None,
        )
        yield f":{number}"
    finally:
        server.terminate()
        server.wait(timeout=HANG_S)


def _x(display: str, *argv: str) -> str:
    """An X tool's output ("" if it fails or hangs: ``import`` grabbing a window can wait on
    the X server for ever on a loaded machine; the caller's poll then tries again)."""
    env = {**os.environ, "DISPLAY": display}
    try:
        done = subprocess.run(
            argv, env=env, capture_output=True, text=True, check=False, timeout=X_TIMEOUT_S / 4
        )
    except subprocess.TimeoutExpired:
        return ""
    return done.stdout.strip()


def test_view_in_a_real_x_window_scrubs_to_an_event_and_draws_the_traced_pose(
    rundir: Path, xdisplay: str, tmp_path: Path
) -> None:
    """``amsa-phys view`` on Xvfb, keys pressed by xdotool, the window grabbed by import:
    End then b (the last event before the end), and each rover's pixel is its colour where
    the trace puts it then (and not where it stood at t = 0)."""
    size = (800, 480)
    env = {k: v for k, v in os.environ.items() if k != "SDL_VIDEODRIVER"}
    env["DISPLAY"] = xdisplay
    # the console script, as a user runs it: X names the window's class after it
    script = Path(sys.executable).with_name("amsa-phys")
    if not script.is_file():
        pytest.skip("the amsa-phys console script is not installed next to this Python")
    argv = [str(script), "view", str(rundir), "--size", "800x480"]
    with (tmp_path / "stderr.txt").open("w") as err_file:  # a file: a full pipe would block it
        viewer = subprocess.Popen(argv, env=env, stderr=err_file, text=True)

    def said() -> str:  # what the viewer said by then, for a failure's message
        code = viewer.poll()
        text = (tmp_path / "stderr.txt").read_text()[-2000:]
        return f"viewer {'running' if code is None else f'exited {code}'}; stderr: {text!r}"

    def window_shown() -> str | None:
        found = _x(xdisplay, "xdotool", "search", "--class", "amsa-phys")
        if not found and viewer.poll() is not None:  # it ended: no window will come
            raise AssertionError(f"no window: {said()}")
        return found or None

    try:
        window = _poll("the window", window_shown, said).splitlines()[0]
        _x(xdisplay, "xdotool", "windowfocus", "--sync", window)
        # End then b lands on the same event however often it is pressed: pressed again
        # while the window does not show it yet (keys sent before the viewer listens for
        # them are lost: a loaded machine lost them once)
        keys = ["xdotool", "key", "--window", window, "End", "b"]
        _x(xdisplay, *keys)
        scene = load_run(rundir)
        target = [e for e in scene.events if e.t < scene.t[-1]][-1]
        expected = _drawn_at(scene, scene.row_at(target.t), size)
        # the slider's cursor (ink) stands at the event's time, no longer at the start
        span = float(scene.t[-1] - scene.t[0])
        bar_y = size[1] - SLIDER_H + 10 + (SLIDER_H - 20) // 2
        cursor = (round(12 + (target.t - float(scene.t[0])) / span * (size[0] - 24)), bar_y)
        shot = tmp_path / "shot.png"

        looks = [0]

        def matches() -> bool | None:
            looks[0] += 1
            if looks[0] % 10 == 0:
                _x(xdisplay, *keys)
            _x(xdisplay, "import", "-window", window, str(shot))
            if not shot.is_file():
                return None
            image = pygame.image.load(str(shot))
            ok = all(tuple(image.get_at(px))[:3] == colour for px, colour in expected)
            return True if ok and tuple(image.get_at(cursor))[:3] == INK else None

        _poll(f"the rovers and the slider at t = {target.t:g} s in the real window", matches, said)
        image = pygame.image.load(str(shot))
        assert tuple(image.get_at((12, bar_y)))[:3] != INK  # the cursor left the start
    finally:
        viewer.terminate()
        viewer.wait(timeout=HANG_S)


def _drawn_at(
    scene: object, row: int, size: tuple[int, int]
) -> list[tuple[tuple[int, int], tuple[int, int, int]]]:
    """Where the paused player draws each rover's centre after End then b (at ``row``), and
    in which colour: the same player, headless, given the same keys (the camera frames the
    rovers under its HUD, which then holds the jump's notice; in fit mode it settles at once
    while paused)."""
    player = Player(scene, title="model", size=size)  # type: ignore[arg-type]
    player.step(player.scene.rows)
    player.jump(-1)
    assert player.row == row
    player.frame(0.0)
    out = []
    for r in player.scene.frame(row).rovers:
        x, y = player.camera.to_screen(r.x, r.y)
        out.append(((round(x), round(y)), rover_colour(r.index)))
    return out


def test_lost_fixes_are_found_whatever_the_gps_timer_phase(tmp_path: Path) -> None:
    """A GPS whose timer is shifted (``phase: 0.1``: samples at 0.1, 0.35, ... s) loses the
    same samples in the trace as in the running component: the losses are counted from the
    fixes themselves, not from a grid of multiples of the period."""
    world = (ROOT / "worlds" / "mde_challenge.yaml").read_text()
    shifted = world.replace(
        "    template: GPS\n    freq: 4\n", "    template: GPS\n    freq: 4\n    phase: 0.1\n", 1
    )
    assert shifted != world
    (tmp_path / "w.yaml").write_text(shifted)
    text = SCENARIO.read_text().replace("../../worlds/mde_challenge.yaml", str(tmp_path / "w.yaml"))
    (tmp_path / "s.yaml").write_text(text)
    scenario = load_scenario(tmp_path / "s.yaml", ["LeaderGPS.lostDataGPS=30"], duration=30)
    live: dict[str, int] = {}

    def drive(sim, scenario, recorder):  # type: ignore[no-untyped-def]
        scene = Scene(sim, scenario.quality)
        sim.advance(sim.grid.ticks(sim.duration))
        live.update({g.path: g.lost_total for g in scene.gps})

    out = tmp_path / "run"
    out.mkdir()
    run_scenario(scenario, out, window=drive, plot=False)
    replay = load_run(out)
    assert live["LeaderGPS"] > 10
    assert {g.path: g.lost_total for g in replay.frame(replay.rows - 1).gps} == live


def test_replayed_ground_changes_when_the_live_one_did(tmp_path: Path) -> None:
    """A mud zone whose friction the timeline changes at 5 s: the replay draws the zone with
    the values the live window showed before and after."""
    world = (ROOT / "worlds" / "mde_challenge.yaml").read_text()
    mud = (
        "components:\n  Mud:\n    template: frictionZone\n"
        "    params: {friction: 0.45, rollingResistance: 0.05,"
        " polygon: [[20, -5], [25, -5], [25, 5], [20, 5]]}\n"
    )
    (tmp_path / "w.yaml").write_text(world.replace("components:\n", mud, 1))
    (tmp_path / "s.yaml").write_text(
        f"world: {tmp_path / 'w.yaml'}\nduration: 8\nseed: 1\n"
        "timeline:\n  - {at: 5, set: {Mud.friction: 0.1}}\n"
    )
    scenario = load_scenario(tmp_path / "s.yaml")
    live: dict[float, list[tuple[str, float, float]]] = {}

    def drive(sim, scenario, recorder):  # type: ignore[no-untyped-def]
        scene = Scene(sim, scenario.quality)
        for t in (3, 8):
            sim.advance(sim.grid.ticks(sim.duration * t // 8))
            live[t] = [(z.name, z.friction, z.rolling_resistance) for z in scene.zones()]

    out = tmp_path / "run"
    out.mkdir()
    run_scenario(scenario, out, window=drive, plot=False)
    replay = load_run(out)
    for t, zones in live.items():
        shown = replay.frame(replay.row_at(t)).zones
        assert [(z.name, z.friction, z.rolling_resistance) for z in shown] == zones
    assert live[3] != live[8]  # the change happened
    assert replay.frame(0).zones[0].polygon == ((20, -5), (25, -5), (25, 5), (20, 5))


def test_a_run_quit_from_a_real_window_says_in_its_plots_where_it_was_cut(
    xdisplay: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``amsa-phys run`` in a window on Xvfb, q pressed by xdotool once the run has logged
    a few instants: exit 0, ``metrics.json`` says it was closed in the window, both plots
    are written, and their titles say where the 500 s scenario was cut (issue 30, 8)."""
    from amsa_phys.plots import distance, trajectory

    env = {k: v for k, v in os.environ.items() if k != "SDL_VIDEODRIVER"}
    env["DISPLAY"] = xdisplay
    script = Path(sys.executable).with_name("amsa-phys")
    if not script.is_file():
        pytest.skip("the amsa-phys console script is not installed next to this Python")
    out = tmp_path / "run"
    argv = [str(script), "run", str(SCENARIO), "--out", str(out), "-q"]
    # stderr to a file, never a pipe nobody reads while the run goes on (a full pipe would
    # freeze the run in its window), and said in full if anything goes wrong
    err_path = tmp_path / "stderr.txt"
    with err_path.open("w") as err_file:
        runner = subprocess.Popen(argv, env=env, stderr=err_file, text=True)

    def said() -> str:
        return f"the run's exit {runner.poll()}, its stderr: {err_path.read_text()!r}"

    def alive() -> None:
        if runner.poll() is not None:
            raise AssertionError(f"the run ended before q was pressed: {said()}")

    try:

        def found() -> str | None:
            alive()
            return _x(xdisplay, "xdotool", "search", "--class", "amsa-phys") or None

        window = _poll("the window", found, said).splitlines()[0]
        shots = [tmp_path / "a.png", tmp_path / "b.png"]

        def moving() -> bool | None:  # two grabs differ: the clock and the rovers advance
            alive()
            for shot in shots:  # a grab that fails leaves no file: never compare a stale one
                shot.unlink(missing_ok=True)
                _x(xdisplay, "import", "-window", window, str(shot))
            if not all(shot.is_file() for shot in shots):
                return None
            a, b = (pygame.image.tobytes(pygame.image.load(str(s)), "RGB") for s in shots)
            return True if a != b else None

        _poll("the run to advance in its window", moving, said)
        _x(xdisplay, "xdotool", "key", "--window", window, "q")
        runner.wait(timeout=X_TIMEOUT_S)
    finally:
        if runner.poll() is None:
            runner.terminate()
            runner.wait(timeout=HANG_S)
    assert runner.returncode == 0, said()
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["status"].startswith("closed in the window at t=")
    ran = metrics["simulated"]
    assert 0 < ran < 500
    assert (out / "distance.png").is_file()
    assert (out / "trajectory.png").is_file()
    titles: list[str] = []

    def keep_title(fig: object, path: Path, **kw: object) -> Path:
        titles.append(fig.axes[0].get_title())  # type: ignore[attr-defined]
        return path

    monkeypatch.setattr(distance, "save_png", keep_title)
    monkeypatch.setattr(trajectory, "save_png", keep_title)
    distance.plot_distance(out / "trace.csv", metrics, tmp_path / "d.png")
    trajectory.plot_trajectory(out / "trace.csv", metrics, tmp_path / "t.png")
    cut = f" — cut at {ran:g} s of 500 s (closed in the window)"
    assert len(titles) == 2
    assert all(title.endswith(cut) for title in titles), titles


def test_hud_shows_the_value_in_force_after_a_change_inside_a_phase(tmp_path: Path) -> None:
    """A timeline step with ``new_phase: false`` changes Kv inside phase 0: from then on the
    live window's HUD and the replay's say the new value and when it landed, never the
    phase's old one (a stale HUD showed Kv=0.35 at t = 40 s after Kv=0.15 at 20 s)."""
    world = (Path(__file__).resolve().parents[2] / "worlds" / "mde_challenge.yaml").as_posix()
    scen = tmp_path / "inside.yaml"
    scen.write_text(
        f"world: {world}\nduration: 40\nseed: 1\n"
        "set: {MyFollowerController.Kv: 0.35}\n"
        "timeline:\n  - {at: 20, set: {MyFollowerController.Kv: 0.15}, new_phase: false}\n"
    )
    from amsa_phys.engine.runner import Simulation
    from amsa_phys.view.scene import describe_phase

    sim = Simulation.from_scenario(load_scenario(scen))
    sim.initialize()
    sim.advance(sim.grid.ticks(10))
    assert describe_phase(sim).endswith(": Kv=0.35")
    sim.advance(sim.grid.ticks(30))
    line = describe_phase(sim)
    assert "Kv=0.15 at 20.0 s" in line
    assert "Kv=0.35" not in line
    out = tmp_path / "run"
    assert main(["run", str(scen), "--headless", "-q", "--no-plot", "--out", str(out)]) == 0
    p = Player(load_run(out), title="test", size=(640, 360))
    early = p.scene.frame(int(np.searchsorted(p.scene.t, 10.0))).phase_text
    late = p.scene.frame(len(p.scene.t) - 1).phase_text
    assert early.endswith(": Kv=0.35")
    assert "Kv=0.15 at 20.0 s" in late
    assert "Kv=0.35" not in late


def test_the_slider_marks_speak_the_palettes_language(tmp_path: Path) -> None:
    """A live change was a grey line with a red core on the slider (two events: the phase's
    change and the run's ``live change`` event, the second drawn as an alert). Now each
    change is one event and one grey mark, phase starts grey lines, and red is only for
    alerts (here lost fixes): no red where the timeline changed."""
    from amsa_phys.palette import ALERT, PHASE
    from amsa_phys.view.window import Window

    world = ROOT / "worlds" / "mde_challenge.yaml"
    path = tmp_path / "s.yaml"
    path.write_text(
        f"world: {world}\nduration: 12\nseed: 1\n"
        "quality: {signal: MyDistanceMonitor.distanceFollowerToLeader, reference: 15}\n"
        "set: {LeaderGPS.lostDataGPS: 30}\n"
        "timeline:\n  - {at: 6, set: {MyFollowerController.Kv: 0.15}}\n"
        "  - {at: 9, set: {MyFollowerController.Kv: 0.1}, new_phase: false}\n"
    )

    def live_change_at_two_seconds(sim, scenario, rec):  # type: ignore[no-untyped-def]
        w = Window(sim, scenario.quality, size=(320, 240))
        while sim.now < 2:
            w.frame(0.1)
        press(pygame.K_p)
        w.frame(0.0)
        while w.panel.row.key != "MyFollowerController.Kv":
            press(pygame.K_DOWN)
            w.frame(0.0)
        for ch in "0.2":
            press(pygame.K_PERIOD if ch == "." else ord(ch), text=ch)
        press(pygame.K_RETURN)
        w.frame(0.0)
        while not w.finished:
            w.frame(0.5)

    out = tmp_path / "session"
    out.mkdir()
    run_scenario(load_scenario(path), out, window=live_change_at_two_seconds, plot=False)
    scene = load_run(out)
    timeline = [e for e in scene.events if e.kind not in ("lost fix",)]
    assert [(e.kind, e.text.split(":")[0]) for e in timeline] == [
        ("change", "live change"),
        ("phase", "phase 1"),
        ("change", "change"),
    ]
    assert any(e.kind == "lost fix" for e in scene.events)
    p = Player(scene, title="test", size=(800, 480))
    p.seek(float(scene.t[-1]))  # the cursor out of the way, at the end
    p.frame(0.0)
    bar = p.slider

    def colours(x: int, rows: range) -> set[tuple[int, int, int]]:
        return {tuple(p.screen.get_at((c, y)))[:3] for c in (x - 1, x, x + 1) for y in rows}

    upper = range(bar.top - 4, bar.centery - 1)  # where no lost fix or collision reaches
    for e in timeline:
        seen = colours(p.slider_x(e.t), upper)
        assert PHASE in seen, e
        assert ALERT not in seen, e  # the timeline is never drawn as an alert
    # a phase start crosses the bar; a change inside a phase stops at its middle
    lower = range(bar.centery + 2, bar.bottom + 3)
    phase_x = p.slider_x(timeline[1].t)
    assert PHASE in colours(phase_x, lower)
    assert PHASE not in colours(p.slider_x(timeline[2].t), lower)
    lost = next(e for e in scene.events if e.kind == "lost fix")
    assert ALERT in colours(p.slider_x(lost.t), range(bar.top, bar.bottom))
