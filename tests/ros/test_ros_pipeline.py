"""Pipelined lockstep's simulator side (``ros/runtime/pipeline.py``), without ROS.

A pipelined run is only as good as its checks: a node that publishes another value than its
in-process template, or another set of outputs, or refuses a parameter the engine took, must
end the run with a fault naming the Leaf, the instant and both values; and the requests must
carry each input's exact double in the template's port order (the C++ Leaf indexes them so).
The container is played here by a function answering each message as
``files/amsa_container.h`` does, from what it is asked (or with one value changed).
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from fractions import Fraction
from pathlib import Path
from typing import Any

import pytest

from amsa_phys.errors import RunFault
from amsa_phys.model.scenario import load_scenario
from amsa_phys.ros import names
from amsa_phys.ros.graph import RosGraph, classify
from amsa_phys.ros.runtime import pipeline as pipeline_mod
from amsa_phys.ros.runtime.pipeline import Pipeline

ROOT = Path(__file__).resolve().parent.parent.parent


class _Msg:
    def __init__(self, data: str) -> None:
        self.data = data


class _Link:
    """What the pipeline uses of ``simulator.Link``; ``answer`` plays the container."""

    def __init__(self, answer: Callable[[str], str]) -> None:
        world = load_scenario(ROOT / "scenarios" / "scenario1.yaml").world
        local = classify(world)
        self.graph = RosGraph.of(world, local, False, [p for p in world.leaves if p not in local])
        self.cond = threading.Condition()
        self.seq = 0
        self.String = _Msg
        self.sent: list[str] = []
        self.answer = answer
        self.pipeline = Pipeline(self)  # type: ignore[arg-type]
        self.to_paths = {names.ns(p): p for p in self.graph.shared}
        self.container = self
        self.pub = self

    def publish(self, msg: _Msg) -> None:
        self.sent.append(msg.data)

    def _wait(self, ready: Callable[[], bool], who: str, t: Fraction, what: str) -> None:
        """The container answers every message not yet answered, in order."""
        while self.sent:
            lines = self.sent.pop(0).split("\n")
            answers = []
            for line in lines:
                node, _, request = line.partition(" ")
                answers.append((self.to_paths[node], self.answer(request)))
            self.pipeline.on_answers(answers)
        assert ready()


def _same(request: str) -> str:
    """The container's answer when the node agrees: NormalizePower's clamp * motorCoef %."""
    verb, seq, *rest = request.split(" ")
    if verb == "set":
        return f"done {seq}"
    _num, _den, left, right = rest
    k = 100 * 0.01
    values = [min(100.0, max(-100.0, float.fromhex(v))) * k for v in (left, right)]
    return f"done {seq} 0 1 | " + " ".join(v.hex() for v in values)


def _clamp(x: float) -> float:
    return min(100.0, max(-100.0, x))


def _step(link: _Link, t: Fraction, left: float, right: float) -> None:
    inp = {"powerL": left, "powerR": right}
    out = {"normalizedPowerL": _clamp(left), "normalizedPowerR": _clamp(right)}
    link.pipeline.stepped("MyNormalizePower", t, inp, out)


def test_a_request_carries_each_input_exactly_in_the_templates_port_order() -> None:
    link = _Link(_same)
    # the dict's order is not the template's: the request follows the template
    link.pipeline.stepped("MyNormalizePower", Fraction(1, 4), {"powerR": 0.1, "powerL": -2.5}, {})
    link.pipeline.send()
    assert link.sent == [f"/MyNormalizePower call 1 1 4 {(-2.5).hex()} {(0.1).hex()}"]
    # an array port's numbers, each exact, as one word
    assert pipeline_mod._hex((1.0, 0.1)) == f"[{(1.0).hex()},{(0.1).hex()}]"


def test_agreeing_answers_pass_and_every_request_is_answered() -> None:
    link = _Link(_same)
    for k in range(2 * pipeline_mod.BATCH + 7):
        _step(link, Fraction(k, 4), 3.0 + k / 7, -1.0 - k / 9)
    link.pipeline.changed("MyNormalizePower", "motorCoef", 80, Fraction(3))
    link.pipeline.drain()
    assert link.pipeline.expected == {}
    assert link.pipeline.in_flight == 0


def test_a_value_one_ulp_off_ends_the_run_naming_leaf_instant_and_both_values() -> None:
    def off(request: str) -> str:
        answer = _same(request)
        if request.split(" ")[2:4] == ["21", "4"]:  # t = 5.25 s
            head, _, values = answer.partition("| ")
            left, right = values.split(" ")
            bumped = float.fromhex(left)
            return f"{head}| {(bumped + abs(bumped) * 2**-52).hex()} {right}"
        return answer

    link = _Link(off)
    for k in range(40):
        _step(link, Fraction(k, 4), 3.0 + k / 7, -1.0)
    with pytest.raises(RunFault) as caught:
        link.pipeline.drain()
    fault = caught.value
    assert fault.t == 5.25
    assert fault.component == "MyNormalizePower (NormalizePower)"
    assert "published normalizedPowerL=" in fault.cause
    assert "where its in-process template published normalizedPowerL=" in fault.cause


def test_a_node_publishing_other_outputs_than_its_template_is_a_fault() -> None:
    link = _Link(lambda request: f"done {request.split(' ')[1]} 0 | {(1.0).hex()}")
    _step(link, Fraction(0), 1.0, 2.0)
    with pytest.raises(
        RunFault,
        match=r"published normalizedPowerL=1\.0 where .* "
        r"normalizedPowerL=1\.0, normalizedPowerR=2\.0",
    ):
        link.pipeline.drain()


@pytest.mark.parametrize(
    ("answer", "cause"),
    [
        (
            "error {seq} /MyNormalizePower/motorCoef: 180 is above the maximum 100",
            "refused the parameter value where its template did not: /MyNormalizePower/motorCoef",
        ),
        ("fault {seq} inputs out of step", "inputs out of step"),
    ],
)
def test_a_refused_parameter_or_a_fault_ends_the_run_with_the_nodes_words(
    answer: str, cause: str
) -> None:
    def reply(request: str) -> Any:
        seq = request.split(" ")[1]
        return answer.format(seq=seq) if request.startswith("set") else _same(request)

    link = _Link(reply)
    link.pipeline.changed("MyNormalizePower", "motorCoef", 180, Fraction(7, 2))
    with pytest.raises(RunFault, match=cause) as caught:
        link.pipeline.drain()
    assert caught.value.t == 3.5


def test_at_most_depth_messages_go_unanswered() -> None:
    unanswered: list[int] = []
    link = _Link(_same)
    publish = link.publish

    def counting(msg: _Msg) -> None:
        publish(msg)
        unanswered.append(len(link.sent))

    link.publish = counting  # type: ignore[method-assign]
    for k in range(6 * pipeline_mod.BATCH):
        _step(link, Fraction(k, 4), 1.0, 1.0)
    link.pipeline.drain()
    assert max(unanswered) == pipeline_mod.DEPTH + 1  # the new one, and DEPTH before it
    assert link.sent == []
