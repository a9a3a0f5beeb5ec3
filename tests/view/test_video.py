"""``--record``: the video decodes, has the right frames and size, and shows the rovers moving."""

from __future__ import annotations

import csv
import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import imageio_ffmpeg
import numpy as np
import pytest
import sigint
from deadlines import HANG_S

from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parent.parent.parent
WORLD = ROOT / "worlds" / "mde_challenge.yaml"


def circling_scenario(tmp_path: Path, duration: float = 20) -> Path:
    """The MDE world with the leader driving circles: the picture must turn with it."""
    path = tmp_path / "circle.yaml"
    path.write_text(
        f"world: {WORLD}\n"
        f"duration: {duration}\n"
        "seed: 3\n"
        "quality: {signal: MyDistanceMonitor.distanceFollowerToLeader, reference: 15,"
        " tolerance: 1.5}\n"
        "set: {Leader.behavior: 2, Leader.circleRadius: 8, MyFollowerController.Kv: 0.1,"
        " LeaderGPS.lostDataGPS: 30, Leader.cruisePower: 22, Leader.stallForce: 45,"
        " Leader.maxWheelTorque: 4.5, Follower.stallForce: 45, Follower.maxWheelTorque: 4.5}\n"
        # fast rovers on ordinary ground (the world's paper-calibrated ones are slow)
        "physics: {ground: {rolling_resistance: 0.02}}\n"
    )
    return path


def decode(path: Path) -> tuple[dict, list[np.ndarray]]:
    """Every frame of a video as an RGB array, with ffmpeg's metadata."""
    reader = imageio_ffmpeg.read_frames(str(path))
    meta = next(reader)
    w, h = meta["size"]
    frames = [np.frombuffer(f, np.uint8).reshape(h, w, 3) for f in reader]
    return meta, frames


def centroid(frame: np.ndarray, colour: tuple[int, int, int]) -> tuple[float, float] | None:
    """Mean pixel position of pixels near ``colour`` (a rover body's solid fill)."""
    diff = np.abs(frame.astype(int) - np.array(colour)).sum(axis=2)
    ys, xs = np.nonzero(diff < 60)
    if len(xs) < 6:
        return None
    return float(xs.mean()), float(ys.mean())


def trace_rows(path: Path) -> dict[float, dict[str, float]]:
    with path.open() as f:
        return {float(r["t"]): {k: float(v) for k, v in r.items()} for r in csv.DictReader(f)}


def test_recording_has_the_frames_the_size_and_the_motion(tmp_path: Path) -> None:
    scen = circling_scenario(tmp_path)
    video = tmp_path / "out.mp4"
    args = ["run", str(scen), "--headless", "--out", str(tmp_path / "r"), "-q"]
    args += ["--record", str(video), "--fps", "2", "--size", "640x360"]
    assert main(args) == 0
    meta, frames = decode(video)
    assert meta["codec"] == "h264"
    assert meta["pix_fmt"].startswith("yuv420p")
    assert meta["size"] == (640, 360)
    assert len(frames) == 20 * 2  # duration x fps
    metrics = json.loads((tmp_path / "r" / "metrics.json").read_text())
    assert metrics["video"]["frames"] == 40
    rows = trace_rows(tmp_path / "r" / "trace.csv")
    angles = []
    for k in range(4, 40, 3):  # frame k stands for t = k / 2 s
        row = rows[k / 2]
        leader = centroid(frames[k], (230, 120, 30))
        follower = centroid(frames[k], (31, 119, 180))
        assert leader is not None, f"leader not visible in frame {k}"
        assert follower is not None, f"follower not visible in frame {k}"
        # screen y grows downward; the camera neither rotates nor mirrors x
        seen = math.atan2(-(leader[1] - follower[1]), leader[0] - follower[0])
        true = math.atan2(
            row["Leader.posY"] - row["Follower.posY"], row["Leader.posX"] - row["Follower.posX"]
        )
        error = (seen - true + math.pi) % (2 * math.pi) - math.pi
        assert abs(math.degrees(error)) < 4, f"frame {k}: drawn at {seen:.2f}, true {true:.2f}"
        angles.append(true)
    # and the picture really turned: the leader's bearing swept over 20 degrees
    assert max(angles) - min(angles) > 0.35
    assert not np.array_equal(frames[5], frames[6])


def test_speedup_compresses_video_time(tmp_path: Path) -> None:
    scen = circling_scenario(tmp_path, duration=12)
    video = tmp_path / "fast.mp4"
    args = ["run", str(scen), "--headless", "--out", str(tmp_path / "r"), "-q", "--no-plot"]
    args += ["--record", str(video), "--fps", "10", "--size", "320x240", "--speedup", "4"]
    assert main(args) == 0
    meta, frames = decode(video)
    assert len(frames) == 12 * 10 // 4
    assert meta["fps"] == 10


def test_gif_recording_plays(tmp_path: Path) -> None:
    scen = circling_scenario(tmp_path, duration=3)
    video = tmp_path / "clip.gif"
    args = ["run", str(scen), "--headless", "--out", str(tmp_path / "r"), "-q", "--no-plot"]
    args += ["--record", str(video), "--fps", "5", "--size", "320x240"]
    assert main(args) == 0
    assert video.read_bytes()[:6] == b"GIF89a"
    meta, frames = decode(video)
    assert len(frames) == 15
    assert meta["size"] == (320, 240)


@pytest.mark.parametrize(
    ("flag", "value", "message"),
    [
        ("--size", "641x360", "--size: 641x360: width and height must be even"),
        ("--size", "big", "--size: expected WIDTHxHEIGHT"),
        ("--fps", "0", "--fps: 0: frames per second must be 1..240"),
        ("--speedup", "-2", "--speedup: -2: must be above 0"),
    ],
)
def test_bad_recording_options_are_refused_before_running(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], flag: str, value: str, message: str
) -> None:
    scen = circling_scenario(tmp_path, duration=3)
    out = tmp_path / "r"
    args = ["run", str(scen), "--headless", "--out", str(out), "--record", str(tmp_path / "v.mp4")]
    assert main([*args, flag, value]) == 2
    err = capsys.readouterr().err
    assert message in err
    assert len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_record_target_problems_are_one_line_errors(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scen = circling_scenario(tmp_path, duration=3)
    base = ["run", str(scen), "--headless", "--out", str(tmp_path / "r")]
    assert main([*base, "--record", str(tmp_path / "v.avi")]) == 2
    assert "--record: unknown format '.avi'; use .mp4 or .gif" in capsys.readouterr().err
    assert main([*base, "--record", str(tmp_path / "nowhere" / "v.mp4")]) == 2
    assert "--record: directory does not exist" in capsys.readouterr().err
    existing = tmp_path / "old.mp4"
    existing.write_bytes(b"keep me")
    assert main([*base, "--record", str(existing)]) == 2
    assert "file exists (use --force to replace it)" in capsys.readouterr().err
    assert existing.read_bytes() == b"keep me"


def test_encoder_failure_is_a_fault_with_outputs_kept(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    import amsa_phys.view.encoder as encoder

    monkeypatch.setattr(encoder, "ffmpeg_exe", lambda: "/bin/false")
    scen = circling_scenario(tmp_path, duration=5)
    out = tmp_path / "r"
    args = ["run", str(scen), "--headless", "--out", str(out), "-q", "--no-plot"]
    assert main([*args, "--record", str(tmp_path / "v.mp4")]) == 3
    err = capsys.readouterr().err
    assert "in recorder: ffmpeg failed writing" in err
    assert len(err.strip().splitlines()) == 1
    assert (out / "trace.csv").exists()
    assert (out / "metrics.json").exists()
    assert not (tmp_path / "v.mp4").exists()


def test_ctrl_c_during_a_recording_leaves_a_playable_video(tmp_path: Path) -> None:
    """SIGINT to the whole process group, as a terminal's Ctrl-C does."""
    scen = circling_scenario(tmp_path, duration=600)
    video = tmp_path / "long.mp4"
    out = tmp_path / "r"
    env = {**os.environ, "SDL_VIDEODRIVER": "dummy", "PYTHONUNBUFFERED": "1"}
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "amsa_phys",
            "run",
            str(scen),
            "--headless",
            "--out",
            str(out),
            "-q",
            "--no-plot",
            "--record",
            str(video),
            "--size",
            "320x240",
        ],
        env=env,
        start_new_session=True,  # its own group, so killpg does not hit pytest
        preexec_fn=sigint.at_default,
        stderr=subprocess.PIPE,
        text=True,
    )
    tmp = video.with_name(video.name + ".tmp")
    deadline = time.monotonic() + HANG_S
    try:
        while not (tmp.exists() and tmp.stat().st_size > 20_000):
            assert proc.poll() is None, proc.stderr.read() if proc.stderr else ""
            assert time.monotonic() < deadline, "recording never started"
            time.sleep(0.05)
        os.killpg(proc.pid, signal.SIGINT)
        _, err = proc.communicate(timeout=HANG_S)
    finally:  # a failed or hung run must not outlive the test (its ffmpeg follows it)
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    assert proc.returncode == 130, err
    assert not tmp.exists()
    _, frames = decode(video)
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["status"] == "interrupted"
    assert len(frames) == metrics["video"]["frames"] > 0
    assert metrics["simulated"] < 600
