"""The live window's status box says what the video is doing: recording while the run goes,
no frames while paused (frames follow simulated time), and, once the run has finished, that
the file is saved when the window closes (it is written as FILE.tmp until then), not
"recording" over a run that records nothing more."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

from amsa_phys.engine.runner import Simulation
from amsa_phys.model.scenario import load_scenario
from amsa_phys.view.window import Window

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO = ROOT / "tests" / "fixtures" / "mde_short.yaml"


def test_the_status_box_says_what_the_video_is_doing() -> None:
    scenario = load_scenario(SCENARIO, duration=2)
    sim = Simulation.from_scenario(scenario)
    sim.initialize()
    w = Window(sim, scenario.quality, size=(640, 360))
    assert all("video" not in line and "recording" not in line for line in w.status())
    # what the status box reads of a recorder: its file's name (no encoder needed here)
    w.recorder = SimpleNamespace(options=SimpleNamespace(path=Path("/tmp/run.mp4")))
    w.paused = False
    assert w.status()[-1] == "recording run.mp4"
    w.paused = True
    assert w.status()[-1] == "recording run.mp4 (paused: no frames)"
    while not w.finished:  # the run to its end
        w.paused = False
        w.frame(1.0)
    assert w.status()[0].startswith("finished")
    assert w.status()[-1] == "video run.mp4: saved when closed"
