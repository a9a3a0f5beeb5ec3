"""Loop timing of a Leaf: transport latency, jitter and the phase of its timer.

In the paper the components are ROS nodes, each on its own timer: a message published by one
node is read by another only at that node's next tick, after the transport's delay. The engine
models that explicitly, per Leaf (``components.NAME`` keys, beside ``freq``):

* ``latency`` (s): the Leaf's outputs reach their readers this long after the step that
  published them (every output, every reader: the Leaf's processing and transport delay);
* ``jitter`` (s): each publication is delayed by a further ``u * jitter``, ``u`` uniform in
  [0, 1) drawn from the Leaf's own *timing* stream of the seed tree (``engine/rng.py``), so a
  world without jitter draws nothing and its other random streams are untouched. Messages
  of one Leaf arrive in the order they were sent (a ROS topic is a FIFO connection);
* ``phase`` (s, below the period): the Leaf runs at ``phase + k / freq`` instead of
  ``k / freq``; ``random`` draws it from the timing stream, as for separately started nodes.

``timing: {free_running: true}`` in a world gives every Leaf without its own ``phase`` a
random one. Random phases are rounded down to ``timing.resolution`` (default 1 ms) so they
stay on the engine's exact time grid. These keys hold for the whole run: a scenario may set
them in ``set:`` (``MyFollowerController.latency: 0``) or ``--set``, never in its timeline.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from fractions import Fraction
from typing import Any

from .params import short_repr

#: The Leaf keys this module reads (besides ``freq``), in the order they are documented.
TIMING_KEYS = ("latency", "jitter", "phase")
#: Largest latency or jitter: beyond a minute it is a typo, and a long delay line is memory.
MAX_DELAY_S = Fraction(60)
#: Default resolution of random phases (s).
DEFAULT_RESOLUTION = Fraction(1, 1000)
RANDOM = "random"


@dataclass(frozen=True)
class LeafTiming:
    """A Leaf's timing: ``phase`` None means 0, or random in a free-running world."""

    latency: Fraction = Fraction(0)
    jitter: Fraction = Fraction(0)
    phase: Fraction | str | None = None

    @property
    def delayed(self) -> bool:
        """Whether the Leaf's outputs travel through a delay line.

        Both are never negative (``seconds`` refuses it), so "above 0" is "not 0": a
        Fraction's truth is its numerator's, where ``> 0`` goes through Fraction's rich
        comparison (~4 µs; a 1,000-env vector env's reset asks 8,000 times)."""
        return bool(self.latency) or bool(self.jitter)


def seconds(value: Any, what: str, limit: Fraction | None = MAX_DELAY_S) -> Fraction:
    """A non-negative duration from a file or ``--set``: a number or a fraction ``"1/3"``.

    Raises ValueError with the message the user sees (the caller adds file, line and key).
    """
    if isinstance(value, bool) or not isinstance(value, int | float | str):
        raise ValueError(f"expected {what} in seconds, got {short_repr(value)}")
    try:
        out = Fraction(str(value).strip())
    except (ValueError, ZeroDivisionError):
        raise ValueError(f"expected {what} in seconds, got {short_repr(value)}") from None
    if out < 0:
        raise ValueError(f"{what} must be >= 0, got {value}")
    if limit is not None and out > limit:
        raise ValueError(f"{what} must be <= {limit} s, got {value}")
    return out


def timed(timing: LeafTiming, key: str, value: Any, freq: Fraction) -> LeafTiming:
    """``timing`` with ``latency``, ``jitter`` or ``phase`` set, judged (ValueError if bad).

    A new LeafTiming: a world's Leaf (and so its timing) may be shared by cached scenarios.
    """
    if key == "phase":
        if value == RANDOM:
            return replace(timing, phase=RANDOM)
        phase = seconds(value, "a phase (or 'random')", limit=None)
        period = 1 / freq
        if phase >= period:
            raise ValueError(
                f"a phase must be below the period (1/{_num(freq)} Hz = {_num(period)} s), "
                f"got {value}"
            )
        return replace(timing, phase=phase)
    return replace(timing, **{key: seconds(value, f"a {key}")})


def check_phase(timing: LeafTiming, freq: Fraction) -> str | None:
    """Why a fixed phase no longer fits the Leaf's (changed) frequency, or None."""
    if isinstance(timing.phase, Fraction) and timing.phase >= 1 / freq:
        return (
            f"phase {_num(timing.phase)} s is not below the period of {_num(freq)} Hz "
            f"({_num(1 / freq)} s)"
        )
    return None


def resolution(world_timing: dict[str, Any]) -> Fraction:
    """The world's resolution of random phases."""
    value = world_timing.get("resolution")
    return DEFAULT_RESOLUTION if value is None else Fraction(str(value))


def describe(timing: LeafTiming, free_running: bool) -> str:
    """``latency 0.25 s, phase random`` (empty when the Leaf has default timing)."""
    parts = []
    if timing.latency:
        parts.append(f"latency {_num(timing.latency)} s")
    if timing.jitter:
        parts.append(f"jitter {_num(timing.jitter)} s")
    phase = timing.phase
    if phase is None and free_running:
        parts.append("phase random (free-running)")
    elif phase == RANDOM:
        parts.append("phase random")
    elif phase:
        parts.append(f"phase {_num(Fraction(phase))} s")
    return ", ".join(parts)


def _num(value: Fraction) -> str:
    """A Fraction as a short decimal when it has one, else ``7/3``."""
    f = float(value)
    return f"{f:g}" if Fraction(str(f)) == value else str(value)
