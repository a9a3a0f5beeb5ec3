"""The C++ context estimators (``ros/files/cpp/*Monitor.inc``) against their templates, bitwise.

The ROS export runs MotorMonitor, LeaderMonitor and GPSLossMonitor as C++ Leaves, and the
lockstep checks every answer bit for bit against the Python template: the bodies must repeat
the templates' arithmetic exactly (CPython's ``hypot`` and ``%``, ``round(x, 6)``, ``min()``'s
choice on ties, the plain running ``sum``), every output port included (``valid``), and the
same steps must publish. A small program built from the bodies (behind a stand-in of
``amsa_leaf_node.h``'s interface: no ROS needed) steps hundreds of random estimators of each
template through random input sequences -- rovers driving, stopping, reversing, worn or
impossibly strong; leaders straight, turning, too slow for a course; fixes held or lost --
with parameters over their ranges, and compares every output of every step with the
template's. Skipped where there is no C++ compiler.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

from amsa_phys.control.estimators.gpsloss import GPSLossMonitor
from amsa_phys.control.estimators.leader import LeaderMonitor
from amsa_phys.control.estimators.motor import MotorMonitor
from amsa_phys.model.template import Template

#: compiles C++ with g++: the build tier, not the quick one
pytestmark = pytest.mark.build

FILES = Path(__file__).resolve().parents[2] / "amsa_phys" / "ros" / "files"
TEMPLATES: tuple[type[Template], ...] = (MotorMonitor, LeaderMonitor, GPSLossMonitor)
HARNESS = """#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>
#include "amsa_pymath.h"
#include "amsa_window.h"
namespace amsa {  // the part of amsa_leaf_node.h's LeafNode a body sees
class LeafNode {
 public:
  virtual ~LeafNode() = default;
  virtual void doStep(double, const std::vector<double>&, std::vector<double>&,
                      std::vector<bool>&) = 0;
  double p(const std::string& name) const { return values_.at(name); }
  std::map<std::string, double> values_;
};
}  // namespace amsa
class MotorMonitor : public amsa::LeafNode {
 public:
#include "MotorMonitor.inc"
};
class LeaderMonitor : public amsa::LeafNode {
 public:
#include "LeaderMonitor.inc"
};
class GPSLossMonitor : public amsa::LeafNode {
 public:
#include "GPSLossMonitor.inc"
};
static const std::vector<std::vector<std::string>> kParams = {PARAMS};
static const std::size_t kIn[] = {INS};
static const std::size_t kOut[] = {OUTS};
int main() {
  double head[2];  // template index, steps
  while (std::fread(head, sizeof(double), 2, stdin) == 2) {
    const int which = static_cast<int>(head[0]);
    std::unique_ptr<amsa::LeafNode> node;  // a new estimator per case
    if (which == 0) node.reset(new MotorMonitor);
    if (which == 1) node.reset(new LeaderMonitor);
    if (which == 2) node.reset(new GPSLossMonitor);
    for (const auto& name : kParams[which]) {
      double v;
      if (std::fread(&v, sizeof v, 1, stdin) != 1) return 1;
      node->values_[name] = v;
    }
    for (int s = 0; s < static_cast<int>(head[1]); ++s) {
      double t;
      std::vector<double> in(kIn[which]), out(kOut[which], 0.0);
      std::vector<bool> published(kOut[which], false);
      if (std::fread(&t, sizeof t, 1, stdin) != 1) return 1;
      if (std::fread(in.data(), sizeof(double), in.size(), stdin) != in.size()) return 1;
      node->doStep(t, in, out, published);
      for (std::size_t k = 0; k < out.size(); ++k) {  // published flag, then the value
        const double row[2] = {published[k] ? 1.0 : 0.0, published[k] ? out[k] : 0.0};
        std::fwrite(row, sizeof(double), 2, stdout);
      }
    }
  }
}
"""

Case = tuple[int, dict[str, float], list[Fraction], list[list[float]]]


def _params(template: type[Template], rng: np.random.Generator) -> dict[str, float]:
    """Defaults 40 % of the time, else uniform within the range (capped at 60)."""
    out: dict[str, float] = {}
    for p in template.params:
        lo, hi = max(p.min, 0.0), min(p.max, 60.0)
        out[p.name] = float(p.default) if rng.random() < 0.4 else float(rng.uniform(lo, hi))
    return out


def _times(rng: np.random.Generator, seconds: float) -> list[Fraction]:
    """Step times at a rate whose period mostly divides 1 s (the world's 4 Hz first)."""
    freq = int(rng.choice([4, 4, 4, 1, 2, 3, 5, 10]))
    return [Fraction(k, freq) for k in range(int(seconds * freq) + 1)]


def _track(
    rng: np.random.Generator, times: list[Fraction], speed: float, noise: float
) -> list[tuple[float, float]]:
    """A rover's GPS fixes: straight or turning at ``speed``, noise, some fixes held."""
    x, y, heading = rng.uniform(-50, 50), rng.uniform(-50, 50), rng.uniform(-4, 4)
    turn = 0.0 if rng.random() < 0.4 else rng.uniform(-0.3, 0.3)
    change = rng.random() < 0.4  # the random behaviour: a new heading now and then
    hold = rng.uniform(0.0, 0.4) if rng.random() < 0.3 else 0.0
    fixes: list[tuple[float, float]] = []
    last = 0.0
    for t in times:
        dt = float(t) - last
        last = float(t)
        if change and rng.random() < 0.02:
            heading += rng.uniform(-1.5, 1.5)
        heading += turn * dt
        x += speed * dt * np.cos(heading)
        y += speed * dt * np.sin(heading)
        fix = (float(x + rng.normal(0, noise)), float(y + rng.normal(0, noise)))
        if fixes and rng.random() < hold:
            fix = fixes[-1]  # a lost sample: the previous fix again
        fixes.append(fix)
    if rng.random() < 0.2:
        fixes = [(round(a, 2), round(b, 2)) for a, b in fixes]  # a receiver's resolution
    return fixes


def _motor(rng: np.random.Generator) -> Case:
    params = _params(MotorMonitor, rng)
    params["window"] = float(rng.choice([30.0, 10.0, 5.0, rng.uniform(1.0, 40.0)]))
    params["spacing"] = float(rng.choice([1.0, 1.0, 0.5, 0.25, 2.0, rng.uniform(0.01, 5)]))
    if rng.random() < 0.6:  # the rover's model as the world's: shares about 1
        params.update(maxSpeed=5.5, frictionPower=2.9, timeConstant=10.0, minPower=3.0)
    params["edge"] = float(rng.uniform(0.01, 8.0)) if rng.random() < 0.5 else 4.0
    params["maxShare"] = float(rng.choice([1.15, 1.0, rng.uniform(1.0, 3.0)]))
    # the held estimate's decaying confidence, and how much cancelling out ends it
    params["validHold"] = float(rng.choice([0.0, 20.0, rng.uniform(0.5, 60.0)]))
    params["holdReverse"] = float(rng.choice([1.0, 0.4, rng.uniform(0.0, 1.0)]))
    # the recent share's short window: off, the world's, or anything in range
    params["recentWindow"] = float(rng.choice([0.0, 5.0, 8.0, rng.uniform(0.5, 20.0)]))
    # the estimate over forward seconds only: off, the world's, or anything in range
    params["forwardPower"] = float(rng.choice([0.0, 3.0, 3.0, rng.uniform(0.0, 20.0)]))
    params["settle"] = float(rng.choice([5.0, 0.0, rng.uniform(0.0, 15.0)]))
    params["quietPower"] = float(rng.choice([0.0, 15.0, rng.uniform(0.0, 60.0)]))
    params["minForward"] = float(rng.choice([0.5, rng.uniform(0.0, 1.0)]))
    params["wholeWindow"] = float(rng.choice([0.0, 1.0]))
    params["powerMax"] = float(rng.choice([100.0, rng.uniform(5.0, 120.0)]))
    times = _times(rng, params["window"] + rng.uniform(5, 60))
    # commands about a level, sometimes reversing or too small; speed from a delivered share
    level = float(rng.choice([rng.uniform(5, 40), rng.uniform(0, 4)]))
    # a swing beyond 100 % saturates the actuator (an oscillating loop)
    swing = float(rng.choice([0.0, rng.uniform(0, 10), rng.uniform(10, 50), rng.uniform(80, 150)]))
    delivered = float(rng.choice([1.0, rng.uniform(0.4, 1.0), rng.uniform(1.0, 1.5)]))
    speed = max(0.0, delivered * (level - params["frictionPower"]) * params["maxSpeed"] / 100)
    fixes = _track(rng, times, speed, float(rng.choice([0.0, 0.015, 0.02])))
    stops = rng.random() < 0.2  # now and then a command of exactly zero: not forward
    late = rng.random() < 0.4  # forward first, reversing once the window is full (the hold)
    inputs = []
    for t, (x, y) in zip(times, fixes, strict=True):
        wave = swing * np.sin(0.3 * float(t))
        if late and float(t) < params["window"]:
            wave = 0.0
        left = level + wave + rng.normal(0, 1.0)
        right = level + wave + rng.normal(0, 1.0)
        if stops and rng.random() < 0.02:
            left = right = 0.0
        inputs.append([float(left), float(right), x, y])
    return 0, params, times, inputs


def _leader(rng: np.random.Generator) -> Case:
    params = _params(LeaderMonitor, rng)
    params["window"] = float(rng.choice([30.0, 10.0, rng.uniform(1.0, 40.0)]))
    params["spacing"] = float(rng.choice([4.0, 4.0, 1.0, 2.0, 3.0, 0.5, rng.uniform(0.5, 6)]))
    params["threshold"] = float(rng.choice([0.02, 0.0, rng.uniform(0.0, 0.2)]))
    params["minTravel"] = float(rng.choice([0.2, 0.0, rng.uniform(0.0, 1.0)]))
    params["fixNoise"] = float(rng.choice([0.015, 0.0, rng.uniform(0.0, 0.05)]))
    params["noiseFactor"] = float(rng.choice([1.5, 0.0, rng.uniform(0.0, 5.0)]))
    params["minShare"] = float(rng.choice([0.25, rng.uniform(0.0, 1.0), 1.0]))
    times = _times(rng, params["window"] + rng.uniform(5, 60))
    speed = float(rng.choice([0.22, 0.06, 0.0, rng.uniform(0.0, 0.6)]))
    fixes = _track(rng, times, speed, float(rng.choice([0.015, 0.0, rng.uniform(0, 0.05)])))
    return 1, params, times, [[x, y] for x, y in fixes]


def _gps_loss(rng: np.random.Generator) -> Case:
    params = {"window": float(rng.choice([30.0, rng.uniform(1.0, 20.0)]))}
    times = _times(rng, params["window"] + rng.uniform(1, 30))
    fixes = _track(rng, times, float(rng.uniform(0, 0.5)), 0.015)
    return 2, params, times, [[x, y] for x, y in fixes]


def _python(case: Case) -> list[float]:
    """The template's outputs at every step: (published, value) per output port."""
    which, params, times, inputs = case
    template = TEMPLATES[which]
    comp = template("Est", dict(params))
    comp.initialize(None)
    ports = [p.name for p in template.inputs]
    out: list[float] = []
    for t, values in zip(times, inputs, strict=True):
        got = comp.do_step(t, dict(zip(ports, values, strict=True)))
        for port in template.outputs:
            out += [1.0, float(got[port.name])] if port.name in got else [0.0, 0.0]
    return out


def _harness(tmp_path: Path) -> Path:
    """The program built from the three bodies with the package's CMake flags."""
    params = ", ".join("{" + ", ".join(f'"{p.name}"' for p in t.params) + "}" for t in TEMPLATES)
    text = (
        HARNESS.replace("PARAMS", params)
        .replace("INS", ", ".join(str(len(t.inputs)) for t in TEMPLATES))
        .replace("OUTS", ", ".join(str(len(t.outputs)) for t in TEMPLATES))
    )
    (tmp_path / "harness.cpp").write_text(text)
    exe = tmp_path / "harness"
    flags = ["-O2", "-ffp-contract=off", "-fno-fast-math"]  # the package's CMake flags
    includes = [f"-I{FILES}", f"-I{FILES / 'cpp'}"]
    cmd = ["g++", *flags, *includes, str(tmp_path / "harness.cpp"), "-o", str(exe)]
    subprocess.run(cmd, check=True)
    return exe


@pytest.mark.skipif(shutil.which("g++") is None, reason="no C++ compiler (g++)")
@pytest.mark.skipif(sys.version_info[:2] != (3, 11), reason="the port is of CPython 3.11's hypot")
def test_cpp_estimators_give_the_templates_bits(tmp_path: Path) -> None:
    exe = _harness(tmp_path)
    rng = np.random.default_rng(43)
    cases = [make(rng) for _ in range(250) for make in (_motor, _leader, _gps_loss)]
    stream: list[float] = []
    want: list[float] = []
    for case in cases:
        which, params, times, inputs = case
        stream += [which, len(times), *(params[p.name] for p in TEMPLATES[which].params)]
        for t, values in zip(times, inputs, strict=True):
            stream += [float(t), *values]
        want += _python(case)
    done = subprocess.run(
        [str(exe)], input=np.array(stream).tobytes(), capture_output=True, check=True
    )
    got = np.frombuffer(done.stdout)
    expected = np.array(want)
    assert got.shape == expected.shape
    differ = np.flatnonzero(got.view(np.int64) != expected.view(np.int64))
    assert differ.size == 0, (differ.size, differ[:4], got[differ[:4]], expected[differ[:4]])
    _check_coverage(cases, expected)


def _check_coverage(cases: list[Case], expected: np.ndarray) -> None:
    """The cases reached the branches the comparison is meant to cover."""
    rows: dict[int, list[np.ndarray]] = {0: [], 1: [], 2: []}
    at = 0
    for which, _, times, _ in cases:
        width = 2 * len(TEMPLATES[which].outputs)
        block = expected[at : at + width * len(times)].reshape(len(times), width)
        rows[which].append(block)
        at += width * len(times)
    motor = np.concatenate(rows[0])
    delivered, motor_valid = motor[:, 1], motor[:, 3]
    assert (motor_valid == 1.0).sum() > 1000
    assert (motor_valid == 0.0).sum() > 1000
    assert ((delivered == 1.0) & (motor_valid == 1.0)).sum() > 100  # capped at 1
    assert ((delivered < 0.9) & (motor_valid == 1.0)).sum() > 100  # worn motors
    leader = np.concatenate(rows[1])
    turning, leader_valid = leader[:, 1], leader[:, 5]
    assert (leader_valid == 1.0).sum() > 1000
    assert (leader_valid == 0.0).sum() > 1000
    assert ((turning > 0.0) & (turning < 1.0)).sum() > 1000
    loss = np.concatenate(rows[2])
    assert (loss[:, 0] == 0.0).sum() > 0
    assert (loss[:, 1] > 0.0).sum() > 100
