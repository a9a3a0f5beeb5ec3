"""Normal load: the drive wheels and the caster share the weight by statics, and the drive
force moves load between them through the centre of mass's height (issue 31 item 2).

Closed forms (per drive wheel, axle at ``x_a`` and caster at ``x_c`` along the heading from
the centre of mass, ``L = x_a - x_c``, centre of mass at height ``z``):

* statics: ``N0 = m g (-x_c) / (2 L)``, the caster ``m g x_a / L``;
* load transfer: pitch balance about the centre of mass with ground force ``F`` along the
  heading gives ``N = N0 - z F / (2 L)``;
* traction limit on slippery ground: ``|F| = 2 mu N(F)``, so a launch accelerates at
  ``2 mu N0 / (m (1 + mu z / L))`` and a locked-wheel stop decelerates at
  ``2 mu N0 / (m (1 - mu z / L))`` (``L`` signed: an axle ahead of the centre of mass gains
  load braking, one behind it loses load).

Each check has a mutation run through the same measurement: the old model (each drive wheel
carrying m g / 2, no transfer) fails it.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rig import drive

from amsa_phys.physics.space import wheel_model
from amsa_phys.physics.templates import rover_params

G = 9.81
MU = 0.05
BASE = rover_params()
MASS = BASE.mass


def static_load(x_a: float, x_c: float) -> float:
    return MASS * G * -x_c / (2 * (x_a - x_c))


def ice(mu: float = MU) -> dict[str, Any]:
    return {"gravity": G, "ground": {"friction": mu, "rolling_resistance": 0.02}}


def test_statics_share_the_weight_with_the_caster() -> None:
    """The default base: the caster carries its share and the moments balance."""
    w = wheel_model(BASE, G)
    x_a, x_c = BASE.axleOffset, BASE.casterOffset
    caster = MASS * G - 2 * w.load_n
    assert w.load_n == pytest.approx(static_load(x_a, x_c), rel=1e-12)
    assert caster > 0.1 * MASS * G  # not zero by construction: ~14 % for the default base
    assert 2 * w.load_n * x_a + caster * x_c == pytest.approx(0.0, abs=1e-9)


def accel(tmp_path: Path, robot: dict[str, Any], t0: float, t1: float, **kw: Any) -> float:
    """The rover's mean acceleration along its heading between ``t0`` and ``t1`` (m/s²)."""
    tr, _ = drive(tmp_path, kw.pop("left", 100), kw.pop("right", 100), t1, robot=robot, **kw)
    t, v = tr["t"], tr["Rover.speed"]
    sel = (t >= t0) & (t <= t1)
    return float(np.polyfit(t[sel], v[sel], 1)[0])


def launch_error(
    tmp_path: Path, robot: dict[str, Any], model: dict[str, Any] | None = None
) -> float:
    """Relative error of a full-power launch on ice against the traction limit's closed form
    with load transfer, the tyres sliding (40 N of motor against ~7 N of grip). ``model``
    (the mutation tests) changes the simulated rover's geometry, not the closed form's."""
    p = rover_params(**robot)
    x_a, x_c, z = p.axleOffset, p.casterOffset, p.comHeight
    big_l = x_a - x_c
    want = 2 * MU * static_load(x_a, x_c) / (MASS * (1 + MU * z / big_l))
    got = accel(tmp_path, {**robot, **(model or {})}, 0.2, 1.0, physics=ice())
    return got / want - 1


def braking_error(
    tmp_path: Path, robot: dict[str, Any], model: dict[str, Any] | None = None
) -> float:
    """Relative error of a locked-wheel stop on ice (the shorted motors brake with up to
    40 N against ~7 N of grip) against the closed form: moving at ~1.4 m/s on good ground,
    then the ground turns to ice and the power to 0 at t = 3 s (``model`` as in
    :func:`launch_error`)."""
    p = rover_params(**robot)
    x_a, x_c, z = p.axleOffset, p.casterOffset, p.comHeight
    big_l = x_a - x_c
    want = -2 * MU * static_load(x_a, x_c) / (MASS * (1 - MU * z / big_l))
    zone = {
        "Ice": {
            "template": "frictionZone",
            "freq": 1,
            "params": {
                "friction": 0.8,
                "rollingResistance": 0.02,
                "polygon": [[-100, -100], [100, -100], [100, 100], [-100, 100]],
            },
        }
    }
    timeline = [{"at": 3, "set": {"Ice.friction": MU, "Ctl.left": 0, "Ctl.right": 0}}]
    got = accel(
        tmp_path,
        {**robot, **(model or {})},
        3.3,
        4.5,
        physics=ice(0.8),
        extra=zone,
        timeline=timeline,
    )
    return got / want - 1


GEOMETRIES = {
    "axle ahead, caster behind": {"axleOffset": 0.05, "casterOffset": -0.3, "comHeight": 0.2},
    "axle behind, caster ahead": {"axleOffset": -0.1, "casterOffset": 0.3, "comHeight": 0.3},
}


@pytest.mark.parametrize("robot", GEOMETRIES.values(), ids=GEOMETRIES.keys())
def test_a_launch_on_ice_reaches_the_traction_limit_with_load_transfer(
    tmp_path: Path, robot: dict[str, Any]
) -> None:
    assert abs(launch_error(tmp_path, robot)) < 0.01


@pytest.mark.parametrize("robot", GEOMETRIES.values(), ids=GEOMETRIES.keys())
def test_a_locked_wheel_stop_decelerates_with_the_transferred_load(
    tmp_path: Path, robot: dict[str, Any]
) -> None:
    assert abs(braking_error(tmp_path, robot)) < 0.01


#: The mutants the docstring names, as the simulated rover's geometry: the old model (each
#: drive wheel m g / 2: the axle under the centre of mass, on the ground) and the statics
#: without the transfer (the centre of mass on the ground).
MUTANTS = {
    "m g / 2 a wheel": {"axleOffset": 0.0, "comHeight": 0.0},
    "no transfer": {"comHeight": 0.0},
}


@pytest.mark.parametrize("model", MUTANTS.values(), ids=MUTANTS.keys())
@pytest.mark.parametrize("robot", GEOMETRIES.values(), ids=GEOMETRIES.keys())
def test_mutation_traction_checks_fail_with_the_old_load(
    tmp_path: Path, robot: dict[str, Any], model: dict[str, Any]
) -> None:
    # measured 13-38 % off with m g / 2 a wheel, 2.9-3.8 % without the transfer (real: 1e-5)
    for sub in ("launch", "braking"):
        (tmp_path / sub).mkdir()
    launch = launch_error(tmp_path / "launch", robot, model)
    braking = braking_error(tmp_path / "braking", robot, model)
    assert max(abs(launch), abs(braking)) > 0.01, (launch, braking)


def test_the_compiled_and_the_pure_step_agree_with_load_transfer(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Bit for bit, sliding on ice on a slope (the transfer's cos from the pull): a skid
    launch, a turn, then a locked-wheel stop, with a high centre of mass."""
    runs = []
    for pure in ("0", "1"):
        monkeypatch.setenv("AMSA_PHYS_PURE", pure)
        tmp = tmp_path / pure
        tmp.mkdir()
        zone = {
            "Hill": {
                "template": "gradeZone",
                "freq": 1,
                "params": {
                    "angle": 0.05,
                    "direction": 0.7,
                    "polygon": [[-100, -100], [100, -100], [100, 100], [-100, 100]],
                },
            }
        }
        tr, _ = drive(
            tmp,
            100,
            100,
            5,
            robot={"comHeight": 0.4},
            physics=ice(0.1),
            extra=zone,
            timeline=[
                {"at": 1.5, "set": {"Ctl.left": 90, "Ctl.right": -20}},
                {"at": 3, "set": {"Ctl.left": 0, "Ctl.right": 0}},
            ],
        )
        runs.append(tr)
    for name in runs[0]:
        assert (runs[0][name] == runs[1][name]).all(), name
    assert abs(runs[0]["Rover.yawRate"]).max() > 0.5  # it did turn


def test_a_geometry_statics_cannot_stand_on_is_refused_with_one_line(tmp_path: Path) -> None:
    """Axle and caster on one side of the centre of mass: one of them would pull the ground."""
    scen = tmp_path / "w.yaml"
    scen.write_text(
        "duration: 1\nworld:\n  components:\n    Rover:\n      template: controlledRobot\n"
        "      freq: 10\n      params: {axleOffset: 0.1, casterOffset: 0.3}\n"
    )
    env = {**os.environ, "SDL_VIDEODRIVER": "dummy", "MPLBACKEND": "Agg"}
    out = subprocess.run(
        [sys.executable, "-m", "amsa_phys", "run", str(scen), "--headless"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env=env,
        check=False,
    )
    assert out.returncode == 2
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1
    assert "w.yaml:7" in lines[0]
    assert "casterOffset" in lines[0]
