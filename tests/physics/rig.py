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


#: A base whose drive axle passes under the centre of mass, the centre of mass on the ground:
#: each drive wheel carries m g / 2, the caster nothing, no load transfer. For checks whose
#: subject is not the normal load (tyre slip curves, contacts, sub-steps, the IMU, the sliding
#: tyre's convergence) and whose closed forms take N = m g / 2; ``test_normal_load.py`` holds
#: the default geometry to its own closed forms.
ON_AXLE = {"axleOffset": 0.0, "comHeight": 0.0}


def traction_accel(mu: float, robot: dict[str, Any] | None = None, g: float = 9.81) -> float:
    """Closed form: a launch limited by the tyres on ground ``mu`` accelerates at
    ``2 mu N0 / (m (1 + mu z / L))`` (statics share ``N0 = m g (-x_c) / (2 L)``, ``L = x_a -
    x_c``; the launch's force moves ``z F / L`` from the drive axle to the caster)."""
    from amsa_phys.physics.templates import rover_params

    p = rover_params(**(robot or {}))
    span = p.axleOffset - p.casterOffset
    n0 = p.mass * g * -p.casterOffset / (2 * span)
    return 2 * mu * n0 / (p.mass * (1 + mu * p.comHeight / span))
