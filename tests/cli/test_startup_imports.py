"""What a command's process imports and starts, checked in a fresh process (issue 29).

Start-up is most of a short run's cost: a headless run without plots must not import the
plot child's multiprocessing, the progress bar, matplotlib, pygame, Gymnasium or the bag
writer; a sweep or falsify whose stderr is not a terminal draws no bar, so imports no tqdm;
and the command line keeps numpy's BLAS to one thread unless the user said otherwise.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO = ROOT / "tests" / "fixtures" / "mde_short.yaml"
HEAVY = ("multiprocessing", "concurrent.futures", "tqdm", "matplotlib", "pygame", "gymnasium")


def imported_after(argv: list[str], tmp: Path, env: dict[str, str] | None = None) -> list[str]:
    """The last stdout line of ``main(argv)`` run in a fresh process: ``rc [modules]``."""
    code = (
        "import sys\n"
        "from amsa_phys.cli.main import main\n"
        f"rc = main({argv!r})\n"
        f"print(rc, sorted(m for m in {(*HEAVY, 'mcap')!r} if m in sys.modules))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        cwd=tmp,
        env=env,
        timeout=300,
        check=False,
    )
    return done.stdout.strip().splitlines()[-1:] or [done.stderr]


def test_a_headless_run_without_plots_imports_nothing_it_does_not_use(tmp_path: Path) -> None:
    argv = ["run", str(SCENARIO), "--headless", "--no-plot", "-q", "--duration", "2"]
    assert imported_after([*argv, "--out", str(tmp_path / "r")], tmp_path) == ["0 []"]


def test_a_sweep_off_a_terminal_imports_no_progress_bar(tmp_path: Path) -> None:
    argv = ["sweep", str(SCENARIO), "--grid", "MyFollowerController.Kv=0.1,0.2", "-j", "1"]
    argv += ["--duration", "2", "--out", str(tmp_path / "s")]
    line = imported_after(argv, tmp_path)
    assert line[0].startswith("0 "), line
    assert "'tqdm'" not in line[0]


def test_the_command_line_keeps_blas_to_one_thread_unless_told(tmp_path: Path) -> None:
    code = (
        "import os\n"
        "import amsa_phys.cli.main\n"
        "import numpy\n"  # after the CLI, as every command imports it
        "print(os.environ['OPENBLAS_NUM_THREADS'])\n"
    )
    env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_NUM_THREADS"}

    def said(extra: dict[str, str]) -> str:
        done = subprocess.run(
            [sys.executable, "-c", code],
            capture_output=True,
            text=True,
            env={**env, **extra},
            check=True,
        )
        return done.stdout.strip()

    assert said({}) == "1"
    assert said({"OPENBLAS_NUM_THREADS": "2"}) == "2"  # the user's choice stands


def test_a_runs_plots_are_drawn_without_pyplot(tmp_path: Path) -> None:
    # the plot child imports matplotlib's Figure and Agg canvas only: pyplot's backend
    # machinery is start-up the two default plots do not use
    out = tmp_path / "r"
    argv = [sys.executable, "-m", "amsa_phys", "run", str(SCENARIO), "--headless", "-q"]
    subprocess.run([*argv, "--no-plot", "--out", str(out), "--duration", "5"], check=True)
    code = (
        "import json, sys\n"
        "from pathlib import Path\n"
        "from amsa_phys.runs.plotjob import draw_run_plots\n"
        f"out = Path({str(out)!r})\n"
        "metrics = json.loads((out / 'metrics.json').read_text())\n"
        "made = draw_run_plots(out / 'trace.csv', metrics, out / 'd.png', out / 't.png')\n"
        "print(len(made), 'matplotlib.pyplot' in sys.modules)\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.stdout.split() == ["2", "False"], done.stderr
    assert (out / "d.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
