"""A one-rover test rig: ConstantPower -> NormalizePower -> controlledRobot."""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from amsa_phys.engine.runner import Simulation
from amsa_phys.model.scenario import load_scenario


def drive(
    tmp_path: Path,
    left: float,
    right: float,
    duration: float,
    *,
    robot: dict[str, Any] | None = None,
    coef: int = 100,
    physics: dict[str, Any] | None = None,
    timeline: list[dict[str, Any]] | None = None,
    rate_hz: int = 50,
    extra: dict[str, Any] | None = None,
) -> tuple[dict[str, np.ndarray], Simulation]:
    """Run the rig; return the trace as named columns (at ``rate_hz``) and the simulation.

    ``extra`` adds components to the world (terrain zones).
    """
    world = {
        "physics": {"rate": 100, **(physics or {})},
        "components": {
            "Ctl": {
                "template": "ConstantPower",
                "freq": rate_hz,
                "params": {"left": left, "right": right},
            },
            "Norm": {
                "template": "NormalizePower",
                "freq": rate_hz,
                "params": {"motorCoef": coef},
                "inputs": {"powerL": "Ctl.LeftPower", "powerR": "Ctl.RightPower"},
            },
            "Rover": {
                "template": "controlledRobot",
                "freq": rate_hz,
                "params": robot or {},
                "inputs": {"powerL": "Norm.normalizedPowerL", "powerR": "Norm.normalizedPowerR"},
            },
            **(extra or {}),
        },
    }
    scen: dict[str, Any] = {"world": world, "duration": duration, "log_rate": rate_hz}
    if timeline:
        scen["timeline"] = timeline
    path = tmp_path / "rig.yaml"
    path.write_text(yaml.safe_dump(scen))
    sc = load_scenario(path)
    rows: list[list[float]] = []
    sim = Simulation.from_scenario(sc, trace=lambda t, v: rows.append([t, *v]))
    sim.run()
    data = np.array(rows)
    cols = {"t": data[:, 0]}
    for i, name in enumerate(sim.columns):
        cols[name] = data[:, i + 1]
    assert sim.now == Fraction(str(duration))
    return cols, sim
