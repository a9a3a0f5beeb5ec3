"""Where the time of a run goes: a sampling profile of the engine's hot loop, by part.

Two targets:

* ``gym``: ``amsa_phys/Follow-v0`` (``gymnasium.make``, its wrappers included) stepped with
  random actions, resetting at the end of each episode;
* ``run``: ``amsa_phys.run`` of scenario1 (300 s simulated, trace kept in memory).

The profiler is a CPU-time timer (``SIGPROF``, every ``--interval`` ms of process CPU) whose
handler records the Python stack it interrupts: it costs nothing between samples, unlike
cProfile, whose per-call overhead inflates exactly the short calls a step is made of. A
sample is charged to the innermost frame of the package's own code (C code and libraries
called from it count as its, and so do the engine's noise and random-draw helpers a
component calls), and that frame's module says the part:

=====================  ==============================================================
part                   what
=====================  ==============================================================
physics step (C)       ``physics/space.py``'s step: the compiled step's one C call
components             every component's ``do_step`` (robots, sensors, controllers)
engine loop            ``engine/``: the schedule walk, the component calls, deliveries, and
                       the components stepped as compiled bodies (``engine/kernels.py``)
log and trace          ``engine/log.py`` and the trace and signal writers
gym env                ``gym/``: the agent's step, the episode's stack switch, observations
gymnasium              Gymnasium's own wrappers (``gymnasium.make`` adds them)
reset and build        a reset: the scenario loaded, the simulation built and initialised
=====================  ==============================================================

Run: ``python -m benchmarks.profile_loop gym`` (or ``run``); ``--top N`` lists the N
hottest lines: where the interpreter noticed the timer (its next call or loop jump), so
read them as near the cost, the parts as the cost. A handler runs only between two Python
instructions: C time that calls no Python meanwhile (the compiled schedule walk, the
components' compiled bodies it calls) is charged to the next Python frame entered, mostly
the physics step's or the agent's. The timer fires at the kernel's tick at
best (often every 4 ms): the loops are long enough for a thousand samples or more. The
shares are of the samples in the measured loop; the CPU time beside them is that share of
the loop's measured CPU time per step (or per run).

``python -m benchmarks.perf --save --only profile`` profiles both targets ``--reps`` times and
writes each part's share to ``benchmarks/results/perf.json``; the manual's "Where the time
goes" table is generated from there (:func:`perf`).
"""

from __future__ import annotations

import argparse
import collections
import os
import signal
import statistics
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from types import FrameType

ROOT = Path(__file__).resolve().parent.parent
#: the package's directory as imported (``main`` sets it: another checkout may be on the path)
PACKAGE = str(ROOT / "amsa_phys") + os.sep
SCENARIO1 = str(ROOT / "scenarios" / "scenario1.yaml")

#: code names whose presence on the stack makes a sample a reset's
_BUILD = {"reset", "from_scenario", "initialize", "_compile", "_load", "load"}
_LOG = ("engine/log.py", "engine/tracemem.py", "engine/tracefile.py", "engine/signals.py")
#: the engine's helpers for components (noise, random draws, libm): charged to their caller
_HELPERS = ("engine/noise.py", "engine/rng.py", "engine/libm.py")


def part_of(frame: FrameType | None) -> tuple[str, str]:
    """The part a sample belongs to and its innermost line of the package's code."""
    inner = ""
    part = ""
    gymnasium = False
    while frame is not None:
        code = frame.f_code
        name = code.co_filename
        if code.co_name in _BUILD and name.startswith(PACKAGE):
            return "reset and build", inner or f"{_short(name)}:{frame.f_lineno}"
        if not part:
            if name.startswith(PACKAGE) and not _short(name).startswith(_HELPERS):
                inner = f"{_short(name)}:{frame.f_lineno} ({code.co_name})"
                part = _part(_short(name), code.co_name)
            elif f"{os.sep}gymnasium{os.sep}" in name:
                gymnasium = True
        frame = frame.f_back
    if not part:
        return ("gymnasium" if gymnasium else "other"), inner
    return part, inner


def _short(filename: str) -> str:
    return filename[len(PACKAGE) :] if filename.startswith(PACKAGE) else filename


def _part(module: str, function: str) -> str:
    if module == "physics/space.py" and function in ("step", "step_many"):
        return "physics step (C)"
    if module.startswith(_LOG):
        return "log and trace"
    if module.startswith("engine/"):
        return "engine loop"
    if module.startswith("gym/"):
        return "gym env"
    return "components"


class Sampler:
    """Stacks sampled every ``interval`` s of process CPU time (``SIGPROF``)."""

    def __init__(self, interval: float) -> None:
        self.interval = interval
        self.parts: collections.Counter[str] = collections.Counter()
        self.lines: collections.Counter[str] = collections.Counter()

    def _handler(self, _signum: int, frame: FrameType | None) -> None:
        part, line = part_of(frame)
        self.parts[part] += 1
        self.lines[f"{part}: {line}"] += 1

    def __enter__(self) -> Sampler:
        signal.signal(signal.SIGPROF, self._handler)
        signal.setitimer(signal.ITIMER_PROF, self.interval, self.interval)
        return self

    def __exit__(self, *exc: object) -> None:
        signal.setitimer(signal.ITIMER_PROF, 0, 0)
        signal.signal(signal.SIGPROF, signal.SIG_DFL)


def gym_loop(steps: int) -> tuple[Callable[[], None], str, int]:
    """``steps`` random-action steps of Follow-v0 (its default scenario)."""
    import gymnasium
    import numpy as np

    import amsa_phys.gym  # noqa: F401  (registers the environment)

    env = gymnasium.make("amsa_phys/Follow-v0")
    env.reset(seed=0)
    env.action_space.seed(0)
    actions = [env.action_space.sample() for _ in range(steps)]
    np.asarray(actions)  # made before the measured loop

    def loop() -> None:
        for action in actions:
            _, _, terminated, truncated, _ = env.step(action)
            if terminated or truncated:
                env.reset()

    return loop, "env step", steps


def run_loop(runs: int) -> tuple[Callable[[], None], str, int]:
    """``runs`` calls of ``amsa_phys.run`` on scenario1."""
    import amsa_phys as ap

    ap.run(SCENARIO1)  # imports and caches warm

    def loop() -> None:
        for _ in range(runs):
            ap.run(SCENARIO1)

    return loop, "run", runs


#: what each target measures by default, and its unit of CPU time
COUNTS = {"gym": 100_000, "run": 40}
SCALE = {"gym": ("env step", "µs", 1e6), "run": ("run", "ms", 1e3)}
#: the parts in the order a table lists them
PARTS = (
    "physics step (C)",
    "components",
    "engine loop",
    "log and trace",
    "gym env",
    "gymnasium",
    "reset and build",
    "other",
)


@dataclass
class Profile:
    """One profiled loop: CPU per unit (in its scale) and the samples by part and line."""

    target: str
    count: int
    per: float
    parts: collections.Counter[str]
    lines: collections.Counter[str]

    @property
    def total(self) -> int:
        return sum(self.parts.values()) or 1

    def share(self, part: str) -> float:
        """``part``'s share of the samples, in percent."""
        return 100 * self.parts[part] / self.total


def profile(target: str, count: int | None = None, interval_ms: float = 0.5) -> Profile:
    """Profile ``target`` (``gym`` or ``run``) over ``count`` env steps or runs."""
    import amsa_phys

    global PACKAGE
    PACKAGE = str(Path(amsa_phys.__file__).resolve().parent) + os.sep
    make = gym_loop if target == "gym" else run_loop
    loop, _unit, n = make(count or COUNTS[target])
    sampler = Sampler(interval_ms / 1000)
    cpu = time.process_time()
    with sampler:
        loop()
    cpu = time.process_time() - cpu
    return Profile(target, n, cpu / n * SCALE[target][2], sampler.parts, sampler.lines)


def perf(reps: int, report: Callable[[str, str, str, bool | None], None]) -> None:
    """The ``profile`` target of ``benchmarks/perf.py``: each part's share of the CPU of the
    single env's step and of ``amsa_phys.run``'s loop, median over ``reps`` profiles, with
    that share of the CPU time per env step (per run) beside it. Figures without an aim
    (INFO): where the time goes, for the docs' "Where the time goes"."""
    for target in ("gym", "run"):
        unit, scale, _ = SCALE[target]
        runs = [profile(target, COUNTS[target] // 2) for _ in range(reps)]
        per = [r.per for r in runs]
        report(f"{target}: CPU per {unit}, {scale}", _med(per), "", None)
        mid = statistics.median(per)
        for part in PARTS:
            shares = [r.share(part) for r in runs]
            if not any(shares):
                continue
            cost = mid * statistics.median(shares) / 100
            report(
                f"{target}: {part}, % of CPU",
                f"{_med(shares)}; {cost:.3g} {scale} per {unit}",
                "",
                None,
            )


def _med(xs: list[float]) -> str:
    """``median (min a, max b)``, as ``perf.med`` (``results.py`` parses it)."""
    return f"{statistics.median(xs):.4g} (min {min(xs):.4g}, max {max(xs):.4g})"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("target", choices=["gym", "run"])
    parser.add_argument("--count", type=int, help="env steps (gym, 100000) or runs (run, 40)")
    parser.add_argument("--interval", type=float, default=0.5, help="ms of CPU between samples")
    parser.add_argument("--top", type=int, default=15, help="hottest lines listed")
    args = parser.parse_args(argv)
    prof = profile(args.target, args.count, args.interval)
    unit, scale, _ = SCALE[args.target]
    per, total = prof.per, prof.total
    print(
        f"{args.target}: {prof.count} x {unit}, {per:.1f} {scale} CPU per {unit}, {total} samples"
    )
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    for part, k in prof.parts.most_common():
        print(f"  {100 * k / total:5.1f} %  {per * k / total:8.2f} {scale}  {part}")
    print(f"hottest lines ({args.top}):")
    for line, k in prof.lines.most_common(args.top):
        print(f"  {100 * k / total:5.1f} %  {line}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
