"""Every sensor's clock (``model/sensorclock.py``): the stamped twins of IMU, odometry, compass and
lidar publish their sensor's very samples plus a stamp, and the stamps follow the closed forms
(a constant offset shifts them by exactly it, a drift by exactly ppm·t, the jitter's spread).
GNSS has the same clock (``test_gnss.py`` holds its stamps); its code is this one."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rig import drive

from amsa_phys.model import sensorclock as clock
from amsa_phys.model.template import resolve_template

FREQ = 20
#: the four sensors, each with noise and losses on (so "the same samples" means something),
#: and the output that shows whether a sample was published
SENSORS: dict[str, tuple[str, dict[str, Any], dict[str, str], str]] = {
    "Imu": (
        "IMU",
        {"gyro_stddev": 0.01, "accel_stddev": 0.05, "lostData": 20.0},
        {"speed": "Rover.speed", "yawRate": "Rover.yawRate"},
        "gyroZ",
    ),
    "Odo": (
        "WheelOdometry",
        {"stddev": 0.01, "lostData": 20.0},
        {"wheelSpeedL": "Rover.wheelSpeedL", "wheelSpeedR": "Rover.wheelSpeedR"},
        "odomX",
    ),
    "Cmp": (
        "Compass",
        {"stddev": 0.02, "lostData": 20.0},
        {"heading": "Rover.heading"},
        "compassHeading",
    ),
    "Lid": (
        "Lidar",
        {"beams": 4, "stddev": 0.05, "lostScan": 20.0},
        {"posX": "Rover.posX", "posY": "Rover.posY", "heading": "Rover.heading"},
        "ranges[0]",
    ),
}


def run(tmp_path: Path, stamped: bool, clock_values: dict[str, float] | None = None) -> dict:
    """A rover turning gently in a walled yard for 60 s with the four sensors (stamped twins
    or the plain templates, same paths, same parameters), traced at their rate. Every lidar
    beam meets a wall, so every published scan is noisy, hence new."""
    tmp_path.mkdir(parents=True, exist_ok=True)
    extra = {
        name: {
            "template": ("Stamped" if stamped else "") + template,
            "freq": FREQ,
            "params": {**params, **(clock_values or {})} if stamped else params,
            "inputs": inputs,
        }
        for name, (template, params, inputs, _) in SENSORS.items()
    }
    yard = {"xmin": -15.0, "xmax": 15.0, "ymin": -15.0, "ymax": 15.0}
    cols, _ = drive(
        tmp_path,
        40,
        50,
        60,
        rate_hz=FREQ,
        physics={"walls": yard},
        extra=extra,
    )
    return cols


def test_a_stamped_twin_publishes_its_sensors_very_samples(tmp_path: Path) -> None:
    """Noise, losses and ranges bit for bit the plain sensor's, with a jittered, drifting
    clock on (the jitter has its own stream); ``stamp`` only on the twin."""
    plain = run(tmp_path / "plain", False)
    twin = run(tmp_path / "twin", True, {"stampJitter": 0.01, "syncDrift": 50.0})
    for name, (_, _, _, shown) in SENSORS.items():
        assert f"{name}.stamp" not in plain
        for column in plain:
            if column.startswith(f"{name}."):
                assert np.array_equal(plain[column], twin[column]), column
        assert np.mean(np.diff(twin[f"{name}.{shown}"]) == 0) > 0.1  # losses hold samples


def test_a_constant_offset_shifts_every_stamp_by_exactly_it(tmp_path: Path) -> None:
    cols = run(tmp_path, True, {"clockOffset": -0.0371})
    t = cols["t"]
    for name in SENSORS:
        stamp = cols[f"{name}.stamp"]
        fresh = fresh_rows(cols, name)
        assert np.all(np.abs(stamp[fresh] - t[fresh] + 0.0371) < 1e-12), name


def test_a_drift_moves_every_stamp_by_exactly_ppm_times_t(tmp_path: Path) -> None:
    cols = run(tmp_path, True, {"syncDrift": 250.0})
    t = cols["t"]
    for name in SENSORS:
        fresh = fresh_rows(cols, name)
        err = cols[f"{name}.stamp"][fresh] - t[fresh]
        assert np.all(np.abs(err - 250e-6 * t[fresh]) < 1e-12), name
        assert err[-1] > 0.014  # 250 ppm over ~60 s: 15 ms by the end


def test_the_stamp_jitter_has_the_declared_spread_and_no_mean(tmp_path: Path) -> None:
    """stampJitter 0.004 s: the stamp error of the published samples has mean 0 (within 4
    standard errors) and spread 0.004 (~960 samples a sensor: standard error of the spread
    ~2.3 %, within 10 %); the four sensors' jitters are independent."""
    cols = run(tmp_path, True, {"stampJitter": 0.004})
    t = cols["t"]
    errs = {}
    for name in SENSORS:
        fresh = fresh_rows(cols, name)
        err = cols[f"{name}.stamp"][fresh] - t[fresh]
        assert abs(err.mean()) < 4 * 0.004 / math.sqrt(len(err)), name
        assert abs(err.std() / 0.004 - 1) < 0.1, name
        errs[name] = np.where(fresh, cols[f"{name}.stamp"] - t, np.nan)
    both = ~np.isnan(errs["Imu"]) & ~np.isnan(errs["Cmp"])
    assert abs(np.corrcoef(errs["Imu"][both], errs["Cmp"][both])[0, 1]) < 0.15


def test_a_lost_sample_carries_no_stamp(tmp_path: Path) -> None:
    """Where the sensor published nothing the stamp holds too (readers keep the last sample
    and its stamp together)."""
    cols = run(tmp_path, True, {"clockOffset": 0.5})
    for name in SENSORS:
        outputs = [c for c in cols if c.startswith(f"{name}.") and c != f"{name}.stamp"]
        # noise: a fresh sample differs in some output
        held = np.all([np.diff(cols[c]) == 0 for c in outputs], axis=0)
        assert held.any()
        moved = np.diff(cols[f"{name}.stamp"]) != 0
        assert np.array_equal(moved, ~held), name


def fresh_rows(cols: dict, name: str) -> np.ndarray:
    """Rows where sensor ``name`` published a sample: its stamp moved (a stamp is the
    sample's time on the sensor's clock, so each new sample's differs from the last)."""
    stamp = cols[f"{name}.stamp"]
    return np.concatenate([[stamp[0] != 0.0], np.diff(stamp) != 0])


def test_mutation_a_drift_in_ppb_fails_the_drift_check(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def wrong(now: float, p: Any, jitter: float) -> float:
        return now + p.clockOffset + p.syncDrift * 1e-9 * now + p.stampJitter * jitter

    monkeypatch.setattr(clock.SensorClock, "at", staticmethod(wrong))
    with pytest.raises(AssertionError):
        test_a_drift_moves_every_stamp_by_exactly_ppm_times_t(tmp_path)


def test_the_twins_declare_the_clock_and_the_stamp() -> None:
    for _, (template, _, _, _) in SENSORS.items():
        twin = resolve_template("Stamped" + template)
        base = resolve_template(template)
        assert [p.name for p in twin.outputs] == [p.name for p in base.outputs] + ["stamp"]
        names = [p.name for p in twin.params]
        assert names == [p.name for p in base.params] + list(clock.CLOCK_NAMES)
        assert not hasattr(twin, "step_many")  # one sample at a time, with the clock
        assert twin.is_random({**{p.name: p.default for p in twin.params}, "stampJitter": 0.1})
