"""Array ports (a lidar's ranges) through the engine, trace, describe, graph and templates;
the paper's parameter names beside Gazebo's; the sweep's warning when seeds cannot differ;
grouped sensors equal to one-by-one ones; the worked example's picture."""

from __future__ import annotations

import csv
import statistics
from pathlib import Path

import pytest
import toys
import yaml

from amsa_phys.cli.main import main
from amsa_phys.engine.runner import Simulation
from amsa_phys.model.scenario import load_scenario
from amsa_phys.view.scene import Scene

ROOT = Path(__file__).resolve().parent.parent.parent
COURSE = ROOT / "scenarios" / "obstacle_course.yaml"


def toy_scenario(tmp_path: Path, scanner: dict[str, object] | None = None) -> Path:
    world = {
        "components": {
            "Scan": {"template": "toys:Scanner", "freq": 2, "params": {"n": 4, **(scanner or {})}},
            "Sum": {"template": "toys:Summer", "freq": 2, "inputs": {"vals": "Scan.vals"}},
            "One": {
                "template": "toys:Sink",
                "freq": 2,
                "inputs": {"a": "Scan.vals[2]", "b": "Scan.vals[0]"},
            },
        }
    }
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump({"world": world, "duration": 2, "log_rate": 2}))
    return path


def test_an_array_port_is_one_buffer_per_element_end_to_end(tmp_path: Path) -> None:
    toys.LOG.clear()
    rows: list[list[float]] = []
    sim = Simulation.from_scenario(
        load_scenario(toy_scenario(tmp_path)), trace=lambda t, v: rows.append([t, *v])
    )
    sim.run()
    cols = sim.columns
    assert cols[:4] == [f"Scan.vals[{i}]" for i in range(4)]
    last = dict(zip(["t", *cols], rows[-1], strict=True))
    assert [last[f"Scan.vals[{i}]"] for i in range(4)] == [5.0, 6.0, 7.0, 8.0]  # step 5
    assert last["Sum.total"] == 26.0
    assert last["Sum.count"] == 4.0
    sums = [entry for entry in toys.LOG if entry[0] == "Sum"]
    assert sums[0][2]["vals"] == [1.0, 2.0, 3.0, 4.0]  # the whole array, read as numpy
    ones = [entry for entry in toys.LOG if entry[0] == "One"]
    assert ones[0][2] == {"a": 3.0, "b": 1.0}  # one element, linked as a number


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        ({"shape": 3}, "in Scan (Scanner): output vals has shape (3,), expected (4,)"),
        ({"bad": True}, "in Scan (Scanner): output vals[1] is nan"),
    ],
)
def test_a_bad_array_output_is_a_run_fault_naming_the_element(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], edit: dict[str, object], message: str
) -> None:
    code = main(
        [
            "run",
            str(toy_scenario(tmp_path, edit)),
            "--headless",
            "--no-plot",
            "-q",
            "--out",
            str(tmp_path / "out"),
        ]
    )
    assert code == 3
    assert message in capsys.readouterr().err


def test_the_obstacle_course_traces_describes_and_draws_its_lidar(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "run"
    short = tmp_path / "course.yaml"  # the course for 3 s, without its end-of-run checks
    short.write_text(f"world: {ROOT / 'worlds' / 'obstacle_course.yaml'}\nduration: 3\n")
    assert (
        main(
            [
                "run",
                str(short),
                "--headless",
                "-q",
                "--no-plot",
                "--out",
                str(out),
            ]
        )
        == 0
    )
    header = (out / "trace.csv").read_text().splitlines()[0].split(",")
    beams = [h for h in header if h.startswith("Scanner.ranges[")]
    assert beams == [f"Scanner.ranges[{i}]" for i in range(31)]
    capsys.readouterr()
    assert main(["describe", str(COURSE)]) == 0
    text = capsys.readouterr().out
    assert "-> ranges[31]" in text
    assert "<- ranges: Scanner.ranges (31 values)" in text
    assert main(["templates", "Lidar"]) == 0
    assert "out ranges[beams] [m]" in capsys.readouterr().out
    assert main(["graph", str(COURSE), "-o", str(tmp_path / "g.dot")]) == 0
    assert "ranges [31]" in (tmp_path / "g.dot").read_text()
    # the resolved scenario replays byte for byte, array and all
    again = tmp_path / "again"
    assert (
        main(
            [
                "run",
                str(out / "scenario.yaml"),
                "--headless",
                "-q",
                "--no-plot",
                "--out",
                str(again),
            ]
        )
        == 0
    )
    assert (out / "trace.csv").read_bytes() == (again / "trace.csv").read_bytes()


def test_the_window_and_video_draw_the_lidar_scan() -> None:
    sim = Simulation.from_scenario(load_scenario(COURSE, duration=2.0))
    sim.run()
    (scan,) = Scene(sim).frame().scans
    assert scan.mount == "Rover"
    assert len(scan.angles) == 31
    hits = [r for r in scan.ranges if r < scan.range_max]
    assert hits
    assert min(hits) > 5.0  # the first box is ~9 m ahead at the start


def test_no_true_distance_line_to_a_parked_rover_when_the_run_is_about_a_goal() -> None:
    """The course's quality is the distance to a goal (GoalMonitor reads one rover): a line
    "true 10.1 m" from the rover to the parked one would read as that quality. The MDE world's
    monitor reads both rovers: there the line is what the run is about."""
    course = load_scenario(COURSE, duration=0.5)
    assert not Scene(Simulation.from_scenario(course), course.quality).frame().pair_lines
    mde = load_scenario(ROOT / "scenarios" / "scenario1.yaml", duration=0.5)
    assert Scene(Simulation.from_scenario(mde), mde.quality).frame().pair_lines


def test_paper_names_work_beside_gazebo_names(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "run"
    scen = ROOT / "tests" / "golden" / "golden_degraded.yaml"  # sets LeaderGPS.noise
    assert (
        main(
            [
                "run",
                str(scen),
                "--headless",
                "-q",
                "--no-plot",
                "--duration",
                "2",
                "--set",
                "FollowerCompass.bias=0.01",
                "--out",
                str(out),
            ]
        )
        == 0
    )
    resolved = yaml.safe_load((out / "scenario.yaml").read_text())
    sets = resolved["set"]
    assert sets["LeaderGPS.stddev"] == 0.3
    assert sets["FollowerCompass.mean"] == 0.01
    capsys.readouterr()
    assert main(["templates", "GPS"]) == 0
    assert "param stddev (also noise): float = 0.0 m [0, 100]" in capsys.readouterr().out


def quiet_world(tmp_path: Path) -> Path:
    """The MDE world with perfect sensors (the paper's original, noise-free)."""
    data = yaml.safe_load((ROOT / "worlds" / "mde_challenge.yaml").read_text())
    for name in ("LeaderGPS", "FollowerGPS", "FollowerCompass"):
        data["components"][name].pop("params", None)
    (tmp_path / "quiet.yaml").write_text(yaml.safe_dump(data, sort_keys=False))
    scen = tmp_path / "sweep.yaml"
    scen.write_text(
        "world: quiet.yaml\nduration: 6\nseed: 1\n"
        "quality: {signal: MyDistanceMonitor.distanceFollowerToLeader, reference: 15}\n"
        "sweep:\n  contexts:\n    nominal: {Leader.behavior: 1}\n"
        "    random leader: {Leader.behavior: 4}\n  seeds: 2\n"
    )
    return scen


def test_sweep_warns_once_when_seeds_cannot_differ(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scen = quiet_world(tmp_path)
    assert main(["sweep", str(scen), "-j", "1", "--out", str(tmp_path / "a")]) == 0
    err = [line for line in capsys.readouterr().err.splitlines() if "warning" in line]
    assert err == [
        "warning: nothing random at 1 of 2 grid points (e.g. context=nominal: no sensor noise "
        "or loss, no random leader), so their 2 seeds give identical runs"
    ]
    with open(tmp_path / "a" / "results.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    nominal = [r["rms_error"] for r in rows if r["context"] == "nominal"]
    randomised = [r["rms_error"] for r in rows if r["context"] == "random leader"]
    assert nominal[0] == nominal[1]
    assert randomised[0] != randomised[1]


def test_no_warning_with_the_shipped_noisy_sensors(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scen = ROOT / "scenarios" / "context_sweep.yaml"
    assert (
        main(
            [
                "sweep",
                str(scen),
                "-j",
                "1",
                "--duration",
                "2",
                "--grid",
                "MyFollowerController.Kv=0.1",
                "--out",
                str(tmp_path / "a"),
            ]
        )
        == 0
    )
    assert "warning" not in capsys.readouterr().err


def test_the_obstacle_course_crosses_the_mud_slower_and_reaches_the_goal(
    tmp_path: Path,
) -> None:
    """The worked example end to end: goal reached, nothing touched, and the mud strip it
    cannot see (x 30-35 m, Crr 0.05 against the ground's 0.02) slows it to under half its
    cruise speed on firm ground, a property of the terrain, not of the avoider: the same run
    without the zone keeps its speed."""

    def crossing(drop_mud: bool) -> tuple[float, float, int]:
        out = tmp_path / ("dry" if drop_mud else "mud")
        args = ["run", str(COURSE), "--headless", "-q", "--no-plot", "--out", str(out)]
        if drop_mud:
            args += ["--set", "Mud.rollingResistance=0.02", "--set", "Mud.friction=0.8"]
        code = main(args)
        with (out / "trace.csv").open() as f:
            xv = [(float(r["Rover.posX"]), float(r["Rover.speed"])) for r in csv.DictReader(f)]
        firm = statistics.median(v for x, v in xv if 24 < x < 29)
        mud = statistics.median(v for x, v in xv if 31 < x < 34)
        return firm, mud, code

    firm, mud, code = crossing(drop_mud=False)
    assert code == 0  # the scenario's own expectations: goal within 1 m, no collision
    assert mud < 0.5 * firm
    firm_dry, mud_dry, _ = crossing(drop_mud=True)
    assert mud_dry > 0.8 * firm_dry  # mutation: ground values in the zone, no slowdown
