"""A sensor group keeps what depends on its parameters alone between steps
(``engine/batch.derived``); a change of those parameters during the episode must reach
every run at once, so the vector env stays the single env bit for bit through it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("gymnasium", reason="the gym extra is not installed")

from amsa_phys.gym import FollowEnv
from amsa_phys.gym.vector import FollowVecEnv

ROOT = Path(__file__).resolve().parent.parent.parent
WORLD = ROOT / "worlds" / "mde_challenge.yaml"


def _scenario(tmp_path: Path) -> Path:
    """The MDE challenge with a random leader, whose sensors change what they derive from
    their parameters twice: a turn-on bias, quantisation off then on again (every copy or
    none), burst losses, a latency, a dynamic bias with another correlation time."""
    path = tmp_path / "changes.yaml"
    path.write_text(
        f"world: {WORLD}\nduration: 8\nseed: 5\n"
        "quality: {signal: MyDistanceMonitor.distanceFollowerToLeader, reference: 15, "
        "tolerance: 1.5}\n"
        "set: {Leader.behavior: 4, LeaderGPS.bias_stddev: 0.2, FollowerCompass.bias_stddev: 0.05}\n"
        "timeline:\n"
        "  - {at: 2, new_phase: false, set: {LeaderGPS.bias_mean: 0.7, LeaderGPS.precision: 0,"
        " FollowerCompass.bias_mean: 0.02, FollowerCompass.precision: 0,"
        " FollowerGPS.burstLoss: 20, FollowerGPS.burstLength: 3}}\n"
        "  - {at: 4.5, new_phase: false, set: {LeaderGPS.precision: 0.25,"
        " FollowerCompass.precision: 0.05, FollowerGPS.dynamic_bias_correlation_time: 5,"
        " FollowerGPS.burstLoss: 0, LeaderGPS.latency: 0.5}}\n"
    )
    return path


def test_parameter_changes_reach_every_run_bit_for_bit(tmp_path: Path) -> None:
    scenario = str(_scenario(tmp_path))
    seeds = [3, 4, 5]
    vec = FollowVecEnv(3, scenario, observation="absolute", stepping="batch")
    obs, _ = vec.reset(seed=seeds)
    actions = np.random.default_rng(2).uniform(-1, 1, size=(32, 3, 2))
    seen = [obs]
    for a in actions:
        seen.append(vec.step(a)[0])
    vec.close()
    for i, seed in enumerate(seeds):
        single = FollowEnv(scenario, observation="absolute")
        s_obs, _ = single.reset(seed=seed)
        np.testing.assert_array_equal(seen[0][i], s_obs)
        for k, a in enumerate(actions):
            s_obs = single.step(a[i])[0]
            np.testing.assert_array_equal(seen[k + 1][i], s_obs, err_msg=f"step {k + 1}")
        single.close()
    # the changes show: the leader's fix unquantised between 2 s and 4.5 s, on a 0.25 m
    # grid after (every env: the change reached all of them)
    leader_x = np.array(seen)[:, :, 0]
    unquantised = leader_x[10:18]
    assert not np.allclose(unquantised / 0.01, np.round(unquantised / 0.01))
    late = leader_x[-6:]
    np.testing.assert_allclose(late / 0.25, np.round(late / 0.25), atol=1e-9)
