"""Headless run speed: scenario1 against a bare pymunk loop in the same process.

Prints the real-time factor of the full engine (all eight components, trace at 20 Hz to a
file) and of a bare loop that steps the same two rover bodies with the same wheel model at
the same physics rate (the same force code and batch I/O the engine's physics uses, no
components, no trace, no scheduler) — the floor the engine is measured against. Median of
N repetitions, min and max shown.
Run: ``python benchmarks/bench_run.py [--reps 5] [--duration 300]``.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from fractions import Fraction
from pathlib import Path

import pymunk
import yaml

from amsa_phys.engine.runner import Simulation
from amsa_phys.engine.tracefile import TraceWriter
from amsa_phys.model.scenario import load_scenario
from amsa_phys.physics import compiled
from amsa_phys.physics.bodyio import BodyIO
from amsa_phys.physics.fewrovers import FewRovers
from amsa_phys.physics.forces import ground_list
from amsa_phys.physics.reference import reference_forces
from amsa_phys.physics.rover import DiffDriveRover
from amsa_phys.physics.space import wheel_model
from amsa_phys.physics.templates import rover_params

ROOT = Path(__file__).resolve().parent.parent
GROUND = (0.8, 0.02)  # the MDE world's (friction, rolling resistance)


def engine_run(duration: float) -> float:
    """Wall seconds for scenario1 through the engine, trace written to a temp dir."""
    sc = load_scenario(ROOT / "scenarios" / "scenario1.yaml", duration=duration)
    with tempfile.TemporaryDirectory() as tmp:
        trace = TraceWriter(Path(tmp) / "trace.csv", list(sc.world.buffers))
        t0 = time.perf_counter()
        Simulation.from_scenario(sc, trace=trace.write).run()
        trace.close()
        return time.perf_counter() - t0


def two_rovers() -> tuple[pymunk.Space, list[DiffDriveRover]]:
    """The two scenario1 rover bodies (default template parameters) driving in a space."""
    space = pymunk.Space()
    world = yaml.safe_load((ROOT / "worlds" / "mde_challenge.yaml").read_text())
    p = rover_params(**world["components"]["Follower"]["params"])
    wheel = wheel_model(p, 9.81)
    rovers = [
        DiffDriveRover(
            space,
            name,
            mass_kg=30.0,
            length_m=0.8,
            width_m=0.6,
            track_m=0.5,
            wheel=wheel,
            x=x,
            y=0.0,
            heading=0.0,
            collision_type=1,
        )
        for name, x in (("Leader", 15.0), ("Follower", 0.0))
    ]
    rovers[0].set_power(22, 22)
    rovers[1].set_power(30, 28)
    return space, rovers


def bare_loop(duration: float, rate: int = 100) -> float:
    """Wall seconds to step two rovers with the same wheel model, no engine around them.

    The floor: the same force code, batch I/O and C step the engine's physics uses.
    """
    space, rovers = two_rovers()
    dt = 1.0 / rate
    grounds = [ground_list(r, GROUND, GROUND) for r in rovers]
    io = BodyIO(space, [r.body for r in rovers])
    if compiled.usable(io):  # the engine's step is the compiled one: the floor uses it too
        fast = compiled.CompiledFewRovers(io, rovers, dt, (100.0, 1e4), grounds)
        t0 = time.perf_counter()
        for _ in range(int(duration * rate)):
            fast.advance()
        return time.perf_counter() - t0
    model = FewRovers(io, rovers, dt, (100.0, 1e4), grounds)
    t0 = time.perf_counter()
    state = io.read()
    for _ in range(int(duration * rate)):
        model.apply(state)
        io.write()
        io.step(dt)
        state = io.read()
    return time.perf_counter() - t0


def fused_loop(duration: float, trace: bool = True) -> float:
    """Wall seconds for scenario1 hand-fused: the least any scheduler could add (context).

    The same component objects, physics hook and trace writer as :func:`engine_run`, called
    from one hand-written loop: no table, no run-length instants, no output checks, no phase
    or live-change tests. What it costs beyond :func:`bare_loop` is the components' and the
    trace's own Python, which no engine can remove. It reads the engine's compiled task list
    (private names) on purpose, so that it calls exactly what the engine calls.
    """
    sc = load_scenario(ROOT / "scenarios" / "scenario1.yaml", duration=duration)
    with tempfile.TemporaryDirectory() as tmp:
        writer = TraceWriter(Path(tmp) / "trace.csv", list(sc.world.buffers))
        sim = Simulation.from_scenario(sc, trace=writer.write)
        sim.initialize()
        values = sim.store.data  # the store's array: tasks and the log's row index it by position
        row = sim.log.row
        write = writer.write if trace else (lambda t, v: None)
        (hook,) = [fn for _, fn, _ in sim._hooks]
        cycle, log_period = sim._cycle, sim._log_period
        num, den = sim._tick_num, sim._tick_den
        due: list[list] = [[] for _ in range(cycle)]
        for task in sim._tasks:
            for off in range(0, cycle, task.period):
                due[off].append((task.comp.do_step, task.reads, task.writes))
        end = int(duration * den / num)
        t0 = time.perf_counter()
        for tick in range(end):
            tasks = due[tick % cycle]
            if tasks:
                now = Fraction(tick * num, den)
                for do_step, inputs, targets in tasks:
                    out = do_step(now, {port: values[buf] for port, buf in inputs})
                    if out:
                        for key, value in out.items():
                            values[targets[key]] = float(value)
            if tick % log_period == 0:
                write(tick * num / den, row(values))
            hook()
        writer.close()
        return time.perf_counter() - t0


def plain_loop(duration: float, rate: int = 100) -> float:
    """Wall seconds for the straightforward loop the issue describes (context, not a target).

    Same bodies and wheel model, written the obvious way (``reference.reference_forces``: pymunk
    properties read and set per body, the wheel functions called per wheel), ``space.step``.
    """
    space, rovers = two_rovers()
    dt = 1.0 / rate
    t0 = time.perf_counter()
    rims = [(0.0, 0.0) for _ in rovers]
    for _ in range(int(duration * rate)):
        for k, r in enumerate(rovers):
            fx, fy, torque, left, right = reference_forces(r, dt, rims[k], (GROUND, GROUND))
            rims[k] = (left, right)
            r.body.force = (fx, fy)
            r.body.torque = torque
        space.step(dt)
    return time.perf_counter() - t0


def main() -> None:
    """Measure and print."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--duration", type=float, default=300.0)
    args = ap.parse_args()
    engine, bare, plain = [], [], []
    for _ in range(args.reps):
        engine.append(engine_run(args.duration))
        bare.append(bare_loop(args.duration))
        plain.append(plain_loop(args.duration))
    d = args.duration
    for name, xs in (
        ("engine (scenario1, 8 components, trace)", engine),
        ("bare pymunk loop, same bodies and wheels", bare),
        ("plain per-property loop (context)", plain),
    ):
        med = statistics.median(xs)
        print(
            f"{name:45s} median {med:6.3f} s  (min {min(xs):.3f}, max {max(xs):.3f})  "
            f"{d / med:7.0f}x real time"
        )
    ratio = statistics.median(engine) / statistics.median(bare)
    print(
        f"engine / bare loop time ratio: {ratio:.2f}  ({d:g} s simulated at 100 Hz, "
        f"{args.reps} repetitions)"
    )


if __name__ == "__main__":
    main()
