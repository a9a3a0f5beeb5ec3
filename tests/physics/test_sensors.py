"""Sensors against their parameters: seeded statistics with stated confidence bounds."""

from __future__ import annotations

import math
from fractions import Fraction
from typing import Any

import numpy as np
import pytest

from amsa_phys.engine.rng import component_rng
from amsa_phys.sensors.compass import Compass
from amsa_phys.sensors.gps import GPS

N = 20_000


class _Ctx:
    def __init__(self, seed: int, path: str) -> None:
        self.rng = component_rng(seed, path)
        self.path = path


def gps_samples(params: dict[str, Any], seed: int = 7) -> tuple[np.ndarray, np.ndarray]:
    """N steps of a GPS fed a fixed true position (3, 4); returns the published fixes and
    a mask of the steps that published."""
    full = {p.name: p.default for p in GPS.params} | params
    gps = GPS("G", full)
    gps.initialize(_Ctx(seed, "G"))
    out, got = [], []
    for k in range(N):
        fix = gps.do_step(Fraction(k, 4), {"posX": 3.0, "posY": 4.0})
        got.append(bool(fix))
        out.append((fix.get("gpsPosX", np.nan), fix.get("gpsPosY", np.nan)))
    return np.array(out), np.array(got)


def loss_fraction_ok(measured_lost: int, percent: float) -> bool:
    """Within 4 standard deviations of a binomial(N, p): false alarm ~ 6e-5."""
    p = percent / 100
    return abs(measured_lost - N * p) <= 4 * math.sqrt(N * p * (1 - p))


def test_gps_loses_the_declared_share_of_samples() -> None:
    _, got = gps_samples({"lostDataGPS": 10})
    assert loss_fraction_ok(int((~got).sum()), 10)


def test_mutation_gps_loss_check_fails_for_another_rate() -> None:
    _, got = gps_samples({"lostDataGPS": 12})  # the sensor is set to 12 %, checked for 10 %
    assert not loss_fraction_ok(int((~got).sum()), 10)


def test_gps_noise_and_bias_statistics() -> None:
    fixes, _ = gps_samples({"noise": 0.5, "bias": 1.5})
    err = fixes - np.array([3.0, 4.0])
    # mean: bias within 4 standard errors (0.5 / sqrt(N)); std within 3 % (chi-square,
    # N = 20000 gives a relative standard error of 0.5 %)
    assert np.all(np.abs(err.mean(axis=0) - 1.5) < 4 * 0.5 / math.sqrt(N))
    assert np.all(np.abs(err.std(axis=0) / 0.5 - 1) < 0.03)
    assert abs(np.corrcoef(err.T)[0, 1]) < 4 / math.sqrt(N)  # independent axes


def test_gps_noise_sequence_does_not_depend_on_the_loss_rate() -> None:
    a, got_a = gps_samples({"noise": 0.5, "lostDataGPS": 0})
    b, got_b = gps_samples({"noise": 0.5, "lostDataGPS": 30})
    both = got_a & got_b
    assert np.array_equal(a[both], b[both])  # a sweep over loss keeps the same noise


@pytest.mark.parametrize(
    ("heading", "bias", "expected"),
    [
        (3.1, 0.2, 3.3 - 2 * math.pi),
        (-3.1, -0.2, -3.3 + 2 * math.pi),
        (0.5, 0.0, 0.5),
        (math.pi, 0.0, -math.pi),
    ],
)
def test_compass_wraps_to_minus_pi_pi(heading: float, bias: float, expected: float) -> None:
    c = Compass("C", {"noise": 0.0, "bias": bias})
    c.initialize(_Ctx(0, "C"))
    out = c.do_step(Fraction(0), {"heading": heading})["compassHeading"]
    assert -math.pi <= out < math.pi
    assert out == pytest.approx(expected, abs=1e-12)
