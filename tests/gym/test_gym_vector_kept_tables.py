"""What the vector env's groups keep between steps for speed (a compass group without
deviation terms skips them; a random leader's next draw time is compared as a float first;
a robot group keeps its rovers' positions) must not go stale: through deviation terms set
and cleared during the episode, and over a reset to other seeds, every env stays the single
env bit for bit."""

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
    """The MDE challenge with a random leader whose follower's compass has no deviation
    terms, gets two at 2 s and loses them at 4.5 s."""
    path = tmp_path / "deviation.yaml"
    path.write_text(
        f"world: {WORLD}\nduration: 7\nseed: 5\n"
        "quality: {signal: MyDistanceMonitor.distanceFollowerToLeader, reference: 15, "
        "tolerance: 1.5}\n"
        "set: {Leader.behavior: 4, Leader.changePeriod: 0.75, FollowerCompass.precision: 0,"
        " FollowerCompass.deviationB: 0, FollowerCompass.deviationC: 0,"
        " FollowerCompass.deviationD: 0}\n"
        "timeline:\n"
        "  - {at: 2, new_phase: false, set: {FollowerCompass.deviationB: 0.05,"
        " FollowerCompass.deviationE: -0.02}}\n"
        "  - {at: 4.5, new_phase: false, set: {FollowerCompass.deviationB: 0,"
        " FollowerCompass.deviationE: 0}}\n"
    )
    return path


def _singles(scenario: str, seeds: list[int], actions: np.ndarray) -> np.ndarray:
    rows = []
    for i, seed in enumerate(seeds):
        single = FollowEnv(scenario, observation="absolute")
        seen = [single.reset(seed=seed)[0]]
        seen += [single.step(a[i])[0] for a in actions]
        single.close()
        rows.append(seen)
    return np.array(rows).transpose(1, 0, 2)  # (steps, envs, observed)


def test_kept_tables_follow_changes_and_resets(tmp_path: Path) -> None:
    scenario = str(_scenario(tmp_path))
    vec = FollowVecEnv(3, scenario, observation="absolute", stepping="batch")
    actions = np.random.default_rng(4).uniform(-1, 1, size=(27, 3, 2))
    compass = vec.single.observed.index("headingFollower")
    for seeds in ([3, 4, 5], [11, 12, 13]):  # a reset to other seeds: new groups
        seen = [vec.reset(seed=seeds)[0]]
        seen += [vec.step(a)[0] for a in actions]
        want = _singles(scenario, seeds, actions)
        for k, (got, expected) in enumerate(zip(seen, want, strict=True)):
            np.testing.assert_array_equal(got, expected, err_msg=f"seeds {seeds}, step {k}")
    vec.close()
    # the terms showed: the same episode without them reads other headings between 2 and
    # 4.5 s (and the same before)
    plain = tmp_path / "plain.yaml"
    plain.write_text(Path(scenario).read_text().split("timeline:")[0])
    without = _singles(str(plain), [11, 12, 13], actions)[:, :, compass]
    with_terms = np.array(seen)[:, :, compass]
    np.testing.assert_array_equal(with_terms[:8], without[:8])
    assert (with_terms[9:17] != without[9:17]).all()


def test_the_batch_keeps_no_log() -> None:
    """Nothing reads a vector env's quality samples: its batch keeps none (as the single
    env's run keeps no log), so an episode's memory does not grow with its instants and no
    log instant splits the physics between the components' instants."""
    vec = FollowVecEnv(4, stepping="batch")
    vec.reset(seed=1)
    for _ in range(12):
        vec.step(np.zeros((4, 2)))
    sim = vec._episode.sim
    assert not sim.keeps_log
    assert len(sim._q_rows) == 0
    vec.close()
