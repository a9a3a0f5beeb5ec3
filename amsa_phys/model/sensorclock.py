"""A sensor's own clock: the time stamp it puts on a sample, and the templates that publish it.

In the model layer because both sensor packages use it (``sensors/`` and ``physics/``, whose
GNSS and lidar read the world's geometry) and neither may import the other.

One clock model for every sensor. A real sensor stamps a sample with its own clock, which
is off from the robot's by a constant offset, drifts from it at some parts per million
since they were last synchronised (here at t = 0), and is read with some jitter (the
driver's latency between the measurement and the stamp). So the stamp of a sample measured
at true time t is::

    t + clockOffset + syncDrift · 1e-6 · t + stampJitter · N(0, 1)

``GNSS`` has always carried it (``fixTime``). :func:`stamped` gives any other sensor
template the same clock as a twin template (``StampedIMU``, ``StampedWheelOdometry``,
``StampedCompass``, ``StampedLidar``): the sensor's own outputs, bit for bit (its random
streams are its own; the jitter has a stream split off after them), plus an output
``stamp``. Why twins rather than parameters on the sensors themselves: an output port is a
trace column, and the paper's worlds' traces must not change; a user who wants stamps picks
the twin, and the trace then keeps both the true time (``t``) and the stamp.
"""

from __future__ import annotations

from collections.abc import Mapping
from fractions import Fraction
from typing import Any, ClassVar

from .params import Param
from .template import Port, Template

#: the clock's parameters (their names, in the order :func:`clock_params` gives them)
CLOCK_NAMES = ("clockOffset", "syncDrift", "stampJitter")


def clock_params(sample: str = "sample", clock: str = "sensor") -> tuple[Param, ...]:
    """``clockOffset``, ``syncDrift`` and ``stampJitter``, worded for ``sample`` stamps of
    a ``clock`` (GNSS: "fix", "receiver"); all 0 by default: stamps equal true times."""
    return (
        Param(
            "clockOffset", "float", f"constant offset of the {sample} stamps", 0.0, -1e3, 1e3, "s"
        ),
        Param(
            "syncDrift",
            "float",
            f"drift of the {clock} clock from the robot's",
            0.0,
            -1e5,
            1e5,
            "ppm",
        ),
        Param(
            "stampJitter", "float", "standard deviation of the stamp jitter", 0.0, 0.0, 10.0, "s"
        ),
    )


class SensorClock:
    """Stamps samples with a sensor's clock (the formula in this module's docstring).

    ``rng`` is the jitter's own stream: one draw per :meth:`stamp`, whatever the
    parameters, so turning the jitter on or off keeps every other draw of the run.
    """

    def __init__(self, rng: Any) -> None:
        self.rng = rng

    def draw(self) -> float:
        """This sample's jitter draw (standard normal)."""
        return float(self.rng.standard_normal())

    @staticmethod
    def at(now: float, p: Any, jitter: float) -> float:
        """The stamp of a sample measured at true time ``now`` with jitter draw ``jitter``;
        ``p`` has the clock's parameters."""
        return now + p.clockOffset + p.syncDrift * 1e-6 * now + p.stampJitter * jitter

    def stamp(self, now: float, p: Any) -> float:
        """Draw the jitter and stamp a sample measured at ``now``."""
        return self.at(now, p, self.draw())


#: the output every stamped twin adds
STAMP = Port("stamp", 0.0, "sensor's time stamp of the sample (its own clock)", "s")


def stamped(base: type[Template]) -> type[Template]:
    """``base``'s twin with a clock: the same ports, parameters and samples, plus the
    clock's parameters and an output ``stamp`` published with every sample.

    The twin holds a ``base`` sensor (sharing its parameter values, so timeline changes
    reach it) and steps it one sample at a time: ``base.step_many`` is not inherited, as a
    group of copies would need the clock in every template's array code.
    """
    first = (base.__doc__ or "").strip().splitlines()[0].rstrip(".")
    name = f"Stamped{base.name()}"

    class Twin(Template):
        kind = base.kind
        inputs = base.inputs
        outputs = (*base.outputs, STAMP)
        params = (*base.params, *clock_params())
        param_aliases = base.param_aliases
        fixed_once_running = base.fixed_once_running
        setpoints = base.setpoints
        marks = base.marks
        # in a batch each run's copy steps alone (no step_many), as the plain sensor may
        batchable = True
        template_name = name
        sensor: ClassVar[type[Template]] = base

        @classmethod
        def is_random(cls, values: Mapping[str, Any]) -> bool:
            """The sensor's own randomness, or a jittered clock."""
            return base.is_random(values) or values["stampJitter"] > 0

        @classmethod
        def check_params(cls, values: Mapping[str, Any]) -> None:
            """The sensor's own rules (the clock's parameters have none between them)."""
            base.check_params(values)

        def initialize(self, ctx: Any) -> None:
            """The sensor first (its streams as its own template's), then the jitter's."""
            self.inner = base(self.path, {})
            self.inner.p = self.p
            self.inner.initialize(ctx)
            (jitter,) = ctx.rng.spawn(1)
            self.clock = SensorClock(jitter)

        def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
            """The sensor's sample, stamped; nothing when it publishes nothing."""
            jitter = self.clock.draw()  # every step: the stream never depends on losses
            out = self.inner.do_step(t, inp)
            if not out:
                return out
            return {**out, "stamp": SensorClock.at(float(t), self.p, jitter)}

        def on_param_change(self, name: str, value: Any) -> None:
            """The sensor's own parameters reach it; the clock reads its values live."""
            if name not in CLOCK_NAMES:
                self.inner.on_param_change(name, value)

        def __getattr__(self, attr: str) -> Any:
            # the sensor's counters (``lost``, read by the bag writer) and state
            inner = self.__dict__.get("inner")
            if inner is None:
                raise AttributeError(attr)
            return getattr(inner, attr)

    Twin.__name__ = Twin.__qualname__ = name
    Twin.__module__ = base.__module__
    Twin.__doc__ = (
        f"{first}, stamped by the sensor's own clock (offset, drift, jitter).\n\n"
        f"``{base.name()}`` with an output ``stamp``: the sample's true time + ``clockOffset`` "
        "+ ``syncDrift``·1e-6·t + ``stampJitter``·N(0,1) (``model/sensorclock.py``). Everything "
        f"else is ``{base.name()}``'s, sample for sample.\n\n" + (base.__doc__ or "")
    )
    return Twin
