"""Sweeps: results independent of -j and of the executor; bad grids refused up front."""

from __future__ import annotations

import contextlib
import csv
import socket
import warnings
from pathlib import Path

import pytest
import sigint
from daskcluster import local_cluster
from deadlines import HANG_S

from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parent.parent.parent
SCEN = ROOT / "tests" / "fixtures" / "mde_short.yaml"
GRID = [
    "--grid",
    "MyFollowerController.Kv=0.05,0.35",
    "--grid",
    "LeaderGPS.noise=0,0.5",
    "--seeds",
    "2",
    "--duration",
    "20",
]


def rows(out: Path) -> list[dict[str, str]]:
    with open(out / "results.csv", newline="") as fh:
        return list(csv.DictReader(fh))


def test_j1_and_j2_give_identical_results(tmp_path: Path) -> None:
    assert main(["sweep", str(SCEN), *GRID, "-j", "1", "--out", str(tmp_path / "a")]) == 0
    assert main(["sweep", str(SCEN), *GRID, "-j", "2", "--out", str(tmp_path / "b")]) == 0
    a = (tmp_path / "a" / "results.csv").read_bytes()
    assert a == (tmp_path / "b" / "results.csv").read_bytes()
    table = rows(tmp_path / "a")
    assert len(table) == 2 * 2 * 2
    assert {r["MyFollowerController.Kv"] for r in table} == {"0.05", "0.35"}
    assert all(r["error"] == "" for r in table)
    # common random numbers: seed index 1 has the same seed at every grid point
    assert len({r["seed"] for r in table if r["seed_index"] == "1"}) == 1
    # the world's other sensors are noisy too (shipped realistic noise): even without the
    # leader's GPS noise the two seeds differ (test_sweep_warns_when_seeds_cannot_differ
    # covers a world with nothing random)
    quiet = [r for r in table if r["LeaderGPS.noise"] == "0"]
    assert quiet[0]["rms_error"] != quiet[1]["rms_error"]
    assert (tmp_path / "a" / "summary.png").read_bytes()[:4] == b"\x89PNG"


def test_dask_local_cluster_gives_the_same_rows(tmp_path: Path) -> None:
    pytest.importorskip("distributed")
    assert main(["sweep", str(SCEN), *GRID, "-j", "1", "--out", str(tmp_path / "local")]) == 0
    with local_cluster() as cluster:
        code = main(
            [
                "sweep",
                str(SCEN),
                *GRID,
                "--executor",
                "dask",
                "--scheduler",
                cluster.scheduler_address,
                "--out",
                str(tmp_path / "dask"),
            ]
        )
    assert code == 0
    assert rows(tmp_path / "dask") == rows(tmp_path / "local")


def test_a_dask_sweep_warns_of_no_dashboard_port(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """With 8787 taken (here by the test, else by whoever holds it), a sweep on the tests'
    local cluster says nothing of a dashboard or a port: nobody asked for one."""
    pytest.importorskip("distributed")
    argv = ["sweep", str(SCEN), *GRID[:2], "--duration", "2", "--executor", "dask"]
    with contextlib.ExitStack() as stack:
        held = stack.enter_context(socket.socket())
        with contextlib.suppress(OSError):  # already taken: as good
            held.bind(("", 8787))
            held.listen()
        seen = stack.enter_context(warnings.catch_warnings(record=True))
        warnings.simplefilter("always")
        cluster = stack.enter_context(local_cluster())
        out = tmp_path / "o"
        assert main([*argv, "--scheduler", cluster.scheduler_address, "--out", str(out)]) == 0
    said = capsys.readouterr().err + "".join(str(w.message) for w in seen)
    assert "8787" not in said, said
    assert "dashboard" not in said.lower(), said
    assert len(rows(out)) == 2


def test_on_dask_a_job_that_kills_its_workers_is_a_row_error(tmp_path: Path) -> None:
    pytest.importorskip("distributed")
    import dask

    scen = tmp_path / "s.yaml"
    scen.write_text("world:\n  components:\n    D: {template: 'toys:Die', freq: 4}\nduration: 1\n")
    argv = ["sweep", str(scen), "--grid", "D.gain=1,2,3", "--executor", "dask"]
    # no retries on other workers: the test needs one death, not four
    with (
        dask.config.set({"distributed.scheduler.allowed-failures": 0}),
        local_cluster() as cluster,
    ):
        code = main([*argv, "--scheduler", cluster.scheduler_address, "--out", str(tmp_path / "o")])
    assert code == 0
    table = rows(tmp_path / "o")
    assert [r["error"] for r in table] == [
        "",
        "a worker process died (killed, out of memory, or a crash in native code), "
        "on every worker that ran it",
        "",
    ]


def test_a_bad_grid_value_is_refused_before_any_run(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(
        [
            "sweep",
            str(SCEN),
            "--grid",
            "MyFollowerController.Kv=0.1,99",
            "--out",
            str(tmp_path / "x"),
        ]
    )
    assert code == 2
    assert capsys.readouterr().err == (
        "error: --grid MyFollowerController.Kv: 99 is above the maximum 10 (range [0, 10])\n"
    )
    assert not (tmp_path / "x").exists()


def test_range_axis(tmp_path: Path) -> None:
    assert (
        main(
            [
                "sweep",
                str(SCEN),
                "--range",
                "MyFollowerController.Kv=0.1:0.3:3",
                "--duration",
                "5",
                "-j",
                "1",
                "--out",
                str(tmp_path / "r"),
            ]
        )
        == 0
    )
    assert [r["MyFollowerController.Kv"] for r in rows(tmp_path / "r")] == ["0.1", "0.2", "0.3"]


def test_keep_runs_writes_each_run_directory(tmp_path: Path) -> None:
    assert (
        main(
            [
                "sweep",
                str(SCEN),
                "--grid",
                "MyFollowerController.Kv=0.1,0.2",
                "--duration",
                "5",
                "-j",
                "1",
                "--keep-runs",
                "--out",
                str(tmp_path / "k"),
            ]
        )
        == 0
    )
    runs = sorted((tmp_path / "k" / "runs").iterdir())
    assert [r.name for r in runs] == ["run-00000", "run-00001"]
    assert (runs[1] / "trace.csv").exists()
    assert "MyFollowerController.Kv: 0.2" in (runs[1] / "scenario.yaml").read_text()


class Terminal:
    """A pseudo-terminal for a child's stderr, read without blocking.

    On a terminal the sweep shows its progress bar (tqdm), which moves off ``0/N`` only
    once the parent has *received* a finished row: the one observable event that says
    "some rows are in". A file or a fixed wait cannot say it (results.csv is written at
    the end; a batch's run directories exist before the parent has its rows).
    """

    def __init__(self) -> None:
        import fcntl
        import pty
        import struct
        import termios

        self.master, self.child_end = pty.openpty()
        # a 0-column terminal (a new pty's size) gets an empty bar: give it 24 x 120
        fcntl.ioctl(self.child_end, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 120, 0, 0))
        self.text = ""

    def read(self) -> str:
        """Everything the child wrote so far (never blocks)."""
        import os
        import select

        while select.select([self.master], [], [], 0)[0]:
            try:
                data = os.read(self.master, 65536)
            except OSError:  # EIO: the child closed its end
                break
            if not data:
                break
            self.text += data.decode("utf-8", "replace")
        return self.text

    def close(self) -> None:
        import os

        os.close(self.master)


@pytest.mark.parametrize("how", ["sigint-group", "sigterm"])
def test_ctrl_c_keeps_every_finished_row(tmp_path: Path, how: str) -> None:
    import os
    import re
    import signal
    import subprocess
    import sys

    from longrun import wait_until

    out = tmp_path / "int"
    terminal = Terminal()
    with open(tmp_path / "stdout.txt", "w") as stdout:
        proc = subprocess.Popen(
            [
                sys.executable,
                "-m",
                "amsa_phys",
                "sweep",
                str(SCEN),
                "--range",
                "MyFollowerController.Kv=0.01:0.4:2000",
                "--duration",
                "60",
                "-j",
                "2",
                # batches of 25 runs (~0.5 s each): the sweep is stopped once the first
                # batch's rows are in, long before the 80 batches are
                "--batch-size",
                "25",
                "--out",
                str(out),
            ],
            stdin=subprocess.DEVNULL,
            stdout=stdout,
            stderr=terminal.child_end,
            text=True,
            start_new_session=True,
            preexec_fn=sigint.at_default,
        )
    os.close(terminal.child_end)
    some_rows = re.compile(r"\b[1-9][0-9]*/2000\b")  # the bar past 0/2000
    try:
        wait_until(
            "the sweep received a finished batch",
            lambda: some_rows.search(terminal.read()) is not None,
            proc,
        )
        if how == "sigterm":
            proc.terminate()
        else:
            os.killpg(proc.pid, signal.SIGINT)  # like a terminal's Ctrl-C: the whole group
        proc.wait(timeout=HANG_S)  # bounds a hang only
        err = terminal.read()
    finally:  # a hung sweep must not outlive the test with its workers
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
        terminal.close()
    assert proc.returncode == 130, err
    assert "sweep interrupted" in err
    table = rows(out)
    assert 0 < len(table) < 2000
    assert len(table) % 25 == 0  # whole batches: a batch cut short gives no rows
    assert all(r["error"] == "" for r in table)
    from amsa_phys.plots.save import png_text  # the picture says it is partial

    assert f"interrupted: {len(table)} of 2000 runs" in png_text(out / "summary.png")["Title"]


def test_phase_metrics_and_replotting_a_sweep(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from amsa_phys.runs.sweep import read_results

    out = tmp_path / "s"
    args = ["sweep", str(SCEN), "--range", "MyFollowerController.Kv=0.1:0.3:3", "-j", "1"]
    # the timeline changes Kv at 125 s: phase 1 exists only in runs that reach it
    phase1 = ["--metric", "phase1.rms_error", "--out", str(out)]
    assert main([*args, "--duration", "20", *phase1]) == 2
    assert capsys.readouterr().err.startswith(
        "error: --metric: unknown metric 'phase1.rms_error'; known: max_distance, "
    )
    assert not out.exists()
    assert main([*args, "--duration", "130", *phase1]) == 0
    table, axes = read_results(out / "results.csv")
    assert axes == ["MyFollowerController.Kv"]
    assert [r["MyFollowerController.Kv"] for r in table] == [0.1, 0.2, 0.3]
    assert all(isinstance(r["phase1.rms_error"], float) for r in table)
    assert [r["rms_error"] for r in table] == [float(r["rms_error"]) for r in rows(out)]

    (out / "summary.png").unlink()
    capsys.readouterr()
    assert main(["plot", str(out), "--metric", "phase0.max_distance"]) == 0
    assert capsys.readouterr().out == f"wrote {out / 'summary.png'}\n"
    assert (out / "summary.png").read_bytes()[:4] == b"\x89PNG"
    assert main(["plot", str(out), "--metric", "phase2.rms_error"]) == 2
    assert capsys.readouterr().err.endswith("or phase<i>.<metric> for i in 0..1\n")


def test_a_bad_sweep_metric_in_the_file_names_its_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scen = tmp_path / "s.yaml"
    text = SCEN.read_text().replace("../../worlds/", f"{ROOT}/worlds/")
    scen.write_text(text + "sweep:\n  grid: {MyFollowerController.Kv: [0.1]}\n  metric: rms\n")
    line = len(text.splitlines()) + 3
    assert main(["sweep", str(scen), "--out", str(tmp_path / "o")]) == 2
    assert capsys.readouterr().err.startswith(
        f"error: {scen}:{line}: sweep.metric: unknown metric 'rms'; known: "
    )


def test_a_grid_point_that_breaks_a_rule_is_a_row_error_and_the_rest_run(tmp_path: Path) -> None:
    out = tmp_path / "r"
    argv = ["sweep", str(SCEN), "--grid", "MyNormalizePower.powerMin=0,50"]
    argv += ["--grid", "MyNormalizePower.powerMax=30,100", "--duration", "5", "-j", "1"]
    assert main([*argv, "--out", str(out)]) == 0
    table = rows(out)
    assert [r["error"] for r in table] == [
        "",
        "",
        "MyNormalizePower.powerMax: powerMin 50 is above powerMax 30",
        "",
    ]
    assert table[3]["rms_error"] != ""


def test_a_worker_that_dies_costs_one_row_not_the_sweep(tmp_path: Path) -> None:
    scen = tmp_path / "s.yaml"
    scen.write_text("world:\n  components:\n    D: {template: 'toys:Die', freq: 4}\nduration: 1\n")
    out = tmp_path / "o"
    # gain 2 kills the worker process running it, twice; every other point gives its row
    argv = ["sweep", str(scen), "--grid", "D.gain=1,2,3,4,5,6", "-j", "2", "--out", str(out)]
    assert main(argv) == 0
    table = rows(out)
    assert [r["D.gain"] for r in table] == ["1", "2", "3", "4", "5", "6"]
    assert [r["error"] for r in table] == [
        "",
        "a worker process died (killed, out of memory, or a crash in native code), twice, "
        "running this job",
        "",
        "",
        "",
        "",
    ]
    assert all(
        r["final_distance"] == "" and r["collisions"] == "0" for r in table if not r["error"]
    )


def test_random_timing_is_the_same_serial_or_parallel(tmp_path: Path) -> None:
    """Free-running phases and jitter come from the seed tree: -j 1 and -j 2 agree, and the
    phases differ between seeds (they are drawn, not fixed)."""
    world = tmp_path / "w.yaml"
    world.write_text(
        (ROOT / "worlds" / "mde_challenge.yaml").read_text() + "timing: {free_running: true}\n"
    )
    scen = tmp_path / "s.yaml"
    scen.write_text(
        "world: w.yaml\nduration: 20\nseed: 2\n"
        "quality: {signal: MyDistanceMonitor.distanceFollowerToLeader, reference: 15}\n"
        "set: {Follower.x: 14.0, FollowerGPS.jitter: 0.2}\n"
    )
    grid = ["--grid", "MyFollowerController.Kv=0.05,0.35", "--seeds", "2"]
    assert main(["sweep", str(scen), *grid, "-j", "1", "--out", str(tmp_path / "a")]) == 0
    assert main(["sweep", str(scen), *grid, "-j", "2", "--out", str(tmp_path / "b")]) == 0
    a = (tmp_path / "a" / "results.csv").read_bytes()
    assert a == (tmp_path / "b" / "results.csv").read_bytes()
    table = rows(tmp_path / "a")
    fast = [r for r in table if r["MyFollowerController.Kv"] == "0.35"]
    assert fast[0]["max_distance"] != fast[1]["max_distance"]  # other phases, other run


def test_a_sigterm_while_the_summary_is_drawn_finishes_the_files_then_exits_130(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    request: pytest.FixtureRequest,
) -> None:
    """A stop that lands after the last run (in matplotlib) is noted: results.csv and
    summary.png are complete, and the sweep says so and exits 130 (it died of -15)."""
    import os
    import signal

    from amsa_phys.plots import summary

    real = summary.plot_summary

    def signalled(*args: object, **kw: object) -> Path:
        os.kill(os.getpid(), signal.SIGTERM)
        return real(*args, **kw)  # type: ignore[arg-type]

    class Killed(Exception):
        pass

    def killed(signum: int, frame: object) -> None:  # stands for the default: death by -15
        raise Killed

    monkeypatch.setattr(summary, "plot_summary", signalled)
    previous = signal.signal(signal.SIGTERM, killed)
    request.addfinalizer(lambda: signal.signal(signal.SIGTERM, previous))
    out = tmp_path / "late"
    argv = ["sweep", str(SCEN), "--grid", "MyFollowerController.Kv=0.1,0.3", "--duration", "5"]
    assert main([*argv, "-j", "1", "--out", str(out)]) == 130
    err = capsys.readouterr().err
    assert "interrupted after the sweep's last run; its outputs are complete in" in err
    assert len((out / "results.csv").read_text().splitlines()) == 3
    assert (out / "summary.png").read_bytes().startswith(b"\x89PNG")


def test_batch_size_with_the_one_run_per_process_executor_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ["sweep", str(SCEN), *GRID, "--executor", "local", "--batch-size", "5"]
    assert main([*argv, "--out", str(tmp_path / "o")]) == 2
    assert capsys.readouterr().err == (
        "error: --batch-size: sets the runs of a batch; --executor local runs one per process\n"
    )
    assert not (tmp_path / "o").exists()


def test_force_keeps_the_earlier_sweep_whole_until_the_new_one_ends(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """``sweep --force`` over an earlier sweep: while its runs run, ``--out`` still holds the
    earlier results (the new sweep is written beside it and renamed into place at its end,
    with its kept runs), and nothing is left beside it after."""
    from amsa_phys.cli import sweep as cli_sweep

    out = tmp_path / "s"
    argv = ["sweep", str(SCEN), "--grid", "MyFollowerController.Kv=0.1,0.2", "--duration", "5"]
    argv += ["-j", "1", "--keep-runs", "--out", str(out)]
    assert main(argv) == 0
    (out / "results.csv").write_text("the earlier sweep\n")
    seen: list[str] = []
    real = cli_sweep.rows_from

    def watching(*args: object, **kwargs: object) -> object:
        for row in real(*args, **kwargs):  # type: ignore[arg-type]
            seen.append((out / "results.csv").read_text())
            yield row

    monkeypatch.setattr(cli_sweep, "rows_from", watching)
    assert main([*argv, "--force"]) == 0
    assert seen == ["the earlier sweep\n"] * 2
    assert len(rows(out)) == 2
    assert sorted(p.name for p in (out / "runs").iterdir()) == ["run-00000", "run-00001"]
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []
    capsys.readouterr()
