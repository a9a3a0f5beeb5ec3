"""The fast paths of issue 8 against the plain code they replace.

Each speed-up keeps a slower, obvious route alive (reference wheel model, documented
``pymunk.batch`` calls, plain ``repr`` rows); these tests hold the two to the same results.
"""

from __future__ import annotations

import array
import math
import random
import struct
from fractions import Fraction
from pathlib import Path

import numpy as np
import pymunk
import pytest
from regimes import DT, every_regime, make_rovers

from amsa_phys.engine import schedule
from amsa_phys.engine.runner import Simulation
from amsa_phys.engine.tracefile import TraceWriter, format_rows
from amsa_phys.model.scenario import Change, load_scenario
from amsa_phys.physics import bodyio
from amsa_phys.physics.bodyio import BodyIO
from amsa_phys.physics.fewrovers import FewRovers
from amsa_phys.physics.fleet import Fleet
from amsa_phys.physics.forces import ground_list
from amsa_phys.physics.reference import reference_forces

ROOT = Path(__file__).resolve().parents[2]


def test_inlined_forces_equal_the_reference_wheel_model() -> None:
    space, rovers, rims, grounds = every_regime(20)
    terms = [ground_list(r, *g) for r, g in zip(rovers, grounds, strict=True)]
    model = FewRovers(BodyIO(space, [r.body for r in rovers]), rovers, DT, (100.0, 1e4), terms)
    model.rims = [u for pair in rims for u in pair]
    model.apply(model.state)
    for k, r in enumerate(rovers):
        o = model.rows[k] * bodyio.FORCE
        got = (*model.io.forces[o : o + 3], *model.rim_speeds(k))
        expected = reference_forces(r, DT, rims[k], grounds[k])
        assert got == pytest.approx(expected, rel=1e-11, abs=1e-11), f"rover {k}"


def test_fleet_equals_the_float_path_in_every_regime() -> None:
    """The array fleet (many rovers) and the float path give the same bits, branch by
    branch: one pure arithmetic (``forces.rover_step``) under two bookkeepings; the mix of
    regimes puts every rare branch in the same call."""
    results = []
    for cls in (FewRovers, Fleet):
        space, rovers, rims, grounds = every_regime(60)
        terms = [ground_list(r, *g) for r, g in zip(rovers, grounds, strict=True)]
        model = cls(BodyIO(space, [r.body for r in rovers]), rovers, DT, (100.0, 1e4), terms)
        if cls is Fleet:
            model.rims = np.array(rims).T.copy()
        else:
            model.rims = [u for pair in rims for u in pair]
        for _ in range(30):  # the regimes change as the steps go: rims stick, tyres grip
            model.advance()
        results.append([(*model.kinematics(k), *model.rim_speeds(k)) for k in range(len(rovers))])
    for k, (a, b) in enumerate(zip(*results, strict=True)):
        assert a == b, f"rover {k}"


@pytest.mark.parametrize("direct", [True, False], ids=["direct", "documented"])
def test_batch_io_reads_and_writes_what_pymunk_holds(direct: bool) -> None:
    space, rovers = make_rovers(2)
    rovers[1].body.velocity = (1.5, -2.0)
    rovers[1].body.angular_velocity = 0.25
    io = BodyIO(space, [r.body for r in rovers], direct=direct)
    assert io.direct is direct
    state = io.read()
    i = io.rows[1] * bodyio.STATE
    assert state[i : i + 6] == [5.0, 1.0, 0.3, 1.5, -2.0, 0.25]
    o = io.rows[1] * bodyio.FORCE
    io.forces[o : o + 3] = array.array("d", [3.0, -4.0, 0.5])
    io.write()
    assert tuple(rovers[1].body.force) == (3.0, -4.0)
    assert rovers[1].body.torque == 0.5
    assert tuple(rovers[0].body.force) == (0.0, 0.0)


def test_documented_batch_route_gives_the_same_run(monkeypatch: pytest.MonkeyPatch) -> None:
    def final_state() -> list[list[float]]:
        sc = load_scenario(ROOT / "scenarios" / "scenario1.yaml", duration=20)
        sim = Simulation.from_scenario(sc)
        sim.run()
        return [list(r.kinematics()) for r in sim.shared["physics"].rovers]

    direct = final_state()
    monkeypatch.setattr(bodyio, "_direct_available", lambda space: False)
    assert final_state() == direct


def test_trace_rows_equal_plain_repr_whatever_changes(tmp_path: Path) -> None:
    rng = random.Random(1)
    values = [0.0, 1.0, 2.0, 3.0]
    writer = TraceWriter(tmp_path / "trace.csv", ["a", "b", "c", "d"])
    expected = ["t,a,b,c,d"]
    for k in range(700):  # several chunks, the last one partial
        j = rng.randrange(4)
        tiny_or_huge = rng.uniform(-9.9, 9.9) * 10.0 ** rng.randint(-30, 30)
        values[j] = rng.choice(
            [rng.random(), float(k), values[(j + 1) % 4], -0.0, tiny_or_huge, 1e-05, 1e16]
        )
        writer.write(k * 0.05, list(values))
        expected.append(",".join(map(repr, [k * 0.05, *values])))
    writer.close()
    assert (tmp_path / "trace.csv").read_text().splitlines() == expected


def test_trace_spelling_is_repr_for_any_float() -> None:
    """orjson's spelling of exponents differs from repr's (and between its versions);
    format_rows must give repr's bytes for every finite float, and NaN/inf must not
    become JSON's null."""
    rng = random.Random(7)
    floats = [
        struct.unpack("<d", rng.getrandbits(64).to_bytes(8, "little"))[0] for _ in range(6000)
    ]
    floats = [v for v in floats if math.isfinite(v)]
    floats += [5e-324, 1.7976931348623157e308, 9999999999999998.0, 1e16, 1e-4, 9.9e-05, 0.0]
    rows = [tuple(floats[i : i + 7]) for i in range(0, len(floats) - 7, 7)]
    expected = "".join(",".join(map(repr, row)) + "\n" for row in rows).encode()
    assert format_rows(rows) == expected
    assert format_rows([(0.5, math.nan, -math.inf)]) == b"0.5,nan,-inf\n"
    assert format_rows([]) == b""


def test_batch_io_refuses_a_body_added_behind_its_back() -> None:
    space, rovers = make_rovers(2)
    io = BodyIO(space, [r.body for r in rovers])
    extra = pymunk.Body(1.0, 1.0)
    space.add(extra, pymunk.Circle(extra, 0.1))
    space.step(0.01)  # pymunk validates the new body
    with pytest.raises(RuntimeError, match="added to the space after"):
        io.read()


def scheduled_run(tmp_path: Path, chunks: list[int] | None) -> tuple[list[list[float]], list]:
    """The MDE world with a timeline change and a live change inside runs of physics-only
    instants (t = 2.03 s, between two 20 Hz log rows); ``chunks`` advance in uneven steps."""
    scen = tmp_path / "s.yaml"
    scen.write_text(
        f"world: {ROOT / 'worlds' / 'mde_challenge.yaml'}\n"
        "duration: 6\nseed: 3\n"
        "timeline:\n  - {at: 2.03, set: {Leader.cruisePower: 60}}\n"
    )
    rows: list[list[float]] = []
    sim = Simulation.from_scenario(load_scenario(scen), trace=lambda t, v: rows.append([t, *v]))
    sim.initialize()
    tick = 0
    for step in chunks or [sim.grid.ticks(Fraction(6))]:
        tick += step
        sim.advance(tick)
        if tick == 311:  # queue a live change between two physics-only instants
            sim.apply_live(Change("Leader", "cruisePower", 30.0))
    sim.advance(sim.grid.ticks(Fraction(6)))
    changes = [(at, c.leaf, c.param, c.value) for at, c in sim.change_log]
    return rows, [*changes, [tuple(r.kinematics()) for r in sim.shared["physics"].rovers]]


def test_runs_of_physics_only_instants_change_nothing(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    chunks = [7, 300, 4, 1, 37, 251]  # passes tick 311 and cuts runs in their middle
    fast = scheduled_run(tmp_path, chunks)
    assert scheduled_run(tmp_path, [311, 289]) == fast  # whole runs, the tight loop
    assert fast[1][0][0] == Fraction(203, 100)  # the timeline change, at its exact instant
    assert fast[1][1][0] == Fraction(312, 100)  # the live change, at the next instant
    # the same run with every instant its own table entry (no runs)
    monkeypatch.setattr(
        schedule,
        "runs",
        lambda instants: [
            (i.offset, tuple(i.tasks), i.log, tuple(i.hooks), i.offset, 1) for i in instants
        ],
    )
    assert scheduled_run(tmp_path, chunks) == fast
    assert scheduled_run(tmp_path, [1] * 600) == fast


@pytest.mark.parametrize("cars", [5, 45], ids=["float path", "fleet"])
def test_commanding_many_rovers_equals_one_by_one(tmp_path: Path, cars: int) -> None:
    """``PhysicsWorld.set_powers`` (the grouped controlled robots) saturates like
    ``set_power`` and reaches whatever force model the world runs."""
    import numpy as np
    import yaml

    world = yaml.safe_load((ROOT / "worlds" / "platoon.yaml").read_text())
    world["components"]["Car"]["count"] = cars
    (tmp_path / "w.yaml").write_text(yaml.safe_dump(world))
    (tmp_path / "s.yaml").write_text("world: w.yaml\nduration: 2\n")
    sims = []
    for _ in range(2):
        sim = Simulation.from_scenario(load_scenario(tmp_path / "s.yaml"))
        sim.initialize()
        sim.advance(10)
        sims.append(sim)
    rng = np.random.default_rng(3)
    left = rng.uniform(-150, 150, cars)
    right = rng.uniform(-150, 150, cars)
    left[0], right[1] = np.nan, 100.0
    # inside, at and just outside the driver's 2 % deadband, and -0.0
    left[2], right[2], left[3], right[3], left[4] = 1.5, -2.0, 2.0000001, -1.9999, -0.0
    many, one = (s.shared["physics"] for s in sims)
    chosen = many.rovers[1:]  # the cars, not the leader
    many.set_powers(chosen, many.index_of(chosen), left, right)
    for rover, lp, rp in zip(one.rovers[1:], left.tolist(), right.tolist(), strict=True):
        rover.set_power(lp, rp)
    # a single command after the group's wins (the leader's is set this way every step)
    many.rovers[2].set_power(33.0, -7.5)
    one.rovers[2].set_power(33.0, -7.5)

    def bits(r: object) -> list[bytes]:
        return [
            np.float64(getattr(r, k)).tobytes()
            for k in ("power_l", "power_r", "drive_l", "drive_r")
        ]

    for a, b in zip(many.rovers, one.rovers, strict=True):
        assert bits(a) == bits(b)
    assert one.rovers[3].drive_l == 0.0  # the band bites
    assert one.rovers[3].drive_r == -2.0
    for sim in sims:
        sim.run()
    finals = [[list(r.kinematics()) for r in s.shared["physics"].rovers] for s in sims]
    assert finals[0] == finals[1]
