"""The vector env's physics step alone, against another build of it, bit for bit.

From a few dozen envs up, a batched vector env's step is mostly its rovers' physics (the
``vector env`` rows of ``bench_speed.py`` give its share and the rate it caps), so a faster
vector env needs a cheaper compiled step (``_step.Columns``: forces, integration, contact
screening, safety check) that still computes every bit as before. This measures both at
once, in one process: the step of this checkout and the step of a baseline build (another
checkout's compiled ``_step`` module) run the same physics steps on copies of the same
arrays (a vector env's columns after its first step, new random drives every 25 steps, as
an agent's actions would set them), the two calls interleaved, and after every call the
states, rim speeds, forces and contact marks are compared byte for byte: a difference stops
the benchmark (exit 1) naming the array, the size and the call.

Reported per number of envs: CPU nanoseconds per env and physics step (two rovers) of each
build, and the ratio this / baseline per call pair (median and quartiles: the ratio of two
calls made back to back moves less with the machine's load than either figure). Without a
baseline only this checkout's step is timed. Nothing here depends on the baseline being
older or newer: swap them and the ratio inverts.

Run: ``python benchmarks/bench_physics_step.py [--baseline DIR] [--envs 16 64 1000]
[--rounds 60] [--save]``. ``DIR`` is another checkout whose extension is built in place
(``pip install -e .`` or ``python setup.py build_ext --inplace`` there), or the ``_step``
module's file itself. ``--save`` writes ``benchmarks/results/physics_step.json`` and
regenerates the docs' ``<!-- results: physics-step -->`` table.
"""

from __future__ import annotations

import argparse
import importlib.machinery
import importlib.util
import os
import statistics
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import Any

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("MPLBACKEND", "Agg")
sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "benchmarks" / "results" / "physics_step.json"
#: physics steps an agent step takes in the packaged scenario (its agent's period / dt)
STEPS_PER_CALL = 25
#: the arrays a step writes, compared after every call
WRITTEN = ("state", "rims", "forces", "touched")


class BenchError(Exception):
    """Bad input: one line for the user, exit 2."""


def load_step(where: str) -> ModuleType:
    """The compiled ``_step`` module at ``where``: a checkout's root (its in-place build) or
    the module's file. Loaded under a name of its own, beside this checkout's."""
    path = Path(where)
    if path.is_dir():
        found = [
            path / "amsa_phys" / "physics" / f"_step{suffix}"
            for suffix in importlib.machinery.EXTENSION_SUFFIXES
        ]
        found = [p for p in found if p.is_file()]
        if not found:
            raise BenchError(
                f"{where}: no compiled amsa_phys/physics/_step module (build it there with "
                "`python setup.py build_ext --inplace`)"
            )
        path = found[0]
    elif not path.is_file():
        raise BenchError(f"{where}: no such directory or file")
    name = "baseline_step._step"  # the init function is found by the last part: PyInit__step
    loader = importlib.machinery.ExtensionFileLoader(name, str(path))
    spec = importlib.util.spec_from_file_location(name, str(path), loader=loader)
    if spec is None:
        raise BenchError(f"{path}: not an extension module")
    module = importlib.util.module_from_spec(spec)
    try:
        loader.exec_module(module)
    except ImportError as exc:
        raise BenchError(f"{path}: cannot be loaded ({exc})") from None
    if not hasattr(module, "Columns"):
        raise BenchError(f"{path}: this _step has no Columns step (too old to compare)")
    return module


def describe(where: str) -> str:
    """The baseline as the results file names it: its checkout's commit, else its path."""
    import subprocess

    path = Path(where)
    top = path if path.is_dir() else path.parent
    try:
        head = subprocess.run(
            ["git", "-C", str(top), "rev-parse", "--short", "HEAD"],
            capture_output=True,
            text=True,
            check=True,
        ).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return str(path)
    return f"`{head}`"


def column_arrays(n: int) -> dict[str, Any]:
    """The arrays of a vector env's column physics after its first step: ``n`` envs of the
    packaged scenario, every argument ``_step.Columns`` takes."""
    from amsa_phys.gym.vector import FollowVecEnv
    from amsa_phys.physics.columns import REACH_M

    env = FollowVecEnv(n, stepping="batch")
    try:
        env.reset(seed=0)
        env.step(np.zeros((n, 2)))
        columns = env._episode.columns  # type: ignore[union-attr]
        if columns is None or columns._fused is None:
            raise BenchError("the vector env does not step on the compiled columns here")
        model, io = columns._model, columns._io
        return {
            "plan": model._plan.copy(),
            "drives": model.drives.copy(),
            "rims": model.rims.copy(),
            "ground": model.ground.copy(),
            "state": io.state.copy(),
            "forces": io._f.copy(),
            "m_inv": io.m_inv.copy(),
            "i_inv": io.i_inv.copy(),
            "dt": model.dt,
            "max2": model.max_speed**2,
            "extent": model.extent,
            "run": columns._run.astype(np.int64),
            "radius": columns._radius.copy(),
            "sub": columns._sub.astype(np.float64),
            "reach": REACH_M,
            "pairs_a": columns._pa.astype(np.int64),
            "pairs_b": columns._pb.astype(np.int64),
            "boxes": np.ascontiguousarray(columns._boxes, dtype=np.float64).reshape(-1, 4),
            "touched": np.zeros_like(columns._touched),
        }
    finally:
        env.close()


def make_step(module: ModuleType, arrays: dict[str, Any]) -> tuple[Any, dict[str, Any]]:
    """``module``'s ``Columns`` over its own copies of ``arrays`` (returned with it)."""
    mine = {k: v.copy() if isinstance(v, np.ndarray) else v for k, v in arrays.items()}
    positional = [mine[k] for k in ("plan", "drives", "rims", "ground", "state", "forces")]
    positional += [mine[k] for k in ("m_inv", "i_inv", "dt", "max2", "extent")]
    keywords = {k: mine[k] for k in ("run", "radius", "sub", "reach", "pairs_a", "pairs_b")}
    keywords.update(boxes=mine["boxes"], touched=mine["touched"])
    return module.Columns(*positional, **keywords), mine


def first_difference(a: dict[str, Any], b: dict[str, Any]) -> str | None:
    """The first array of :data:`WRITTEN` whose bytes differ between ``a`` and ``b``, with
    where and by how much; None when all are identical."""
    for key in WRITTEN:
        x, y = np.asarray(a[key]), np.asarray(b[key])
        if x.tobytes() != y.tobytes():
            at = int(np.flatnonzero(x.view(np.uint8).ravel() != y.view(np.uint8).ravel())[0])
            item = at // x.itemsize
            return f"{key}[{item}]: {x.ravel()[item]!r} vs {y.ravel()[item]!r}"
    return None


@dataclass
class Sitting:
    """One size's measurement: CPU ns per env and physics step of each call, per build."""

    envs: int
    ours: list[float]
    theirs: list[float]  # empty without a baseline
    steps: int  # physics steps each build took (and compared)

    def ratios(self) -> list[float]:
        return [o / t for o, t in zip(self.ours, self.theirs, strict=True)]


def measure(n: int, rounds: int, baseline: ModuleType | None, seed: int = 5) -> Sitting:
    """``rounds`` calls of :data:`STEPS_PER_CALL` physics steps of ``n`` envs by this
    checkout's step (and the baseline's, interleaved, alternating which goes first), new
    random drives before each; raises :class:`AssertionError` on the first difference."""
    from amsa_phys.physics import _step

    arrays = column_arrays(n)
    ours, mine = make_step(_step, arrays)
    builds = [(ours, mine, [])]
    if baseline is not None:
        builds.append((*make_step(baseline, arrays), []))
    rng = np.random.default_rng(seed)
    steps = 0
    for r in range(rounds):
        drives = rng.uniform(-100.0, 100.0, arrays["drives"].shape)
        order = builds if r % 2 == 0 else builds[::-1]
        taken = set()
        for step, held, times in order:
            held["drives"][...] = drives
            t0 = time.process_time()
            done, _ = step.advance_many(STEPS_PER_CALL, True)
            times.append((time.process_time() - t0) / max(done, 1) / n * 1e9)
            taken.add(done)
        if baseline is not None:
            diff = None if len(taken) == 1 else f"steps taken {sorted(taken)}"
            diff = diff or first_difference(builds[0][1], builds[1][1])
            if diff is not None:
                raise AssertionError(f"{n} envs, call {r + 1}: the builds differ: {diff}")
        steps += taken.pop()
    theirs = builds[1][2] if baseline is not None else []
    return Sitting(n, builds[0][2], theirs, steps)


def _quartiles(xs: list[float]) -> tuple[float, float, float]:
    q = statistics.quantiles(xs, n=4) if len(xs) > 1 else [xs[0]] * 3
    return q[0], q[1], q[2]


def row(s: Sitting) -> list[str]:
    """A sitting as the table's cells (:data:`COLUMNS`, or :data:`ALONE` without a baseline)."""
    ours = f"{statistics.median(s.ours):.0f}"
    if not s.theirs:
        lo, _, hi = _quartiles(s.ours)
        return [f"{s.envs:,}", ours, f"{lo:.0f}–{hi:.0f}", f"{s.steps:,}"]
    lo, mid, hi = _quartiles(s.ratios())
    return [
        f"{s.envs:,}",
        ours,
        f"{statistics.median(s.theirs):.0f}",
        f"{mid:.3f} ({lo:.3f}–{hi:.3f})",
        f"identical, {s.steps:,} steps",
    ]


COLUMNS = [
    "envs",
    "this step, ns per env-step of physics",
    "baseline, ns",
    "this / baseline, median (quartiles)",
    "bits",
]
#: the table's columns without a baseline
ALONE = ["envs", "ns per env-step of physics, median", "quartiles", "physics steps"]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--baseline", help="another checkout (built in place) or its _step file")
    ap.add_argument("--envs", type=int, nargs="+", default=[16, 64, 1000])
    ap.add_argument("--rounds", type=int, default=60, help="calls of 25 steps per size")
    ap.add_argument("--save", action="store_true", help="write the results file and the docs")
    args = ap.parse_args(argv)
    try:
        if any(n < 1 for n in args.envs) or args.rounds < 1:
            raise BenchError("--envs and --rounds must be >= 1")
        baseline = load_step(args.baseline) if args.baseline else None
        from amsa_phys.physics import compiled

        if not compiled.columns_compiled():
            raise BenchError("this checkout's compiled step is not built (or AMSA_PHYS_PURE)")
    except BenchError as exc:
        print(f"bench_physics_step: {exc}", file=sys.stderr)
        return 2
    load0 = os.getloadavg()[0]
    columns = COLUMNS if baseline is not None else ALONE
    rows = []
    for n in args.envs:
        try:
            sitting = measure(n, args.rounds, baseline)
        except AssertionError as exc:
            print(f"bench_physics_step: {exc}", file=sys.stderr)
            return 1
        rows.append(row(sitting))
        print("  ".join(f"{c}: {v}" for c, v in zip(columns, rows[-1], strict=True)), flush=True)
    load1 = os.getloadavg()[0]
    print(f"load {load0:.2f}–{load1:.2f}")
    if args.save:
        import results

        doc = results.table_doc(
            columns,
            rows,
            "The vector env's compiled column step alone (`_step.Columns.advance_many`, "
            f"{STEPS_PER_CALL} steps a call, two rovers an env) of `{results.commit()}`, CPU "
            f"time, medians of {args.rounds} calls"
            + (
                f", interleaved with the step of {describe(args.baseline)} and compared with "
                "it byte for byte after every call"
                if args.baseline
                else ""
            ),
            "python benchmarks/bench_physics_step.py"
            + (" --baseline DIR" if args.baseline else "")
            + " --save",
            commit=results.commit(),
        )
        doc["load"] = [round(load0, 2), round(load1, 2)]
        OUT.parent.mkdir(parents=True, exist_ok=True)
        OUT.write_text(results.json.dumps(doc, indent=1) + "\n")
        for page in results.write_pages():
            print(f"rewrote {page.relative_to(ROOT)}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
