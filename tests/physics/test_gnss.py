"""GNSS fixes against closed forms: open-sky spread, the sky a long wall hides (HDOP), multipath
beside the wall and not in the open, outages (sky, denied rectangle, losses) at their rates,
and the time stamps (a constant offset, a drift, the jitter's spread)."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from deadlines import HANG_S

from amsa_phys.engine.runner import Simulation
from amsa_phys.model.scenario import load_scenario

WALL_X = 10.0  # the near face of a long wall (x 10..12, y -200..200)
HEIGHT = 5.0  # obstacleHeight of the tests: the sky reach is 5 / tan(10 deg) = 28 m
MASK = 0.1745
RAYS = 16
FREQ = 4


def gnss_run(
    tmp_path: Path,
    gnss: dict[str, Any],
    x: float,
    duration: float = 400,
    others: dict[str, Any] | None = None,
) -> tuple[np.ndarray, list[str], Simulation]:
    """A still rover at (x, 0) beside (or far from) the wall; the trace at the GNSS's rate."""
    world = {
        "physics": {
            "obstacles": [{"type": "box", "x": WALL_X + 1, "y": 0, "width": 2, "height": 400}]
        },
        "components": {
            "Ctl": {"template": "ConstantPower", "freq": FREQ},
            "Norm": {
                "template": "NormalizePower",
                "freq": FREQ,
                "inputs": {"powerL": "Ctl.LeftPower", "powerR": "Ctl.RightPower"},
            },
            "Rover": {
                "template": "controlledRobot",
                "freq": FREQ,
                "params": {"x": x, "y": 0.0},
                "inputs": {"powerL": "Norm.normalizedPowerL", "powerR": "Norm.normalizedPowerR"},
            },
            "Fix": {
                "template": "GNSS",
                "freq": FREQ,
                "params": {"obstacleHeight": HEIGHT, "elevationMask": MASK, **gnss},
                "inputs": {"posX": "Rover.posX", "posY": "Rover.posY"},
            },
            **(others or {}),
        },
    }
    path = tmp_path / "gnss.yaml"
    path.write_text(yaml.safe_dump({"world": world, "duration": duration, "log_rate": FREQ}))
    rows: list[list[float]] = []
    sim = Simulation.from_scenario(load_scenario(path), trace=lambda t, v: rows.append([t, *v]))
    sim.run()
    return np.array(rows, dtype=float), ["t", *sim.columns], sim


def col(rows: np.ndarray, cols: list[str], name: str) -> np.ndarray:
    return rows[:, cols.index(name)]


def wall_hdop(dist: float, hdop_open: float) -> float:
    """HDOP beside an endless wall ``dist`` away, from the geometry alone: the ray at azimuth a
    (0: towards the wall) meets it at dist / cos a; at that range a wall HEIGHT tall hides the
    sky up to atan(HEIGHT cos a / dist), the share (elev - mask) / (90 deg - mask) of it."""
    reach = HEIGHT / math.tan(MASK)
    shares = []
    for k in range(RAYS):
        a = 2 * math.pi * k / RAYS
        c = math.cos(a)
        if c > 0 and dist / c < reach:
            elev = math.atan(HEIGHT * c / dist)
            shares.append(max(0.0, (elev - MASK) / (math.pi / 2 - MASK)))
        else:
            shares.append(0.0)
    return hdop_open / math.sqrt(1 - sum(shares) / RAYS)


def test_open_sky_fix_has_the_receiver_spread_and_its_hdop(tmp_path: Path) -> None:
    """Far from the wall: per-axis error N(0, stddev²) (1601 samples: the spread within 10 %,
    ~4 standard errors; the mean within 4 σ/√n), and fixQuality is hdopOpen exactly."""
    rows, cols, _ = gnss_run(tmp_path, {"stddev": 0.5, "hdopOpen": 0.9, "multipathStd": 4.0}, -60)
    ex = col(rows, cols, "Fix.gpsPosX") - col(rows, cols, "Rover.posX")
    ey = col(rows, cols, "Fix.gpsPosY") - col(rows, cols, "Rover.posY")
    n = len(ex)
    for e in (ex, ey):
        assert abs(e.std() / 0.5 - 1) < 0.1
        assert abs(e.mean()) < 4 * 0.5 / math.sqrt(n)
    assert np.all(col(rows, cols, "Fix.fixQuality") == 0.9)


def test_a_wall_hides_sky_and_raises_hdop_and_noise(tmp_path: Path) -> None:
    """2 m from the wall: fixQuality is the geometric HDOP (1e-9), the white noise grows by
    the same factor (spread within 10 %)."""
    rows, cols, _ = gnss_run(tmp_path, {"stddev": 0.5, "hdopOpen": 0.9}, WALL_X - 2)
    hdop = wall_hdop(2.0, 0.9)
    assert hdop / 0.9 > 1.15  # the wall matters here (beyond the 10 % tolerance)
    q = col(rows, cols, "Fix.fixQuality")
    assert np.all(np.abs(q - hdop) < 1e-9)
    ey = col(rows, cols, "Fix.gpsPosY") - col(rows, cols, "Rover.posY")
    assert abs(ey.std() / (0.5 * hdop / 0.9) - 1) < 0.1


def test_multipath_beside_a_wall_not_in_the_open(tmp_path: Path) -> None:
    """White multipath (multipathTime 0) of multipathStd·exp(-d/range): at d = 2 m, range 4 m,
    the error spread is 6·e^(-1/2) = 3.64 m (within 10 %); 60 m from the wall, nothing but the
    receiver's 0.1 m."""
    mp = {"stddev": 0.1, "multipathStd": 6.0, "multipathRange": 4.0, "multipathTime": 0.0}
    near, cols, _ = gnss_run(tmp_path, mp, WALL_X - 2)
    far, _, _ = gnss_run(tmp_path, mp, -60)
    hdop = wall_hdop(2.0, 1.0)
    expect = math.hypot(0.1 * hdop, 6.0 * math.exp(-0.5))
    e_near = col(near, cols, "Fix.gpsPosX") - col(near, cols, "Rover.posX")
    e_far = col(far, cols, "Fix.gpsPosX") - col(far, cols, "Rover.posX")
    assert abs(e_near.std() / expect - 1) < 0.1
    assert abs(e_far.std() / 0.1 - 1) < 0.1


def test_multipath_correlation_time(tmp_path: Path) -> None:
    """multipathTime T: the error's lag-one autocorrelation at 4 Hz is e^(-0.25/T) (T = 2 s:
    0.8825; 1601 samples, standard error ~ (1 - ρ²)/√n = 0.006: within 0.05)."""
    mp = {"multipathStd": 3.0, "multipathRange": 4.0, "multipathTime": 2.0}
    rows, cols, _ = gnss_run(tmp_path, mp, WALL_X - 1, duration=800)
    e = col(rows, cols, "Fix.gpsPosX") - col(rows, cols, "Rover.posX")
    rho = float(np.corrcoef(e[:-1], e[1:])[0, 1])
    assert abs(rho - math.exp(-0.25 / 2.0)) < 0.05


def held_share(rows: np.ndarray, cols: list[str]) -> float:
    """The share of samples that repeat the previous fix (noise makes a fresh fix differ)."""
    x = col(rows, cols, "Fix.gpsPosX")
    return float(np.mean(np.diff(x) == 0))


def test_outages_sky_denied_zone_and_losses(tmp_path: Path) -> None:
    """No fix at all where the sky is below minSky or inside the denied rectangle (the fix
    stays at its default 0); a lostDataGPS of 30 % loses 30 % (1600 draws: within 0.05,
    ~4.4 standard errors) and counts them."""
    near_wall = WALL_X - 0.5  # more than half the sky towards the wall is hidden
    rows, cols, sim = gnss_run(tmp_path, {"stddev": 0.2, "minSky": 0.9}, near_wall, 50)
    assert np.all(col(rows, cols, "Fix.gpsPosX") == 0.0)
    assert sim.components["Fix"].lost == len(rows)
    box = {"deniedXMin": -65, "deniedXMax": -55, "deniedYMin": -5, "deniedYMax": 5}
    rows, cols, _ = gnss_run(tmp_path, {"stddev": 0.2, **box}, -60, 50)
    assert np.all(col(rows, cols, "Fix.gpsPosX") == 0.0)
    rows, cols, _ = gnss_run(tmp_path, {"stddev": 0.2, **box}, -50, 50)  # just outside it
    assert held_share(rows, cols) == 0.0
    rows, cols, sim = gnss_run(tmp_path, {"stddev": 0.2, "lostDataGPS": 30}, -60)
    assert abs(sim.components["Fix"].lost / len(rows) - 0.3) < 0.05
    assert abs(held_share(rows, cols) - 0.3) < 0.05


def test_defaults_are_a_perfect_receiver_stamped_on_time(tmp_path: Path) -> None:
    """Template defaults: the true position, fixQuality hdopOpen, fixTime the step's time."""
    rows, cols, _ = gnss_run(tmp_path, {"obstacleHeight": 0.0}, WALL_X - 1, 20)
    assert np.array_equal(col(rows, cols, "Fix.gpsPosX"), col(rows, cols, "Rover.posX"))
    assert np.all(col(rows, cols, "Fix.fixQuality") == 1.0)
    assert np.array_equal(col(rows, cols, "Fix.fixTime"), rows[:, 0])


def test_a_clock_offset_shifts_every_stamp_by_exactly_it(tmp_path: Path) -> None:
    """clockOffset c: fixTime = t + c (1e-12); with latency L at 4 Hz the stamp is that of the
    measurement, t - ceil(L/0.25)·0.25 + c."""
    rows, cols, _ = gnss_run(tmp_path, {"clockOffset": 0.137}, -60, 20)
    assert np.all(np.abs(col(rows, cols, "Fix.fixTime") - rows[:, 0] - 0.137) < 1e-12)
    rows, cols, _ = gnss_run(tmp_path, {"clockOffset": 0.137, "latency": 0.3}, -60, 20)
    later = rows[:, 0] >= 0.5
    lag = col(rows, cols, "Fix.fixTime")[later] - rows[later, 0]
    assert np.all(np.abs(lag - (0.137 - 0.5)) < 1e-12)


def test_sync_drift_and_stamp_jitter(tmp_path: Path) -> None:
    """syncDrift 500 ppm: the stamp error grows as 5e-4·t (1e-12); stampJitter 0.02 s: the
    stamp error has mean 0 (4 standard errors) and spread 0.02 (within 10 %)."""
    rows, cols, _ = gnss_run(tmp_path, {"syncDrift": 500.0}, -60, 100)
    t = rows[:, 0]
    assert np.all(np.abs(col(rows, cols, "Fix.fixTime") - t * (1 + 5e-4)) < 1e-12)
    rows, cols, _ = gnss_run(tmp_path, {"stampJitter": 0.02}, -60)
    err = col(rows, cols, "Fix.fixTime") - rows[:, 0]
    assert abs(err.mean()) < 4 * 0.02 / math.sqrt(len(err))
    assert abs(err.std() / 0.02 - 1) < 0.1


def test_a_gps_denied_zone_holds_every_fix_inside_it(tmp_path: Path) -> None:
    """A gpsDeniedZone (a tunnel) over the rover: no fix; the same zone 5 m away: every fix."""
    tunnel = [[-65, -3], [-55, -3], [-55, 3], [-65, 3]]
    zone = {"Tunnel": {"template": "gpsDeniedZone", "params": {"polygon": tunnel}}}
    rows, cols, sim = gnss_run(tmp_path, {"stddev": 0.2}, -60, 20, zone)
    assert np.all(col(rows, cols, "Fix.gpsPosX") == 0.0)
    assert sim.components["Fix"].lost == len(rows)
    rows, cols, _ = gnss_run(tmp_path, {"stddev": 0.2}, -50, 20, zone)
    assert held_share(rows, cols) == 0.0


def test_a_zone_without_area_is_refused_naming_it(tmp_path: Path) -> None:
    """Two corners: one line naming the zone and the polygon, exit 2, no traceback."""
    zone = {"Tunnel": {"template": "gpsDeniedZone", "params": {"polygon": [[0, 0], [1, 1]]}}}
    world = {"components": zone}
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump({"world": world, "duration": 1}))
    proc = subprocess.run(
        [sys.executable, "-m", "amsa_phys", "validate", str(path)],
        capture_output=True,
        text=True,
        timeout=HANG_S,
    )
    assert proc.returncode == 2
    assert "Tunnel" in proc.stderr
    assert "polygon" in proc.stderr
    assert "Traceback" not in proc.stderr
