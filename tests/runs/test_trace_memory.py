"""``plot`` reads a trace in bounded memory: a trace twice as long does not take the process
further (the whole file used to be held, twice: a 1 GB trace took it past 2 GiB), and the
rows kept for drawing are the trace's own, its last row always among them."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from amsa_phys.cli.main import main
from amsa_phys.engine.traceread import read_rows

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO = ROOT / "tests" / "fixtures" / "mde_short.yaml"
#: runs ``amsa-phys plot DIR`` as its only child and prints the child's peak RSS in kB
PEAK = (
    "import resource, subprocess, sys\n"
    "done = subprocess.run([sys.executable, '-m', 'amsa_phys', 'plot', sys.argv[1]],"
    " capture_output=True, text=True)\n"
    "assert done.returncode == 0, done.stderr\n"
    "print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)\n"
)


@pytest.fixture(scope="module")
def clean_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("made") / "run"
    argv = ["run", str(SCENARIO), "--headless", "-q", "--no-plot", "--duration", "4"]
    assert main([*argv, "--out", str(out)]) == 0
    return out


def long_copy(run: Path, to: Path, megabytes: int) -> Path:
    """``run`` with its trace made ``megabytes`` long: its last row again and again, t rising."""
    shutil.copytree(run, to)
    lines = (run / "trace.csv").read_text().splitlines()
    rest = lines[-1].split(",", 1)[1]
    with open(to / "trace.csv", "w") as fh:
        fh.write(lines[0] + "\n")
        size = i = 0
        while size < megabytes << 20:
            block = "".join(f"{(i + k) / 20!r},{rest}\n" for k in range(10_000))
            fh.write(block)
            size += len(block)
            i += 10_000
    return to


def peak_mb(rundir: Path) -> float:
    done = subprocess.run(
        [sys.executable, "-c", PEAK, str(rundir)],
        env={**os.environ, "MPLBACKEND": "Agg"},
        capture_output=True,
        text=True,
        timeout=600,
        check=True,
    )
    return int(done.stdout.split()[-1]) / 1024


def test_a_trace_twice_as_long_takes_plot_no_further(clean_run: Path, tmp_path: Path) -> None:
    small = peak_mb(long_copy(clean_run, tmp_path / "a", 64))
    large = peak_mb(long_copy(clean_run, tmp_path / "b", 128))
    # holding the file would add ~2.5x the 64 MB more; streamed, it is the same few blocks
    assert large - small < 32, (small, large)
    assert (tmp_path / "b" / "trajectory.png").stat().st_size > 0


def test_kept_rows_are_the_traces_own_and_end_with_its_last(tmp_path: Path) -> None:
    trace = tmp_path / "trace.csv"
    t = np.arange(10_007) / 10
    rows = np.column_stack((t, np.sin(t), t * t))
    with open(trace, "w") as fh:
        fh.write("t,a,b\n")
        fh.writelines(",".join(repr(float(v)) for v in r) + "\n" for r in rows)
    names, kept, stride = read_rows(trace, max_cells=3 * 2_500)
    assert names == ["t", "a", "b"]
    assert stride == 5  # 10,007 rows into the minimum of 2,000 kept
    assert np.array_equal(kept[:-1], rows[::stride])
    assert np.array_equal(kept[-1], rows[-1])  # the run's end, whatever the stride
    _, whole, one = read_rows(trace)
    assert one == 1
    assert np.array_equal(whole, rows)
