"""``amsa-phys run --headless``: the run directory, determinism, summary, overrides."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
import yaml
from deadlines import HANG_S

from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO1 = ROOT / "tests" / "fixtures" / "mde_short.yaml"  # scenario1 minus expectations


def run_argv(out: Path, *extra: str) -> list[str]:
    """``amsa-phys run`` of the short scenario for 30 s into ``out``."""
    return [
        "run",
        str(SCENARIO1),
        "--headless",
        "--out",
        str(out),
        "--duration",
        "30",
        "-q",
        *extra,
    ]


def run(tmp_path: Path, name: str, *extra: str) -> Path:
    out = tmp_path / name
    assert main(run_argv(out, *extra)) == 0
    return out


def test_run_writes_the_run_directory(tmp_path: Path) -> None:
    out = run(tmp_path, "a")
    assert sorted(p.name for p in out.iterdir()) == [
        ".amsa-phys-run",
        "distance.png",
        "metrics.json",
        "scenario.yaml",
        "trace.csv",
        "trajectory.png",
    ]
    header = (out / "trace.csv").read_text().splitlines()[0].split(",")
    assert header[0] == "t"
    assert "MyDistanceMonitor.distanceFollowerToLeader" in header
    assert "LeaderGPS.gpsPosX" in header
    assert "Follower.posX" in header
    rows = (out / "trace.csv").read_text().splitlines()[1:]
    assert len(rows) == 30 * 20 + 1  # 20 Hz, both ends
    metrics = json.loads((out / "metrics.json").read_text())
    for key in (
        "max_distance",
        "min_distance",
        "mean_error",
        "rms_error",
        "settling_time",
        "collisions",
    ):
        assert key in metrics["overall"]
        assert key in metrics["phases"][0]
    assert metrics["seed"] == 1
    assert metrics["duration"] == 30.0
    assert (out / "distance.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_same_seed_gives_byte_identical_traces(tmp_path: Path) -> None:
    a, b = run(tmp_path, "a"), run(tmp_path, "b")
    assert (a / "trace.csv").read_bytes() == (b / "trace.csv").read_bytes()


def test_identical_in_another_process_with_another_hash_seed(tmp_path: Path) -> None:
    a = run(tmp_path, "a")
    out = tmp_path / "sub"
    env = {**os.environ, "PYTHONHASHSEED": "12345"}
    subprocess.run(
        [sys.executable, "-m", "amsa_phys", *run_argv(out, "--no-plot")], check=True, env=env
    )
    assert (a / "trace.csv").read_bytes() == (out / "trace.csv").read_bytes()


def test_a_different_seed_changes_a_noisy_run(tmp_path: Path) -> None:
    a = run(tmp_path, "a", "--set", "LeaderGPS.noise=0.5")
    b = run(tmp_path, "b", "--set", "LeaderGPS.noise=0.5", "--seed", "2")
    assert (a / "trace.csv").read_bytes() != (b / "trace.csv").read_bytes()


def test_resolved_scenario_replays_exactly(tmp_path: Path) -> None:
    a = run(tmp_path, "a", "--set", "MyFollowerController.Kv=0.2")
    replay = tmp_path / "replay"
    assert main(["run", str(a / "scenario.yaml"), "--headless", "--out", str(replay), "-q"]) == 0
    assert (a / "trace.csv").read_bytes() == (replay / "trace.csv").read_bytes()
    resolved = yaml.safe_load((a / "scenario.yaml").read_text())
    assert resolved["world"]["components"]["Follower"]["params"]["mass"] == 30.0
    assert resolved["set"]["MyFollowerController.Kv"] == 0.2


def test_existing_out_dir_is_not_overwritten_without_force(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = run(tmp_path, "a")
    before = (out / "trace.csv").read_bytes()
    code = main(["run", str(SCENARIO1), "--headless", "--out", str(out), "-q"])
    assert code == 2
    assert (
        "directory exists and is not empty (use --force to replace it)" in capsys.readouterr().err
    )
    assert (out / "trace.csv").read_bytes() == before
    run(tmp_path, "a", "--force")


def test_summary_table_is_printed(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    main(["run", str(SCENARIO1), "--headless", "--out", str(tmp_path / "x"), "--duration", "10"])
    out = capsys.readouterr().out
    assert out.splitlines()[0].split()[:5] == ["phase", "start", "max", "max", "after"]
    assert "real time" in out


def test_shipped_scenarios_meet_their_expectations(tmp_path: Path) -> None:
    for name in ("scenario1", "scenario2"):
        path = ROOT / "scenarios" / f"{name}.yaml"
        assert (
            main(["run", str(path), "--headless", "--out", str(tmp_path / name), "-q", "--no-plot"])
            == 0
        )


def test_validate_describe_templates(capsys: pytest.CaptureFixture[str]) -> None:
    shipped = ROOT / "scenarios" / "scenario1.yaml"
    assert main(["validate", str(shipped), str(ROOT / "worlds" / "mde_challenge.yaml")]) == 0
    assert main(["describe", str(shipped)]) == 0
    text = capsys.readouterr().out
    assert "MyFollowerController: FollowerController (controller) at 4 Hz, latency 0.75 s" in text
    assert "Kv = 0.35 1/m  [0, 10]" in text or "Kv = 0.05 1/m  [0, 10]" in text
    assert (
        "execution order at a shared instant: Leader -> Follower -> LeaderGPS -> FollowerGPS"
        " -> FollowerCompass -> MyDistanceMonitor -> MyFollowerController -> MyNormalizePower"
    ) in text
    assert "loop timing: outputs of MyFollowerController reach their readers after" in text
    assert "expect rms_error (phase 0) above 2\nexpect settling_time (phase 3) below 60\n" in text
    assert main(["templates"]) == 0
    text = capsys.readouterr().out
    # the keys every Leaf takes besides its parameters, loop timing included
    assert "    latency: s = 0  its outputs reach their readers this long after its step" in text
    for name in (
        "freeRobot (environment)",
        "controlledRobot (process)",
        "GPS (sensor)",
        "NormalizePower (actuator)",
        "FollowerController (controller)",
    ):
        assert name in text
    assert "param lostDataGPS: int = 0 % [0, 100]" in text


def test_expectations_are_checked_and_reported(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scen = tmp_path / "s.yaml"
    scen.write_text(
        f"world: {ROOT / 'worlds' / 'mde_challenge.yaml'}\nduration: 20\n"
        "quality: {signal: MyDistanceMonitor.distanceFollowerToLeader, "
        "reference: 15}\nexpect:\n  - {metric: max_distance, below: 1}\n"
        "  - {metric: min_distance, above: 1}\n"
    )
    code = main(["run", str(scen), "--headless", "--out", str(tmp_path / "o"), "-q"])
    captured = capsys.readouterr()
    assert code == 1
    # every verdict on stdout in the file's order (``run > log`` keeps the FAIL lines too);
    # stderr says once that the run failed its checks
    lines = [line for line in captured.out.splitlines() if line.startswith("expect ")]
    assert lines[0].startswith("expect max_distance = ")
    assert lines[0].endswith("below 1: FAIL")
    assert lines[1].startswith("expect min_distance = ")
    assert lines[1].endswith(": pass")
    assert captured.err == "error: 1 check of 2 failed: max_distance\n"


def test_sigint_finalises_outputs_and_exits_130(tmp_path: Path) -> None:
    import signal

    from longrun import start_long_run

    out = tmp_path / "int"
    proc = start_long_run(out, stderr=subprocess.PIPE)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=HANG_S)
    assert proc.returncode == 130
    assert "interrupted at t=" in err
    assert "Traceback" not in err
    assert not (out / "trace.csv.tmp").exists()
    rows = (out / "trace.csv").read_text().splitlines()
    assert len(rows) > 10
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["status"] == "interrupted"
    assert 0 < metrics["simulated"] < 100000


def _ignore_sigint() -> None:
    """What a shell script's ``cmd &`` does to its background job."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)


@pytest.mark.parametrize("sigint", ["default", "ignored"])
@pytest.mark.parametrize("stdout", ["terminal", "file"])
def test_sigterm_stops_on_a_whole_second_however_the_run_was_started(
    tmp_path: Path, stdout: str, sigint: str
) -> None:
    """``kill`` gives the same on a terminal and in ``amsa-phys run ... > log &`` from a
    script (stdout a file, SIGINT ignored): one line naming the instant and the directory,
    exit 130, metrics.json ``interrupted`` at a whole second, the trace up to that instant.
    With SIGINT ignored the SIGTERM used to land wherever the run was: mid-second."""
    import pty
    import re
    import signal

    from longrun import start_long_run

    out = tmp_path / "int"
    if stdout == "terminal":
        main_fd, sink = pty.openpty()
    else:
        sink = os.open(tmp_path / "stdout.txt", os.O_WRONLY | os.O_CREAT)
    pre = _ignore_sigint if sigint == "ignored" else None
    try:
        proc = start_long_run(out, stdout=sink, stderr=subprocess.PIPE, preexec_fn=pre)
    finally:
        os.close(sink)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=HANG_S)
    if stdout == "terminal":
        os.close(main_fd)
    assert proc.returncode == 130
    match = re.fullmatch(r"error: interrupted at t=(\d+)\.00 s; outputs so far are in (.*)\n", err)
    assert match, err
    assert match[2] == str(out)
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["status"] == "interrupted"
    assert metrics["simulated"] == int(match[1])  # between two simulated seconds, never in one
    last = (out / "trace.csv").read_text().rstrip("\n").rsplit("\n", 1)[-1]
    assert float(last.split(",", 1)[0]) == metrics["simulated"]
    assert sorted(p.name for p in out.iterdir() if p.name.endswith(".tmp")) == []


def test_plot_redraws_both_figures(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = run(tmp_path, "a")
    (out / "distance.png").unlink()
    (out / "trajectory.png").unlink()
    assert main(["plot", str(out)]) == 0
    assert (out / "distance.png").read_bytes()[:4] == b"\x89PNG"
    assert (out / "trajectory.png").read_bytes()[:4] == b"\x89PNG"
    assert main(["plot", str(tmp_path)]) == 2
    assert "not a run directory: trace.csv is missing" in capsys.readouterr().err
