"""What a search is told before it runs: the warnings of a box and an objective that would
spend the budget on less than the user meant.

One list for both front ends: ``amsa-phys falsify`` prints each on a ``warning:`` line, and
``ap.falsify`` raises each as a :class:`~amsa_phys.api.falsify.SearchWarning` (a Python user
reads ``search_on=`` where the command says ``--search-on``).
"""

from __future__ import annotations

from fractions import Fraction

from ..model.scenario import Scenario
from ..runs.sweep import timeline_overlaps
from ..stl.requirement import cut_windows
from .objective import Objective
from .space import Space


def search_warnings(
    scenario: Scenario, objective: Objective, space: Space, end: float, search_on: bool
) -> list[str]:
    """The warnings of a search of ``space`` for ``objective`` in runs of ``end`` s: a
    requirement whose windows the runs cut, ``--search-on`` where nothing stops the search
    anyway, an axis the scenario's timeline sets again."""
    warnings = []
    for name, until in cut_windows(scenario.expect, end, objective.requirements):
        warnings.append(  # a window cut by a shorter run judges fewer samples
            f"the requirement {name} reads until t={until:g} s: runs of {end:g} s cut its "
            "windows, so its robustness judges only what they log"
        )
    if search_on and not objective.falsifies:
        warnings.append("--search-on only matters with --requirement: the whole budget is spent")
    keys = [d.key for d in space.dims]
    return warnings + timeline_overlaps(keys, scenario, Fraction(str(end)))
