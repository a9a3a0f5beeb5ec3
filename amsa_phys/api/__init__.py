"""The Python API: run a scenario and get its metrics, trace and events in memory.

``import amsa_phys as ap; run = ap.run("scenarios/scenario2.yaml", seed=3)`` (the package
exposes these names lazily, so ``import amsa_phys`` stays cheap). See the README's
"From Python".
"""

from ..runs.overrides import OverrideWarning
from .memory import TraceSizeWarning
from .result import Run, run
from .source import MAPPING, load, validate

__all__ = ["MAPPING", "OverrideWarning", "Run", "TraceSizeWarning", "load", "run", "validate"]
