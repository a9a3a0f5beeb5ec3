"""How a loaded scenario configures a :class:`~.runner.Simulation`: the one mapping from a
scenario to the constructor's arguments, kept apart from the hot loop's module so that the
ROS simulator and the engine share it without reaching into the loop."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from ..model.scenario import Scenario, traced_columns
from .signals import RequirementWatch

if TYPE_CHECKING:
    from .runner import Simulation


class FromScenario:
    """``Simulation.from_scenario`` and what it is made of (a mixin of the Simulation)."""

    watch: RequirementWatch | None

    @classmethod
    def from_scenario(cls, scenario: Scenario, **kw: Any) -> Simulation:
        """A Simulation configured by a loaded scenario (sampling what its STL requirements
        read, so :meth:`result` judges them)."""
        sim: Simulation = cls(scenario.world, **cls.scenario_kwargs(scenario), **kw)  # type: ignore[call-arg]
        sim.watch_requirements(scenario)
        return sim

    def watch_requirements(self, scenario: Scenario) -> None:
        """Sample what ``scenario``'s STL requirements read; :meth:`result` judges them."""
        # no expectation, no requirement: a reset of the single env asks this every episode,
        # and the requirements' look-up imports the STL modules' names each time
        self.watch = RequirementWatch.of(scenario, self) if scenario.expect else None

    @staticmethod
    def scenario_kwargs(scenario: Scenario) -> dict[str, Any]:
        """What a scenario says to the constructor besides its world: the one mapping from a
        scenario to a Simulation (``from_scenario``; the ROS simulator's ``RosSimulation``)."""
        return {
            "seed": scenario.seed,
            "timeline": scenario.timeline,
            "log_rate": scenario.log_rate,
            "quality_signal": scenario.quality.signal if scenario.quality else None,
            "columns": traced_columns(scenario),
            "adapt": scenario.adapt,
        }
