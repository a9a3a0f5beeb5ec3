"""The single env's episode on a coroutine (issue 29): thread affinity, faults, teardown."""

from __future__ import annotations

import gc
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest

gymnasium = pytest.importorskip("gymnasium", reason="the gym extra is not installed")

from deadlines import HANG_S  # noqa: E402

from amsa_phys.errors import RunFault  # noqa: E402
from amsa_phys.gym import FollowEnv  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO1 = str(ROOT / "scenarios" / "scenario1.yaml")
HALF = np.array([0.5, 0.5])


def observations(env: FollowEnv, seed: int, steps: int) -> list[np.ndarray]:
    obs, _ = env.reset(seed=seed)
    seen = [obs]
    for _ in range(steps):
        seen.append(env.step(HALF)[0])
    return seen


def test_stepping_from_another_thread_is_refused_and_the_episode_goes_on() -> None:
    env = FollowEnv(SCENARIO1, duration=20)
    reference = observations(FollowEnv(SCENARIO1, duration=20), 2, 4)
    env.reset(seed=2)
    env.step(HALF)
    env.step(HALF)
    caught: list[BaseException] = []

    def other() -> None:
        try:
            env.step(HALF)
        except BaseException as exc:
            caught.append(exc)

    worker = threading.Thread(target=other)
    worker.start()
    worker.join()
    assert len(caught) == 1
    assert isinstance(caught[0], RuntimeError)
    # one line, as the docs quote it (greenlet's own message, several lines, is not said)
    assert str(caught[0]) == "step() must be called from the thread that called reset()"
    # the refused step did not happen: the episode continues where it was
    obs = [env.step(HALF)[0], env.step(HALF)[0]]
    assert all(np.array_equal(a, b) for a, b in zip(obs, reference[3:], strict=True))
    env.close()


def test_a_fault_in_the_run_is_raised_by_step_and_ends_the_episode() -> None:
    env = FollowEnv(SCENARIO1, duration=20)
    env.reset(seed=1)
    env.step(HALF)
    with pytest.raises(RunFault, match=r"MyFollowerController"):
        env.step(np.array([np.nan, 0.5]))  # a non-finite output, refused by the engine
    with pytest.raises(gymnasium.error.ResetNeeded):
        env.step(HALF)
    env.reset(seed=1)  # and a new episode runs as usual
    assert env.step(HALF)[4]["t"] == 0.25
    env.close()


def test_closing_or_dropping_an_episode_midway_leaves_nothing_behind() -> None:
    fresh = observations(FollowEnv(SCENARIO1, duration=20), 4, 6)
    env = FollowEnv(SCENARIO1, duration=20)
    threads = threading.active_count()
    observations(env, 4, 3)
    assert threading.active_count() == threads  # no worker thread any more
    env.close()
    env.close()  # twice is fine
    again = observations(env, 4, 6)  # reset after a close mid-episode: a fresh episode
    assert all(np.array_equal(a, b) for a, b in zip(again, fresh, strict=True))
    observations(env, 5, 2)  # reset mid-episode drops the paused one
    unraisable: list[object] = []
    previous = sys.unraisablehook
    sys.unraisablehook = unraisable.append
    try:
        del env  # never closed: collected with its run paused inside an instant
        gc.collect()
    finally:
        sys.unraisablehook = previous
    assert unraisable == []


def test_an_env_left_open_at_exit_says_nothing() -> None:
    # the interpreter shuts down with the run paused inside an instant: no "Exception
    # ignored" noise on stderr, exit 0
    script = (
        "import numpy as np\n"
        "from amsa_phys.gym import FollowEnv\n"
        f"env = FollowEnv({SCENARIO1!r}, duration=20)\n"
        "env.reset(seed=1)\n"
        "env.step(np.array([0.5, 0.5]))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=HANG_S, check=False
    )
    assert (done.returncode, done.stderr) == (0, "")


def test_a_reset_in_another_thread_moves_the_env_there() -> None:
    """The episode belongs to the thread that reset it: another thread may take the env
    over by calling reset() (the paused episode is dropped), and steps there as usual; the
    first thread's step is then refused with the clear error, not greenlet's."""
    env = FollowEnv(SCENARIO1, duration=20)
    reference = observations(FollowEnv(SCENARIO1, duration=20), 6, 3)
    env.reset(seed=1)
    env.step(HALF)
    seen: list[np.ndarray] = []
    worker = threading.Thread(target=lambda: seen.extend(observations(env, 6, 3)))
    worker.start()
    worker.join()
    assert all(np.array_equal(a, b) for a, b in zip(seen, reference, strict=True))
    with pytest.raises(RuntimeError, match="the thread that called reset"):
        env.step(HALF)
    env.reset(seed=6)  # and back: a reset here takes it again
    assert np.array_equal(env.step(HALF)[0], reference[1])
    env.close()
