"""GPS: a position fix with per-axis noise and biases, latency, quantisation and losses."""

from __future__ import annotations

from collections import deque
from collections.abc import Callable, Mapping, Sequence
from fractions import Fraction
from math import floor
from typing import Any, ClassVar

import numpy as np

from ..engine import batch_bodies
from ..engine import noise as nz
from ..engine.batch import all_positive, derived, gauss_markov
from ..engine.clock import seconds
from ..engine.rng import Drawn, DrawnMany
from ..model.params import Param
from ..model.template import Kind, Port, Template
from ..templatemarks import Fix

#: Slack when comparing float times (steps fall on a rational grid; floats of it round).
_EPS = 1e-9


class GPS(Template):
    """Position fix: Gazebo noise per axis, Gauss-Markov bias, latency, independent and burst loss.

    Each axis gets ``mean`` + a turn-on bias + a Gauss–Markov dynamic bias + white noise
    (``sensors/noise.py``), then is rounded to ``precision``. With ``latency`` L the fix
    published at a step is the one *measured* at the newest earlier step at least L before:
    the receiver measures at its own rate, so the lag is L rounded up to a whole number of
    periods (L = 0.3 s at 4 Hz publishes the position of 0.5 s before); until such a fix
    exists, nothing is published. A lost sample (``lostDataGPS`` %, independent, or a
    Gilbert–Elliott burst: ``burstLoss`` %, mean ``burstLength`` samples) publishes nothing,
    so consumers keep the stale fix — the paper's degraded context relies on it. Every step
    draws from four separate streams (white noise, loss, bias, burst), lost or not, so a
    sweep over any loss parameter keeps the same noise sequence.
    """

    kind = Kind.SENSOR
    inputs = (Port("posX", 0.0, "true x", "m"), Port("posY", 0.0, "true y", "m"))
    outputs = (Port("gpsPosX", 0.0, "measured x", "m"), Port("gpsPosY", 0.0, "measured y", "m"))
    params = (
        *nz.noise_params("", "m", "position on each axis", 100.0),
        Param("latency", "float", "age of a fix when published", 0.0, 0.0, 10.0, "s"),
        Param("lostDataGPS", "int", "share of samples lost independently", 0, 0, 100, "%"),
        *nz.burst_params("samples"),
    )
    #: the paper's names: ``noise`` (standard deviation) and ``bias`` (offset on both axes)
    param_aliases: ClassVar[Mapping[str, str]] = {"noise": "stddev", "bias": "mean"}
    #: drawn as fixes in the measured rover's colour, a lost sample as a red cross
    marks = (Fix("gpsPosX", "gpsPosY", "posX", "lost", ("lostDataGPS", "burstLoss")),)

    @classmethod
    def check_params(cls, values: Mapping[str, Any]) -> None:
        """A burst share the chain can reach: entering a burst has a probability <= 1."""
        nz.check_burst(values["burstLoss"], values["burstLength"])

    @classmethod
    def is_random(cls, values: Mapping[str, Any]) -> bool:
        """Noise, a random bias or any loss makes the fixes depend on the seed."""
        return nz.is_noisy(values) or values["lostDataGPS"] > 0 or values["burstLoss"] > 0

    def initialize(self, ctx: Any) -> None:
        """Split this component's stream: white noise, loss, bias and burst draws.

        The first two are the streams the GPS has always used, so a noise-and-loss-only GPS
        draws exactly what it did before the biases and bursts existed.
        """
        self.check_params(self.p.as_dict())
        white, loss, bias, burst = ctx.rng.spawn(4)
        self.turn_on = nz.TurnOn(bias, 2)
        self.gm_start = bias.standard_normal(2).tolist()
        self.noise = Drawn(white.standard_normal)
        self.draw_loss = Drawn(loss.random)
        self.draw_bias = Drawn(bias.standard_normal)
        self.draw_burst = Drawn(burst.random)
        self.lost = 0  # samples lost so far: the renderer marks them
        self.bx = self.by = 0.0  # dynamic biases
        self.t_prev: float | None = None
        self.bad = False  # Gilbert-Elliott state
        self.history: deque[tuple[float, float, float]] = deque()
        self._gm: tuple[tuple[float, float, float], tuple[float, float]] = ((-1, -1, -1), (1, 0))
        self._derive()

    def on_param_change(self, name: str, value: Any) -> None:
        """Recompute what depends on the parameters (changed from code: check them too)."""
        self.check_params(self.p.as_dict())
        self._derive()

    def _derive(self) -> None:
        p = self.p
        self.on_x = self.turn_on.value(0, p.bias_mean, p.bias_stddev)
        self.on_y = self.turn_on.value(1, p.bias_mean, p.bias_stddev)
        self.enter, self.leave = nz.burst_chance(p.burstLoss, p.burstLength)

    def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
        """The paper's doStep: measure the position, publish a (late) fix or lose it.

        Written for speed (it runs at every fix of every receiver): parameters and state
        read into locals once, ``float(t)`` and :func:`~amsa_phys.engine.noise.quantise`
        inlined (``Fraction.__float__`` alone was ~0.5 us). The arithmetic is the same, in
        the same order: the same floats.
        """
        noise, bias = self.noise, self.draw_bias
        ex = noise()
        ey = noise()
        gx = bias()
        gy = bias()
        u_loss = self.draw_loss()
        u_burst = self.draw_burst()
        p = self.p
        # float(t) (``numbers.Rational.__float__``: numerator / denominator) without its calls
        now = t._numerator / t._denominator if t.__class__ is Fraction else float(t)
        t_prev = self.t_prev
        first = t_prev is None
        if first:
            sigma = p.dynamic_bias_stddev
            s0 = nz.stationary_std(sigma, p.dynamic_bias_correlation_time)
            self.bx, self.by = s0 * self.gm_start[0], s0 * self.gm_start[1]
            # the burst chain starts from its stationary distribution
            self.bad = u_burst * 100.0 < p.burstLoss
        else:
            sigma = p.dynamic_bias_stddev
            bx, by = self.bx, self.by
            if sigma > 0 or bx != 0.0 or by != 0.0:
                key = (sigma, p.dynamic_bias_correlation_time, now - t_prev)
                gm = self._gm
                if key != gm[0]:
                    self._gm = gm = (key, nz.gauss_markov(*key))
                phi, q = gm[1]
                self.bx = phi * bx + q * gx
                self.by = phi * by + q * gy
        self.t_prev = now
        mean, stddev = p.mean, p.stddev
        x = inp["posX"] + mean + self.on_x + self.bx + stddev * ex
        y = inp["posY"] + mean + self.on_y + self.by + stddev * ey
        precision = p.precision
        if precision > 0:  # nz.quantise, inlined
            x = floor(x / precision + 0.5) * precision
            y = floor(y / precision + 0.5) * precision
        if not first:
            self.bad = (u_burst >= self.leave) if self.bad else (u_burst < self.enter)
        lost = self.bad or u_loss * 100.0 < p.lostDataGPS
        latency = p.latency
        if latency > 0 or self.history:
            x, y, ready = self._delay(now, x, y, latency)
            if not ready:
                return {}
        if lost:
            self.lost += 1
            return {}
        return {"gpsPosX": x, "gpsPosY": y}

    def _delay(self, now: float, x: float, y: float, latency: float) -> tuple[float, float, bool]:
        """The newest fix measured at least ``latency`` ago (and whether there is one)."""
        hist = self.history
        hist.append((now, x, y))
        due = now - latency + _EPS
        while len(hist) > 1 and hist[1][0] <= due:
            hist.popleft()
        t0, x0, y0 = hist[0]
        return x0, y0, t0 <= due

    @classmethod
    def step_many(
        cls, comps: Sequence[Any], t: Fraction, inp: Mapping[str, Any], p: Any, state: Any
    ) -> tuple[Mapping[str, Any], np.ndarray]:
        """``do_step`` for many copies at once (``engine/batch.py``).

        Each copy draws from its own streams in the scalar order and follows the scalar
        arithmetic (the same formulas on arrays); lost or not-yet-due copies publish
        nothing (the mask returned).
        """
        if "noise" not in state:
            state["noise"] = DrawnMany([c.noise for c in comps])
            state["loss"] = DrawnMany([c.draw_loss for c in comps])
            state["bias"] = DrawnMany([c.draw_bias for c in comps])
            state["burst"] = DrawnMany([c.draw_burst for c in comps])
            state["gm_start"] = np.array([c.gm_start for c in comps]).T
            state["on_z"] = np.array([c.turn_on.z for c in comps]).T
            state["on_sign"] = np.array([c.turn_on.sign for c in comps]).T
            state["bad"] = np.zeros(len(comps), dtype=bool)
            state["history"] = deque()
            state["t_prev"] = None
            #: the fix after the first step as one compiled call, where built
            state["fix"] = batch_bodies.gps_fix()
        ex = state["noise"]()
        ey = state["noise"]()
        gx = state["bias"]()
        gy = state["bias"]()
        u_loss = state["loss"]()
        u_burst = state["burst"]()
        now = seconds(t)
        sigma, tau = p.dynamic_bias_stddev, p.dynamic_bias_correlation_time
        first = state["t_prev"] is None
        if first:
            s0 = np.where(tau > 0, sigma * np.sqrt(tau / 2), 0.0)
            state["bx"], state["by"] = s0 * state["gm_start"][0], s0 * state["gm_start"][1]
            state["bad"] = u_burst * 100.0 < p.burstLoss
        else:
            phi, q = gauss_markov(state, sigma, tau, now - state["t_prev"])
            fix = state["fix"]
            if fix is not None and not state["history"]:
                # what the body reads that depends on the parameters alone, None with a
                # latency (the numpy path keeps the history): one lookup a step
                held = derived(
                    state,
                    "fix_params",
                    (p.bias_mean, p.bias_stddev, p.burstLoss, p.burstLength, p.latency),
                    _fix_params(state["on_z"], state["on_sign"]),
                )
                if held is not None:
                    state["t_prev"] = now
                    draws = (ex, ey, gx, gy, u_loss, u_burst)
                    return _fix_compiled(fix, comps, inp, p, state, draws, phi, q, held)
            state["bx"] = phi * state["bx"] + q * gx
            state["by"] = phi * state["by"] + q * gy
        state["t_prev"] = now
        # what depends on the parameters alone, computed again only when they change
        # (``batch.derived``): the same arithmetic, so the same floats
        z, sign = state["on_z"], state["on_sign"]
        on_x, on_y = derived(state, "turn_on", (p.bias_mean, p.bias_stddev), _turn_on_many(sign, z))
        x = inp["posX"] + p.mean + on_x + state["bx"] + p.stddev * ex
        y = inp["posY"] + p.mean + on_y + state["by"] + p.stddev * ey
        precision = p.precision
        if derived(state, "all_quantise", (precision,), all_positive):
            x = np.floor(x / precision + 0.5) * precision  # quantise_many's arithmetic
            y = np.floor(y / precision + 0.5) * precision
        else:
            x = nz.quantise_many(x, precision)
            y = nz.quantise_many(y, precision)
        if not first:
            enter, leave = derived(state, "burst_chance", (p.burstLoss, p.burstLength), _burst_many)
            bad = state["bad"]
            state["bad"] = np.where(bad, u_burst >= leave, u_burst < enter)
        lost = state["bad"] | (u_loss * 100.0 < p.lostDataGPS)
        published = ~lost
        latency = p.latency
        if derived(state, "any_latency", (latency,), np.any) or state["history"]:
            x, y, ready = _delay_many(state["history"], now, x, y, latency)
            published &= ready
            lost &= ready
        for k in np.flatnonzero(lost).tolist():
            comps[k].lost += 1
        return {"gpsPosX": x, "gpsPosY": y}, published


def _turn_on_many(
    sign: np.ndarray, z: np.ndarray
) -> Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]:
    """The copies' turn-on biases (x, y) for parameter arrays ``(bias_mean, bias_stddev)``
    (``noise.TurnOn.value``'s arithmetic), for :func:`~amsa_phys.engine.batch.derived`."""
    return lambda m, s: (sign[0] * (m + s * z[0]), sign[1] * (m + s * z[1]))


def _fix_compiled(
    fix: Any,
    comps: Sequence[Any],
    inp: Mapping[str, Any],
    p: Any,
    state: dict[str, Any],
    draws: tuple[np.ndarray, ...],
    phi: np.ndarray,
    q: np.ndarray,
    held: tuple[np.ndarray, ...],
) -> tuple[Mapping[str, Any], np.ndarray]:
    """``step_many`` after the first step without latency, in one compiled call
    (``engine/batch_bodies.py``): the numpy path's operations in its order, so its floats;
    the dynamic biases and the burst state updated in place. ``held``: the turn-on biases
    and the burst chances (:func:`_fix_params`)."""
    on_x, on_y, enter, leave = held
    n = len(comps)
    kept = state.get("fix_out")
    if kept is None or len(kept[0]) != n:
        # made once a group: the engine copies a group's outputs and mask at once (and sends
        # copies), so a template may reuse its arrays
        kept = state["fix_out"] = (
            np.empty(n), np.empty(n), np.empty(n, dtype=bool), np.empty(n, dtype=bool),
            {},
        )  # fmt: skip
    x, y, published, lost, out = kept
    ex, ey, gx, gy, u_loss, u_burst = draws
    if fix(
        inp["posX"], inp["posY"], ex, ey, gx, gy, u_loss, u_burst, phi, q, p.mean, on_x, on_y,
        p.stddev, p.precision, enter, leave, p.lostDataGPS, state["bx"], state["by"],
        state["bad"], x, y, published, lost,
    ):  # fmt: skip
        for k in lost.nonzero()[0].tolist():
            comps[k].lost += 1
    out["gpsPosX"], out["gpsPosY"] = x, y
    return out, published


def _fix_params(z: np.ndarray, sign: np.ndarray) -> Callable[..., tuple[np.ndarray, ...] | None]:
    """For :func:`~amsa_phys.engine.batch.derived`: from parameter arrays ``(bias_mean,
    bias_stddev, burstLoss, burstLength, latency)``, the compiled fix's ``(on_x, on_y,
    enter, leave)`` (the numpy path's arithmetic: :func:`_turn_on_many`, :func:`_burst_many`),
    or None when a copy has a latency (the numpy path's history then)."""

    def make(
        mean: np.ndarray, std: np.ndarray, loss: np.ndarray, length: np.ndarray, lat: np.ndarray
    ) -> tuple[np.ndarray, ...] | None:
        if np.any(lat):
            return None
        return (*_turn_on_many(sign, z)(mean, std), *_burst_many(loss, length))

    return make


def _burst_many(burst_loss: np.ndarray, length: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each copy's ``(enter, leave)`` per-sample probabilities (``noise.burst_chance``'s
    arithmetic on arrays)."""
    pi = burst_loss / 100.0
    leave = 1.0 / length
    return leave * pi / (1.0 - pi), leave


def _delay_many(
    hist: deque[tuple[float, np.ndarray, np.ndarray]],
    now: float,
    x: np.ndarray,
    y: np.ndarray,
    latency: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each copy's newest fix measured at least its ``latency`` ago, and which copies have one."""
    hist.append((now, x, y))
    oldest_due = now - float(latency.max()) + _EPS
    while len(hist) > 1 and hist[1][0] <= oldest_due:
        hist.popleft()
    times = np.array([h[0] for h in hist])
    due = now - latency + _EPS
    j = np.searchsorted(times, due, side="right") - 1
    ready = j >= 0
    j = np.maximum(j, 0)
    xs = np.array([h[1] for h in hist])
    ys = np.array([h[2] for h in hist])
    cols = np.arange(len(x))
    return xs[j, cols], ys[j, cols], ready
