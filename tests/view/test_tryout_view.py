"""What a new user's tryout found in the window, the replay and the CLI (polish2's list):
each test here failed on the code before its fix."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from amsa_phys.cli.main import main
from amsa_phys.cli.view import load_run
from amsa_phys.engine.runner import Simulation
from amsa_phys.model.scenario import load_scenario
from amsa_phys.view.pg import pygame
from amsa_phys.view.player import Player
from amsa_phys.view.scene import describe_phase
from amsa_phys.view.window import Window

ROOT = Path(__file__).resolve().parent.parent.parent
WORLD = (ROOT / "worlds" / "mde_challenge.yaml").as_posix()


def press(key: int, text: str = "", mod: int = 0) -> None:
    pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=key, mod=mod, unicode=text))


def scenario(tmp_path: Path, quality: str, extra: str = "", duration: float = 6) -> Path:
    path = tmp_path / "s.yaml"
    path.write_text(
        f"world: {WORLD}\nduration: {duration}\nseed: 1\nquality: {quality}\n"
        "set: {Leader.behavior: 1, MyFollowerController.Kv: 0.35}\n" + extra
    )
    return path


def test_a_huge_legal_reference_draws_instead_of_crashing(tmp_path: Path) -> None:
    """``reference: 1.0e+308`` is legal: ``(v - reference) ** 2`` raised OverflowError in the
    scene's live metrics (snapshot, video, window) and the HUD printed a 309-digit error."""
    huge = (
        "{signal: MyDistanceMonitor.distanceFollowerToLeader, reference: 1.0e+308, tolerance: 1.5}"
    )
    scen = scenario(tmp_path, huge)
    out, png = tmp_path / "run", tmp_path / "snap.png"
    argv = ["run", str(scen), "--headless", "-q", "--no-plot", "--out", str(out)]
    assert main([*argv, "--snapshot", str(png)]) == 0
    assert png.stat().st_size > 0
    sim = Simulation.from_scenario(load_scenario(scen))
    sim.initialize()
    w = Window(sim, load_scenario(scen).quality, size=(800, 450))
    sim.advance(sim.grid.ticks(2))
    w.frame(0.0)
    hud = "\n".join(w.renderer.texts["hud"])
    assert "ref 1e+308" in hud
    assert "error -1e+308 m" in hud
    assert "rms error overflow m" in hud  # metrics.json writes it null, listed as nonfinite
    assert max(len(line) for line in hud.splitlines()) < 120
    p = Player(load_run(out), title="test", size=(640, 360))
    p.frame(0.0)
    assert "error -1e+308 m" in "\n".join(p.renderer.texts["hud"])
    # distance.png still plots the signal (it said "no quality signal")
    from amsa_phys.plots.distance import distance_figure

    metrics = json.loads((out / "metrics.json").read_text())
    labels = distance_figure(out / "trace.csv", metrics).axes[0].get_legend_handles_labels()[1]
    assert labels == [
        "reference 1e+308 m (off the scale)",
        "MyDistanceMonitor.distanceFollowerToLeader",
    ]


QUALITY = "{signal: MyDistanceMonitor.distanceFollowerToLeader, reference: 15, tolerance: 1.5}"


def test_a_parameter_value_is_spelt_alike_in_the_table_the_hud_and_the_replay(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``cruisePower=9.0`` in the run's table and the replay's HUD, ``9`` in the live HUD,
    and ``:g`` rounded 0.1234567 to 0.123457 there: one spelling, every digit, no ``.0``."""
    extra = (
        "timeline:\n"
        "  - {at: 3, set: {Leader.cruisePower: 9.0, MyFollowerController.Kv: 0.1234567}}\n"
    )
    scen = scenario(tmp_path, QUALITY, extra)
    out = tmp_path / "run"
    assert main(["run", str(scen), "--headless", "--no-plot", "--out", str(out)]) == 0
    table = capsys.readouterr().out
    assert "Leader.cruisePower=9, MyFollowerController.Kv=0.1234567" in table
    sim = Simulation.from_scenario(load_scenario(scen))
    sim.initialize()
    sim.advance(sim.grid.ticks(4))
    live = describe_phase(sim)
    assert live.endswith("from 3 s: cruisePower=9, Kv=0.1234567")
    p = Player(load_run(out), title="test", size=(640, 360))
    replay = p.scene.frame(len(p.scene.t) - 1).phase_text
    assert replay == live
    # the window's panel spells it so too (it rounded to 6 digits: 0.123457)
    w = Window(sim, load_scenario(scen).quality, size=(640, 360))
    press(pygame.K_p)
    w.frame(0.0)
    while w.panel.row.key != "MyFollowerController.Kv":
        press(pygame.K_DOWN)
        w.frame(0.0)
    (selected,) = [line for line in w.panel.lines() if line.startswith(">")]
    assert selected.startswith("> MyFollowerController.Kv = 0.1234567 ")


def test_the_replay_hud_forgets_a_jumps_notice_and_ends_where_the_run_did(tmp_path: Path) -> None:
    """PgDn then End left ``125.00 s: phase 1: ...`` in the HUD at the run's end; a run closed
    early in the window said ``/ 200 s`` in the HUD and ``/ 4 s`` on the slider."""
    short = ROOT / "tests" / "fixtures" / "mde_short.yaml"
    out = tmp_path / "run"
    assert main(["run", str(short), "--headless", "-q", "--no-plot", "--duration", "130",
                 "--out", str(out)]) == 0  # fmt: skip
    p = Player(load_run(out), title="test", size=(800, 480))
    press(pygame.K_PAGEDOWN)
    p.frame(0.0)
    assert "125.00 s: phase 1" in "\n".join(p.renderer.texts["hud"])
    press(pygame.K_END)
    p.frame(0.0)
    assert p.t == 130.0
    hud = "\n".join(p.renderer.texts["hud"])
    assert "125.00 s" not in hud
    assert hud.startswith("t   130.00 s / 130 s\nphase 1 (of 0–1) from 125 s: Kv=0.15")

    def close_at_four_seconds(sim: Simulation, scen: object, rec: object) -> None:
        w = Window(sim, load_scenario(short).quality, size=(320, 240))
        while sim.now < 4:
            w.frame(0.1)
        press(pygame.K_ESCAPE)
        w.frame(0.1)

    from amsa_phys.runs.single import run_scenario

    early = tmp_path / "early"
    early.mkdir()
    run_scenario(
        load_scenario(short, duration=200), early, window=close_at_four_seconds, plot=False
    )
    p = Player(load_run(early), title="test", size=(800, 480))
    press(pygame.K_END)
    p.frame(0.0)
    end = p.scene.t[-1]
    assert 4 <= end < 5
    assert p.renderer.texts["hud"][0] == f"t {end:8.2f} s / {end:g} s"
    assert p.scene.duration == end  # the slider's label says the same end


def test_the_gym_frame_does_not_show_the_replaced_controllers_parameters() -> None:
    """The agent replaced MyFollowerController: its ``Kv=0.35`` acts on nothing, and the
    ``rgb_array`` HUD showed it as if it did."""
    gym = pytest.importorskip("amsa_phys.gym", reason="the gym extra is not installed")
    env = gym.FollowEnv(
        str(ROOT / "scenarios" / "scenario1.yaml"),
        duration=10,
        render_mode="rgb_array",
        render_size=(640, 360),
    )
    env.reset(seed=1)
    env.step(env.action_space.sample())
    assert env.render() is not None
    hud = env._frames.renderer.texts["hud"]
    status = env._frames.renderer.texts["status"]
    assert hud[1] == "phase 0 from 0 s: behavior=1, lostDataGPS=0, motorCoef=100"
    assert "agent: MyFollowerController" in status
    env.close()


def logged(sim: Simulation) -> dict[float, dict[str, float]]:
    """Every logged row of ``sim`` by time, as trace.csv will have it."""
    rows: dict[float, dict[str, float]] = {}
    sim.add_log_listener(lambda t, values: rows.__setitem__(t, dict(values)))
    return rows


def test_a_picture_at_a_logged_instant_shows_that_instants_sample(tmp_path: Path) -> None:
    """A video frame (and the snapshot, and the window) at t was drawn before the components
    due at t ran: its HUD showed the sample before t (21.42 m at 130.00 s where trace.csv
    has 21.14 m). Now the HUD's measured value and the drawn rovers are trace.csv's row at t;
    the trace itself is unchanged (the golden and byte-identity tests hold it)."""
    from fractions import Fraction

    from amsa_phys.view.drive import advance
    from amsa_phys.view.video import Snapshot, SnapshotOptions

    class Seen(Snapshot):
        """The snapshot, noting what it drew (the HUD's value then: the metrics live on)."""

        def write(self, t: Fraction | None = None) -> Path:
            frame = self.scene.frame(None if t is None else float(t))
            self.seen = (frame, frame.metrics.value)
            return super().write(t)

    short = ROOT / "tests" / "fixtures" / "mde_short.yaml"
    scen = load_scenario(short, duration=12)
    signal = scen.quality.signal
    for at in (Fraction(10), Fraction(21, 2)):  # the monitor runs at 4 Hz: 10 s and 10.5 s
        sim = Simulation.from_scenario(scen)
        sim.initialize()
        rows = logged(sim)
        snap = Seen(sim, SnapshotOptions(tmp_path / "s.png", (320, 240), at), scen.quality)
        advance(sim, sim.grid.ticks(at) + 100, [snap])  # on past the picture
        row = rows[float(at)]
        frame, value = snap.seen
        assert value == row[signal]
        assert rows[float(at) - 0.05][signal] != row[signal]  # the sample before differs
        for r in frame.rovers:
            assert (r.x, r.y) == (row[f"{r.name}.posX"], row[f"{r.name}.posY"])
    # the live window: the picture after an instant is that instant's row too
    sim = Simulation.from_scenario(scen)
    sim.initialize()
    rows = logged(sim)
    w = Window(sim, scen.quality, size=(320, 240))
    while sim.now < 10:
        w.frame(0.1)
    frame = w.scene.frame()
    row = rows[frame.t]
    assert w.scene.metrics.value == row[signal]
    for r in frame.rovers:
        assert (r.x, r.y) == (row[f"{r.name}.posX"], row[f"{r.name}.posY"])
