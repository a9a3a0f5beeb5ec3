"""``boundary:=true``: the boundary node's values topic carries the simulator's values; any
other text on it (another publisher, a torn message, NaN, a negative instant) is said in one
line and dropped, the node going on, where it used to raise in rospy's callback (a traceback
per message) or pass a NaN on to the standard messages."""

from __future__ import annotations

import threading
from fractions import Fraction
from types import SimpleNamespace

import pytest

from amsa_phys.ros.runtime.boundary import BoundaryNode, format_values, parse_values

HOSTILE = ["", "x", "1 0", "1 2 A.x", "1 2 A.x nan", "1 2 A.x abc", "-1 2", "1 2 A.x inf"]


def test_the_simulators_message_reads_back_exactly() -> None:
    text = format_values(Fraction(7, 3), [("A.x", 0.1), ("B.y", -2.5e-300)])
    assert parse_values(text) == (Fraction(7, 3), [("A.x", 0.1), ("B.y", -2.5e-300)])


@pytest.mark.parametrize("text", HOSTILE, ids=repr)
def test_anything_else_is_refused_naming_it(text: str) -> None:
    with pytest.raises(ValueError, match=r"^not a values message"):
        parse_values(text)


def test_the_node_says_it_once_a_message_and_keeps_its_values() -> None:
    said: list[str] = []
    got: list[tuple[str, object]] = []
    node = object.__new__(BoundaryNode)
    node.rospy = SimpleNamespace(logerr=said.append)
    node.lock = threading.Lock()
    node.values = {"A.x": 1.0}
    node.readers = {"A.x": [SimpleNamespace(got=lambda b, at: got.append((b, at)))]}
    for text in HOSTILE:
        node._on_values(SimpleNamespace(data=text))
    assert node.values == {"A.x": 1.0}
    assert got == []
    assert len(said) == len(HOSTILE)
    assert all("\n" not in line and "not a values message" in line for line in said)
    node._on_values(SimpleNamespace(data=format_values(Fraction(1, 4), [("A.x", 2.0)])))
    assert node.values == {"A.x": 2.0}
    assert got == [("A.x", Fraction(1, 4))]
