"""A controller aiming at one value while the run is judged against another: say so.

The metrics of a run (``rms_error``, ``settling_time``, ``max after approach``) measure the
quality signal against ``quality.reference``. A scenario, ``--set`` or a timeline entry that
moves a controller's setpoint (a template's :attr:`~amsa_phys.model.template.Template.setpoints`,
``FollowerController.distanceRef``) away from that reference leaves every metric measuring the
distance from a value the controller no longer aims at, without a word. The CLI says so on a
``warning:`` line, the API with a :class:`ReferenceWarning`; the text is made here, once.
"""

from __future__ import annotations

from fractions import Fraction
from typing import Any

from ..model.scenario import Scenario


class ReferenceWarning(UserWarning):
    """A controller's setpoint differs from the scenario's ``quality.reference``."""


def reference_notes(scenario: Scenario) -> list[str]:
    """One line per setpoint parameter that some instant of the run sets away from the
    quality reference (its first such value). Only setpoints in the quality signal's unit
    count: a controller of another quantity is not judged by it."""
    quality = scenario.quality
    if quality is None:
        return []
    unit = _signal_unit(scenario, quality.signal)
    notes = []
    for path, leaf in scenario.world.leaves.items():
        for name in sorted(leaf.template.setpoints):
            param = next((p for p in leaf.template.params if p.name == name), None)
            if param is None or unit is None or param.unit != unit:
                continue
            key = f"{path}.{name}"
            start = leaf.params.get(name)  # the world's, then the scenario's set: and --set
            first = scenario.timeline.phases[0] if scenario.timeline.phases else None
            for change in first.changes if first is not None else ():
                if change.key == key:
                    start = change.value
            values: list[tuple[Fraction, Any]] = [(Fraction(0), start)]
            values += [
                (p.at, c.value)
                for p in scenario.timeline.points()
                for c in p.changes
                if c.key == key and p.at < scenario.duration
            ]
            off = [(t, v) for t, v in values if v is not None and float(v) != quality.reference]
            if not off:
                continue
            at, value = off[0]
            when = "" if at == 0 else f" from t = {float(at):g} s"
            notes.append(
                f"{key} is {float(value):g} {unit}{when}, but the run is judged against "
                f"quality.reference {quality.reference:g} {unit}: every metric measures the "
                f"distance from {quality.reference:g}; set quality: {{reference: "
                f"{float(value):g}}} to judge the run against its own setpoint"
            )
    return notes


def _signal_unit(scenario: Scenario, signal: str) -> str | None:
    """The unit of the quality signal's buffer (``Leaf.output``), None when unknown."""
    path, _, port = signal.rpartition(".")
    leaf = scenario.world.leaves.get(path)
    if leaf is None:
        return None
    found = next((p for p in leaf.template.outputs if p.name == port), None)
    return None if found is None else found.unit
