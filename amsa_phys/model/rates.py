"""The rates a world and a scenario may use: each within bounds, together repeating soon.

What validates must run. The engine precomputes one cycle of its schedule (the instants
until every rate's pattern repeats, ``engine/clock.py``); rates that are each reasonable
can still be incommensurate together (0.001 Hz and 10 kHz repeat every 1000 s, 10^7
events), and the engine would refuse them only once the run starts. So the loader checks
the same count with the same arithmetic first: exact rationals, the cycle is the least
common multiple of the periods, and each rate contributes ``cycle / period`` events.
"""

from __future__ import annotations

from collections.abc import Iterable
from fractions import Fraction
from math import gcd, lcm

#: Slowest component or trace rate: one step every 1000 s.
MIN_RATE_HZ = 0.001
#: Slowest physics rate: a step longer than a second is no longer a simulation of rovers.
MIN_PHYSICS_RATE_HZ = 1
#: Fastest rate of anything: 100x the default physics rate; ~1 s of computer time per
#: simulated second for the physics alone.
MAX_RATE_HZ = 10_000
#: Events (component steps, trace rows, physics steps) in one cycle of the schedule.
MAX_EVENTS_PER_CYCLE = 2_000_000


def cycle_of(rates: Iterable[Fraction]) -> tuple[Fraction, int]:
    """The schedule's cycle in seconds and the events in it, for ``rates`` in Hz."""
    periods = [1 / Fraction(r) for r in rates if r > 0]
    if not periods:
        return Fraction(0), 0
    num = lcm(*(p.numerator for p in periods))
    den = 0
    for p in periods:
        den = gcd(den, p.denominator)
    cycle = Fraction(num, den)
    return cycle, sum(int(cycle / p) for p in periods)


def cycle_problem(rates: Iterable[Fraction]) -> str | None:
    """Why ``rates`` cannot be scheduled together (None if they can)."""
    cycle, events = cycle_of(rates)
    if events <= MAX_EVENTS_PER_CYCLE:
        return None
    return (
        f"the rates repeat only every {float(cycle):g} s ({events:,} events per cycle, "
        f"the limit is {MAX_EVENTS_PER_CYCLE:,}); use commensurate frequencies"
    )
