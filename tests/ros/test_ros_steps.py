"""Changes inside a phase (``new_phase: false``) under ROS: applied at their instant, in lockstep.

A window session with a live change writes its resolved ``scenario.yaml`` with the change as
a ``new_phase: false`` entry; replaying that file under ROS must run the change, not the
value the parameter server held before it. Both a file's entry and a window session's live
change are compared byte for byte with the in-process run (trace.csv) and judged by
``rosrun PKG run_lockstep``. Skipped, with the reason, where ROS, catkin, unshare or root is
missing.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest
import ros_launch
import yaml
from ros_launch import Launch, build_workspace, package_edit, ros_missing
from windowdrive import live_change

from amsa_phys.cli.main import main
from amsa_phys.model.scenario import load_scenario
from amsa_phys.runs.single import run_scenario

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO = ROOT / "tests" / "fixtures" / "ros_steps.yaml"  # built in the background (conftest)
PKG = "mdeChallenge"

pytestmark = [
    pytest.mark.ros,
    pytest.mark.skipif(ros_missing() is not None, reason=str(ros_missing())),
]
launcher = ros_launch.launcher  # the fixture


@pytest.fixture(scope="module")
def workspace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The fixture exported and built once (resolved: the build may be a link)."""
    return build_workspace(tmp_path_factory.mktemp("ros_steps_ws"), SCENARIO, PKG).resolve()


@pytest.fixture(scope="module")
def checked(workspace: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A directory whose ``launch.sh`` runs ``rosrun PKG run_lockstep`` on the build."""
    return ros_launch.run_lockstep_dir(workspace, PKG, tmp_path_factory.mktemp("checked"))


def _rows(run_dir: Path) -> list[str]:
    return (run_dir / "trace.csv").read_text().splitlines()


def _first_difference(ros: Path, ref: Path) -> str:
    """Where two traces part (time and column), for a failing assertion's message."""
    mine, theirs = _rows(ros), _rows(ref)
    header = mine[0].split(",")
    for a, b in zip(mine[1:], theirs[1:], strict=False):
        if a != b:
            for name, x, y in zip(header, a.split(","), b.split(","), strict=False):
                if x != y:
                    return f"t = {a.split(',')[0]} s: {name} {x} under ROS, {y} in process"
    return f"{len(mine)} rows under ROS, {len(theirs)} in process"


def _lockstep(checked: Path, launcher: Callable[..., Launch], out: Path) -> str:
    launch = launcher(checked, "ros_steps", f"out:={out}", "plots:=false")
    text = launch.finish()
    assert launch.proc.returncode == 0, text[-3000:]
    assert "run_lockstep: pass" in text, text[-3000:]
    return text


def test_a_change_inside_a_phase_runs_under_ros_as_in_process(
    checked: Path, launcher: Callable[..., Launch], tmp_path: Path
) -> None:
    """The file's ``{at: 40, set: {Kv: 0.15}, new_phase: false}`` lands at 40 s under ROS:
    before, the scenario node applied phase starts only and the follower kept Kv = 0.35."""
    ref = tmp_path / "ref"
    argv = ["run", str(SCENARIO), "--headless", "--out", str(ref), "-q", "--no-plot"]
    assert main(argv) == 0
    out = tmp_path / "ros"
    _lockstep(checked, launcher, out)
    assert _rows(out) == _rows(ref), _first_difference(out, ref)


#: run to 60 s, set MyFollowerController.Kv = 0.1 in the panel, run at x8 to the end
live_change_at_sixty_seconds = live_change("MyFollowerController.Kv", "0.1", at=60, faster=3)


def test_a_live_change_from_the_window_replays_under_ros(
    workspace: Path, checked: Path, launcher: Callable[..., Launch], tmp_path: Path
) -> None:
    """A window session's ``scenario.yaml`` (the file's step and the live change, both
    ``new_phase: false``) put in the package runs the session's trace under ROS."""
    session = tmp_path / "session"
    session.mkdir()
    run_scenario(load_scenario(SCENARIO), session, window=live_change_at_sixty_seconds, plot=False)
    resolved = (session / "scenario.yaml").read_text()
    doc = yaml.safe_load(resolved)
    assert [e.get("new_phase", True) for e in doc["timeline"]] == [False, False]
    assert doc["timeline"][1]["set"] == {"MyFollowerController.Kv": 0.1}
    scenario_file = workspace / "src" / PKG / "config" / "ros_steps.yaml"
    assert scenario_file.exists()
    out = tmp_path / "ros"
    with package_edit(scenario_file, resolved):
        _lockstep(checked, launcher, out)
    assert _rows(out) == _rows(session), _first_difference(out, session)
