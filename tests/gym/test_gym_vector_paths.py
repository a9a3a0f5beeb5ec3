"""The vector env's two ways of stepping give the same bits, and the size chooses between
them: single envs in turn below ``SINGLES_BELOW``, one batched simulation from there on
(``gym/vecsingles.py``, ``gym/vecepisode.py``). And the batch's physics taken a run of steps
at a time in C, touched runs frozen there, is the numpy path's, bit for bit."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

pytest.importorskip("gymnasium", reason="the gym extra is not installed")

from amsa_phys.gym.vecsingles import SINGLES_BELOW
from amsa_phys.gym.vector import FollowVecEnv
from amsa_phys.physics import compiled
from amsa_phys.physics.columns import ColumnPhysics

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO1 = str(ROOT / "scenarios" / "scenario1.yaml")


def test_the_size_chooses_the_path_and_an_argument_overrides_it() -> None:
    small = FollowVecEnv(SINGLES_BELOW - 1, SCENARIO1, duration=1)
    large = FollowVecEnv(SINGLES_BELOW, SCENARIO1, duration=1)
    assert (small.stepping, large.stepping) == ("single", "batch")
    assert FollowVecEnv(2, SCENARIO1, duration=1, stepping="batch").stepping == "batch"
    small.reset(seed=1)
    large.reset(seed=1)
    assert small._episode is small._singles  # single envs, no batch
    assert large._singles is None
    assert large._episode.sim is not None  # type: ignore[union-attr]  # one batch
    small.close()
    large.close()


def _episode(stepping: str, actions: np.ndarray, seeds: list[int]) -> list[tuple[Any, ...]]:
    """Every step's results of a vector env over ``actions``, the autoreset's included."""
    vec = FollowVecEnv(len(seeds), SCENARIO1, duration=40, stepping=stepping)
    seen: list[tuple[Any, ...]] = [vec.reset(seed=seeds)]
    seen += [vec.step(a) for a in actions]
    assert vec._episode is not None
    alone = sorted(vec._episode.solo)
    seen.append(vec.step(actions[0]))  # the autoreset: new seeds from the env's generator
    seen.append(vec.step(actions[1]))
    seen.append(("went alone", alone))
    vec.close()
    return seen


def test_both_paths_give_the_same_bits_rammers_included() -> None:
    """Four envs over a whole 40 s episode: random actions, one env at full power from the
    start and one from 10 s on (both ram their leader: in the batch they go alone), then the
    autoreset. Observations, rewards, ends and every info array are equal to the bit."""
    n, steps = 4, 160
    actions = np.random.default_rng(3).uniform(-1, 1, size=(steps, n, 2))
    actions[:, 0] = 1.0
    actions[40:, 2] = 1.0
    seeds = [41, 42, 43, 44]
    batch = _episode("batch", actions, seeds)
    single = _episode("single", actions, seeds)
    assert batch[-1][1] == [0, 2]  # the batch did hand the rammers over
    assert single[-1][1] == []  # single envs: nothing to hand over
    batch, single = batch[:-1], single[:-1]
    assert len(batch) == len(single) == steps + 3
    for k, (b, s) in enumerate(zip(batch, single, strict=True)):
        b_info, s_info = b[-1], s[-1]
        for x, y in zip(b[:-1], s[:-1], strict=True):
            assert np.asarray(x).tobytes() == np.asarray(y).tobytes(), k
        assert b_info.keys() == s_info.keys()
        for key in b_info:
            assert b_info[key].tobytes() == s_info[key].tobytes(), (k, key)
    assert batch[steps][3].all()  # the episode ended at its duration...
    assert single[-2][-1]["t"].tolist() == [0.0] * n  # ...and the autoreset started anew
    assert single[-3][-1]["collisions"][0] >= 1  # the rammer collided


@pytest.mark.skipif(
    not compiled.columns_compiled(), reason="the compiled step was not built (no C compiler)"
)
def test_the_c_run_of_column_steps_is_the_numpy_path_bit_for_bit(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The batch's physics: runs of steps in one C call, a touched run's rows held in C,
    against one numpy step a call with the numpy freezing (the pure path's), for an env that
    rams its leader (frozen from then on) beside envs that drive on: the columns' state,
    rims and touched runs after every vector step, and every observation, are equal."""
    steps = 120
    actions = np.random.default_rng(5).uniform(-1, 1, size=(steps, 3, 2))
    actions[:, 1] = 1.0

    def run(fused: bool) -> tuple[list[bytes], int]:
        with monkeypatch.context() as m:
            if not fused:
                m.delattr(compiled.ColumnForces, "columns")
            vec = FollowVecEnv(3, SCENARIO1, duration=30, stepping="batch")
            obs, _ = vec.reset(seed=[7, 8, 9])
            episode = vec._episode
            assert episode is not None
            columns = episode.columns
            assert columns is not None
            seen = [obs.tobytes()]
            for a in actions:
                obs, reward, _, _, _ = vec.step(a)
                model = columns._model
                seen += [obs.tobytes(), reward.tobytes(), columns._io.state.tobytes()]
                seen += [model.rims.tobytes(), columns._touched.tobytes()]
            assert (columns._fused is not None) == fused
            assert episode.solo == {1}
            vec.close()
            return seen, columns.steps

    in_c, steps_c = run(True)
    in_numpy, steps_numpy = run(False)
    assert steps_c == steps_numpy == 3000
    first = next((k for k, (a, b) in enumerate(zip(in_c, in_numpy, strict=True)) if a != b), None)
    assert first is None, f"first difference at record {first}"


@pytest.mark.skipif(
    not compiled.columns_compiled(), reason="the compiled step was not built (no C compiler)"
)
def test_runs_of_steps_are_taken_in_one_call(monkeypatch: pytest.MonkeyPatch) -> None:
    """What makes the batch cheap: the physics steps between two instants with components
    go to C in one call each (a vector step of the MDE world: 25 steps, in a handful of
    calls), not one Python call a step."""
    calls: list[int] = []
    many = ColumnPhysics.step_many

    def spy(self: ColumnPhysics, count: int, seek: Any) -> int:
        done = many(self, count, seek)
        calls.append(done)
        return done

    monkeypatch.setattr(ColumnPhysics, "step_many", spy)
    vec = FollowVecEnv(2, SCENARIO1, duration=5, stepping="batch")
    vec.reset(seed=1)
    calls.clear()
    for _ in range(4):
        vec.step(np.zeros((2, 2)))
    vec.close()
    assert sum(calls) == 4 * 25  # every physics step of the 4 vector steps...
    assert len(calls) <= 4 * 5  # ...in a few calls (between the log's and the Leader's rows)


@pytest.mark.parametrize("stepping", ["batch", "single"])
def test_a_rover_leaving_the_world_faults_as_in_the_single_env(
    tmp_path: Path, stepping: str
) -> None:
    """A physics fault inside a run of steps taken in one C call is reported at its own
    step, as the single env reports it: the same message (rover, time, place)."""
    from amsa_phys.errors import RunFault
    from amsa_phys.gym import FollowEnv

    path = tmp_path / "small.yaml"
    path.write_text(
        f"world: {ROOT / 'worlds' / 'mde_challenge.yaml'}\nduration: 60\nseed: 1\n"
        "physics:\n  extent: 25\n"
        "set: {Leader.cruisePower: 100}\n"
        "quality: {signal: MyDistanceMonitor.distanceFollowerToLeader, reference: 15, "
        "tolerance: 1.5}\n"
    )
    turn = np.array([0.3, 0.2])  # the leader, at full power from 15 m, leaves the world

    def fault(env: Any, action: np.ndarray) -> str:
        env.reset(seed=[4, 5] if action.ndim == 2 else 4)
        try:
            for _ in range(240):
                env.step(action)
        except RunFault as exc:
            return str(exc)
        finally:
            env.close()
        raise AssertionError("no fault")

    single = fault(FollowEnv(str(path)), turn)
    assert "in Leader: body left the world" in single
    assert not single.startswith("run fault at t=0.")  # well into the run: mid-run of steps
    vec = FollowVecEnv(2, str(path), stepping=stepping)
    assert fault(vec, np.array([turn, turn])) == single
