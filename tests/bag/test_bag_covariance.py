"""A bag's stated covariance is the error a reader actually sees.

Checked where it was wrong: a compass's yaw variance left out the deviation δ(θ), so a
compass with about a degree of deviation and a tenth of a degree of noise stated a variance
fifty times below its real mean square error (an estimator fusing it would trust it that
much too far). Over turns of the robot the yaw in the bag, against the true yaw, must show
the variance the message states.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

import amsa_phys as ap
from amsa_phys.stdmsgs import quaternion_yaw

NS = 1_000_000_000

SCENARIO = {
    "world": {
        "components": {
            "Rover": {
                "template": "freeRobot",
                "freq": 20,
                # a tight circle: several full turns, every heading equally often
                "params": {"behavior": 2, "circleRadius": 1.5},
            },
            "Compass": {
                "template": "Compass",
                "freq": 20,
                "params": {
                    "stddev": 0.002,
                    "deviationB": 0.015,
                    "deviationC": -0.01,
                    "deviationD": 0.005,
                    "deviationE": 0.008,
                },
                "inputs": {"heading": "Rover.heading"},
            },
        }
    },
    "duration": 120,
    "seed": 3,
}


def test_the_compass_yaw_variance_is_its_real_mean_square_error(tmp_path: Path) -> None:
    bag = tmp_path / "c.mcap"
    ap.run(SCENARIO, bag=bag)
    truth: dict[int, float] = {}
    measured: dict[int, float] = {}
    stated: set[float] = set()
    with bag.open("rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for _, channel, message, m in reader.iter_decoded_messages(
            topics=["/Rover/ground_truth/odom", "/Rover/Compass/heading"]
        ):
            if channel.topic.endswith("odom"):
                truth[message.log_time] = quaternion_yaw(m.pose.pose.orientation)
            else:
                measured[message.log_time] = quaternion_yaw(m.orientation)
                stated.add(m.orientation_covariance[8])
    (variance,) = stated
    turned = max(truth.values()) - min(truth.values())
    assert turned > 6.0  # every heading seen
    errors = np.array(
        [
            math.remainder(measured[t] - truth[t], math.tau)
            for t in measured
            if t >= 10 * NS  # after the start, whose heading is 0 alone
        ]
    )
    mean_square = float(np.mean(errors**2))
    assert 0.8 * variance < mean_square < 1.25 * variance, (mean_square, variance)
