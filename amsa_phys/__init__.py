"""amsa-phys: a physics-backed 2D rover testbed implementing the AMSA component framework.

Public API: :func:`load_scenario`, :func:`load_world`, :func:`run_scenario`.
"""

from .model.scenario import load_scenario
from .model.world import load_world
from .runs.single import run_scenario

__version__ = "0.1.0"
__all__ = ["__version__", "load_scenario", "load_world", "run_scenario"]
