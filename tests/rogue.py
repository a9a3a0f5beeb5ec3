"""A user template that misbehaves on purpose, importable as ``rogue:Rogue`` (hostile tests).

``mode`` says how, from simulated time ``at`` on: return a list or a number too large for a
float, ``sys.exit()`` in ``do_step``, ``initialize`` or ``on_param_change``, hang in an endless
loop, or (as a group of copies) return the wrong number of rows from ``step_many``.
"""

from __future__ import annotations

import os
import sys
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np

from amsa_phys.model.params import Param
from amsa_phys.model.template import Kind, Port, Template

MODES = (
    "none",
    "max",
    "list",
    "huge",
    "exit0",
    "exit7",
    "init_exit",
    "param_exit",
    "stuck",
    "rows",
)


class Rogue(Template):
    """Publishes 1.0 until ``at``, then misbehaves as ``mode`` says."""

    kind = Kind.CONTROLLER
    outputs = (Port("u"),)
    params = (
        Param("mode", "enum", "how to misbehave", "none", choices=MODES),
        Param("at", "float", "from when", 1.0, 0.0, 1e6),
        Param("k", "float", "a parameter to change", 1.0, 0.0, 10.0),
    )

    def initialize(self, ctx: Any) -> None:
        if self.p.mode == "init_exit":
            sys.exit(0)

    def do_step(self, t: Fraction, inp: Any) -> Any:
        mode = self.p.mode
        if t < self.p.at or mode == "none":
            return {"u": 1.0}
        if mode == "max":
            return {"u": 1.7e308}  # finite, but its error against a negative reference is not
        if mode == "list":
            return [1.0, 2.0]
        if mode == "huge":
            return {"u": 10**400}
        if mode == "exit0":
            sys.exit(0)
        if mode == "exit7":
            sys.exit(7)
        if mode == "stuck":
            mark = os.environ.get("ROGUE_MARK")
            if mark:  # tells a test that this worker is now stuck
                Path(f"{mark}.{os.getpid()}").touch()
            while True:  # a bug: never returns, never checks for Ctrl-C
                pass
        return {"u": 1.0}

    def on_param_change(self, name: str, value: Any) -> None:
        if self.p.mode == "param_exit":
            sys.exit(0)

    @classmethod
    def step_many(cls, comps: Any, t: Fraction, inp: Any, p: Any, state: Any) -> Any:
        """Copies step here; mode ``rows`` returns three rows too many."""
        extra = 3 if comps[0].p.mode == "rows" and t >= comps[0].p.at else 0
        return {"u": np.ones(len(comps) + extra)}, None
