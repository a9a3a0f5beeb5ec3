"""Where a batched vector env's step goes: the rovers' physics, each component group, the rest.

``FollowVecEnv(N)`` (the default scenario, ``stepping="batch"``) stepped with random actions
for ``--steps`` vector steps (within one episode: no reset is timed). Each component group's
step (``Steppers.for_group``, what the schedule calls) and the column physics' C calls are
timed with ``time.perf_counter_ns`` around the call, so the table says per vector step:

* ``physics (C)``: every rover's forces and integration (``ColumnPhysics``' fused step);
* one row per group, by template: its ``step_many`` with the engine's gather and write
  around it, and how many times a vector step it runs;
* ``agent``: the agent's exchange (the stack switch) and the vector env's own Python
  between two batch steps (actions, rewards, observations, info);
* ``rest``: the schedule walk around them.

The timers add ~0.1 µs a call, so read the rows as near the cost, not to the last µs. Run:
``python -m benchmarks.profile_vector 16 64`` (sizes; 16 by default). Nothing is saved.
"""

from __future__ import annotations

import argparse
import collections
import time
from typing import Any

import numpy as np


class _Timed:
    """The columns' fused C step with the wall time of its calls summed."""

    def __init__(self, inner: Any, into: collections.Counter[str]) -> None:
        self.inner, self.into = inner, into

    def advance_many(self, count: int, freeze: bool) -> Any:
        t0 = time.perf_counter_ns()
        out = self.inner.advance_many(count, freeze)
        self.into["physics (C)"] += time.perf_counter_ns() - t0
        return out

    def advance(self) -> Any:
        t0 = time.perf_counter_ns()
        out = self.inner.advance()
        self.into["physics (C)"] += time.perf_counter_ns() - t0
        return out


def profile(n: int, steps: int) -> list[tuple[str, float, float]]:
    """``(row, µs a vector step, calls a vector step)`` for ``n`` envs, the total first."""
    from amsa_phys.engine import tasks
    from amsa_phys.gym.vector import FollowVecEnv

    spent: collections.Counter[str] = collections.Counter()
    calls: collections.Counter[str] = collections.Counter()
    on = [False]
    real = tasks.Steppers.for_group

    def for_group(self: Any, group: Any) -> Any:
        step = real(self, group)
        name = group.template.__name__

        def timed(g: Any, now: Any) -> None:
            if not on[0]:
                step(g, now)
                return
            t0 = time.perf_counter_ns()
            try:
                step(g, now)
            finally:  # the agent's group switches out and back in between
                spent[name] += time.perf_counter_ns() - t0
                calls[name] += 1

        return timed

    tasks.Steppers.for_group = for_group  # type: ignore[method-assign]
    try:
        env = FollowVecEnv(n, stepping="batch")
        env.reset(seed=1)
    finally:
        tasks.Steppers.for_group = real  # type: ignore[method-assign]
    actions = np.random.default_rng(n).uniform(-1, 1, (steps + 20, n, 2))
    for a in actions[:20]:  # the columns start at the first physics step
        env.step(a)
    columns = env._episode.columns
    if getattr(columns, "_fused", None) is not None:
        columns._fused = _Timed(columns._fused, spent)
    on[0] = True
    t0 = time.perf_counter_ns()
    for a in actions[20:]:
        env.step(a)
    total = time.perf_counter_ns() - t0
    env.close()
    # the agent's group switches out to the vector env's own step and back: its row is
    # the exchange and everything the env does between two batch steps
    if "Agents" in spent:
        spent["agent: exchange + env's own step"] = spent.pop("Agents")
        calls["agent: exchange + env's own step"] = calls.pop("Agents")
    rows = [("total", total / steps / 1000, 1.0)]
    rows.append(("physics (C)", spent.pop("physics (C)", 0) / steps / 1000, float("nan")))
    rows += [(k, v / steps / 1000, calls[k] / steps) for k, v in spent.most_common()]
    rest = total / steps / 1000 - sum(r[1] for r in rows[1:])
    rows.append(("rest (the schedule walk)", rest, float("nan")))
    return rows


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("sizes", nargs="*", type=int, default=[16], help="numbers of envs")
    parser.add_argument("--steps", type=int, default=300, help="vector steps timed")
    args = parser.parse_args(argv)
    print(f"# load {_load()}")
    for n in args.sizes:
        steps = max(10, min(args.steps, 470))  # within the default 120 s episode (480 steps)
        rows = profile(n, steps)
        total = rows[0][1]
        print(f"{n} envs: {total:.1f} µs a vector step ({n / total * 1e6:,.0f} env-steps/s)")
        for name, us, per in rows[1:]:
            times = "" if per != per else f"  ({per:.1f} a step)"
            print(f"  {name:34s} {us:8.1f} µs  {us / total:6.1%}{times}")


def _load() -> str:
    """The 1-minute load average, where the system says it."""
    try:
        with open("/proc/loadavg") as f:
            return f.read().split()[0]
    except OSError:
        return "unknown"


if __name__ == "__main__":
    main()
