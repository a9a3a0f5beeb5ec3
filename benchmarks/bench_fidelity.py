"""The physics page's measured fidelity figures, measured: ``python -m benchmarks.perf --only
fidelity --save`` writes them to ``benchmarks/results/perf.json`` and the ``fidelity`` block of
``docs/physics.md`` shows them.

Why a benchmark and not prose: ``docs/physics.md`` used to type these figures by hand (the
long skid's convergence, the steady drifts against the tyre law, a turn's radius against the
straight-line closed form, the yaw rate against the encoders), and a change of the step left
them stale. Each figure here is a simulation against an independent reference:

* the long low-friction manoeuvre of ``tests/physics/test_long_skid.py`` (default rover):
  position and heading at 100 Hz against 6,400 Hz, and the orders over 100-800 Hz; the 600 N
  rover's too, whose heading does not converge monotonically (shown, not judged);
* the steady drifts and turns of ``tests/physics/test_drift_law.py`` against the documented
  tyre law, solved there by Newton's method without the step code (the largest relative
  difference of speed and yaw rate over the family);
* a gentle turn's radius ``u / w`` against ``(track/2)(v_R + v_L)/(v_R - v_L)`` from each
  wheel's top speed at its power (the scrub and the tyres' slip make it wider), and its yaw
  rate against what the encoders imply, ``(u_R - u_L) / track``, at 100 and 1,600 Hz.

The rigs are the tests' (``tests/physics/rig.py`` and the two test modules), so the figure and
the test that holds it measure the same thing. Cheap: about a minute of CPU on the compiled
step. Run alone, ``python benchmarks/bench_fidelity.py`` prints the same lines.
"""

from __future__ import annotations

import sys
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests" / "physics"))

#: default rover, default ground: the turns of the "scrub and step" figures (left, right %)
TURNS = ((50.0, 60.0), (80.0, 100.0))
TRACK = 0.5


def long_skid(report: Callable[..., None]) -> None:
    """The long manoeuvre's pose at 100 Hz against 6,400 Hz, and the orders."""
    import test_long_skid

    with tempfile.TemporaryDirectory() as tmp:
        c = test_long_skid.convergence(Path(tmp), {})
    report(
        "long skid on mu 0.1, position off at 100 Hz",
        f"{c['error']:.4f} m",
        "0.05 m",
        c["error"] < 0.05,
    )
    report(
        "long skid on mu 0.1, heading off at 100 Hz",
        f"{c['heading_error']:.4f} rad",
        "0.01 rad",
        c["heading_error"] < 0.01,
    )
    report(
        "long skid, order in position over 100-800 Hz",
        f"{c['order']:.3f}",
        ">= 0.9",
        c["order"] >= 0.9,
    )
    report(
        "long skid, order in heading over 100-800 Hz",
        f"{c['heading_order']:.3f}",
        ">= 0.9",
        c["heading_order"] >= 0.9,
    )
    with tempfile.TemporaryDirectory() as tmp:
        strong = test_long_skid.convergence(Path(tmp), test_long_skid.ROUGH["600 N"])
    report(
        "long skid, 600 N rover, position off at 100 Hz, order over 100-800 Hz",
        f"{strong['error']:.4f} m, order {strong['order']:.2f}",
        "",
        None,
    )
    report(
        "long skid, 600 N rover, heading off at 100/200/400/800 Hz",
        "/".join(f"{a:.4f}" for a in strong["heading_errors"]) + " rad",
        "",
        None,
    )


def drifts(report: Callable[..., None]) -> None:
    """Each rover of the drift family against the documented law, at 100 Hz."""
    import test_drift_law

    for case in test_drift_law.FAMILY:
        mass, c, stall, mu = case
        with tempfile.TemporaryDirectory() as tmp:
            err, _ = test_drift_law.law_error(Path(tmp), case)
        kind = "drift" if stall > 200.0 else "turn"
        name = f"steady {kind} vs tyre law: {mass:g} kg, c {c:g}, {stall:g} N, mu {mu:g}"
        report(name, f"{100.0 * err:.3f} % off", "1 %", err < 0.01)
    # the 600 N drifts on mu 0.3 settle slowly: taken after 20 s
    for case in test_drift_law.SLOW_DRIFTS:
        with tempfile.TemporaryDirectory() as tmp:
            err, _ = test_drift_law.law_error(Path(tmp), case, 20.0)
        name = f"steady drift vs tyre law after 20 s: {case[0]:g} kg, c 0.0001, 600 N, mu 0.3"
        report(name, f"{100.0 * err:.3f} % off", "1 %", err < 0.01)


def turn(tmp: Path, left: float, right: float, rate: int) -> dict[str, float]:
    """A 20 s turn of the default rover on mu 0.8, Crr 0.02: the last sample's state."""
    from rig import drive

    tr, _ = drive(
        tmp,
        left,
        right,
        20,
        physics={"rate": rate, "ground": {"friction": 0.8, "rolling_resistance": 0.02}},
    )
    return {
        k: float(tr[f"Rover.{k}"][-1]) for k in ("speed", "yawRate", "wheelSpeedL", "wheelSpeedR")
    }


def top_speed(power: float) -> float:
    """The default rover's top speed at ``power`` % on Crr 0.02 (``docs/physics.md``):
    ``v_free (p/100 - R / F_stall)``, ``R = Crr m g / 2 + jointFriction / r``."""
    res = 0.02 * 30.0 * 9.81 / 2.0 + 0.2 / 0.1
    return 1.6 * (power / 100.0 - res / 120.0)


def turns(report: Callable[..., None]) -> None:
    """A gentle turn's radius against the closed form; its yaw rate against the encoders."""
    for left, right in TURNS:
        vl, vr = top_speed(left), top_speed(right)
        closed = TRACK / 2.0 * (vr + vl) / (vr - vl)
        for rate in (100, 1600):
            with tempfile.TemporaryDirectory() as d:
                s = turn(Path(d), left, right, rate)
            enc = (s["wheelSpeedR"] - s["wheelSpeedL"]) / TRACK
            below = 100.0 * (1.0 - s["yawRate"] / enc)
            report(
                f"turn {left:g}/{right:g} %, yaw rate below the encoders' at {rate} Hz",
                f"{below:.2f} %",
                "",
                None,
            )
            if rate == 100:
                radius = s["speed"] / s["yawRate"]
                report(
                    f"turn {left:g}/{right:g} %, radius (closed form: {closed:.3f} m)",
                    f"{radius:.3f} m, {100.0 * (radius / closed - 1.0):.1f} % wider",
                    "",
                    None,
                )


def perf(reps: int, report: Callable[..., Any]) -> None:
    """The ``fidelity`` target. Deterministic (the same figures every time), so one run
    whatever ``reps``: the table's reps column is the sitting's, not repetitions here."""
    long_skid(report)
    drifts(report)
    turns(report)


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT / "benchmarks"))
    from results import print_report

    perf(1, print_report)
