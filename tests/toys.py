"""Tiny templates for engine tests: they record when they ran and what they saw."""

from __future__ import annotations

import math
import os
import signal
from fractions import Fraction
from typing import Any

import numpy as np

from amsa_phys.model.params import Param
from amsa_phys.model.template import Kind, Port, Template

#: (path, t, inputs) of every step, in execution order; reset by each test.
LOG: list[tuple[str, Fraction, dict[str, Any]]] = []


class Source(Template):
    """Publishes its step count (1, 2, 3, ...) times ``gain``."""

    kind = Kind.ENVIRONMENT
    outputs = (Port("count", initial=-1.0),)
    params = (
        Param("gain", "float", "multiplier", 1.0, -10.0, 10.0),
        Param("silent", "bool", "publish nothing", False),
        Param("mode", "enum", "a mode", 1, choices=(1, 2), aliases={"fast": 2}),
        Param("label", "str", "a label", "x"),
    )

    def initialize(self, ctx: Any) -> None:
        self.n = 0

    def do_step(self, t: Fraction, inp: Any) -> Any:
        self.n += 1
        LOG.append((self.path, t, dict(inp)))
        return {} if self.p.silent else {"count": self.n * self.p.gain}


class Relay(Template):
    """A sensor that republishes its input."""

    kind = Kind.SENSOR
    inputs = (Port("x"),)
    outputs = (Port("y", initial=-2.0),)

    def do_step(self, t: Fraction, inp: Any) -> Any:
        LOG.append((self.path, t, dict(inp)))
        return {"y": inp["x"]}


class Sink(Template):
    """An observer that only records."""

    kind = Kind.OBSERVER
    inputs = (Port("a"), Port("b"))

    def do_step(self, t: Fraction, inp: Any) -> Any:
        LOG.append((self.path, t, dict(inp)))
        return {}


class Ctl(Template):
    """A controller with one input and one output (for loops)."""

    kind = Kind.CONTROLLER
    inputs = (Port("x"),)
    outputs = (Port("u"),)

    def do_step(self, t: Fraction, inp: Any) -> Any:
        LOG.append((self.path, t, dict(inp)))
        return {"u": inp["x"] + 1}


class Act(Template):
    """An actuator."""

    kind = Kind.ACTUATOR
    inputs = (Port("u"),)
    outputs = (Port("v"),)

    def do_step(self, t: Fraction, inp: Any) -> Any:
        LOG.append((self.path, t, dict(inp)))
        return {"v": inp["u"]}


class Plant(Template):
    """A process whose output is its last input."""

    kind = Kind.PROCESS
    inputs = (Port("v"),)
    outputs = (Port("x"),)

    def do_step(self, t: Fraction, inp: Any) -> Any:
        LOG.append((self.path, t, dict(inp)))
        return {"x": inp["v"]}


class Bad(Template):
    """A controller that publishes NaN after t = 1 s or raises when ``boom``."""

    kind = Kind.CONTROLLER
    outputs = (Port("u"),)
    params = (Param("boom", "bool", "raise instead", False),)

    def do_step(self, t: Fraction, inp: Any) -> Any:
        if t >= 1:
            if self.p.boom:
                raise ZeroDivisionError("division by zero")
            return {"u": float("nan")}
        return {"u": 0.0}


class Divider(Template):
    """A sensor publishing ``1 / (k x)``, one copy at a time or many at once (``step_many``)."""

    kind = Kind.SENSOR
    inputs = (Port("x"),)
    outputs = (Port("y"),)
    params = (Param("k", "float", "factor", 1.0, -10.0, 10.0),)

    def do_step(self, t: Fraction, inp: Any) -> Any:
        k = inp["x"] * self.p.k
        return {"y": 1.0 / k if k else math.inf}

    @classmethod
    def step_many(cls, comps: Any, t: Fraction, inp: Any, p: Any, state: Any) -> Any:
        with np.errstate(divide="ignore"):
            return {"y": 1.0 / (inp["x"] * p.k)}, None


class CtrlC(Template):
    """Publishes its step count and sends its own process ``signals`` signals at ``at`` s.

    Stands in for a user's Ctrl-C (or ``kill``) landing in the middle of an instant.
    """

    kind = Kind.CONTROLLER
    outputs = (Port("u"),)
    params = (
        Param("at", "float", "when to signal", 2.5, 0.0, 1e6),
        Param("signals", "int", "how many signals", 1, 1, 2),
        Param("term", "bool", "SIGTERM instead of SIGINT", False),
    )

    def initialize(self, ctx: Any) -> None:
        self.n = 0

    def do_step(self, t: Fraction, inp: Any) -> Any:
        self.n += 1
        if t == Fraction(self.p.at):
            for _ in range(self.p.signals):
                os.kill(os.getpid(), signal.SIGTERM if self.p.term else signal.SIGINT)
        return {"u": float(self.n)}


class Picky(Template):
    """A controller that refuses parameter changes after its fourth step (a state rule)."""

    kind = Kind.CONTROLLER
    outputs = (Port("u"),)
    params = (Param("gain", "float", "output", 1.0, -10.0, 10.0),)

    def initialize(self, ctx: Any) -> None:
        self.n = 0

    def do_step(self, t: Fraction, inp: Any) -> Any:
        self.n += 1
        return {"u": self.p.gain}

    def on_param_change(self, name: str, value: Any) -> None:
        if self.n > 4:
            raise ValueError(f"too late to change {name} after 4 steps")


class Die(Template):
    """Publishes ``gain``; its process dies at once when ``gain`` is 2 (a native crash, an OOM
    kill: nothing Python can catch)."""

    kind = Kind.CONTROLLER
    outputs = (Port("u"),)
    params = (Param("gain", "float", "output", 1.0, -10.0, 10.0),)

    def do_step(self, t: Fraction, inp: Any) -> Any:
        if self.p.gain == 2:
            os._exit(9)
        return {"u": self.p.gain}


class DieMany(Die):
    """:class:`Die` with ``step_many``: a batch holding a copy with ``gain`` 2 dies whole."""

    @classmethod
    def step_many(cls, comps: Any, t: Fraction, inp: Any, p: Any, state: Any) -> Any:
        if any(c.p.gain == 2 for c in comps):
            os._exit(9)
        return {"u": p.gain}, None


class Scanner(Template):
    """An array output of ``n`` numbers: k, k+1, ... at step k; ``shape``/``bad`` misbehave."""

    kind = Kind.SENSOR
    outputs = (Port("vals", 0.0, "n numbers", "", array=True, size="n"),)
    params = (
        Param("n", "int", "how many", 3, 1, 100),
        Param("shape", "int", "publish this many instead (0: n)", 0, 0, 100),
        Param("bad", "bool", "publish a NaN", False),
    )

    def initialize(self, ctx: Any) -> None:
        self.k = 0

    def do_step(self, t: Fraction, inp: Any) -> Any:
        self.k += 1
        vals = np.arange(self.p.shape or self.p.n, dtype=float) + self.k
        if self.p.bad:
            vals[1] = np.nan
        return {"vals": vals}


class Summer(Template):
    """Sums an array input (an observer)."""

    kind = Kind.OBSERVER
    inputs = (Port("vals", 0.0, "numbers", "", array=True),)
    outputs = (Port("total"), Port("count"))

    def do_step(self, t: Fraction, inp: Any) -> Any:
        LOG.append((self.path, t, {"vals": list(inp["vals"])}))
        return {"total": float(np.sum(inp["vals"])), "count": len(inp["vals"])}
