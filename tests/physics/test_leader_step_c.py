"""A random leader group's whole step in one C call (``_step.leader_step``) is the three calls
it replaces in ``FreeRobot.step_many`` (``steer_random`` on the rovers' angles,
``column_powers`` into the drives, ``robot_poses``), to the bit: on edge angles, headings,
powers at and beyond the limits and the deadband, NaN, rovers in any order; and a vector
env whose leaders step through it gives the episodes of the three calls."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from amsa_phys.physics import compiled, freerobot
from amsa_phys.physics.step_path import extension

pytestmark = pytest.mark.skipif(
    extension() is None or not compiled.columns_compiled(),
    reason="the compiled step was not built (no C compiler at install)",
)


def fleet(seed: int) -> dict[str, np.ndarray]:
    """Rovers (N = 300) and a leader group over some of them, reordered, with the steering's
    inputs at their edges: the errors wrap, the cosine's cut, gains that push the powers
    past ±100 and into the deadband, NaN."""
    rng = np.random.default_rng(seed)
    n = 300
    state = rng.normal(0, 20, (n, 6))
    pi = math.pi
    edges = [0.0, -0.0, pi, -pi, 3 * pi, 2 * pi, 1e-300, 1e15, -1e15, math.nan]
    state[: len(edges), 2] = edges
    index = rng.permutation(n)[:250].astype(np.int64)
    m = len(index)
    heading = rng.uniform(-20, 20, m)
    heading[:12] = [0.0, -0.0, pi, -pi, math.nan, 1e16, -1e16, 2 * pi, 1e-300, 5.0, 5.0, 5.0]
    gain = rng.choice([0.0, 1e-3, 0.5, 5.0, 80.0, 1e4], m)
    cruise = rng.choice([0.0, 0.3, 9.0, 60.0, 150.0], m)
    band = rng.choice([0.0, 0.5, 2.0], n)
    return {
        "heading": heading,
        "state": state,
        "rims": rng.normal(0, 3, (2, n)),
        "index": index,
        "cruise": cruise,
        "factor": rng.uniform(0.5, 1.2, m),
        "gain": gain,
        "band": band,
    }


def three_calls(f: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """The drives and the pose outputs as ``FreeRobot.step_many`` made them before."""
    from amsa_phys.physics import _step  # type: ignore[attr-defined]

    m, n = len(f["index"]), len(f["state"])
    left, right = np.empty(m), np.empty(m)
    angle = f["state"][f["index"], 2]
    _step.steer_random(f["heading"], angle, f["cruise"], f["factor"], f["gain"], left, right)
    drives = np.full((2, n), 7.0)
    _step.column_powers(left, right, f["index"], f["band"], drives)
    out = np.empty((7, m))
    _step.robot_poses(f["state"], f["rims"], f["index"], out)
    return drives, out


def one_call(f: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    from amsa_phys.physics import _step  # type: ignore[attr-defined]

    m, n = len(f["index"]), len(f["state"])
    drives, out = np.full((2, n), 7.0), np.empty((7, m))
    _step.leader_step(
        f["heading"], f["state"], f["rims"], f["index"], f["cruise"], f["factor"], f["gain"],
        f["band"], drives, out,
    )  # fmt: skip
    return drives, out


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_one_call_is_the_three_calls_bit_for_bit(seed: int) -> None:
    f = fleet(seed)
    drives, out = one_call(f)
    want_drives, want_out = three_calls(f)
    assert drives.tobytes() == want_drives.tobytes()
    assert out.tobytes() == want_out.tobytes()
    # the cases reach the clip, the deadband and NaN's -100
    set_ = drives[:, f["index"]]
    assert (set_ == 100.0).any()
    assert (set_ == -100.0).any()
    assert (set_ == 0.0).any()


def test_it_refuses_what_it_would_read_or_write_out_of_bounds() -> None:
    from amsa_phys.physics import _step  # type: ignore[attr-defined]

    f = fleet(4)
    for bad in (-1, len(f["state"])):
        g = {**f, "index": f["index"].copy()}
        g["index"][3] = bad
        with pytest.raises(IndexError, match="out of range"):
            one_call(g)
    with pytest.raises(ValueError, match=r"drives \(2, N\)"):
        _step.leader_step(
            f["heading"], f["state"], f["rims"], f["index"], f["cruise"], f["factor"],
            f["gain"], f["band"], np.empty((2, 3)), np.empty((7, len(f["index"]))),
        )  # fmt: skip


def _episode(n: int) -> list[Any]:
    from amsa_phys.gym.vector import FollowVecEnv

    vec = FollowVecEnv(n, stepping="batch")  # the packaged scenario: random leaders
    seen: list[Any] = [vec.reset(seed=5)[0]]
    rng = np.random.default_rng(5)
    for _ in range(120):
        obs, reward, _, _, info = vec.step(rng.uniform(-1, 1, (n, 2)))
        seen += [obs, reward, info["signal"]]
    vec.close()
    return seen


def test_a_vector_env_through_it_gives_the_episodes_of_the_three_calls(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    taken = []
    real = freerobot._leader_step

    def counted(*args: Any) -> Any:
        out = real(*args)
        taken.append(out is not None)
        return out

    monkeypatch.setattr(freerobot, "_leader_step", counted)
    fused = _episode(6)
    assert sum(taken) > 250  # every leader step after the first went through the one call
    monkeypatch.setattr(freerobot, "_leader_step", lambda *args: None)
    usual = _episode(6)
    assert len(fused) == len(usual)
    for a, b in zip(fused, usual, strict=True):
        assert np.asarray(a).tobytes() == np.asarray(b).tobytes()
