"""Start-up with and without the package's bytecode, where Python writes none itself.

With ``PYTHONDONTWRITEBYTECODE=1`` an editable install compiles every module it imports from
source in every process, unless the ``.pyc`` are there (``amsa_phys/bytecode.py`` writes
them at the end of a command). This measures both, interleaved, as whole processes (CPU of
the child: user + system), against ``python -c pass``:

* ``source``: the package's ``__pycache__`` removed before each run, the warm-up off
  (``AMSA_PHYS_NO_PYC=1``), so each run compiles what it imports;
* ``bytecode``: after the first command wrote them, as every later command finds them.

The package's ``__pycache__`` directories are removed and rewritten (they are generated
files); nothing else is touched. Run:
``python -m benchmarks.bench_bytecode [--reps 5] [--command run|help]``.
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PKG = ROOT / "amsa_phys"
SCENARIO1 = ROOT / "scenarios" / "scenario1.yaml"


def child_cpu(argv: list[str], **env: str) -> float:
    """CPU seconds (user + system) of one process and what it forked."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    full = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1", **env}
    subprocess.run(argv, check=True, capture_output=True, env=full)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def drop_bytecode() -> None:
    for cache in PKG.rglob("__pycache__"):
        shutil.rmtree(cache, ignore_errors=True)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reps", type=int, default=5)
    parser.add_argument("--command", choices=["run", "help"], default="run")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        command = [sys.executable, "-m", "amsa_phys"]
        if args.command == "run":
            command += ["run", str(SCENARIO1), "--headless", "--no-plot", "-q"]
            command += ["--out", f"{tmp}/run", "--force"]
        else:
            command += ["--help"]
        source, compiled, bare = [], [], []
        load = os.getloadavg()[0]
        for _ in range(args.reps):
            drop_bytecode()
            source.append(child_cpu(command, AMSA_PHYS_NO_PYC="1"))
            child_cpu(command)  # this one writes the bytecode (its own cost: not measured)
            compiled.append(child_cpu(command))
            bare.append(child_cpu([sys.executable, "-c", "pass"]))
    s, c, b = (statistics.median(x) for x in (source, compiled, bare))
    print(f"amsa-phys {args.command}, PYTHONDONTWRITEBYTECODE=1, median of {args.reps}:")
    print(f"  from source    {s:.3f} s CPU  ({s / b:.1f}x python -c pass)")
    print(f"  from bytecode  {c:.3f} s CPU  ({c / b:.1f}x python -c pass)")
    print(f"  source / bytecode {s / c:.2f}; load average {load:.2f} -> {os.getloadavg()[0]:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
