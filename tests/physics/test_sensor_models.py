"""The sensor models against closed forms (issue 16), each bound justified where it is set.

Gauss–Markov bias: autocorrelation exp(-τ/T) and stationary variance σ²T/2; Gilbert–Elliott
loss: loss fraction and mean burst length; GPS latency: the lag of the published fix;
quantisation: the step; compass: the deviation curve; IMU: bias random-walk variance σ²t
and the accelerometer's kinematics; odometry: exact on straight lines and circles.
"""

from __future__ import annotations

import math
from fractions import Fraction
from typing import Any

import numpy as np
import pytest

from amsa_phys.engine.rng import component_rng
from amsa_phys.sensors.compass import Compass, deviation
from amsa_phys.sensors.gps import GPS
from amsa_phys.sensors.imu import IMU
from amsa_phys.sensors.odometry import WheelOdometry


class _Ctx:
    def __init__(self, seed: int, path: str) -> None:
        self.rng = component_rng(seed, path)
        self.path = path
        self.world = None


def make(template: Any, params: dict[str, Any], seed: int = 7, path: str = "S") -> Any:
    comp = template(path, params)
    comp.initialize(_Ctx(seed, path))
    return comp


def gps_series(params: dict[str, Any], n: int, rate_hz: int = 1, xy: Any = None) -> np.ndarray:
    """``n`` steps of a GPS at ``rate_hz``; rows (t, x or NaN if nothing published, y)."""
    gps = make(GPS, params)
    out = np.empty((n, 3))
    for k in range(n):
        t = Fraction(k, rate_hz)
        x, y = xy(float(t)) if xy else (0.0, 0.0)
        fix = gps.do_step(t, {"posX": x, "posY": y})
        out[k] = (float(t), fix.get("gpsPosX", np.nan), fix.get("gpsPosY", np.nan))
    return out


def autocorrelation(x: np.ndarray, lag: int) -> float:
    x = x - x.mean()
    return float(np.dot(x[:-lag], x[lag:]) / np.dot(x, x))


# -- Gauss–Markov dynamic bias ---------------------------------------------------------------
T_CORR = 5.0
SIGMA = 0.2  # m/√s: stationary std 0.2 * sqrt(2.5) = 0.316 m
N_GM = 40_000  # at 1 Hz: phi = exp(-1/5) = 0.819, ~4000 effective samples


def gm_bias(corr_time: float) -> np.ndarray:
    fixes = gps_series(
        {"dynamic_bias_stddev": SIGMA, "dynamic_bias_correlation_time": corr_time}, N_GM
    )
    return fixes[:, 1:]


def gm_matches(b: np.ndarray, corr_time: float) -> bool:
    """Stationary variance within 12 % of σ²T/2 and autocorrelation within 0.05 of
    exp(-τ/T) at τ = 1, 2, 5, 10 s. With ~4000 effective samples per axis the variance's
    relative standard error is ~2.3 % and the autocorrelations' ~0.016: both bounds are
    over 3 standard errors, for each axis."""
    var = SIGMA**2 * corr_time / 2
    ok = bool(np.all(np.abs(b.var(axis=0) / var - 1) < 0.12))
    for lag in (1, 2, 5, 10):
        for axis in (0, 1):
            ok &= abs(autocorrelation(b[:, axis], lag) - math.exp(-lag / corr_time)) < 0.05
    return ok


def test_gauss_markov_bias_has_the_closed_form_variance_and_autocorrelation() -> None:
    b = gm_bias(T_CORR)
    assert gm_matches(b, T_CORR)
    assert abs(np.corrcoef(b.T)[0, 1]) < 0.1  # per axis: independent


def test_mutation_gauss_markov_check_fails_for_another_correlation_time() -> None:
    assert not gm_matches(gm_bias(8.0), T_CORR)  # the sensor at 8 s, checked for 5 s


# -- Gilbert–Elliott burst loss ----------------------------------------------------------------
N_GE = 50_000


def bursts(lost: np.ndarray) -> np.ndarray:
    """Lengths of the runs of consecutive lost samples."""
    edges = np.diff(np.concatenate(([0], lost.astype(int), [0])))
    return np.flatnonzero(edges == -1) - np.flatnonzero(edges == 1)


def ge_lost(burst_loss: float, length: float, independent: int = 0) -> np.ndarray:
    fixes = gps_series(
        {"burstLoss": burst_loss, "burstLength": length, "lostDataGPS": independent}, N_GE
    )
    return np.isnan(fixes[:, 1])


def ge_matches(lost: np.ndarray, share: float, length: float) -> bool:
    """Loss fraction within 0.02 of ``share`` (its standard error is ~0.004: Markov
    correlation inflates the binomial variance ~5x) and mean burst length within 0.3 of
    ``length`` (~2500 geometric bursts of std ~3.5: standard error 0.07); the share of
    one-sample bursts within 0.03 of 1/length (binomial over ~2500 bursts, SE 0.009)."""
    runs = bursts(lost)
    return (
        abs(lost.mean() - share) < 0.02
        and abs(runs.mean() - length) < 0.3
        and abs((runs == 1).mean() - 1 / length) < 0.03
    )


def test_gilbert_elliott_loss_fraction_and_mean_burst_length() -> None:
    assert ge_matches(ge_lost(20.0, 4.0), 0.20, 4.0)


def test_burst_and_independent_losses_combine() -> None:
    # bad state: all lost; good state: 10 % lost independently -> 0.2 + 0.8 * 0.1
    lost = ge_lost(20.0, 4.0, independent=10)
    assert abs(lost.mean() - 0.28) < 0.02


def test_mutation_gilbert_elliott_check_fails_for_another_burst_length() -> None:
    assert not ge_matches(ge_lost(20.0, 6.0), 0.20, 4.0)  # sensor at 6, checked for 4


def test_a_sweep_over_burst_loss_keeps_the_noise_sequence() -> None:
    a = gps_series({"stddev": 0.5}, 2000)
    b = gps_series({"stddev": 0.5, "burstLoss": 30.0}, 2000)
    both = ~np.isnan(a[:, 1]) & ~np.isnan(b[:, 1])
    assert both.sum() > 1000
    assert np.array_equal(a[both], b[both])


# -- latency ---------------------------------------------------------------------------------
def lag_of(latency: float, rate_hz: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """Lag of the published fix behind the truth on a ramp x = 2 t; times of the fixes."""
    fixes = gps_series({"latency": latency}, 200, rate_hz, xy=lambda t: (2.0 * t, 0.0))
    got = ~np.isnan(fixes[:, 1])
    return fixes[got, 0] - fixes[got, 1] / 2.0, fixes[got, 0]


@pytest.mark.parametrize(
    ("latency", "expected"), [(0.0, 0.0), (0.25, 0.25), (0.3, 0.5), (0.5, 0.5), (1.1, 1.25)]
)
def test_latency_is_the_lag_of_the_published_fix_in_whole_periods(
    latency: float, expected: float
) -> None:
    lag, t = lag_of(latency)
    assert np.allclose(lag, expected, atol=1e-12)  # ceil(L / period) * period
    assert t[0] == pytest.approx(expected)  # no fix before one is old enough


def test_mutation_latency_check_fails_when_the_sensor_is_not_late() -> None:
    lag, _ = lag_of(0.0)
    assert not np.allclose(lag, 0.5, atol=1e-12)


# -- quantisation ----------------------------------------------------------------------------
def quantised(precision: float) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(3)
    truth = rng.uniform(-50, 50, size=(4000, 2))
    gps = make(GPS, {"precision": precision})
    out = np.array(
        [
            list(gps.do_step(Fraction(k, 4), {"posX": x, "posY": y}).values())
            for k, (x, y) in enumerate(truth.tolist())
        ]
    )
    return truth, out


def quantisation_ok(truth: np.ndarray, out: np.ndarray, step: float) -> bool:
    """Every output a multiple of ``step``, within step/2 of the truth, and the error's
    std within 5 % of step/√12 (uniform error; 8000 values give a ~0.8 % standard error)."""
    k = out / step
    err = out - truth
    return bool(
        np.all(np.abs(k - np.round(k)) < 1e-6)
        and np.all(np.abs(err) <= step / 2 + 1e-9)
        and abs(err.std() / (step / math.sqrt(12)) - 1) < 0.05
    )


def test_gps_output_is_quantised_to_its_precision() -> None:
    truth, out = quantised(0.1)
    assert quantisation_ok(truth, out, 0.1)


def test_mutation_quantisation_check_fails_for_another_step() -> None:
    truth, out = quantised(0.07)
    assert not quantisation_ok(truth, out, 0.1)


# -- compass deviation -----------------------------------------------------------------------
DEV = {"deviationB": 0.03, "deviationC": -0.02, "deviationD": 0.01, "deviationE": 0.015}


def compass_error_curve(params: dict[str, Any]) -> tuple[np.ndarray, np.ndarray]:
    comp = make(Compass, params)
    headings = np.linspace(-math.pi, math.pi, 721)[:-1]
    out = np.array(
        [
            comp.do_step(Fraction(k, 4), {"heading": h})["compassHeading"]
            for k, h in enumerate(headings.tolist())
        ]
    )
    err = (out - headings + math.pi) % (2 * math.pi) - math.pi
    return headings, err


def test_compass_error_follows_the_deviation_curve() -> None:
    h, err = compass_error_curve({**DEV, "mean": 0.01})
    expected = 0.01 + 0.03 * np.sin(h) - 0.02 * np.cos(h) + 0.01 * np.sin(2 * h)
    expected += 0.015 * np.cos(2 * h)
    assert np.abs(err - expected).max() < 1e-12


def test_compass_deviation_is_recovered_from_noisy_samples() -> None:
    # least squares on [1, sin, cos, sin 2, cos 2] recovers A..E: 720 samples of 0.01 rad
    # noise give coefficient standard errors of ~0.0005; bound 0.002 (4 SE)
    h, err = compass_error_curve({**DEV, "stddev": 0.01})
    basis = np.column_stack([np.ones_like(h), np.sin(h), np.cos(h), np.sin(2 * h), np.cos(2 * h)])
    coef = np.linalg.lstsq(basis, err, rcond=None)[0]
    assert np.allclose(coef, [0.0, 0.03, -0.02, 0.01, 0.015], atol=0.002)


def test_mutation_compass_curve_check_fails_without_soft_iron() -> None:
    h, err = compass_error_curve({**DEV, "deviationD": 0.0})
    assert np.abs(err - deviation(h, 0.03, -0.02, 0.01, 0.015)).max() > 0.005


# -- IMU -------------------------------------------------------------------------------------
Q_RW = 0.01  # rad/s/√s: the gyro bias random walk
IMU_RATE = 10
IMU_STEPS = 300  # 30 s
IMU_COPIES = 300


def gyro_bias_ensemble(corr_time: float) -> np.ndarray:
    """(copies, steps) gyro readings of still IMUs, each with its own stream."""
    params = {
        "gyro_dynamic_bias_stddev": Q_RW,
        "gyro_dynamic_bias_correlation_time": corr_time,
    }
    out = np.empty((IMU_COPIES, IMU_STEPS))
    for c in range(IMU_COPIES):
        imu = make(IMU, params, seed=11, path=f"Imu{c}")
        for k in range(IMU_STEPS):
            out[c, k] = imu.do_step(Fraction(k, IMU_RATE), {"speed": 0.0, "yawRate": 0.0})["gyroZ"]
    return out


def random_walk_ok(gyro: np.ndarray) -> bool:
    """Across 300 copies the variance at t = 5, 15, 30 s is within 30 % of q² t (relative
    standard error of a variance over 300 samples: sqrt(2/300) = 8 %; bound ~3.7 SE)."""
    for t in (5.0, 15.0, 30.0):
        k = round(t * IMU_RATE) - 1
        elapsed = k / IMU_RATE  # the walk starts at 0 at the first sample
        if abs(gyro[:, k].var() / (Q_RW**2 * elapsed) - 1) > 0.3:
            return False
    return True


def test_imu_gyro_bias_random_walk_variance_grows_like_t() -> None:
    assert random_walk_ok(gyro_bias_ensemble(0.0))


def test_mutation_random_walk_check_fails_for_a_gauss_markov_bias() -> None:
    assert not random_walk_ok(gyro_bias_ensemble(5.0))  # saturates at q² T / 2


def test_imu_accelerometer_kinematics() -> None:
    # v = 0.5 + 0.8 t, ω = 0.3: forward 0.8 m/s² (after the first sample), centripetal v ω
    imu = make(IMU, {})
    for k in range(40):
        t = k / 10
        v = 0.5 + 0.8 * t
        out = imu.do_step(Fraction(k, 10), {"speed": v, "yawRate": 0.3})
        assert out["gyroZ"] == 0.3
        assert out["accelX"] == pytest.approx(0.0 if k == 0 else 0.8, abs=1e-12)
        assert out["accelY"] == pytest.approx(v * 0.3, abs=1e-12)


# -- wheel odometry --------------------------------------------------------------------------
def odometry_on(vl: float, vr: float, track: float = 0.5, steps: int = 400, **params: Any) -> Any:
    """Integrate constant wheel speeds for ``steps`` at 4 Hz; the final pose and time."""
    odo = make(WheelOdometry, {"track": track, "x": 1.0, "y": -2.0, "heading": 0.3, **params})
    for k in range(steps):
        out = odo.do_step(Fraction(k, 4), {"wheelSpeedL": vl, "wheelSpeedR": vr})
    return out, (steps - 1) / 4


def unicycle(vl: float, vr: float, track: float, t: float) -> tuple[float, float, float]:
    """The closed-form pose of a unicycle from (1, -2, 0.3) with constant wheel speeds."""
    v, w = (vl + vr) / 2, (vr - vl) / track
    th0 = 0.3
    if w == 0:
        return 1 + v * t * math.cos(th0), -2 + v * t * math.sin(th0), th0
    r = v / w
    th = th0 + w * t
    return 1 + r * (math.sin(th) - math.sin(th0)), -2 - r * (math.cos(th) - math.cos(th0)), th


@pytest.mark.parametrize(("vl", "vr"), [(1.2, 1.2), (0.8, 1.3), (1.0, -1.0), (-0.5, -0.9)])
def test_odometry_is_exact_on_straight_lines_and_circles(vl: float, vr: float) -> None:
    out, t = odometry_on(vl, vr)
    x, y, th = unicycle(vl, vr, 0.5, t)
    assert out["odomX"] == pytest.approx(x, abs=1e-9)
    assert out["odomY"] == pytest.approx(y, abs=1e-9)
    assert math.cos(out["odomHeading"] - th) == pytest.approx(1.0, abs=1e-12)


def test_mutation_odometry_check_fails_with_a_wrong_wheel_radius() -> None:
    out, t = odometry_on(0.8, 1.3, scaleErrorL=0.5)
    x, y, _ = unicycle(0.8, 1.3, 0.5, t)
    assert math.hypot(out["odomX"] - x, out["odomY"] - y) > 0.05
