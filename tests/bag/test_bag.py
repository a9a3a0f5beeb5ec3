"""``--bag``: a run as an MCAP bag with ROS 2 encodings, read back by two libraries.

The bag is read with ``mcap`` + ``mcap-ros2-support`` (the writer's own stack) and with
``rosbags`` (an independent MCAP reader and CDR deserialiser), and checked against the
run's ``trace.csv``: every traced buffer's scalars are the trace's column, the fixes are the
GPS columns at the GPS's own instants, lost fixes are absent.
"""

from __future__ import annotations

import csv
import json
import math
import os
import signal
import subprocess
import sys
from collections import Counter, defaultdict
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import sigint
from deadlines import HANG_S
from longrun import wait_until
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore

import amsa_phys as ap
from amsa_phys.cli.main import main
from amsa_phys.stdmsgs import DEFAULT_ORIGIN, data_topic, geodetic_to_enu, quaternion_yaw

ROOT = Path(__file__).resolve().parents[2]
FIXTURE = ROOT / "tests" / "fixtures" / "mde_short.yaml"
OBSTACLES = ROOT / "scenarios" / "obstacle_course.yaml"
NS = 1_000_000_000

#: topic -> ROS 2 type of the MDE world's bag, as the README documents them
MDE_TOPICS = {
    "/amsa/events": "amsa_msgs/msg/Event",
    "/tf": "tf2_msgs/msg/TFMessage",
    "/tf_static": "tf2_msgs/msg/TFMessage",
    "/Leader/ground_truth/odom": "nav_msgs/msg/Odometry",
    "/Follower/ground_truth/odom": "nav_msgs/msg/Odometry",
    "/Follower/wheel_cmd": "sensor_msgs/msg/JointState",
    "/Leader/LeaderGPS/fix": "sensor_msgs/msg/NavSatFix",
    "/Follower/FollowerGPS/fix": "sensor_msgs/msg/NavSatFix",
    "/Follower/FollowerCompass/heading": "sensor_msgs/msg/Imu",
}


def run_with_bag(tmp_path: Path, name: str, *extra: str) -> tuple[Path, Path]:
    """``amsa-phys run`` of the short MDE scenario with ``--bag``; (run dir, bag)."""
    out, bag = tmp_path / name, tmp_path / f"{name}.mcap"
    argv = ["run", str(FIXTURE), "--headless", "--out", str(out), "--bag", str(bag)]
    argv += ["--no-plot", "-q", "--duration", "40", *extra]
    assert main(argv) == 0
    return out, bag


def read_trace(out: Path) -> tuple[list[str], np.ndarray]:
    with (out / "trace.csv").open() as fh:
        rows = list(csv.reader(fh))
    return rows[0], np.array(rows[1:], dtype=float)


def read_mcap(bag: Path) -> tuple[dict[str, str], list[tuple[str, int, Any]]]:
    """(topic -> schema name, [(topic, log_time, decoded message)]) in file order."""
    with bag.open("rb") as fh:
        reader = make_reader(fh, decoder_factories=[DecoderFactory()])
        summary = reader.get_summary()
        assert summary is not None  # finalised: MCAP's summary section is there
        types = {ch.topic: summary.schemas[ch.schema_id].name for ch in summary.channels.values()}
        msgs = [(ch.topic, m.log_time, d) for _, ch, m, d in reader.iter_decoded_messages()]
    return types, msgs


@pytest.fixture(scope="module")
def mde(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """One run with a lossy leader GPS, its trace and its bag read with mcap."""
    tmp = tmp_path_factory.mktemp("bag")
    out, bag = run_with_bag(tmp, "mde", "--set", "LeaderGPS.lostDataGPS=40")
    header, trace = read_trace(out)
    types, msgs = read_mcap(bag)
    return {"out": out, "bag": bag, "header": header, "trace": trace, "types": types, "msgs": msgs}


def test_topics_and_types_are_the_documented_ones(mde: dict[str, Any]) -> None:
    types = mde["types"]
    for topic, msg_type in MDE_TOPICS.items():
        assert types[topic] == msg_type
    scalars = {t for t, s in types.items() if s == "amsa_msgs/msg/Scalar"}
    assert scalars == {data_topic(c) for c in mde["header"][1:]}  # every traced buffer
    assert set(types) == set(MDE_TOPICS) | scalars


def test_scalars_are_the_trace(mde: dict[str, Any]) -> None:
    """Each traced buffer: one stamped scalar per trace row, the row's time and value."""
    by_topic: dict[str, list[tuple[int, int, float]]] = defaultdict(list)
    for topic, log_time, m in mde["msgs"]:
        if topic.startswith("/amsa/data/"):
            stamp = m.header.stamp.sec * NS + m.header.stamp.nanosec
            by_topic[topic].append((log_time, stamp, m.data))
    trace = mde["trace"]
    t_ns = [round(t * NS) for t in trace[:, 0]]
    for k, col in enumerate(mde["header"][1:], start=1):
        got = by_topic[data_topic(col)]
        assert [g[0] for g in got] == t_ns
        assert [g[1] for g in got] == t_ns
        assert [g[2] for g in got] == trace[:, k].tolist()  # exact: same doubles


def test_fixes_are_the_gps_at_its_instants_and_lost_ones_are_absent(mde: dict[str, Any]) -> None:
    """NavSatFix back on the plane is the trace's GPS columns at the same instant; every
    4 Hz GPS instant without a message kept the previous fix (a lost sample), and about the
    40 % asked for are lost."""
    header, trace = mde["header"], mde["trace"]
    row = {round(t * NS): i for i, t in enumerate(trace[:, 0])}
    ix, iy = header.index("LeaderGPS.gpsPosX"), header.index("LeaderGPS.gpsPosY")
    fixes = {log_time: m for topic, log_time, m in mde["msgs"] if topic == "/Leader/LeaderGPS/fix"}
    for log_time, m in fixes.items():
        x, y = geodetic_to_enu(m.latitude, m.longitude, DEFAULT_ORIGIN)
        i = row[log_time]
        assert (x, y) == pytest.approx((trace[i, ix], trace[i, iy]), abs=1e-6)
        assert m.header.stamp.sec * NS + m.header.stamp.nanosec == log_time
        assert m.status.status == 0
        assert m.position_covariance_type == 2
        assert m.position_covariance[0] > 0
    instants = [k * NS // 4 for k in range(4 * 40 + 1)]  # the GPS's 4 Hz steps
    assert set(fixes) <= set(instants)
    missing = [t for t in instants if t not in fixes]
    for t in missing[1:] if missing and missing[0] == 0 else missing:
        i = row[t]
        assert trace[i, ix] == trace[i - 5, ix]  # the fix 0.25 s (5 rows) before: stale
    assert 0.25 < len(missing) / len(instants) < 0.55  # 40 % lost, binomial n = 161


def test_poses_tf_and_wheel_commands(mde: dict[str, Any]) -> None:
    header, trace = mde["header"], mde["trace"]
    row = {round(t * NS): i for i, t in enumerate(trace[:, 0])}
    counts: Counter[str] = Counter()
    for topic, log_time, m in mde["msgs"]:
        i = row.get(log_time)
        if topic == "/Follower/ground_truth/odom":
            counts[topic] += 1
            p = m.pose.pose
            assert p.position.x == trace[i, header.index("Follower.posX")]
            assert quaternion_yaw(p.orientation) == pytest.approx(
                trace[i, header.index("Follower.heading")], abs=1e-12
            )
            assert m.twist.twist.linear.x == trace[i, header.index("Follower.speed")]
            assert (m.header.frame_id, m.child_frame_id) == ("map", "Follower/base_link")
        elif topic == "/tf":
            (tf,) = m.transforms
            robot = tf.child_frame_id.split("/")[0]
            counts[f"/tf {robot}"] += 1
            assert tf.transform.translation.y == trace[i, header.index(f"{robot}.posY")]
        elif topic == "/Follower/wheel_cmd":
            counts[topic] += 1
            assert list(m.name) == ["left_wheel_joint", "right_wheel_joint"]
            assert list(m.effort) == [
                trace[i, header.index("MyNormalizePower.normalizedPowerL")],
                trace[i, header.index("MyNormalizePower.normalizedPowerR")],
            ]
    # at each robot's own rate: the Follower at 4 Hz, the Leader at 10 Hz, over 40 s
    assert counts["/Follower/ground_truth/odom"] == 161
    assert counts["/Follower/wheel_cmd"] == 161
    assert counts["/tf Follower"] == 161
    assert counts["/tf Leader"] == 401


def test_events_are_the_phases(tmp_path: Path) -> None:
    _, bag = run_with_bag(tmp_path, "ph", "--duration", "130")
    _, msgs = read_mcap(bag)
    events = [(t, m.kind, m.detail) for topic, t, m in msgs if topic == "/amsa/events"]
    assert events == [
        (
            0,
            "phase",
            "phase 0 starts: Leader.behavior=1, LeaderGPS.lostDataGPS=0, "
            "MyNormalizePower.motorCoef=100, MyFollowerController.Kv=0.35",
        ),
        (125 * NS, "phase", "phase 1 starts: MyFollowerController.Kv=0.15"),
    ]


def test_an_overridden_value_is_listed_once_with_its_value(tmp_path: Path) -> None:
    """``--set`` over a file's phase-0 value: the phase's event names the value in force only."""
    _, bag = run_with_bag(tmp_path, "ov", "--duration", "10", "--set", "Leader.behavior=2")
    _, msgs = read_mcap(bag)
    (first, *_) = [m.detail for topic, _, m in msgs if topic == "/amsa/events"]
    assert first == (
        "phase 0 starts: LeaderGPS.lostDataGPS=0, MyNormalizePower.motorCoef=100, "
        "MyFollowerController.Kv=0.35, Leader.behavior=2"
    )


def test_rosbags_reads_the_same_bag(mde: dict[str, Any]) -> None:
    """An independent reader (rosbags: its own MCAP parser and CDR deserialiser) finds the
    same topics, types, message counts and values."""
    by_mcap: Counter[str] = Counter(topic for topic, _, _ in mde["msgs"])
    store = get_typestore(Stores.ROS2_HUMBLE)
    counts: Counter[str] = Counter()
    with AnyReader([mde["bag"]], default_typestore=store) as reader:
        types = {c.topic: c.msgtype for c in reader.connections}
        assert types == mde["types"]
        scalars: dict[str, list[float]] = defaultdict(list)
        for conn, _, raw in reader.messages():
            counts[conn.topic] += 1
            msg = reader.deserialize(raw, conn.msgtype)
            if conn.msgtype == "amsa_msgs/msg/Scalar":
                scalars[conn.topic].append(msg.data)
            elif conn.topic == "/Follower/FollowerGPS/fix":
                assert msg.header.frame_id == "Follower/base_link"
    assert counts == by_mcap
    col = "Follower.posX"
    k = mde["header"].index(col)
    assert scalars[data_topic(col)] == mde["trace"][:, k].tolist()


def test_same_run_same_bytes_and_the_api_writes_the_same_bag(tmp_path: Path) -> None:
    _, a = run_with_bag(tmp_path, "a")
    _, b = run_with_bag(tmp_path, "b")
    assert a.read_bytes() == b.read_bytes()
    c = tmp_path / "api.mcap"
    ap.run(FIXTURE, duration=40, bag=c)
    assert c.read_bytes() == a.read_bytes()
    _, d = run_with_bag(tmp_path, "d", "--seed", "2")
    assert d.read_bytes() != a.read_bytes()  # the seed reaches the bag


def test_another_hash_seed_gives_the_same_bag(tmp_path: Path) -> None:
    _, a = run_with_bag(tmp_path, "a", "--duration", "5")
    b = tmp_path / "b.mcap"
    env = {**os.environ, "PYTHONHASHSEED": "12345"}
    cmd = [sys.executable, "-m", "amsa_phys", "run", str(FIXTURE), "--headless", "--no-plot"]
    cmd += ["-q", "--duration", "5", "--out", str(tmp_path / "b"), "--bag", str(b)]
    subprocess.run(cmd, env=env, check=True, capture_output=True)
    assert a.read_bytes() == b.read_bytes()


def test_obstacle_course_scan_imu_odometry(tmp_path: Path) -> None:
    out, bag = tmp_path / "obs", tmp_path / "obs.mcap"
    argv = ["run", str(OBSTACLES), "--headless", "--out", str(out), "--bag", str(bag)]
    assert main([*argv, "--no-plot", "-q", "--duration", "10"]) in (0, 1)
    header, trace = read_trace(out)
    row = {round(t * NS): i for i, t in enumerate(trace[:, 0])}
    types, msgs = read_mcap(bag)
    assert types["/Rover/Scanner/scan"] == "sensor_msgs/msg/LaserScan"
    assert types["/Rover/Imu/imu"] == "sensor_msgs/msg/Imu"
    assert types["/Rover/Odometry/odom"] == "nav_msgs/msg/Odometry"
    scans = [(t, m) for topic, t, m in msgs if topic == "/Rover/Scanner/scan"]
    assert scans
    beams = [header.index(f"Scanner.ranges[{k}]") for k in range(31)]
    for t, m in scans:
        want = np.float32(trace[row[t], beams])  # float32[] in LaserScan
        want[want >= np.float32(12.0)] = np.inf  # no echo: range_max in the trace, REP 117's +inf
        assert np.array_equal(np.array(m.ranges, dtype=np.float32), want)
        assert m.range_max == 12.0
        assert m.angle_min < 0 < m.angle_max
        assert m.angle_increment == pytest.approx((m.angle_max - m.angle_min) / 30, rel=1e-6)
    # every beam is a hit inside [range_min, range_max] or +inf: none sits on the outer arc
    hits = np.concatenate([np.array(m.ranges) for _, m in scans])
    assert np.isinf(hits).any()
    assert not (hits == 12.0).any()
    assert (hits[np.isfinite(hits)] >= 0.15).all()
    imus = [(t, m) for topic, t, m in msgs if topic == "/Rover/Imu/imu"]
    assert imus
    for t, m in imus:
        assert m.angular_velocity.z == trace[row[t], header.index("Imu.gyroZ")]
        assert m.orientation_covariance[0] == -1  # REP 145: no orientation
    odo = [(t, m) for topic, t, m in msgs if topic == "/Rover/Odometry/odom"]
    for t, m in odo:
        assert m.pose.pose.position.x == trace[row[t], header.index("Odometry.odomX")]


def test_ctrl_c_leaves_a_finalised_bag(tmp_path: Path) -> None:
    """SIGINT during a long run: exit 130, the bag under its final name, indexed (summary),
    its last message at or before the instant the run stopped."""
    out, bag = tmp_path / "int", tmp_path / "int.mcap"
    cmd = [sys.executable, "-m", "amsa_phys", "run", str(FIXTURE), "--headless", "--no-plot"]
    cmd += ["-q", "--duration", "100000", "--out", str(out), "--bag", str(bag)]
    proc = subprocess.Popen(cmd, stderr=subprocess.PIPE, text=True, preexec_fn=sigint.at_default)
    try:
        tmp = bag.with_name(bag.name + ".tmp")
        wait_until(  # the event, asserted: a run that exits or hangs first fails here
            "the first 1 MiB chunk reached the bag",
            lambda: tmp.exists() and tmp.stat().st_size > 1024 * 1024,
            proc,
        )
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=HANG_S)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 130, err
    assert not bag.with_name(bag.name + ".tmp").exists()
    simulated = json.loads((out / "metrics.json").read_text())["simulated"]
    types, msgs = read_mcap(bag)
    assert types["/Leader/LeaderGPS/fix"] == "sensor_msgs/msg/NavSatFix"
    last = max(t for _, t, _ in msgs)
    assert 0 < last <= round(simulated * NS)
    rows = (out / "trace.csv").read_text().count("\n") - 1
    follower_x = [m for topic, _, m in msgs if topic == data_topic("Follower.posX")]
    assert len(follower_x) == rows  # the bag holds exactly the instants the trace does


def test_existing_bag_is_refused_without_force(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag = tmp_path / "x.mcap"
    bag.write_bytes(b"keep")
    argv = ["run", str(FIXTURE), "--headless", "--out", str(tmp_path / "o"), "--bag", str(bag)]
    assert main([*argv, "--duration", "1", "-q", "--no-plot"]) == 2
    assert "x.mcap: --bag: file exists (use --force to replace it)" in capsys.readouterr().err
    assert bag.read_bytes() == b"keep"
    assert main(["run", str(FIXTURE), "--headless", "--bag", str(tmp_path / "x.bag")]) == 2
    assert capsys.readouterr().err.endswith(
        "unknown format '.bag'; use .mcap (for a ROS 1 .bag, write the .mcap and convert it: "
        "rosbags-convert --src run.mcap --dst run.bag)\n"
    )
    with pytest.raises(ap.ConfigError, match=r"x\.mcap: bag: file exists"):
        ap.run(FIXTURE, duration=1, bag=bag)


def test_follower_track_from_the_bag(mde: dict[str, Any], tmp_path: Path) -> None:
    """A plot drawn from the bag alone: the follower's fixes and true pose, over the trace's
    true path; the bag's track is the trace's, point for point."""
    from bag_plot import plot_tracks

    tracks = plot_tracks(mde["bag"], tmp_path / "bag_plot.png")
    header, trace = mde["header"], mde["trace"]
    truth = tracks["/Follower/ground_truth/odom"]
    assert np.array_equal(truth[:, 1], trace[::5, header.index("Follower.posX")])
    fixes = tracks["/Follower/FollowerGPS/fix"]
    err = np.hypot(*(fixes[:, 1:] - truth[:, 1:]).T)
    assert err.max() < 0.2  # an RTK-class receiver: centimetres, a wandering bias
    assert (tmp_path / "bag_plot.png").read_bytes()[:4] == b"\x89PNG"
    assert math.isfinite(err.mean())


def test_ros1_bag_by_conversion(mde: dict[str, Any], tmp_path: Path) -> None:
    """``rosbags-convert`` turns the bag into a ROS 1 ``.bag`` with the same messages; where
    ROS 1 is installed its own ``rosbag info`` reads it, standard types with their md5sums."""
    convert = Path(sys.executable).with_name("rosbags-convert")
    if not convert.exists():
        pytest.skip("rosbags-convert is not installed (pip install -e '.[dev]')")
    ros1 = tmp_path / "run.bag"
    subprocess.run(
        [str(convert), "--src", str(mde["bag"]), "--dst", str(ros1)],
        check=True,
        capture_output=True,
    )
    by_mcap: Counter[str] = Counter(topic for topic, _, _ in mde["msgs"])
    with AnyReader([ros1]) as reader:
        assert reader.is2 is False
        counts = Counter(c.topic for c, _, _ in reader.messages())
    assert counts == by_mcap
    rosbag = Path("/usr/bin/rosbag")
    if not rosbag.exists():
        pytest.skip("ROS 1 is not installed: rosbag info not tried")
    env = {"PATH": "/usr/bin:/bin", "HOME": str(tmp_path), "LANG": "C.UTF-8"}
    info = subprocess.run(
        [str(rosbag), "info", "--yaml", str(ros1)],
        env=env,
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    assert "type: sensor_msgs/NavSatFix" in info
    assert "md5: 2d3a8cd499b9b4a0249fb98fd05cfa48" in info  # ROS 1's NavSatFix
    assert "topic: /Leader/LeaderGPS/fix" in info
    assert f"messages: {sum(by_mcap.values())}" in info


def test_live_changes_and_a_fault_reach_the_events(tmp_path: Path) -> None:
    """A change made in a (scripted) window session lands on /amsa/events at its instant; a
    run that faults still leaves a finalised bag of what ran."""
    from fractions import Fraction

    from amsa_phys.bag import BagRecorder
    from amsa_phys.model.scenario import Change, load_scenario
    from amsa_phys.runs.single import run_scenario

    def session(sim: Any, scenario: Any, recorder: Any) -> float:
        sim.advance(sim.grid.ticks(Fraction(2)))
        landed["at"] = sim.apply_live(Change("MyFollowerController", "Kv", 0.2))
        sim.advance(sim.grid.ticks(Fraction(4)))
        return 0.0

    landed: dict[str, Fraction] = {}
    scenario = load_scenario(FIXTURE, duration=10)
    bag = BagRecorder(tmp_path / "live.mcap", scenario)
    out = tmp_path / "live"
    out.mkdir()
    try:
        run_scenario(scenario, out, window=session, plot=False, simulation=bag.simulation)
    finally:
        bag.close()
    _, msgs = read_mcap(tmp_path / "live.mcap")
    events = [(t, m.kind, m.detail) for topic, t, m in msgs if topic == "/amsa/events"]
    at = landed["at"]
    assert events[1:] == [
        (at.numerator * NS // at.denominator, "live change", "MyFollowerController.Kv=0.2")
    ]
    assert max(t for _, t, _ in msgs) == 4 * NS  # the session closed at t = 4 s

    rogue = {
        "world": {
            "name": "r",
            "components": {
                "Bot": {"template": "freeRobot", "freq": 10},
                "R": {"template": "rogue:Rogue", "freq": 10, "params": {"mode": "list"}},
            },
        },
        "duration": 5,
        "set": {"R.at": 2.5},
    }
    with pytest.raises(ap.RunFault, match="do_step must return a mapping"):
        ap.run(rogue, bag=tmp_path / "fault.mcap")
    types, msgs = read_mcap(tmp_path / "fault.mcap")
    assert types["/Bot/ground_truth/odom"] == "nav_msgs/msg/Odometry"
    assert max(t for _, t, _ in msgs) == 2_450_000_000  # the last whole trace instant


def test_a_collision_is_an_event(tmp_path: Path) -> None:
    """The leader turned round towards a follower without power: their collision is on
    /amsa/events at the instant the run recorded it."""
    bag = tmp_path / "hit.mcap"
    push = {"Leader.heading": 3.14159, "Leader.x": 3.0, "MyNormalizePower.motorCoef": 0}
    run = ap.run(FIXTURE, duration=30, set=push, bag=bag)
    hits = [e for e in run.events if e.kind == "collision"]
    assert len(hits) == 1
    _, msgs = read_mcap(bag)
    events = [(t, m.kind, m.detail) for topic, t, m in msgs if topic == "/amsa/events"]
    assert events[1:] == [(round(hits[0].t * NS), "collision", hits[0].detail)]


def test_a_delayed_sensor_is_stamped_when_it_measured(tmp_path: Path) -> None:
    """A compass Leaf with a 0.5 s transport latency: each heading appears in the bag when
    the trace sees it, stamped 0.5 s earlier (its step, the measurement's instant); its lost
    samples are still absent, each absence a stale heading in the trace."""
    out, bag = run_with_bag(
        tmp_path,
        "late",
        "--set",
        "FollowerCompass.latency=0.5",
        "--set",
        "FollowerCompass.lostData=40",
    )
    header, trace = read_trace(out)
    row = {round(t * NS): i for i, t in enumerate(trace[:, 0])}
    ih = header.index("FollowerCompass.compassHeading")
    _, msgs = read_mcap(bag)
    heads = {t: m for topic, t, m in msgs if topic == "/Follower/FollowerCompass/heading"}
    for log_time, m in heads.items():
        assert m.header.stamp.sec * NS + m.header.stamp.nanosec == log_time - NS // 2
        yaw = quaternion_yaw(m.orientation)
        assert yaw == pytest.approx(trace[row[log_time], ih], abs=1e-12)
    visible = [k * NS // 4 + NS // 2 for k in range(4 * 40 - 1)]  # steps 0 .. 39.5 s, +0.5 s
    assert set(heads) <= set(visible)
    missing = [t for t in visible if t not in heads]
    assert 0.25 < len(missing) / len(visible) < 0.55
    for t in missing:
        assert trace[row[t], ih] == trace[row[t] - 5, ih]
