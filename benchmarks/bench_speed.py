"""Speed for learning and search: each figure against its baseline, in one sitting.

Every row is measured interleaved with its baseline (repetition by repetition, so a load
that drifts during the sitting hits both alike), in CPU time of this process (or of the
measured child process), as the median of ``--reps`` repetitions; the ratio is taken per
repetition, and the 1-minute load average is recorded with each row. The rows:

* **the single env** (``amsa_phys/Follow-v0``, the packaged scenario, random actions,
  episodes' resets included) against Gymnasium's CartPole-v1 and LunarLander-v3 (Box2D,
  the ``bench`` extra; without it the row says so): env-steps a second, the ratio to
  LunarLander-v3 (target >= 1), CartPole-v1's figure beside it; and the share of the single
  env's CPU spent in the garbage collector's collections (target <= 1 %: an ended episode is
  freed by reference counting, and a reset sets off no collection), its resets' share
  beside it;
* **the vector env** (``FollowVecEnv``, random actions) at 1, 4, 16 and 64 envs against
  Gymnasium's ``SyncVectorEnv`` over the same number of single envs (``FollowEnv`` itself,
  no wrappers: the faster baseline), ratio of env-steps a second (target >= 1 below 16 envs,
  >= 5 from 16 up), and at 1,000 envs alone (a ``SyncVectorEnv`` of 1,000 single envs is
  not built) over a whole episode's steps: with one thread in CPU time (its reset's CPU
  beside it, an INFO row), then with
  ``threads=2`` in wall time, the time a second core saves, interleaved with one thread's
  wall time (target >= 250,000 env-steps a second on a quiet 2-core machine);
* **the engine's floor**: ``amsa_phys.run`` of scenario1 (300 s) against the compiled
  physics step alone stepping the same two rovers for as long (``bench_run.two_rovers``):
  the engine's per-instant overhead as a multiple of the physics (target: not above the
  6.1x measured when the speed work started);
* **start-up**: the whole ``amsa-phys run --headless --no-plot`` process of scenario1
  (300 s) against ``python -c pass``, CPU of the process and its children (target <= 15).

Run: ``python benchmarks/bench_speed.py [--reps 5] [--only single vector run process]
[--quick] [--save]``, or ``python -m benchmarks.perf --only speed --save``. ``--save``
writes the rows to ``benchmarks/results/perf.json`` (target ``speed``) and regenerates the
docs' ``<!-- results: speed -->`` tables; ``--quick`` is a smoke run (one repetition, a
tenth of the steps: its figures are not for keeping).
"""

from __future__ import annotations

import argparse
import gc
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("MPLBACKEND", "Agg")
sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
SCENARIO1 = ROOT / "scenarios" / "scenario1.yaml"
#: the vector env's sizes against ``SyncVectorEnv``; 1,000 is measured alone
SYNC_SIZES = (1, 4, 16, 64)
LARGE = 1000
#: the issue's targets: ratio to SyncVectorEnv below / from FIVE_FROM envs, and at LARGE
FIVE_FROM = 16
LARGE_RATE = 250_000
#: the large vector env's steps a repetition: a whole episode of the packaged scenario (120 s
#: at 4 Hz; its reset untimed, the collections it sets off during the episode timed, once
#: an episode, as in training)
LARGE_STEPS = 480
#: threads of the large vector env's second row: the two cores of the machines it targets
THREADS = 2
#: the engine's overhead over the C step when the speed work started (not to be exceeded)
FLOOR_RATIO = 6.1
START_RATIO = 15.0

#: ``report(figure, measured, target, ok)``, as ``perf.report``
Report = Callable[[str, str, str, bool | None], None]
#: called before each row is measured (``perf`` records the row's load from there)
Mark = Callable[[], None]


def med(xs: list[float]) -> str:
    """``median (min a, max b)``, as ``perf.med`` (``results.py`` parses it)."""
    return f"{statistics.median(xs):.4g} (min {min(xs):.4g}, max {max(xs):.4g})"


def print_report(name: str, measured: str, target: str, ok: bool | None) -> None:
    verdict = "INFO" if ok is None else "PASS" if ok else "MISS"
    print(f"{verdict}  {name:44s}  {measured}   target {target or '-'}", flush=True)


def _nothing() -> None:
    pass


# -- the single env and its peers -------------------------------------------------------
def _rate(env: Any, actions: list[Any], seed: int) -> float:
    """Env-steps a second (CPU) of ``env`` over ``actions``, resetting at each episode end.

    The garbage of whatever ran before (the other envs of the sitting, interleaved) is
    collected first, untimed: each loop pays for the collections its own allocations set
    off, not for a full collection another env's garbage made due.
    """
    env.reset(seed=seed)
    step, reset = env.step, env.reset
    gc.collect()
    t0 = time.process_time()
    for a in actions:
        _, _, terminated, truncated, _ = step(a)
        if terminated or truncated:
            reset()
    return len(actions) / (time.process_time() - t0)


class _Parts:
    """CPU of a single env's loop spent in its resets and in the garbage collector's
    collections (``gc.callbacks``, whatever set them off), over :func:`_rate_parts` calls."""

    def __init__(self) -> None:
        self.cpu = self.resets = self.collector = 0.0
        self._start = 0.0

    def _noted(self, phase: str, _info: dict[str, Any]) -> None:
        if phase == "start":
            self._start = time.process_time()
        else:
            self.collector += time.process_time() - self._start

    def share(self, part: float) -> float:
        """``part``'s share of the loops' CPU, in percent."""
        return 100 * part / self.cpu if self.cpu else 0.0


def _rate_parts(env: Any, actions: list[Any], seed: int, parts: _Parts) -> float:
    """:func:`_rate`, its resets and the collector's collections timed apart into ``parts``
    (two clock reads a reset, and the collector's callback: nothing per step)."""
    env.reset(seed=seed)
    step, reset = env.step, env.reset
    clock = time.process_time
    resets = 0.0
    gc.collect()  # as :func:`_rate`: the sitting's earlier garbage is not this loop's
    gc.callbacks.append(parts._noted)
    try:
        t0 = clock()
        for a in actions:
            _, _, terminated, truncated, _ = step(a)
            if terminated or truncated:
                r0 = clock()
                reset()
                resets += clock() - r0
        cpu = clock() - t0
    finally:
        gc.callbacks.remove(parts._noted)
    parts.cpu += cpu
    parts.resets += resets
    return len(actions) / cpu


def _lunar_lander() -> tuple[Any, str]:
    """LunarLander-v3, or None and why it cannot be made here."""
    import gymnasium

    try:
        return gymnasium.make("LunarLander-v3"), ""
    except Exception as exc:  # gymnasium raises DependencyNotInstalled without Box2D
        return None, f"LunarLander-v3 not measured: {exc} (pip install 'amsa-phys[bench]')"


def single(reps: int, report: Report, quick: bool, mark: Mark = _nothing) -> None:
    """The single env against CartPole-v1 and LunarLander-v3, random actions, interleaved."""
    import gymnasium

    import amsa_phys  # noqa: F401  (registers amsa_phys/Follow-v0)
    from amsa_phys.gym import FollowEnv

    mark()
    steps = 300 if quick else 10000
    rng = np.random.default_rng(0)
    ours = FollowEnv()
    cart = gymnasium.make("CartPole-v1")
    lander, why = _lunar_lander()
    mine = list(rng.uniform(-1, 1, (steps, 2)))
    two = rng.integers(0, 2, steps).tolist()
    four = rng.integers(0, 4, steps).tolist()
    r_ours, r_cart, r_lander = [], [], []
    parts = [_Parts() for _ in range(reps)]
    for i in range(reps):
        r_ours.append(_rate_parts(ours, mine, i, parts[i]))
        r_cart.append(_rate(cart, two, i))
        if lander is not None:
            r_lander.append(_rate(lander, four, i))
    ours.close()
    cart_ratio = [o / c for o, c in zip(r_ours, r_cart, strict=True)]
    context = (
        f"amsa_phys/Follow-v0 {statistics.median(r_ours):,.0f} env-steps/s; CartPole-v1 "
        f"{statistics.median(r_cart):,.0f}, Follow-v0 / CartPole-v1 "
        f"{statistics.median(cart_ratio):.3g}"
    )
    if lander is None:
        report("single env / LunarLander-v3", f"skipped; {why}; {context}", ">= 1.0", False)
    else:
        lander.close()
        ratio = [o / x for o, x in zip(r_ours, r_lander, strict=True)]
        report(
            "single env / LunarLander-v3",
            f"{med(ratio)}; LunarLander-v3 {statistics.median(r_lander):,.0f} env-steps/s; "
            f"{context}",
            ">= 1.0",
            statistics.median(ratio) >= 1.0,
        )
    collector = [p.share(p.collector) for p in parts]
    resets = [p.share(p.resets) for p in parts]
    report(
        "single env: garbage collector, % of its CPU",
        f"{med(collector)}; its resets {statistics.median(resets):.3g} % of its CPU",
        "<= 1",
        statistics.median(collector) <= 1,
    )


# -- the vector env ------------------------------------------------------------------------
def _vec_rate(
    env: Any,
    actions: np.ndarray,
    seed: int,
    clock: Any = time.process_time,
    resets: list[float] | None = None,
) -> float:
    """Env-steps a second (CPU, or ``clock``'s seconds) of a vector env over ``actions``
    (steps, n, 2); its autoreset (NEXT_STEP) starts new episodes as they end. The reset
    before them is not timed (``resets`` gets its seconds of ``clock``)."""
    t0 = clock()
    env.reset(seed=seed)
    if resets is not None:
        resets.append(clock() - t0)
    step = env.step
    t0 = clock()
    for a in actions:
        step(a)
    return actions.shape[0] * actions.shape[1] / (clock() - t0)


class _TimedPhysics:
    """A batch's column physics (``ColumnPhysics._fused``, the C step of every rover) with
    the CPU time of its calls summed: the physics' share of a vector step."""

    def __init__(self, inner: Any) -> None:
        self.inner = inner
        self.cpu = 0.0

    def advance_many(self, count: int, freeze: bool) -> Any:
        t0 = time.process_time()
        out = self.inner.advance_many(count, freeze)
        self.cpu += time.process_time() - t0
        return out

    def advance(self) -> Any:
        t0 = time.process_time()
        out = self.inner.advance()
        self.cpu += time.process_time() - t0
        return out


def physics_share(env: Any, actions: np.ndarray, seed: int) -> str:
    """What the rovers' physics costs of a batched vector env's step: its share of the CPU,
    and the env-steps a second the env would make if nothing but the physics cost anything
    (the ceiling no work on the rest can pass). Empty when the env does not step as a batch
    on the compiled columns."""
    env.reset(seed=seed)
    env.step(actions[0])  # the columns start at the first physics step
    columns = getattr(env._episode, "columns", None)
    if getattr(columns, "_fused", None) is None:
        return ""
    timed = columns._fused = _TimedPhysics(columns._fused)
    t0 = time.process_time()
    for a in actions[1:]:
        env.step(a)
    total = time.process_time() - t0
    steps = (actions.shape[0] - 1) * actions.shape[1]
    return (
        f"; the rovers' physics {timed.cpu / total:.0%} of its CPU (ceiling "
        f"{steps / timed.cpu:,.0f} env-steps/s)"
    )


def _sync(n: int) -> Any:
    """Gymnasium's ``SyncVectorEnv`` over ``n`` single envs, autoreset as the vector env's."""
    from gymnasium.vector import AutoresetMode, SyncVectorEnv

    from amsa_phys.gym import FollowEnv

    return SyncVectorEnv([FollowEnv] * n, autoreset_mode=AutoresetMode.NEXT_STEP)


def vector(reps: int, report: Report, quick: bool, mark: Mark = _nothing) -> None:
    """The vector env against SyncVectorEnv at each size of :data:`SYNC_SIZES`, then alone at
    :data:`LARGE` envs."""
    from amsa_phys.gym.vector import FollowVecEnv

    budget = 600 if quick else 6000  # env-steps a repetition and side
    for n in SYNC_SIZES:
        mark()
        vec, sync = FollowVecEnv(n), _sync(n)
        actions = np.random.default_rng(n).uniform(-1, 1, (max(4, budget // n), n, 2))
        ours, theirs = [], []
        for i in range(reps):
            ours.append(_vec_rate(vec, actions, i))
            theirs.append(_vec_rate(sync, actions, i))
        share = physics_share(vec, actions, reps)
        vec.close()
        sync.close()
        ratio = [o / s for o, s in zip(ours, theirs, strict=True)]
        aim = 5.0 if n >= FIVE_FROM else 1.0
        report(
            f"vector env, {n} envs / SyncVectorEnv",
            f"{med(ratio)}; vector env {statistics.median(ours):,.0f} env-steps/s "
            f"({vec.stepping}), SyncVectorEnv {statistics.median(theirs):,.0f}{share}",
            f">= {aim:g}",
            statistics.median(ratio) >= aim,
        )
    mark()
    vec = FollowVecEnv(LARGE)
    steps = 3 if quick else LARGE_STEPS
    actions = np.random.default_rng(LARGE).uniform(-1, 1, (steps, LARGE, 2))
    resets: list[float] = []
    rates = [_vec_rate(vec, actions, i, resets=resets) for i in range(reps)]
    share = physics_share(vec, actions, reps)
    report(
        f"vector env, {LARGE} envs, one thread, env-steps/s (CPU)",
        med(rates) + share,
        "",
        None,
    )
    report(
        f"vector env, {LARGE} envs: a reset (every env's new episode), s (CPU)",
        med(resets) + f"; {LARGE_STEPS} steps of an episode take "
        f"{LARGE * LARGE_STEPS / statistics.median(rates):.2f} s",
        "",
        None,
    )
    # both cores: the batch's physics step split between two threads (``threads=2``), in
    # wall time (what two cores are for), interleaved with one thread's wall time
    mark()
    two = FollowVecEnv(LARGE, threads=THREADS)
    one_wall, two_wall = [], []
    for i in range(reps):
        one_wall.append(_vec_rate(vec, actions, i, time.perf_counter))
        two_wall.append(_vec_rate(two, actions, i, time.perf_counter))
    vec.close()
    two.close()
    speedup = [t / o for t, o in zip(two_wall, one_wall, strict=True)]
    report(
        f"vector env, {LARGE} envs, threads={THREADS}, env-steps/s (wall)",
        f"{med(two_wall)}; {statistics.median(speedup):.2f}x one thread's rate "
        f"(one thread {statistics.median(one_wall):,.0f} env-steps/s, wall)",
        f">= {LARGE_RATE}",
        statistics.median(two_wall) >= LARGE_RATE,
    )


# -- the engine against the C step ---------------------------------------------------------
def _c_step_alone(duration: float, rate: int = 100) -> float:
    """CPU seconds of the compiled physics step alone on scenario1's two rovers."""
    import bench_run

    from amsa_phys.physics import compiled
    from amsa_phys.physics.bodyio import BodyIO
    from amsa_phys.physics.forces import ground_list

    space, rovers = bench_run.two_rovers()
    grounds = [ground_list(r, bench_run.GROUND, bench_run.GROUND) for r in rovers]
    io = BodyIO(space, [r.body for r in rovers])
    if not compiled.usable(io):
        raise RuntimeError("the compiled step is not built (no C compiler at install)")
    step = compiled.CompiledFewRovers(io, rovers, 1.0 / rate, (100.0, 1e4), grounds)
    step.advance()  # pymunk checks new bodies at the first step: not the loop's cost
    advance = step.advance
    t0 = time.process_time()
    for _ in range(int(duration * rate)):
        advance()
    return time.process_time() - t0


def engine(reps: int, report: Report, quick: bool, mark: Mark = _nothing) -> None:
    """``amsa_phys.run`` of scenario1 against the compiled step alone, interleaved."""
    import amsa_phys as ap
    from amsa_phys.physics import compiled

    mark()
    if not compiled.active():
        report("ap.run scenario1 / C step alone", "skipped; no compiled step", "<= 6.1", False)
        return
    duration = 30.0 if quick else 300.0
    ap.run(SCENARIO1, duration=1)  # imports and first calls out of the way
    runs, floor = [], []
    for _ in range(reps):
        t0 = time.process_time()
        ap.run(SCENARIO1, duration=duration)
        runs.append(time.process_time() - t0)
        floor.append(_c_step_alone(duration))
    ratio = [r / f for r, f in zip(runs, floor, strict=True)]
    report(
        "ap.run scenario1 / C step alone",
        f"{med(ratio)}; ap.run {statistics.median(runs) * 1e3:.1f} ms CPU, C step "
        f"{statistics.median(floor) * 1e3:.1f} ms, {duration:g} s simulated",
        f"<= {FLOOR_RATIO:g}",
        statistics.median(ratio) <= FLOOR_RATIO,
    )


# -- the whole process ------------------------------------------------------------------------
def child_cpu(argv: list[str]) -> float:
    """CPU seconds (user + system) of one process and everything it forked (``getrusage``:
    microseconds, not ``os.times``' 10 ms ticks)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(argv, check=False, capture_output=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def process(reps: int, report: Report, quick: bool, mark: Mark = _nothing) -> None:
    """The whole ``run --headless --no-plot`` process against ``python -c pass``."""
    mark()
    bare, run = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(reps):
            argv = [sys.executable, "-m", "amsa_phys", "run", str(SCENARIO1), "--headless"]
            argv += ["--duration", "300", "-q", "--no-plot", "--out", f"{tmp}/r{i}"]
            bare.append(child_cpu([sys.executable, "-c", "pass"]))
            run.append(child_cpu(argv))
    ratio = [r / b for r, b in zip(run, bare, strict=True)]
    bytecode = "no .pyc written" if os.environ.get("PYTHONDONTWRITEBYTECODE") else ".pyc allowed"
    report(
        "run --headless --no-plot process CPU / python -c pass",
        f"{med(ratio)}; {statistics.median(run):.3f} s vs {statistics.median(bare):.3f} s "
        f"({bytecode})",
        f"<= {START_RATIO:g}",
        statistics.median(ratio) <= START_RATIO,
    )


ROWS: dict[str, Callable[[int, Report, bool, Mark], None]] = {
    "single": single,
    "vector": vector,
    "run": engine,
    "process": process,
}


def run_all(
    reps: int,
    report: Report = print_report,
    mark: Mark = _nothing,
    only: list[str] | None = None,
    quick: bool = False,
) -> None:
    """Every row of :data:`ROWS` (or ``only`` these), in this order."""
    for name in only or list(ROWS):
        ROWS[name](reps, report, quick, mark)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reps", type=int, default=5, help="repetitions a row (default 5)")
    parser.add_argument("--only", nargs="*", choices=list(ROWS), default=list(ROWS))
    parser.add_argument("--quick", action="store_true", help="a smoke run: 1 rep, few steps")
    parser.add_argument(
        "--save",
        action="store_true",
        help="write the rows to benchmarks/results/perf.json and regenerate the docs' tables",
    )
    args = parser.parse_args()
    if args.reps < 1:
        parser.error("--reps must be at least 1")
    reps = 1 if args.quick else args.reps
    report, mark = print_report, _nothing
    recorder = None
    if args.save:
        import results

        recorder = results.Recorder(reps)
        rec = recorder

        def report(name: str, measured: str, target: str, ok: bool | None) -> None:
            print_report(name, measured, target, ok)
            rec.add(name, measured, target, ok)

        def mark() -> None:
            rec.start("speed")  # each row's load is taken from its own start

    print(
        f"# {os.cpu_count()} cores, Python {sys.version.split()[0]}, median of {reps} "
        f"(min, max), CPU time, load {os.getloadavg()[0]:.2f}",
        flush=True,
    )
    run_all(reps, report, mark, args.only, args.quick)
    if recorder is not None:
        import results

        # a sitting of some rows (--only) keeps the other rows of the target as they were
        fresh = {r.figure for r in recorder.rows}
        kept = [
            results.Row(**r)
            for r in results.load()
            if r["target"] == "speed" and r["figure"] not in fresh
        ]
        recorder.rows[:0] = kept
        recorder.save()
        results.write_pages()


if __name__ == "__main__":
    main()
