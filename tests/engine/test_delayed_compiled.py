"""A delayed Leaf's step is one C call where the extension is built (``_kernels.Delayed``):
``test_delayed_paths.py`` holds it to the Python step's verdicts; here, that it is the step
those comparisons and the single env's agent run."""

from __future__ import annotations

import importlib.util
from array import array
from fractions import Fraction

import numpy as np
import pytest

from amsa_phys.engine import publish
from amsa_phys.engine.tasks import Steppers, Task
from amsa_phys.gym import FollowEnv

BUILT = importlib.util.find_spec("amsa_phys.engine._kernels") is not None
#: built and not switched off (``AMSA_PHYS_PURE=1``)
pytestmark = pytest.mark.skipif(
    not BUILT or publish._extension("_kernels") is None,
    reason="the extension was not built (no C compiler), or the pure path was asked for",
)


class Comp:
    def do_step(self, t: Fraction, inp: dict[str, float]) -> dict[str, float]:
        return {"u": inp["x"] * 2.0, "v": float(t)}


def test_a_delayed_leaf_steps_in_c_and_sends_what_it_published() -> None:
    values = array("d", [0.5, -1.0, 9.0, 4.0])
    sent: list[object] = []
    task = Task("C", Comp(), 1, [("x", "S.x"), ("u", "C.u")], {"u": "C.u", "v": "C.v"})
    task.bind({"S.x": 0, "C.u": 2, "C.v": 3}.__getitem__)
    line = object()
    task.delay = line  # type: ignore[assignment]  # only handed to ``send``
    step = Steppers(values, lambda ln, w: sent.append((ln, w)), lambda p: p).for_task(task)
    assert type(step).__name__ == "Delayed"
    step(task, Fraction(3, 2))
    assert sent == [(line, [(2, 1.0), (3, 1.5)])]  # in flight, in the output order
    assert task.own == {2: 1.0, 3: 1.5}  # read back by the Leaf at once
    assert values.tolist() == [0.5, -1.0, 9.0, 4.0]  # not visible before delivery


def test_the_single_envs_agent_is_the_compiled_delayed_step() -> None:
    env = FollowEnv(duration=5)
    env.reset(seed=0)
    env.step(np.zeros(2))
    steps = {t.path: type(r).__name__ for e in env._episode.sim._plan for r, t in e[1]}
    env.close()
    assert steps["MyFollowerController"] == "Delayed"
