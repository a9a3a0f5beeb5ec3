"""Gazebo/SDFormat Gaussian noise, Gauss–Markov biases, quantisation and burst loss.

Every sensor adds noise the same way, with the parameter names of SDFormat's ``<noise>``
element (gz-sensors ``GaussianNoiseModel``), so a value read off a Gazebo model means the
same here. A measurement ``v`` becomes::

    v + mean + turn_on_bias + dynamic_bias(t) + stddev * N(0, 1), rounded to ``precision``

- ``turn_on_bias``: drawn once per run (and axis) from N(bias_mean, bias_stddev²), its sign
  flipped with probability 1/2 — as Gazebo does, so ``bias_mean`` is a magnitude;
- ``dynamic_bias``: a first-order Gauss–Markov process ``db = -b/T dt + sigma dW`` with
  ``sigma = dynamic_bias_stddev`` and ``T = dynamic_bias_correlation_time``, discretised
  exactly: ``b' = phi b + sigma sqrt(T/2 (1 - phi²)) w``, ``phi = exp(-dt/T)``. This is
  Gazebo's (and RotorS') formula, so ``sigma`` is a *driving density* (unit per √s) and the
  stationary standard deviation is ``sigma * sqrt(T/2)``, not ``sigma``. The process starts
  from its stationary distribution. Gazebo ignores the dynamic bias when ``T = 0``; here
  ``T = 0`` means an infinite correlation time, a random walk ``b' = b + sigma sqrt(dt) w``
  (an IMU's bias instability), starting from 0, whose variance grows as ``sigma² t``;
- ``precision``: the output is rounded to the nearest multiple (0: no rounding).

Unlike Gazebo, the turn-on bias stays constant (Gazebo's Gauss–Markov update also decays
the turn-on bias towards 0). The turn-on draws are unit normals kept from ``initialize``,
so a timeline change of ``bias_mean`` or ``bias_stddev`` scales the same draw.

Gilbert–Elliott burst loss (two-state Markov chain; a sample is lost in the *bad* state):
with ``pi`` the stationary share of samples in bad states and ``L`` the mean burst length in
samples, the chain leaves a bad state with probability ``r = 1/L`` per sample and enters one
with ``r pi / (1 - pi)``; bursts are geometric with mean ``L``. The chain starts from its
stationary distribution.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..model.params import Param
from . import libm
from .rng import Drawn

#: The SDFormat noise parameter names, in the order they are declared.
NOISE_NAMES = (
    "mean",
    "stddev",
    "bias_mean",
    "bias_stddev",
    "dynamic_bias_stddev",
    "dynamic_bias_correlation_time",
    "precision",
)


def noise_params(
    prefix: str, unit: str, what: str, limit: float, defaults: dict[str, float] | None = None
) -> tuple[Param, ...]:
    """The seven SDFormat noise parameters of one measured quantity, named ``prefix + name``.

    ``limit`` bounds the offsets and standard deviations (in ``unit``); ``defaults`` gives
    the shipped values (0 otherwise: a perfect sensor).
    """
    d = {name: 0.0 for name in NOISE_NAMES} | (defaults or {})
    n = prefix
    return (
        Param(
            f"{n}mean", "float", f"constant offset of the {what}", d["mean"], -limit, limit, unit
        ),
        Param(
            f"{n}stddev",
            "float",
            f"white noise of the {what}: standard deviation per sample",
            d["stddev"],
            0.0,
            limit,
            unit,
        ),
        Param(
            f"{n}bias_mean",
            "float",
            f"turn-on bias of the {what}: mean magnitude (sign drawn, as Gazebo)",
            d["bias_mean"],
            -limit,
            limit,
            unit,
        ),
        Param(
            f"{n}bias_stddev",
            "float",
            f"turn-on bias of the {what}: standard deviation across runs",
            d["bias_stddev"],
            0.0,
            limit,
            unit,
        ),
        Param(
            f"{n}dynamic_bias_stddev",
            "float",
            f"Gauss-Markov bias of the {what}: driving density sigma (stationary std "
            "sigma*sqrt(T/2); random walk sigma*sqrt(t) if T = 0)",
            d["dynamic_bias_stddev"],
            0.0,
            limit,
            f"{unit}/√s",
        ),
        Param(
            f"{n}dynamic_bias_correlation_time",
            "float",
            f"Gauss-Markov bias of the {what}: correlation time T (0: a random walk)",
            d["dynamic_bias_correlation_time"],
            0.0,
            1e6,
            "s",
        ),
        Param(
            f"{n}precision",
            "float",
            f"resolution of the {what}: output rounded to a multiple (0: none)",
            d["precision"],
            0.0,
            limit,
            unit,
        ),
    )


def burst_params(what: str, default_length: float = 5.0) -> tuple[Param, ...]:
    """Gilbert–Elliott burst loss: ``burstLoss`` (share in bursts) and ``burstLength``."""
    return (
        Param(
            "burstLoss",
            "float",
            f"share of {what} lost in bursts (Gilbert-Elliott bad state), besides independent loss",
            0.0,
            0.0,
            95.0,
            "%",
        ),
        Param(
            "burstLength",
            "float",
            f"mean length of a burst of lost {what}",
            default_length,
            1.0,
            1e6,
            "samples",
        ),
    )


def is_noisy(values: Any, prefix: str = "") -> bool:
    """Whether the noise parameters in ``values`` (a mapping) draw anything random."""
    return any(
        values[prefix + name] != 0 for name in ("stddev", "bias_stddev", "dynamic_bias_stddev")
    ) or (values[prefix + "bias_mean"] != 0)


def gauss_markov(sigma: float, tau: float, dt: float) -> tuple[float, float]:
    """``(phi, q)`` of one exact step ``b' = phi b + q w`` over ``dt`` (``tau = 0``: a walk)."""
    if tau > 0:
        return math.exp(-dt / tau), sigma * math.sqrt(-0.5 * tau * math.expm1(-2 * dt / tau))
    return 1.0, sigma * math.sqrt(dt)


#: :func:`gauss_markov_many`'s recent answers: a group's sensors ask it every step with the
#: same parameter arrays and period, and its libm calls cost a batched sweep ~5 % (profiled)
_GM_CACHE: dict[tuple[bytes, bytes, float], tuple[np.ndarray, np.ndarray]] = {}
_GM_CACHE_SIZE = 64


def gauss_markov_many(
    sigma: np.ndarray, tau: np.ndarray, dt: float
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`gauss_markov` for arrays of parameters (one per copy). The answer is
    remembered for the same values (read-only arrays: a caller cannot edit a shared one)."""
    sigma = np.asarray(sigma, dtype=np.float64)
    tau = np.asarray(tau, dtype=np.float64)
    key = (sigma.tobytes(), tau.tobytes(), dt)
    hit = _GM_CACHE.get(key)
    if hit is not None and hit[0].shape == np.broadcast_shapes(sigma.shape, tau.shape):
        return hit
    phi, q = _gauss_markov_many(sigma, tau, dt)
    phi.flags.writeable = False
    q.flags.writeable = False
    if len(_GM_CACHE) >= _GM_CACHE_SIZE:
        _GM_CACHE.clear()
    _GM_CACHE[key] = (phi, q)
    return phi, q


def _gauss_markov_many(
    sigma: np.ndarray, tau: np.ndarray, dt: float
) -> tuple[np.ndarray, np.ndarray]:
    safe = np.where(tau > 0, tau, 1.0)
    # libm's exp/expm1, as gauss_markov's math calls: numpy's round otherwise (engine/libm.py)
    phi = np.where(tau > 0, libm.exp(-dt / safe), 1.0)
    q = np.where(
        tau > 0, sigma * np.sqrt(-0.5 * safe * libm.expm1(-2 * dt / safe)), sigma * math.sqrt(dt)
    )
    return phi, q


def stationary_std(sigma: float, tau: float) -> float:
    """Stationary standard deviation of the dynamic bias (0 for a random walk's start)."""
    return sigma * math.sqrt(tau / 2) if tau > 0 else 0.0


def quantise(value: float, precision: float) -> float:
    """``value`` rounded to the nearest multiple of ``precision`` (half up; 0: unchanged)."""
    if precision > 0:
        return math.floor(value / precision + 0.5) * precision
    return value


def quantise_many(value: np.ndarray, precision: np.ndarray) -> np.ndarray:
    """:func:`quantise` element by element (the same arithmetic, so the same floats)."""
    safe = np.where(precision > 0, precision, 1.0)
    return np.where(precision > 0, np.floor(value / safe + 0.5) * safe, value)


def check_burst(burst_loss_pct: float, length: float) -> None:
    """Refuse a burst share no chain with this mean length reaches.

    Entering a burst has probability ``pi / ((1 - pi) L)`` per sample, at most 1: a share
    ``pi`` needs bursts of at least ``pi / (1 - pi)`` samples on average.
    """
    pi = burst_loss_pct / 100.0
    need = pi / (1.0 - pi)
    if need > length:
        raise ValueError(
            f"burstLoss {burst_loss_pct:g} % needs burstLength >= {need:.3g} samples "
            f"(got {length:g}): a burst cannot start more often than every sample"
        )


def burst_chance(burst_loss_pct: float, length: float) -> tuple[float, float]:
    """``(enter, leave)``: per-sample probabilities of entering and leaving a bad state."""
    pi = burst_loss_pct / 100.0
    leave = 1.0 / length
    return leave * pi / (1.0 - pi), leave


class TurnOn:
    """The unit draws behind a turn-on bias: a normal and a sign per axis, from ``initialize``."""

    def __init__(self, rng: np.random.Generator, axes: int) -> None:
        self.z = rng.standard_normal(axes).tolist()
        self.sign = [(-1.0 if u < 0.5 else 1.0) for u in rng.random(axes).tolist()]

    def value(self, axis: int, bias_mean: float, bias_stddev: float) -> float:
        """The turn-on bias of ``axis`` for the current parameter values."""
        return self.sign[axis] * (bias_mean + bias_stddev * self.z[axis])


class Channel:
    """The SDFormat noise of one measured quantity with ``axes`` components, stepped in time.

    For sensors stepped one by one (IMU, odometry, lidar); the GPS and the compass, which
    platoons step as arrays, spell the same arithmetic out inline. Its own two streams
    (split off ``rng``): white noise, and the biases (turn-on draws first, then the
    Gauss–Markov start, then one innovation per axis per step). Every step draws the same
    count whatever the parameters, so a change of one noise term leaves the others' draws.
    """

    def __init__(self, rng: np.random.Generator, axes: int, prefix: str = "") -> None:
        white, bias = rng.spawn(2)
        self.axes = axes
        self.prefix = prefix
        self.turn_on = TurnOn(bias, axes)
        self.gm_start = bias.standard_normal(axes).tolist()
        self.white = white
        self.draw_white = Drawn(white.standard_normal)
        self.draw_bias = Drawn(bias.standard_normal)
        self.b = [0.0] * axes
        self.t_prev: float | None = None

    def value(self, p: Any, name: str) -> Any:
        """Parameter ``name`` of this channel (``gyro_stddev`` for ``stddev``)."""
        return getattr(p, self.prefix + name)

    def offsets(self, now: float, p: Any) -> list[float]:
        """Per axis: mean + turn-on bias + the dynamic bias advanced to ``now``."""
        sigma = self.value(p, "dynamic_bias_stddev")
        tau = self.value(p, "dynamic_bias_correlation_time")
        g = [self.draw_bias() for _ in range(self.axes)]
        if self.t_prev is None:
            s0 = stationary_std(sigma, tau)
            self.b = [s0 * z for z in self.gm_start]
        else:
            phi, q = gauss_markov(sigma, tau, now - self.t_prev)
            self.b = [phi * b + q * w for b, w in zip(self.b, g, strict=True)]
        self.t_prev = now
        mean = self.value(p, "mean")
        bm, bs = self.value(p, "bias_mean"), self.value(p, "bias_stddev")
        return [mean + self.turn_on.value(k, bm, bs) + self.b[k] for k in range(self.axes)]

    def apply(self, values: list[float], now: float, p: Any) -> list[float]:
        """``values`` (one per axis) measured at ``now``: offsets, white noise, rounding."""
        off = self.offsets(now, p)
        std = self.value(p, "stddev")
        prec = self.value(p, "precision")
        return [
            quantise(v + o + std * self.draw_white(), prec)
            for v, o in zip(values, off, strict=True)
        ]

    def apply_array(self, values: np.ndarray, now: float, p: Any) -> np.ndarray:
        """Many readings sharing one bias (a lidar's beams): white noise drawn per reading."""
        (off,) = self.offsets(now, p)
        noisy = values + off + self.value(p, "stddev") * self.white.standard_normal(len(values))
        prec = self.value(p, "precision")
        return quantise_many(noisy, np.full(len(values), prec)) if prec > 0 else noisy
