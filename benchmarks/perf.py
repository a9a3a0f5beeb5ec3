"""Every performance target of the project, measured in one go: value, baseline, PASS/MISS.

Run: ``python -m benchmarks.perf [--reps 5] [--only NAME ...] [--save]``. Each figure is the
median of ``--reps`` repetitions (min and max shown); each baseline is measured in the same
run, in the same process where the target says so, because these machines are noisy and only
ratios compare. ``--save`` writes every PASS/MISS line to ``benchmarks/results/perf.json`` (with the
load, date and commit) and regenerates the docs' tables from it (``benchmarks/results.py``).
Targets:

* headless run of scenario1 (300 s, 100 Hz physics, 8 components, trace at 20 Hz):
  >= 1000x real time in-process, and <= 1.2x the time of a bare loop stepping the same two
  bodies with the same wheel model;
* the whole ``amsa-phys run --headless`` process (imports, plots, files) < 1.5 s;
* platoon: cost per rover-step flat from 2 to 200 rovers (<= 1.2x the 2-rover cost), and
  >= 50x real time with 200 rovers;
* recording at 1280x720: >= 150 frames/s, within 1.3x of the encoder alone;
* sweeps: speed-up from -j 1 to -j N >= 0.9 N;
* memory: peak RSS of a 1-hour run and of a 1-hour recording within 1.5x of a 1-minute one;
* plots never slow the run: a 200-rover, 30 s run with plots <= 1.3x the same run without;
* start-up: the whole ``run --headless`` process of scenario1 (300 s), CPU of the
  process and its children, <= 15x ``python -c pass`` without plots and <= 40x with plots;
* the Gymnasium env: >= 20,000 steps/s (one env, constant action); the vector env
  >= 50,000 env-steps/s with 1,000 envs;
* batched sweeps (``bench_batch.py``): 1,000 runs of scenario1 <= 5 s on 2 cores and >= 10x
  the process pool; 10,000 runs <= 60 s with RSS <= 1.5x that of 1,000;
* the engine (``bench_engine.py``): batched sweep >= 5x the process pool
  for scenario1 and scenario2 at 1,000 runs of 60 s, 1,000 scenario2 runs <= 5 s; the
  1,000-rover platoon >= 40x real time with the cost per rover-step flat from 200 to 1,000
  rovers; the API run of scenario1; the vector env >= 50,000 env-steps/s at 1,000 envs;
* speed for learning and search (``bench_speed.py``): the single env against CartPole-v1 and
  LunarLander-v3, the vector env at 1 to 1,000 envs against ``SyncVectorEnv``, ``ap.run``
  against the compiled step alone, the whole process against ``python -c pass``.
* benchmarks that need more than this package, each saying so in its rows where what it needs
  is missing: the exported ROS 1 package (``bench_ros.py``: lockstep pipelined within 3x the
  in-process loop, the build, the platoon's launch under 1 GiB), ROS 2 (``bench_ros2.py``),
  IR-SIM (``bench_irsim.py``), the falsification search (``bench_falsify.py``) and PSY-TaLiRo
  beside it (``bench_falsify_peers.py``); and ``--bag`` (``bench_bag.py``), the window's
  frame (``bench_view.py``), and the test suite's duration and memory with the MDE package's
  build (``bench_suite.py``).
"""

from __future__ import annotations

import argparse
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

import bench_batch
import bench_compiled
import bench_engine
import bench_plots
import bench_record
import bench_run
import bench_speed
import bench_sweep
import results
import yaml

from amsa_phys.engine.runner import Simulation
from amsa_phys.model.scenario import load_scenario

ROOT = Path(__file__).resolve().parent.parent
SCENARIO1 = ROOT / "scenarios" / "scenario1.yaml"


def med(xs: list[float]) -> str:
    """``median (min..max)`` with sensible digits."""
    return f"{statistics.median(xs):.4g} (min {min(xs):.4g}, max {max(xs):.4g})"


#: The sitting's rows when ``--save`` is given (``report`` adds each line to it).
RECORDER: results.Recorder | None = None
#: Standard output while ``--save`` records (the PASS/MISS lines other benchmarks print).
TEE: results.Tee | None = None


def report(name: str, measured: str, target: str, ok: bool | None, skipped: bool = False) -> None:
    """Print a figure's line and, with ``--save``, record it (``ok`` None: no aim; ``skipped``:
    not measurable here, ``measured`` saying why)."""
    with results.quiet(TEE):
        results.print_report(name, measured, target, ok, skipped)
    if RECORDER is not None:
        RECORDER.add(name, measured, target, ok, skipped)


# -- headless run ----------------------------------------------------------------------------
def headless(reps: int) -> None:
    engine, bare, plain, fused = [], [], [], []
    for _ in range(reps):  # interleaved, so drifting machine load hits all four alike
        engine.append(300 / bench_run.engine_run(300))
        bare.append(300 / bench_run.bare_loop(300))
        plain.append(300 / bench_run.plain_loop(300))
        fused.append(300 / bench_run.fused_loop(300))
    ratio = [b / e for e, b in zip(engine, bare, strict=True)]  # engine time / bare time
    report("headless run, x real time", med(engine), ">= 1000", statistics.median(engine) >= 1000)
    report(
        "engine time / bare loop time",
        f"{med(ratio)}; bare loop {statistics.median(bare):.0f}x real time",
        "<= 1.2",
        statistics.median(ratio) <= 1.2,
    )
    vs_plain = [p / e for e, p in zip(engine, plain, strict=True)]
    print(
        f"info  engine time / plain per-property loop time: {med(vs_plain)}; plain loop "
        f"{statistics.median(plain):.0f}x real time (the straightforward loop, for context)",
        flush=True,
    )
    vs_fused = [b / f for f, b in zip(fused, bare, strict=True)]
    print(
        f"info  hand-fused loop time / bare loop time: {med(vs_fused)}; the same components "
        "and trace writer called from one hand-written loop (the floor for any scheduler)",
        flush=True,
    )


def process(reps: int) -> None:
    walls = []
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(reps):
            argv = [sys.executable, "-m", "amsa_phys", "run", str(SCENARIO1), "--headless"]
            argv += ["--duration", "300", "--out", f"{tmp}/r{i}", "-q"]
            t0 = time.perf_counter()
            subprocess.run(argv, check=False, capture_output=True)
            walls.append(time.perf_counter() - t0)
    report("amsa-phys run process, s", med(walls), "< 1.5", statistics.median(walls) < 1.5)


def _child_cpu(argv: list[str]) -> float:
    """CPU seconds (user + system) of one process and everything it forked.

    From ``getrusage`` (microseconds), not ``os.times`` (clock ticks: 10 ms, half of a
    ``python -c pass``, so the ratios moved by 0.5x with the rounding alone).
    """
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(argv, check=False, capture_output=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def _compile_package() -> None:
    """Byte-compile the package, as installing a wheel does: an editable install in an
    environment with PYTHONDONTWRITEBYTECODE=1 otherwise compiles every module from source
    in every measured process (+90 ms a run)."""
    import compileall

    compileall.compile_dir(str(ROOT / "amsa_phys"), quiet=1)


def startup(reps: int) -> None:
    """Whole-process CPU of ``run --headless`` over that of ``python -c pass``, interleaved.

    Also the plot child's share (with plots - without) against its floor: importing
    numpy, ``matplotlib.figure`` and the Agg canvas in a bare process, less numpy alone.
    """
    _compile_package()
    bare, no_plot, with_plot, mpl, np_only = [], [], [], [], []
    mpl_code = "import numpy, matplotlib.figure, matplotlib.backends.backend_agg"
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(reps):
            argv = [sys.executable, "-m", "amsa_phys", "run", str(SCENARIO1), "--headless"]
            argv += ["--duration", "300", "-q"]
            bare.append(_child_cpu([sys.executable, "-c", "pass"]))
            no_plot.append(_child_cpu([*argv, "--no-plot", "--out", f"{tmp}/n{i}"]))
            with_plot.append(_child_cpu([*argv, "--out", f"{tmp}/p{i}"]))
            np_only.append(_child_cpu([sys.executable, "-c", "import numpy"]))
            mpl.append(_child_cpu([sys.executable, "-c", mpl_code]))
    r_no = [n / b for n, b in zip(no_plot, bare, strict=True)]
    r_with = [w / b for w, b in zip(with_plot, bare, strict=True)]
    report(
        "run process CPU / python -c pass",
        f"{med(r_no)}; {statistics.median(no_plot):.3f} s",
        "<= 15",
        statistics.median(r_no) <= 15,
    )
    report(
        "same with plots / python -c pass",
        f"{med(r_with)}; {statistics.median(with_plot):.3f} s",
        "<= 40",
        statistics.median(r_with) <= 40,
    )
    child = statistics.median(with_plot) - statistics.median(no_plot)
    floor = statistics.median(mpl) - statistics.median(np_only)
    print(
        f"info  plot child {child:.3f} s CPU (with plots - without); its floor, importing "
        f"matplotlib.figure + Agg beside numpy: {floor:.3f} s; python -c pass "
        f"{statistics.median(bare):.3f} s",
        flush=True,
    )


def gym_env(reps: int) -> None:
    """Env-steps a second of ``amsa_phys/Follow-v0`` on scenario1 cut to 300 s episodes, a
    constant half-power action, each episode run to its end."""
    import numpy as np

    from amsa_phys.gym import FollowEnv

    rates, floor = [], []
    env = FollowEnv(str(SCENARIO1), duration=300)
    action = np.array([0.5, 0.5])
    for i in range(reps):  # interleaved with its floor, so machine load hits both alike
        env.reset(seed=i)
        steps, truncated = 0, False
        t0 = time.process_time()
        while not truncated:
            *_, truncated, _ = env.step(action)
            steps += 1
        rates.append(steps / (time.process_time() - t0))
        floor.append(_gym_floor(env))
    env.close()
    report("gym env steps/s (CPU)", med(rates), ">= 20000", statistics.median(rates) >= 20000)
    share = [r / f for r, f in zip(rates, floor, strict=True)]
    print(
        f"info  its floor, the engine alone with a constant component in the agent's place: "
        f"{med(floor)} env-steps/s; env / floor {med(share)}",
        flush=True,
    )
    from amsa_phys.gym.vector import FollowVecEnv

    for n in (100, 1000):
        vec_rates = []
        for i in range(reps):
            vec = FollowVecEnv(n, str(SCENARIO1), duration=300)
            vec.reset(seed=i)
            actions = np.full((n, 2), 0.5)
            t0 = time.process_time()
            for _ in range(40):
                vec.step(actions)
            vec_rates.append(n * 40 / (time.process_time() - t0))
            vec.close()
        ok = statistics.median(vec_rates) >= 50000
        report(f"vector env, {n} envs: env-steps/s", med(vec_rates), ">= 50000", ok)
    # whole episodes of the packaged scenario (random leader, GPS loss, 120 s): a random
    # policy (an RL run's start), and every run driving at full power into its leader (each
    # run then goes alone at the contact: the vector env's worst case)
    for n, policy in ((1000, "random actions"), (100, "full power, every run rams its leader")):
        vec_rates, alone = [], []
        for i in range(reps):
            rates_i, alone_i = _vec_episode(FollowVecEnv, n, policy.startswith("random"), i)
            vec_rates.append(rates_i)
            alone.append(alone_i)
        print(
            f"info  vector env, {n} envs, {policy}, whole episodes: {med(vec_rates)} "
            f"env-steps/s; runs gone alone {med(alone)}",
            flush=True,
        )


def _vec_episode(make: Any, n: int, random: bool, seed: int) -> tuple[float, float]:
    """(env-steps a second, runs made alone) over one whole episode of the packaged scenario."""
    import numpy as np

    vec = make(n)
    vec.reset(seed=seed)
    rng = np.random.default_rng(seed)
    steps, done = 0, False
    t0 = time.process_time()
    while not done:
        actions = rng.uniform(-1, 1, (n, 2)) if random else np.ones((n, 2))
        *_, truncated, _ = vec.step(actions)
        steps += 1
        done = bool(truncated.all())
    rate = n * steps / (time.process_time() - t0)
    alone = len(getattr(vec._episode, "solo", ()))  # 0 before the column store
    vec.close()
    return rate, float(alone)


def _gym_floor(env: Any) -> float:
    """Env-steps a second of the env's scenario run by the engine alone, the agent's
    component replaced by one that publishes a constant action (no agent, no exchange):
    the rate no single env over this engine can beat."""
    import dataclasses

    from amsa_phys.gym.episode import stand_in

    scenario = env._scenario
    leaf = scenario.world.leaves[env.path]
    out = dict.fromkeys(env.acted, 50.0)

    class Constant(stand_in(leaf.template)):  # type: ignore[misc,valid-type]
        def do_step(self, t: Any, inp: Any) -> dict[str, float]:
            return out

    const = dataclasses.replace(leaf, template=Constant)
    world = dataclasses.replace(scenario.world, leaves={**scenario.world.leaves, env.path: const})
    sim = Simulation.from_scenario(dataclasses.replace(scenario, world=world))
    sim.initialize()
    t0 = time.process_time()
    sim.run()
    return float(scenario.duration) / env.period / (time.process_time() - t0)


# -- platoon scaling --------------------------------------------------------------------------
def platoon_world(cars: int, tmp: Path) -> Path:
    """worlds/platoon.yaml with ``count: cars`` and a scenario around it."""
    world = yaml.safe_load((ROOT / "worlds" / "platoon.yaml").read_text())
    world["components"]["Car"]["count"] = cars
    (tmp / f"platoon{cars}.yaml").write_text(yaml.safe_dump(world))
    scen = tmp / f"platoon{cars}_scenario.yaml"
    scen.write_text(f"world: platoon{cars}.yaml\nduration: 10\nseed: 1\n")
    return scen


def platoon_cost(scen: Path, duration: float) -> tuple[float, int]:
    """(microseconds per rover-step, rovers) for ``duration`` simulated seconds."""
    sc = load_scenario(scen, duration=duration)
    sim = Simulation.from_scenario(sc)
    sim.initialize()
    rovers = len(sim.shared["physics"].rovers)
    t0 = time.perf_counter()
    sim.run()
    wall = time.perf_counter() - t0
    steps = duration * 100
    return wall / (rovers * steps) * 1e6, rovers


def platoon(reps: int) -> None:
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        costs: dict[int, list[float]] = {}
        for cars in (1, 9, 49, 199):
            scen = platoon_world(cars, tmp)
            duration = max(10.0, 400.0 / (cars + 1))
            for _ in range(reps):
                cost, rovers = platoon_cost(scen, duration)
                costs.setdefault(rovers, []).append(cost)
    base = statistics.median(costs[2])
    for rovers, xs in costs.items():
        rt = [1e6 / (c * rovers * 100) for c in xs]
        print(
            f"      platoon {rovers:3d} rovers: {med(xs)} us per rover-step, {med(rt)}x real time"
        )
    worst = max(statistics.median(xs) for xs in costs.values()) / base
    report("platoon cost per rover-step vs 2", f"worst {worst:.2f}x", "<= 1.2x", worst <= 1.2)
    rt200 = [1e6 / (c * 200 * 100) for c in costs[200]]
    report("platoon 200 rovers, x real time", med(rt200), ">= 50", statistics.median(rt200) >= 50)


# -- recording -------------------------------------------------------------------------------
def recording(reps: int) -> None:
    fps = bench_record.measure(reps, 30.0, (1280, 720))
    rec = fps["record"]
    report("recording 1280x720, frames/s", med(rec), ">= 150", statistics.median(rec) >= 150)
    ratio = [e / r for r, e in zip(rec, fps["encoder alone"], strict=True)]
    report(
        "record time / encoder-alone time",
        f"{med(ratio)}; render alone {statistics.median(fps['render']):.0f} frames/s",
        "<= 1.3",
        statistics.median(ratio) <= 1.3,
    )


# -- sweeps ----------------------------------------------------------------------------------
def sweeps(reps: int) -> None:
    cores = os.cpu_count() or 1
    single = [bench_sweep.one(1) for _ in range(reps)]
    multi = [bench_sweep.one(cores) for _ in range(reps)]
    speedup = [m / s for s, m in zip(single, multi, strict=True)]
    report(
        f"sweep speed-up -j {cores} / -j 1",
        f"{med(speedup)}; -j 1 {statistics.median(single):.1f} runs/s",
        f">= {0.9 * cores:.1f}",
        statistics.median(speedup) >= 0.9 * cores,
    )


# -- memory ----------------------------------------------------------------------------------
#: Starts the measured command and prints its peak RSS (KiB) as the kernel accounts it.
_LAUNCH = (
    "import os, subprocess, sys\n"
    "p = subprocess.Popen(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)\n"
    "print(os.wait4(p.pid, 0)[2].ru_maxrss)\n"
)


def peak_rss_mib(argv: list[str]) -> float:
    """Peak resident memory of a command (MiB), from the kernel's own accounting.

    Started from a small launcher, not from this process: a child (v)forked from the
    benchmark process, which is ~200 MiB by the time this runs, counts the parent's pages in
    its own peak until it execs, and every figure read ~185 MiB whatever the run did.
    """
    out = subprocess.run(
        [sys.executable, "-c", _LAUNCH, *argv], capture_output=True, text=True, check=True
    )
    return int(out.stdout) / 1024


def memory(reps: int) -> None:
    with tempfile.TemporaryDirectory() as tmp:

        def run(duration: int, record: bool, i: int) -> float:
            argv = [sys.executable, "-m", "amsa_phys", "run", str(SCENARIO1), "--headless"]
            argv += ["--duration", str(duration), "--out", f"{tmp}/m{duration}{record}{i}"]
            argv += ["-q", "--no-plot"]
            if record:
                argv += ["--record", f"{tmp}/v{duration}{i}.mp4", "--size", "320x240"]
                argv += ["--speedup", "10"]
            return peak_rss_mib(argv)

        for record, label in ((False, "run"), (True, "recording")):
            short = [run(60, record, i) for i in range(reps)]
            long = [run(3600, record, i) for i in range(reps)]
            ratio = statistics.median(long) / statistics.median(short)
            report(
                f"peak RSS 1 h / 1 min {label}",
                f"{ratio:.2f} ({statistics.median(long):.0f} vs "
                f"{statistics.median(short):.0f} MiB)",
                "<= 1.5",
                ratio <= 1.5,
            )


def plots(reps: int) -> None:
    measured, ok = bench_plots.verdict(reps)  # 200 rovers, 30 s, whole processes
    report("200-rover run, plots / --no-plot", measured, "<= 1.3", ok)


def batched(reps: int) -> None:
    """Batched sweeps: 1,000 and 10,000 runs against the pool (bench_batch.py)."""
    bench_batch.targets()


def _bench(name: str) -> Any:
    """A benchmark module imported when its target runs (ROS's, IR-SIM's, PSY-TaLiRo's
    benchmarks import what the others never need)."""
    import importlib

    return importlib.import_module(name)


#: The ``suite`` target's choices (``--suite``, ``--suite-tests``)
SUITE: dict[str, Any] = {}

TARGETS: dict[str, Callable[[int], None]] = {
    "headless": headless,
    "process": process,
    "platoon": platoon,
    "recording": recording,
    "sweeps": sweeps,
    "memory": memory,
    "plots": plots,
    # compiled step vs pure, process, --help, 1,000-rover platoon (bench_compiled.py)
    "compiled": lambda reps: bench_compiled.run_all(reps, report),
    "batched": batched,
    "startup": startup,  # whole process vs python -c pass
    "gym": gym_env,
    # the column store and the run axis (bench_engine.py): batched vs pool for
    # scenario1 and scenario2, the 1,000-rover platoon, the API run, the vector env
    "engine": lambda reps: [bench_engine.TARGETS[n](reps) for n in bench_engine.TARGETS],
    # the speed table: each row against its baseline, load taken per row (bench_speed.py)
    "speed": lambda reps: bench_speed.run_all(reps, report, _mark_row("speed")),
    # the exported ROS 1 package: lockstep, its floor, the build, the platoon's memory
    "ros": lambda reps: _bench("bench_ros").perf(reps, report),
    "ros2": lambda reps: _bench("bench_ros2").perf(reps, report),
    "irsim": lambda reps: _bench("bench_irsim").perf(reps, report),
    "bag": lambda reps: _bench("bench_bag").perf(reps, report),
    "view": lambda reps: _bench("bench_view").perf(reps, report),
    "falsify": lambda reps: _bench("bench_falsify").perf(reps, report),
    "falsify_peers": lambda reps: _bench("bench_falsify_peers").perf(reps, report),
    # the physics page's fidelity figures: skid convergence, drifts vs the tyre law, turns
    "fidelity": lambda reps: _bench("bench_fidelity").perf(reps, report),
    # where the time goes: each part's share of the single env's and ap.run's CPU (INFO)
    "profile": lambda reps: _bench("profile_loop").perf(reps, report),
    # the test suite's tiers (once each) and the exported MDE package's build
    "suite": lambda reps: _bench("bench_suite").perf(reps, report, **SUITE),
}


def _mark_row(target: str) -> Callable[[], None]:
    """What a benchmark calls before each row, so that the row's load is its own."""

    def mark() -> None:
        if RECORDER is not None:
            RECORDER.start(target)

    return mark


def _junits(ap: argparse.ArgumentParser, args: argparse.Namespace) -> dict[str, Path]:
    """``--suite-junit quick=FILE full=FILE`` checked before anything is measured (a bad one
    is one line and exit 2)."""
    junits: dict[str, Path] = {}
    for item in args.suite_junit:
        tier, sep, file = item.partition("=")
        if not sep or tier not in ("quick", "full") or not file:
            ap.error(f"--suite-junit {item}: expected quick=FILE or full=FILE")
        try:
            _bench("bench_suite").junit_time(Path(file))
        except ValueError as exc:
            ap.error(f"--suite-junit {item}: {exc}")
        junits[tier] = Path(file)
    return junits


#: The most repetitions of the targets that take minutes each (the memory's hour-long runs,
#: ROS launches, the whole test suite): ``--reps`` above it is cut to it
REPS_CAP = {"memory": 3, "ros": 2, "ros2": 3, "suite": 1}


def main() -> None:
    """Measure every target (or ``--only`` some) and print PASS/MISS lines."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--only", nargs="*", choices=list(TARGETS), default=list(TARGETS))
    ap.add_argument(
        "--suite",
        nargs="*",
        choices=["quick", "full", "build"],
        default=["quick", "full", "build"],
        help="what the suite target measures: the quick tier, the full suite, the MDE "
        "package's build (default all three)",
    )
    ap.add_argument(
        "--suite-junit",
        nargs="*",
        default=[],
        metavar="TIER=FILE",
        help="take a tier's time and counts from a JUnit XML report of a run already made "
        "(pytest --junitxml=FILE) instead of running it: quick=FILE, full=FILE",
    )
    ap.add_argument(
        "--suite-tests",
        nargs="*",
        default=[],
        metavar="PATH",
        help="run only these tests in each tier (to check the suite target itself)",
    )
    ap.add_argument(
        "--save",
        action="store_true",
        help="write the figures to benchmarks/results/perf.json and regenerate the docs' tables",
    )
    args = ap.parse_args()
    SUITE.update(parts=tuple(args.suite), paths=tuple(args.suite_tests), junits=_junits(ap, args))
    global RECORDER, TEE
    if args.save:
        RECORDER = results.Recorder(args.reps)
        TEE = results.Tee(sys.stdout, RECORDER)
        sys.stdout = TEE
    print(
        f"# {os.cpu_count()} cores, Python {sys.version.split()[0]}, "
        f"median of {args.reps} (min, max)",
        flush=True,
    )
    failed = []
    try:
        for name in args.only:
            if not _measure(name, max(1, min(args.reps, REPS_CAP.get(name, args.reps)))):
                failed.append(name)
    except KeyboardInterrupt:
        print("interrupted: the targets measured so far are kept", file=sys.stderr)
        sys.exit(130)
    finally:
        if RECORDER is not None:
            results.write_pages()
    if failed:
        sys.exit(f"the benchmark of {', '.join(failed)} stopped (its row says how)")


def _measure(name: str, reps: int) -> bool:
    """Measure one target; with ``--save`` its rows go to the file at once, so a sitting of
    hours keeps every target finished before a failure or a Ctrl-C. A target whose benchmark
    raises gets one MISS row saying so (its old rows would describe other code) and the
    sitting goes on; a Ctrl-C drops the interrupted target's partial rows."""
    if RECORDER is not None:
        RECORDER.start(name)
        RECORDER.reps = reps
    try:
        TARGETS[name](reps)
    except KeyboardInterrupt:
        if RECORDER is not None:
            RECORDER.rows = [r for r in RECORDER.rows if r.target != name]
        raise
    except Exception as exc:  # one target's failure must not lose the others
        import traceback

        traceback.print_exc()
        why = f"{type(exc).__name__}: {exc}".splitlines()[0][:300]
        figure = f"{name}: the benchmark stopped"
        with results.quiet(TEE):
            print(f"MISS  {figure} ({why})", flush=True)
        if RECORDER is not None:  # no number read from the message: it is not a figure
            RECORDER.add_row(figure, None, None, why, "", False)
        return False
    finally:
        if RECORDER is not None:
            RECORDER.save()
            # the pages follow the file at once: a later target (the suite's tiers run the
            # tests that hold the pages to the file) must find the tree consistent
            results.write_pages()
    return True


if __name__ == "__main__":
    main()
