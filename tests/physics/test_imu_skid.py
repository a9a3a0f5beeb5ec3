"""The IMU's accelerometer reads the specific force at its mounting point in a skid (issue 31,
item 3): with the pose linked, a drifting rover's sideways velocity shows in the forward
channel (``a_x = -w v_y``), and a lever arm adds ``-w^2 r``. The reference is the body's own
acceleration, the second difference of its positions at the physics rate (each step's
velocity change exactly), turned into the body frame and averaged over the steady drift.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from rig import ON_AXLE, drive

#: The drift of ``test_step_independence``: the outer wheel spins, the inner one is dragged.
HOT = {"stallForce": 600.0, "freeSpeed": 6.0, "maxWheelTorque": 40.0, **ON_AXLE}
SETTLED = 3.0  # s: the drift is steady from here (it settles within ~2 s)


def skid_imu(tmp_path: Path, imu: dict[str, Any], inputs: dict[str, str]) -> dict[str, float]:
    """Mean true and measured body-frame acceleration over the steady drift."""
    tmp_path.mkdir(exist_ok=True)
    extra = {"Imu": {"template": "IMU", "freq": 10, "params": imu, "inputs": inputs}}
    tr, _ = drive(
        tmp_path,
        60,
        20,
        6,
        robot=HOT,
        physics={"rate": 100, "ground": {"friction": 0.8, "rolling_resistance": 0.02}},
        rate_hz=100,
        extra=extra,
    )
    dt = 0.01
    ax = np.diff(tr["Rover.posX"], 2) / dt**2
    ay = np.diff(tr["Rover.posY"], 2) / dt**2
    a = tr["Rover.heading"][1:-1]
    w = tr["Rover.yawRate"][1:-1]
    steady = tr["t"][1:-1] >= SETTLED
    true_x = ax * np.cos(a) + ay * np.sin(a) - w * w * imu.get("mountX", 0.0)
    true_y = -ax * np.sin(a) + ay * np.cos(a) - w * w * imu.get("mountY", 0.0)
    meas = tr["t"] >= SETTLED + 0.2  # the IMU's own differences are a period behind
    return {
        "true_x": float(true_x[steady].mean()),
        "true_y": float(true_y[steady].mean()),
        "x": float(tr["Imu.accelX"][meas].mean()),
        "y": float(tr["Imu.accelY"][meas].mean()),
    }


POSED = {
    "speed": "Rover.speed",
    "yawRate": "Rover.yawRate",
    "posX": "Rover.posX",
    "posY": "Rover.posY",
    "heading": "Rover.heading",
}


def error(r: dict[str, float]) -> float:
    """The measured specific force's error (m/s²), both axes."""
    return float(np.hypot(r["x"] - r["true_x"], r["y"] - r["true_y"]))


def test_the_accelerometer_reads_the_specific_force_in_a_steady_skid(tmp_path: Path) -> None:
    # measured: 2.8169 / -7.3091 m/s² against 2.8166 / -7.3079 (error 0.0013 m/s²)
    r = skid_imu(tmp_path, {}, POSED)
    assert abs(r["true_x"]) > 2.0  # a real skid: -w v_y is several m/s² forward
    assert error(r) < 0.02 * np.hypot(r["true_x"], r["true_y"])


def test_the_accelerometer_adds_its_lever_arm(tmp_path: Path) -> None:
    # steady (no angular acceleration): the centre's specific force plus -w^2 r, w ~ 4.3 rad/s
    r = skid_imu(tmp_path, {"mountX": 0.3, "mountY": 0.1}, POSED)
    centre = skid_imu(tmp_path / "c", {}, POSED)
    assert r["true_x"] < centre["true_x"] - 5.0  # the arm's share is large: -18 x 0.3 m/s²
    assert error(r) < 0.02 * np.hypot(r["true_x"], r["true_y"])


def test_mutation_skid_check_fails_without_the_pose(tmp_path: Path) -> None:
    """The 2019 wiring (speed and yaw rate only) takes the sideways velocity as 0: 2.8 m/s²
    off forward (the issue measured up to 3.2)."""
    r = skid_imu(tmp_path, {}, {"speed": "Rover.speed", "yawRate": "Rover.yawRate"})
    assert error(r) > 0.02 * np.hypot(r["true_x"], r["true_y"])
