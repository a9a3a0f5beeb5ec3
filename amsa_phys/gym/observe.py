"""Observations an RL agent can learn from: robot-relative, normalised, with finite bounds.

The agent reads what the replaced component reads (its inputs, in port order). Those are
world coordinates in metres, an absolute heading in radians, speeds: unbounded, and a
policy trained on them learns where the world's origin is rather than how to follow. The
default view (``observation="relative"``) is therefore built from the ports' declared units
and names, for any template that follows the project's naming (``xLeader``/``yLeader``,
``headingFollower``):

- the robot's own frame is the ``x<Name>``/``y<Name>`` pair whose ``<Name>`` matches the one
  ``heading<Name>`` input (unit ``rad``); the own position and heading are consumed by it;
- every other position pair becomes (forward, left) in that frame, divided by ``range_m`` and
  clipped to [-1, 1] (``<Name>.forward``, ``<Name>.left``);
- other metres: divided by ``range_m``, clipped; m/s: divided by ``speed_mps``, clipped; other
  angles: wrapped to [-pi, pi) and divided by pi; anything else: ``tanh`` (monotone, bounded).

So every element lies in [-1, 1]. ``observation="absolute"`` keeps the raw inputs (bounds
infinite), as before.
"""

from __future__ import annotations

import math
from array import array
from collections.abc import Sequence
from typing import Any

import numpy as np

from ..errors import ConfigError

MODES = ("relative", "absolute")


class Observer:
    """Maps the component's raw inputs (port order) to the agent's observation."""

    def __init__(
        self,
        ports: Sequence[Any],
        mode: str = "relative",
        range_m: float = 50.0,
        speed_mps: float = 10.0,
    ) -> None:
        if mode not in MODES:
            raise ConfigError(
                f"unknown observation {mode!r}; expected one of: {', '.join(MODES)}",
                key="observation",
            )
        self.mode = mode
        self.raw_names = [p.name for p in ports]
        self._in_c: tuple[Any, ...] | None = None
        self._one: tuple[Any, array] | None = None
        if mode == "absolute":
            self.names = list(self.raw_names)
            self.low = np.full(len(ports), -np.inf)
            self.high = np.full(len(ports), np.inf)
            return
        index = {p.name: i for i, p in enumerate(ports)}
        unit = {p.name: p.unit for p in ports}
        pairs = {
            p.name[1:]: (index[p.name], index["y" + p.name[1:]])
            for p in ports
            if p.name.startswith("x") and unit.get("y" + p.name[1:]) == "m" and p.unit == "m"
        }
        headings = [p.name[len("heading") :] for p in ports if p.name.startswith("heading")]
        own = headings[0] if len(headings) == 1 and headings[0] in pairs else None
        used: set[int] = set()
        self.own: tuple[int, int, int] | None = None
        self.relative: list[tuple[int, int]] = []
        self.names = []
        if own is not None:
            ox, oy = pairs.pop(own)
            oh = index["heading" + own]
            self.own = (ox, oy, oh)
            used |= {ox, oy, oh}
            for name, (ix, iy) in pairs.items():
                self.relative.append((ix, iy))
                self.names += [f"{name}.forward", f"{name}.left"]
                used |= {ix, iy}
        self.rest: list[tuple[int, str]] = []
        for p in ports:
            i = index[p.name]
            if i not in used:
                self.rest.append((i, p.unit))
                self.names.append(p.name)
        self.range_m = range_m
        self.speed_mps = speed_mps
        self.low = np.full(len(self.names), -1.0)
        self.high = np.full(len(self.names), 1.0)
        self._in_c = _rows_in_c(self)
        self._one = _one_in_c(self)

    def __call__(self, raw: np.ndarray) -> np.ndarray:
        """The observation of one raw input vector (float64, within ``low``..``high``)."""
        if self.mode == "absolute":
            return raw
        return self.of_values(raw.tolist())

    def of_rows(self, rows: np.ndarray) -> np.ndarray:
        """:meth:`__call__` of every row of ``rows`` (``(n, len(raw_names))``): the vector
        env's observations, as arrays instead of ``n`` Python calls (a third of a vector
        step at 1,000 envs). The same floats as row by row: the arithmetic is elementwise
        IEEE (each operation rounded once, as in Python), ``%`` is Python's (numpy's
        ``remainder`` takes the divisor's sign the same way), and the transcendental
        functions are ``math``'s, mapped (numpy's SIMD ones may differ in the last bit,
        ``engine/libm.py``); a NaN clips to -1 as in :meth:`of_values`."""
        rows = np.asarray(rows, dtype=np.float64)
        if self.mode == "absolute":
            return rows.copy()
        if self._in_c is not None:  # the same arithmetic in one C call (``_step.c``)
            observe, own, pairs, rest, scales = self._in_c
            out = np.empty((len(rows), len(self.names)))
            observe(np.ascontiguousarray(rows), own, pairs, rest, scales, out, self.range_m)
            return out
        cols: list[np.ndarray] = []
        if self.own is not None:
            ox, oy, oh = self.own
            heading = rows[:, oh].tolist()
            c = np.fromiter(map(math.cos, heading), np.float64, len(heading))
            s = np.fromiter(map(math.sin, heading), np.float64, len(heading))
            x0, y0, scale = rows[:, ox], rows[:, oy], self.range_m
            for ix, iy in self.relative:
                dx, dy = rows[:, ix] - x0, rows[:, iy] - y0
                cols += [(c * dx + s * dy) / scale, (-s * dx + c * dy) / scale]
        for i, unit in self.rest:
            v = rows[:, i]
            if unit == "m":
                cols.append(v / self.range_m)
            elif unit == "m/s":
                cols.append(v / self.speed_mps)
            elif unit == "rad":
                cols.append(((v + math.pi) % (2 * math.pi) - math.pi) / math.pi)
            else:
                cols.append(np.fromiter(map(math.tanh, v.tolist()), np.float64, len(v)))
        out = np.column_stack(cols) if cols else np.zeros((len(rows), 0))
        # the scalar clip: v inside [-1, 1] kept, above 1 -> 1, below -1 or NaN -> -1
        return np.where(out > 1.0, 1.0, np.where(out >= -1.0, out, -1.0))

    def of_values(self, values: Sequence[float]) -> np.ndarray:
        """:meth:`__call__` of the raw inputs as floats (a list or tuple, port order): the
        env's per-step path, which has them as floats already (a handful of them: plain
        Python beats numpy per element, and each unit's rule was chosen once, in
        ``__init__``). Each element is clipped as it is made: ``v if -1 <= v <= 1`` else
        1 or -1 is ``min(1, max(-1, v))`` (NaN too: -1) at a third the time, and a
        comprehension over the finished list was a function call of its own."""
        if self.mode == "absolute":
            return np.array(values, dtype=np.float64)
        one = self._one
        if one is not None:  # the same in one C call (``_kernels.observe_one``), if it takes them
            obs = np.empty(len(self.names))
            if one[0](values, one[1], self.range_m, self.speed_mps, obs):
                return obs
        out: list[float] = []
        append = out.append
        if self.own is not None:
            ox, oy, oh = self.own
            c, s = math.cos(values[oh]), math.sin(values[oh])
            x0, y0, scale = values[ox], values[oy], self.range_m
            for ix, iy in self.relative:
                dx, dy = values[ix] - x0, values[iy] - y0
                v = (c * dx + s * dy) / scale
                append(v if -1.0 <= v <= 1.0 else (1.0 if v > 1.0 else -1.0))
                v = (-s * dx + c * dy) / scale
                append(v if -1.0 <= v <= 1.0 else (1.0 if v > 1.0 else -1.0))
        for i, unit in self.rest:
            v = values[i]
            if unit == "m":
                v = v / self.range_m
            elif unit == "m/s":
                v = v / self.speed_mps
            elif unit == "rad":
                v = ((v + math.pi) % (2 * math.pi) - math.pi) / math.pi
            else:
                v = math.tanh(v)
            append(v if -1.0 <= v <= 1.0 else (1.0 if v > 1.0 else -1.0))
        # every element is a float (a quotient, tanh, or a float clip bound): numpy makes a
        # float64 array of them by itself, in half the time of parsing ``dtype=`` (an empty
        # list too)
        return np.array(out)


#: ``_kernels.observe_one``'s codes of the units :meth:`Observer.of_values` tells apart
_UNITS = {"m": 0, "m/s": 1, "rad": 2}


def _one_in_c(observer: Observer) -> tuple[Any, array] | None:
    """``_kernels.observe_one`` and the observer's rules as its numbers, where the extension
    is built; None otherwise (``AMSA_PHYS_PURE=1`` included). Why: the env makes one
    observation a step, and the Python method's few float operations, calls and list cost
    more than a C call filling an empty array (``tests/gym/test_observe_compiled.py``)."""
    from ..engine import publish

    module = publish._extension("_kernels")
    fn = getattr(module, "observe_one", None) if module is not None else None
    if fn is None or len(observer.names) > 64 or len(observer.raw_names) > 64:
        return None
    plan = array("q", [1, *observer.own] if observer.own is not None else [0, 0, 0, 0])
    plan.append(len(observer.relative))
    for ix, iy in observer.relative:
        plan.extend((ix, iy))
    plan.append(len(observer.rest))
    for i, unit in observer.rest:
        plan.extend((i, _UNITS.get(unit, 3)))
    return fn, plan


def _rows_in_c(observer: Observer) -> tuple[Any, ...] | None:
    """``_step.observe_rows`` and its column plan, where the compiled extension has it and
    every input is a position, a metre or a speed (the rest, angles and ``tanh``, stay in
    numpy); None otherwise (``AMSA_PHYS_PURE=1`` included)."""
    from ..physics import compiled

    if not compiled.columns_compiled() or not hasattr(compiled._step, "observe_rows"):
        return None
    if any(unit not in ("m", "m/s") for _, unit in observer.rest) or not observer.names:
        return None
    scale = {"m": observer.range_m, "m/s": observer.speed_mps}
    own = np.array(observer.own or (), dtype=np.int64)
    pairs = np.array([c for pair in observer.relative for c in pair], dtype=np.int64)
    rest = np.array([i for i, _ in observer.rest], dtype=np.int64)
    scales = np.array([scale[u] for _, u in observer.rest], dtype=np.float64)
    return compiled._step.observe_rows, own, pairs, rest, scales
