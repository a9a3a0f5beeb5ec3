"""The scenario an exported ROS package runs: the file's whole scenario, and the cut apart.

``export ros|ros2 --duration S`` must run what ``amsa-phys run --duration S`` runs. The cut
scenario written out would not: a check of a phase the cut removes names a phase that file
lacks (its loader refuses it), and the phase the cut stops in would read as complete there,
judged instead of skipped. So both exports write the file's whole scenario into ``config/``
and keep the cut beside it (ROS 1: the launch file's ``duration:=`` default; ROS 2:
``config/amsa.yaml``'s ``duration``), and the run applies it with the code ``run --duration``
uses (``model.scenario.shortened`` through ``duration_option``): the same trace, and the same
checks skipped.
"""

from __future__ import annotations

from fractions import Fraction

from ..model.configure import duration_option
from ..model.scenario import Scenario
from ..runs.resolve import resolved_scenario
from .quote import yaml_dump

#: ``config/amsa.yaml``'s key (ROS 2) for the cut, in seconds
KEY = "duration"


def scenario_yaml(scenario: Scenario) -> str:
    """``config/NAME.yaml``: the whole scenario, resolved (world inlined, values written)."""
    return yaml_dump(resolved_scenario(scenario))


def cut_seconds(cut: Fraction | None) -> float | None:
    """The cut as written (a float: ``--duration``'s own type, so reading it back judges and
    rounds it as ``run --duration`` does), or None for the scenario's whole length."""
    return None if cut is None else float(cut)


def cut_text(cut: Fraction | None) -> str:
    """The cut as a launch argument's text (``duration:=``), or "" for the whole run."""
    seconds = cut_seconds(cut)
    return "" if seconds is None else repr(seconds)


def cut_of(value: float, key: str = KEY) -> Fraction:
    """A written cut read back, judged as ``--duration`` is (one line naming ``key``)."""
    return duration_option(value, key)


__all__ = ["KEY", "cut_of", "cut_seconds", "cut_text", "scenario_yaml"]
