"""Compass: heading with a heading-dependent deviation, Gazebo noise and biases, losses."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from fractions import Fraction
from typing import Any, ClassVar

import numpy as np

from ..engine import batch_bodies
from ..engine import noise as nz
from ..engine.batch import all_positive, derived, gauss_markov
from ..engine.clock import seconds
from ..engine.rng import Drawn, DrawnMany
from ..model.params import Param
from ..model.sensorclock import stamped
from ..model.template import Kind, Port, Template

_TWO_PI = 2 * math.pi
_PI, _sin, _cos, _floor = math.pi, math.sin, math.cos, math.floor


def deviation(heading: Any, b: Any, c: Any, d: Any, e: Any) -> Any:
    """The compass deviation δ(θ) = B sin θ + C cos θ + D sin 2θ + E cos 2θ (rad).

    The navigator's classic deviation formula (its constant term A is the noise ``mean``):
    B and C, one cycle per turn, come from hard iron — a magnetic field fixed to the vehicle
    adds to the Earth's and pulls the needle towards one side of the hull; D and E, two
    cycles per turn, from soft iron, which distorts the Earth's field with the heading.
    Works on floats and numpy arrays alike.
    """
    if isinstance(heading, np.ndarray):
        twice = 2 * heading  # once for both terms: the same array
        return b * np.sin(heading) + c * np.cos(heading) + d * np.sin(twice) + e * np.cos(twice)
    return (
        b * math.sin(heading)
        + c * math.cos(heading)
        + d * math.sin(2 * heading)
        + e * math.cos(2 * heading)
    )


class Compass(Template):
    """Heading + deviation(heading) + Gazebo noise and biases, in [-pi, pi); may lose samples.

    The measured heading is ``θ + δ(θ) + mean + turn-on bias + Gauss–Markov bias + white
    noise`` (``sensors/noise.py``; δ: :func:`deviation`), wrapped to [-π, π), rounded to
    ``precision``. A lost sample (``lostData`` %) publishes nothing. White noise comes from
    the component's stream as before; biases and losses from two streams split off it.
    """

    kind = Kind.SENSOR
    inputs = (Port("heading", 0.0, "true heading", "rad"),)
    outputs = (Port("compassHeading", 0.0, "measured heading in [-pi, pi)", "rad"),)
    params = (
        *nz.noise_params("", "rad", "heading", math.pi),
        Param(
            "deviationB",
            "float",
            "hard-iron deviation: coefficient of sin θ",
            0.0,
            -0.5,
            0.5,
            "rad",
        ),
        Param(
            "deviationC",
            "float",
            "hard-iron deviation: coefficient of cos θ",
            0.0,
            -0.5,
            0.5,
            "rad",
        ),
        Param(
            "deviationD",
            "float",
            "soft-iron deviation: coefficient of sin 2θ",
            0.0,
            -0.5,
            0.5,
            "rad",
        ),
        Param(
            "deviationE",
            "float",
            "soft-iron deviation: coefficient of cos 2θ",
            0.0,
            -0.5,
            0.5,
            "rad",
        ),
        Param("lostData", "float", "share of samples lost", 0.0, 0.0, 100.0, "%"),
    )
    #: the paper's names: ``noise`` (standard deviation) and ``bias`` (constant offset)
    param_aliases: ClassVar[Mapping[str, str]] = {"noise": "stddev", "bias": "mean"}

    @classmethod
    def is_random(cls, values: Mapping[str, Any]) -> bool:
        """Noise, a random bias or losses make the headings depend on the seed."""
        return nz.is_noisy(values) or values["lostData"] > 0

    def initialize(self, ctx: Any) -> None:
        """White noise from this component's stream; biases and losses from two split off it."""
        bias, loss = ctx.rng.spawn(2)
        self.turn_on = nz.TurnOn(bias, 1)
        self.gm_start = float(bias.standard_normal())
        self.noise = Drawn(ctx.rng.standard_normal)
        self.draw_bias = Drawn(bias.standard_normal)
        self.draw_loss = Drawn(loss.random)
        self.b = 0.0  # dynamic bias
        self.t_prev: float | None = None
        self.lost = 0
        self._gm: tuple[tuple[float, float, float], tuple[float, float]] = ((-1, -1, -1), (1, 0))

    def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
        """The paper's doStep: one heading sample, or none if lost.

        Written for speed (as ``GPS.do_step``): locals, ``float(t)``, the turn-on bias,
        :func:`deviation` and the quantisation inlined; the same arithmetic in the same
        order, so the same floats.
        """
        w = self.noise()
        g = self.draw_bias()
        u = self.draw_loss()
        p = self.p
        # float(t) (``numbers.Rational.__float__``: numerator / denominator) without its calls
        now = t._numerator / t._denominator if t.__class__ is Fraction else float(t)
        sigma = p.dynamic_bias_stddev
        t_prev = self.t_prev
        if t_prev is None:
            self.b = b = nz.stationary_std(sigma, p.dynamic_bias_correlation_time) * self.gm_start
        else:
            b = self.b
            if sigma > 0 or b != 0.0:
                key = (sigma, p.dynamic_bias_correlation_time, now - t_prev)
                gm = self._gm
                if key != gm[0]:
                    self._gm = gm = (key, nz.gauss_markov(*key))
                phi, q = gm[1]
                self.b = b = phi * b + q * g
        self.t_prev = now
        if u * 100.0 < p.lostData:
            self.lost += 1
            return {}
        h = inp["heading"]
        value = h + p.mean + b + p.stddev * w
        turn_on = self.turn_on  # turn_on.value(0, ...), inlined
        value += turn_on.sign[0] * (p.bias_mean + p.bias_stddev * turn_on.z[0])
        db, dc, dd, de = p.deviationB, p.deviationC, p.deviationD, p.deviationE
        if db or dc or dd or de:  # deviation(h, ...) for a float, inlined
            value += db * _sin(h) + dc * _cos(h) + dd * _sin(2 * h) + de * _cos(2 * h)
        value = (value + _PI) % _TWO_PI - _PI
        precision = p.precision
        if precision > 0:  # nz.quantise, inlined
            value = (_floor(value / precision + 0.5) * precision + _PI) % _TWO_PI - _PI
        return {"compassHeading": value}

    @classmethod
    def step_many(
        cls, comps: Sequence[Any], t: Fraction, inp: Mapping[str, Any], p: Any, state: Any
    ) -> tuple[Mapping[str, Any], np.ndarray]:
        """``do_step`` for many copies at once, each from its own streams (``engine/batch.py``)."""
        if "noise" not in state:
            state["noise"] = DrawnMany([c.noise for c in comps])
            state["bias"] = DrawnMany([c.draw_bias for c in comps])
            state["loss"] = DrawnMany([c.draw_loss for c in comps])
            state["gm_start"] = np.array([c.gm_start for c in comps])
            state["on_z"] = np.array([c.turn_on.z[0] for c in comps])
            state["on_sign"] = np.array([c.turn_on.sign[0] for c in comps])
            state["t_prev"] = None
            #: the heading after the first step as one compiled call, where built
            state["body"] = batch_bodies.compass_heading()
        w = state["noise"]()
        g = state["bias"]()
        u = state["loss"]()
        now = seconds(t)
        sigma, tau = p.dynamic_bias_stddev, p.dynamic_bias_correlation_time
        if state["t_prev"] is None:
            state["b"] = np.where(tau > 0, sigma * np.sqrt(tau / 2), 0.0) * state["gm_start"]
        else:
            phi, q = gauss_markov(state, sigma, tau, now - state["t_prev"])
            body = state["body"]
            if body is not None:
                state["t_prev"] = now
                return _heading_compiled(body, comps, inp, p, state, (w, g, u), phi, q)
            state["b"] = phi * state["b"] + q * g
        state["t_prev"] = now
        lost = u * 100.0 < p.lostData
        for k in np.flatnonzero(lost).tolist():
            comps[k].lost += 1
        h = inp["heading"]
        value = h + p.mean + state["b"] + p.stddev * w
        # what depends on the parameters alone, computed again only when they change
        # (``batch.derived``): the same arithmetic, so the same floats
        sign, z = state["on_sign"], state["on_z"]
        value += derived(state, "turn_on", (p.bias_mean, p.bias_stddev), _turn_on_many(sign, z))
        value += deviation(h, p.deviationB, p.deviationC, p.deviationD, p.deviationE)
        value = (value + math.pi) % _TWO_PI - math.pi
        precision = p.precision
        if derived(state, "all_quantise", (precision,), all_positive):
            q = np.floor(value / precision + 0.5) * precision  # quantise_many's arithmetic
            return {"compassHeading": (q + math.pi) % _TWO_PI - math.pi}, ~lost
        q = nz.quantise_many(value, precision)
        value = np.where(precision > 0, (q + math.pi) % _TWO_PI - math.pi, value)
        return {"compassHeading": value}, ~lost


def _turn_on_many(sign: np.ndarray, z: np.ndarray) -> Callable[[Any, Any], np.ndarray]:
    """The copies' turn-on biases for parameter arrays ``(bias_mean, bias_stddev)``
    (``noise.TurnOn.value``'s arithmetic), for :func:`~amsa_phys.engine.batch.derived`."""
    return lambda m, s: sign * (m + s * z)


def _heading_compiled(
    body: Any,
    comps: Sequence[Any],
    inp: Mapping[str, Any],
    p: Any,
    state: dict[str, Any],
    draws: tuple[np.ndarray, np.ndarray, np.ndarray],
    phi: np.ndarray,
    q: np.ndarray,
) -> tuple[Mapping[str, Any], np.ndarray]:
    """``step_many`` after the first step in one compiled call (``engine/batch_bodies.py``):
    the numpy path's operations in its order, so its floats; the dynamic bias updated in
    place. The deviation stays numpy's (its sines may differ from libm's in the last bit)."""
    sign, z = state["on_sign"], state["on_z"]
    turn_on = derived(state, "turn_on", (p.bias_mean, p.bias_stddev), _turn_on_many(sign, z))
    n = len(comps)
    kept = state.get("heading_out")
    if kept is None or len(kept[0]) != n:
        # made once a group: the engine copies a group's outputs and mask at once (and sends
        # copies), so a template may reuse its arrays
        kept = state["heading_out"] = (np.empty(n), np.empty(n, dtype=bool), {})
    value, published, out = kept
    w, g, u = draws
    h = inp["heading"]
    coefficients = (p.deviationB, p.deviationC, p.deviationD, p.deviationE)
    if derived(state, "no_deviation", coefficients, _all_zero):
        # every term 0 * sin: a zero of either sign, which leaves the heading's bits as they
        # are up to a zero's sign, and the wrap below makes -0.0 and +0.0 one value (the
        # scalar step skips the term alike); headings are finite (a robot's judged pose)
        dev = state.get("zero_deviation")
        if dev is None or dev.shape != np.shape(h):
            dev = state["zero_deviation"] = np.zeros(np.shape(h))
    else:
        dev = _deviation_many(state, h, coefficients)
    if body(
        h, w, g, u, phi, q, p.mean, turn_on, p.stddev, p.precision, p.lostData,
        state["b"], value, published, dev,
    ):  # fmt: skip
        for k in np.flatnonzero(~published).tolist():
            comps[k].lost += 1
    out["compassHeading"] = value
    return out, published


def _deviation_many(
    state: dict[str, Any], h: np.ndarray, coefficients: tuple[np.ndarray, ...]
) -> np.ndarray:
    """:func:`deviation` of the copies' headings ``h``: its four sines and cosines numpy's, as
    there, and their products and sums in one compiled call where built
    (``_groupbodies.deviation``: the same operations in the same order, so the same floats).
    Why: those seven numpy calls were ~3 µs of a compass group's step."""
    combine = state.get("deviation_body", _UNSET)
    if combine is _UNSET:
        combine = state["deviation_body"] = batch_bodies.deviation()
    if combine is None or type(h) is not np.ndarray:
        return deviation(h, *coefficients)  # type: ignore[no-any-return]
    scratch = state.get("deviation_scratch")
    if scratch is None or len(scratch[0]) != len(h):  # the terms' arrays, made once a group
        # each its own array, as the fresh ones numpy's deviation() makes
        scratch = state["deviation_scratch"] = tuple(np.empty(len(h)) for _ in range(6))
    twice, s1, c1, s2, c2, dev = scratch
    np.multiply(2, h, out=twice)  # 2 * h, as deviation(): once for both terms
    np.sin(h, out=s1)
    np.cos(h, out=c1)
    np.sin(twice, out=s2)
    np.cos(twice, out=c2)
    combine(*coefficients, s1, c1, s2, c2, dev)
    return dev


#: a group's state before it asked for its compiled deviation
_UNSET = object()


def _all_zero(*coefficients: np.ndarray) -> bool:
    """Whether every copy's deviation coefficients are all 0 (for ``derived``)."""
    return not any(bool(np.any(c != 0)) for c in coefficients)


#: Compass with the sensor's own clock: an output ``stamp`` (``model/sensorclock.py``)
StampedCompass = stamped(Compass)
