"""Batched sweeps (``--executor batch``): each row is the row of its run made alone (equal
with the compiled step, within 1e-9 on the pure path), a batched sweep is byte-identical to
itself across -j and batch sizes, the runs a batch cannot hold go one per process (said
once), and faults, contacts and dying workers cost their own rows only. The row, fault and
byte-identity tests run on both physics paths: the compiled one (``_step.column_forces``)
and the pure one (``AMSA_PHYS_PURE=1``)."""

from __future__ import annotations

import csv
import math
import random
from pathlib import Path
from typing import Any

import pytest
from daskcluster import local_cluster

from amsa_phys.cli.main import main
from amsa_phys.engine.multirun import MultiRun
from amsa_phys.physics.columns import ColumnPhysics
from amsa_phys.physics.step_path import PURE_ENV, extension
from amsa_phys.runs.batched import plan_units, run_batch
from amsa_phys.runs.sweep import Axis, SweepPlan, run_job

ROOT = Path(__file__).resolve().parents[2]
WORLD = ROOT / "worlds" / "mde_challenge.yaml"
#: The pure path's bound. Why not bitwise there: its batch computes the rovers' forces by the
#: numpy model, which rounds unlike the scalar code in the last bits; over a run that stays
#: ~1e-13 in every metric. With the compiled step a batch's forces are the single run's own C
#: code and its integration is Chipmunk's (``physics/columns.py``): the rows are equal (the
#: components' array steps could still round apart where numpy's transcendental functions
#: and libm's differ, ``engine/batch.py``; on these grids, here, they do not).
TOL = 1e-9
#: The force model a batch takes on each path (``compiled.columns_compiled``).
MODEL = {"compiled": "ColumnForces", "pure": "Fleet"}


@pytest.fixture(params=["compiled", "pure"])
def step_path(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> Any:
    """Run the test on the compiled path and on the pure path (``AMSA_PHYS_PURE=1``, which a
    sweep's worker processes inherit); yields the path and the force models the batches in
    this process chose."""
    if request.param == "compiled":
        if extension() is None:
            pytest.skip("the compiled step was not built (no C compiler at install)")
        monkeypatch.delenv(PURE_ENV, raising=False)
    else:
        monkeypatch.setenv(PURE_ENV, "1")
    chosen: list[str] = []
    start = ColumnPhysics._start

    def spy(self: ColumnPhysics) -> Any:
        model = start(self)
        chosen.append(type(model).__name__)
        return model

    monkeypatch.setattr(ColumnPhysics, "_start", spy)
    return request.param, chosen


CONTEXTS = {
    "nominal": {"Leader.behavior": 1},
    "lossy": {"LeaderGPS.lostDataGPS": 20, "MyNormalizePower.motorCoef": 70},
    "random leader": {"Leader.behavior": 4, "LeaderGPS.lostDataGPS": 10},
}


def scenario(tmp_path: Path, extra: str = "") -> Path:
    """The MDE challenge with a box in the leader's lane (only a fast leader reaches it in
    30 s) and a timeline: a new phase at 10 s (the follower closes to 12 m) and a change
    inside it (the leader's GPS starts losing fixes)."""
    path = tmp_path / "s.yaml"
    path.write_text(
        f"world: {WORLD}\nduration: 30\nseed: 3\n"
        "quality: {signal: MyDistanceMonitor.distanceFollowerToLeader, reference: 15, "
        "tolerance: 1.5}\n"
        "physics:\n  obstacles: [{type: box, x: 36, y: 0.5, width: 1, height: 3}]\n"
        "timeline:\n"
        "  - {at: 10, set: {MyFollowerController.distanceRef: 12}}\n"
        "  - {at: 20.5, set: {LeaderGPS.lostDataGPS: 30}, new_phase: false}\n" + extra
    )
    return path


def random_plan(path: Path, seed: int) -> SweepPlan:
    """A random grid: contexts × Kv × the leader's cruise power, two seeds."""
    rng = random.Random(seed)
    kv = tuple(sorted({round(rng.uniform(0.03, 0.5), 4) for _ in range(3)}))
    cruise = tuple(sorted({7.0, round(rng.uniform(22.0, 30.0), 2)}))
    axes = [
        Axis("context", tuple(CONTEXTS)),
        Axis("MyFollowerController.Kv", kv),
        Axis("Leader.cruisePower", cruise),
    ]
    return SweepPlan(path, axes, seeds=2, base_seed=3, contexts=CONTEXTS)


def assert_rows_close(alone: dict[str, Any], batched: dict[str, Any], path: str) -> None:
    """Equal rows on the compiled path; within :data:`TOL` on the pure path."""
    tol = 0.0 if path == "compiled" else TOL
    assert alone.keys() == batched.keys()
    for key, value in alone.items():
        other = batched[key]
        if isinstance(value, float) and isinstance(other, float):
            assert math.isclose(value, other, rel_tol=0, abs_tol=tol), (alone["run"], key)
        else:
            assert value == other, (alone["run"], key)


@pytest.mark.parametrize("seed", [1, 2])
def test_batched_rows_equal_the_runs_made_alone(tmp_path: Path, seed: int, step_path: Any) -> None:
    path, chosen = step_path
    jobs = random_plan(scenario(tmp_path), seed).jobs()
    stats: dict[str, int] = {}
    batched = run_batch(jobs, stats)
    assert chosen == [MODEL[path]]
    alone = [run_job(job) for job in jobs]
    for a, b in zip(alone, batched, strict=True):
        assert_rows_close(a, b, path)
    # the grid holds what the batch must get right: collisions (runs made alone), runs
    # computed in the columns, GPS losses and a random leader (seed-tree streams), and a
    # timeline (phase metrics)
    assert any(r["collisions"] for r in alone)
    assert 0 < stats["contacts"] < len(jobs) // 2  # the rest computed in the columns
    assert all(not r["error"] for r in alone)
    assert all(r["phase1.rms_error"] is not None for r in alone)
    by_seed = {(r["context"], r["seed_index"]): r["rms_error"] for r in alone}
    assert by_seed[("random leader", 0)] != by_seed[("random leader", 1)]


def test_a_run_that_faults_in_a_batch_has_its_own_row_and_the_rest_run(
    tmp_path: Path, step_path: Any
) -> None:
    path_kind, chosen = step_path
    # at full power the leader leaves a 25 m world within the 8 s; at 7 % it does not
    path = scenario(tmp_path, "")
    path.write_text(path.read_text().replace("physics:\n", "physics:\n  extent: 25\n"))
    plan = SweepPlan(
        path, [Axis("Leader.cruisePower", (7.0, 100.0, 8.0))], seeds=1, base_seed=3, duration=8.0
    )
    jobs = plan.jobs()
    stats: dict[str, int] = {}
    batched = run_batch(jobs, stats)
    alone = [run_job(job) for job in jobs]
    assert [bool(r["error"]) for r in batched] == [False, True, False]
    assert "outside" in batched[1]["error"] or "extent" in batched[1]["error"]
    assert stats["faults"] == 1
    assert set(chosen) == {MODEL[path_kind]}
    for a, b in zip(alone, batched, strict=True):
        assert_rows_close(a, b, path_kind)


def rows(out: Path) -> list[dict[str, str]]:
    with (out / "results.csv").open() as fh:
        return list(csv.DictReader(fh))


@pytest.mark.parametrize(
    "step_path",
    ["compiled", pytest.param("pure", marks=pytest.mark.slow)],  # the same property, 8x dearer
    indirect=True,
)
def test_a_batched_sweep_is_byte_identical_across_j_and_batch_sizes(
    tmp_path: Path, step_path: Any
) -> None:
    path = scenario(tmp_path)
    section = (
        "sweep:\n  contexts:\n"
        + "".join(
            f"    {name}: {{{', '.join(f'{k}: {v}' for k, v in sets.items())}}}\n"
            for name, sets in CONTEXTS.items()
        )
        + "  grid: {MyFollowerController.Kv: [0.05, 0.2, 0.35]}\n  seeds: 2\n"
    )
    path.write_text(path.read_text() + section)
    outs = []
    for i, extra in enumerate(
        (["-j", "1", "--batch-size", "1"], ["-j", "1", "--batch-size", "7"], ["-j", "2"])
    ):
        out = tmp_path / f"o{i}"
        argv = ["sweep", str(path), "--duration", "15", "--out", str(out), *extra]
        assert main(argv) == 0
        outs.append((out / "results.csv").read_bytes())
    assert outs[0] == outs[1] == outs[2]
    assert len(rows(tmp_path / "o0")) == 18


def test_runs_a_batch_cannot_hold_go_one_per_process_said_once(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.syspath_prepend(str(ROOT / "tests"))
    path = tmp_path / "d.yaml"
    path.write_text("world:\n  components:\n    D: {template: 'toys:Die', freq: 4}\nduration: 1\n")
    out = tmp_path / "b"
    assert main(["sweep", str(path), "--grid", "D.gain=1,3,4", "-j", "1", "--out", str(out)]) == 0
    err = capsys.readouterr().err
    note = "runs that a batch cannot hold go one per process: D is a user template (Die) "
    assert err.count(note) == 1, err
    local = tmp_path / "l"
    argv = ["sweep", str(path), "--grid", "D.gain=1,3,4", "--executor", "local", "-j", "1"]
    assert main([*argv, "--out", str(local)]) == 0
    assert (out / "results.csv").read_bytes() == (local / "results.csv").read_bytes()


def test_runs_within_reach_at_the_start_are_made_alone_at_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The paper's Fig. 5 starts the follower 1 m behind the leader: such a run is within
    reach before the first step, so the batch's first step would mark it and it would be
    made again alone (every Fig. 5 sweep computed twice, ~3x the time of the process pool).
    It is made alone at once: the batch steps only the runs that start apart, and every row
    is still the run made alone."""
    fig5 = ROOT / "scenarios" / "paper_fig5_kv035.yaml"
    axes = [Axis("Follower.x", (14.0, 0.0)), Axis("MyFollowerController.Kv", (0.05, 0.35))]
    jobs = SweepPlan(fig5, axes, seeds=1, base_seed=1, duration=4).jobs()
    stepped: list[int] = []  # how many runs each batch stepped in its columns
    run = MultiRun.run

    def spy(self: MultiRun) -> Any:
        stepped.append(len(self.scenarios))
        return run(self)

    monkeypatch.setattr(MultiRun, "run", spy)
    stats: dict[str, int] = {}
    batched = run_batch(jobs, stats)
    assert stats["at_start"] == stats["contacts"] == 2  # the two that start 1 m apart
    assert stepped == [2]  # the two that start 15 m apart: computed once, in the columns
    for alone, row in zip([run_job(job) for job in jobs], batched, strict=True):
        assert_rows_close(alone, row, "pure")
    # a batch of Fig. 5 runs only: nothing is stepped in columns at all
    stepped.clear()
    near = [j for j in jobs if dict(j.point)["Follower.x"] == 14.0]
    run_batch(near, stats)
    assert stepped == []


def test_a_mixed_plan_batches_what_it_can(tmp_path: Path) -> None:
    plan = random_plan(scenario(tmp_path), 1)
    jobs = plan.jobs()
    units, notes = plan_units(jobs, workers=2)
    assert notes == []
    assert all(u.batched for u in units)
    assert sorted(j.index for u in units for j in u.jobs) == list(range(len(jobs)))
    plan.keep_dir = str(tmp_path / "runs")
    units, notes = plan_units(plan.jobs(), workers=2)
    assert not any(u.batched for u in units)
    assert notes == [
        "--keep-runs writes every run's directory (its plots cost ~20x the run): "
        f"{len(jobs)} runs go one per process"
    ]


def test_a_batch_whose_worker_dies_costs_the_killing_run_only(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("PYTHONPATH", str(ROOT / "tests"))
    monkeypatch.syspath_prepend(str(ROOT / "tests"))
    path = tmp_path / "d.yaml"
    path.write_text(
        "world:\n  components:\n    D: {template: 'toys:DieMany', freq: 4}\nduration: 1\n"
    )
    out = tmp_path / "o"
    argv = ["sweep", str(path), "--grid", "D.gain=1,2,3,4", "-j", "2", "--batch-size", "2"]
    assert main([*argv, "--out", str(out)]) == 0
    table = rows(out)
    assert [r["D.gain"] for r in table] == ["1", "2", "3", "4"]
    assert [r["error"] for r in table] == [
        "",
        "a worker process died (killed, out of memory, or a crash in native code), twice, "
        "running this job",
        "",
        "",
    ]


@pytest.mark.slow  # the local pool's twin stays quick: test_a_batch_whose_worker_dies_...
def test_on_dask_a_batch_that_kills_its_workers_costs_the_killing_run_only(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    pytest.importorskip("distributed")
    import dask

    monkeypatch.setenv("PYTHONPATH", str(ROOT / "tests"))
    monkeypatch.syspath_prepend(str(ROOT / "tests"))
    path = tmp_path / "d.yaml"
    path.write_text(
        "world:\n  components:\n    D: {template: 'toys:DieMany', freq: 4}\nduration: 1\n"
    )
    argv = ["sweep", str(path), "--grid", "D.gain=1,2,3", "--executor", "dask"]
    argv += ["--batch-size", "3"]
    # one retry: a run queued on the worker the killing run takes down is run again
    with (
        dask.config.set({"distributed.scheduler.allowed-failures": 1}),
        local_cluster() as cluster,
    ):
        code = main([*argv, "--scheduler", cluster.scheduler_address, "--out", str(tmp_path / "o")])
    assert code == 0
    lost = (
        "a worker process died (killed, out of memory, or a crash in native code), "
        "on every worker that ran it"
    )
    table = rows(tmp_path / "o")
    assert table[1]["error"] == lost
    # Dask may also give up on a run that sat queued on the workers the killer took down
    # (a race of its scheduler); the splitting itself is checked without a cluster below
    assert all(r["error"] in ("", lost) for r in table)


def test_a_lost_dask_batch_is_sent_again_one_run_per_task(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from amsa_phys.runs import batched, sweep

    sent: list[int] = []

    def fake_dask_map(fn: Any, items: Any, scheduler: str, lost: Any) -> Any:
        for unit in items:  # a unit holding gain 2 kills every worker it meets
            sent.append(len(unit.jobs))
            killer = any(dict(j.point)["D.gain"] == 2 for j in unit.jobs)
            yield lost(unit) if killer else fn(unit)

    monkeypatch.setattr(sweep, "dask_map", fake_dask_map)
    monkeypatch.syspath_prepend(str(ROOT / "tests"))
    path = tmp_path / "d.yaml"
    path.write_text(
        "world:\n  components:\n    D: {template: 'toys:DieMany', freq: 4}\nduration: 1\n"
    )
    plan = SweepPlan(path, [Axis("D.gain", (1.0, 2.0, 3.0))], seeds=1, base_seed=1)
    units, _ = plan_units(plan.jobs(), workers=1, size=3)
    table = sorted(batched.iter_dask_batched(units, "tcp://nowhere"), key=lambda r: r["run"])
    assert sent == [3, 1, 1, 1]
    assert [bool(r["error"]) for r in table] == [False, True, False]
    assert "on every worker that ran it" in table[1]["error"]


@pytest.mark.skipif(extension() is None, reason="the compiled step is not built here")
@pytest.mark.slow  # batched rows equal runs made alone: test_batched_rows_equal_the_runs_made_alone
def test_the_shipped_context_sweep_gives_the_same_results_batched_or_one_run_per_process(
    tmp_path: Path,
) -> None:
    """A user compared ``--executor batch`` with ``local`` on scenarios/context_sweep.yaml and
    found the random leader's rows 7e-14 apart: numpy's hypot/arctan2 round unlike libm's in
    the monitor's and controller's array steps (engine/libm.py). On the compiled path the
    two executors now write the same results.csv, byte for byte."""
    scen = ROOT / "scenarios" / "context_sweep.yaml"
    argv = ["sweep", str(scen), "-j", "2"]
    assert main([*argv, "--out", str(tmp_path / "batch")]) == 0
    assert main([*argv, "--executor", "local", "--out", str(tmp_path / "local")]) == 0
    batched = (tmp_path / "batch" / "results.csv").read_bytes()
    assert batched == (tmp_path / "local" / "results.csv").read_bytes()


def test_a_gnss_street_batched_gives_the_rows_of_its_runs_made_alone(tmp_path: Path) -> None:
    """A GNSS receiver casts its sky's rays in its run's Space, ignoring every rover. A
    batch's rovers are not in their Space (it is never stepped): the buildings block the
    same sky, so each batched row is its run's made alone (the compiled path: equal; the
    pure path within :data:`TOL`), with the rovers 4 m from a facade (the fixes' multipath
    and blocked sky differ from the open sky's: the rows would too)."""
    scen = tmp_path / "street.yaml"
    scen.write_text(
        f"world: {ROOT / 'worlds' / 'mde_challenge_urban.yaml'}\nduration: 40\nseed: 1\n"
        "quality: {signal: MyDistanceMonitor.distanceFollowerToLeader, reference: 15, "
        "tolerance: 1.5}\n"
        "set: {Leader.behavior: 4, Leader.cruisePower: 9.0}\n"
    )
    plan = SweepPlan(scen, [Axis("MyFollowerController.Kv", (0.1, 0.35))], seeds=2, base_seed=1)
    jobs = plan.jobs()
    stats: dict[str, int] = {}
    batched = run_batch(jobs, stats)
    alone = [run_job(job) for job in jobs]
    path = "pure" if extension() is None else "compiled"
    for a, b in zip(alone, batched, strict=True):
        assert_rows_close(a, b, path)
    assert stats["contacts"] < len(jobs)  # rows from the batch's columns (a leader may hit a wall)
    assert len({r["rms_error"] for r in alone}) == len(alone)
