"""Parameters, YAML loading with lines, metrics: the small pure pieces."""

from __future__ import annotations

import numpy as np
import pytest

from amsa_phys.engine.clock import fraction_gcd
from amsa_phys.errors import ConfigError
from amsa_phys.model.metrics import block_metrics
from amsa_phys.model.params import Param
from amsa_phys.model.yamlio import parse_yaml


def test_param_coercion_rules() -> None:
    p = Param("n", "int", "count", 0, 0, 100, "%")
    assert p.coerce(10) == 10
    assert p.coerce(10.0) == 10  # YAML's 10.0 is accepted for an int
    with pytest.raises(ValueError, match=r"expected an integer, got 10\.5"):
        p.coerce(10.5)
    with pytest.raises(ValueError, match=r"101 is above the maximum 100 \(range \[0, 100\]\)"):
        p.coerce(101)
    f = Param("x", "float", "x", 0.0)
    with pytest.raises(ValueError, match="expected a finite number, got inf"):
        f.coerce(float("inf"))
    e = Param("b", "enum", "b", 1, choices=(1, 2), aliases={"two": 2})
    assert e.coerce("two") == 2
    with pytest.raises(ValueError, match="expected one of 1, 2, two, got integer 3"):
        e.coerce(3)
    pts = Param("w", "points", "w", ())
    assert pts.coerce([[0, 1], [2.5, 3]]) == ((0.0, 1.0), (2.5, 3.0))


def test_a_template_default_outside_its_range_is_a_bug_at_import() -> None:
    with pytest.raises(ValueError, match="above the maximum"):
        Param("k", "float", "k", 5.0, 0.0, 1.0)


def test_yaml_keeps_lines_and_refuses_duplicates() -> None:
    doc = parse_yaml("a: 1\nb:\n  c: [1, 2]\n  d: x\n", "f.yaml")
    assert doc.data == {"a": 1, "b": {"c": [1, 2], "d": "x"}}
    assert doc.line(("b", "d")) == 4
    assert doc.line(("b", "d", "missing")) == 4  # falls back to the nearest known key
    with pytest.raises(
        ConfigError,
        match=r"f.yaml:3: a: duplicate key 'a' \(first defined "
        r"on line 1\)",
    ):
        parse_yaml("a: 1\nb: 2\na: 3\n", "f.yaml")


def test_yaml_alias_bomb_is_refused_quickly() -> None:
    lines = ["a0: &a0 [x, x, x, x, x, x, x, x, x, x]"]
    lines += [
        f"a{i}: &a{i} [*a{i - 1}, *a{i - 1}, *a{i - 1}, *a{i - 1}, *a{i - 1}, "
        f"*a{i - 1}, *a{i - 1}, *a{i - 1}, *a{i - 1}, *a{i - 1}]"
        for i in range(1, 9)
    ]
    with pytest.raises(ConfigError, match="document too large"):
        parse_yaml("\n".join(lines), "bomb.yaml")


def test_fraction_gcd() -> None:
    from fractions import Fraction as F

    assert fraction_gcd([F(1, 3), F(1, 7), F(10)]) == F(1, 21)
    assert fraction_gcd([F(1, 100), F(125)]) == F(1, 100)


def test_metrics_by_hand() -> None:
    t = np.arange(0.0, 10.5, 0.5)  # 0 .. 10 s
    s = np.where(t < 4, 20.0, 15.2)  # 5 m too far until 4 s, then within tolerance
    m = block_metrics(t, s, 0.0, 10.0, 15.0, 1.5, [2.0, 9.0, 10.0], include_end=True)
    assert m["max_distance"] == 20.0
    assert m["min_distance"] == 15.2
    assert m["settling_time"] == 4.0
    assert m["mean_error"] == pytest.approx((8 * 5.0 + 13 * 0.2) / 21)
    assert m["collisions"] == 3
    first = block_metrics(t, s, 0.0, 5.0, 15.0, 1.5, [2.0, 5.0], include_end=False)
    assert first["collisions"] == 1  # half-open: the event at 5 s belongs to the next block
    assert first["settling_time"] == 4.0
    never = block_metrics(t, np.full_like(t, 30.0), 0, 10, 15, 1.5, [], include_end=True)
    assert never["settling_time"] is None


def test_settling_needs_a_dwell_in_the_band() -> None:
    """Back in the band only for its last samples is not settled (issue 15: Kv = 0.35
    "settled at 300 s" in a 300 s run, at None in a 290 s one)."""
    t = np.arange(0.0, 300.05, 0.05)
    s = np.where(t < 297, 20.0, 15.0)  # in the band for the last 3 s only
    m = block_metrics(t, s, 0.0, 300.0, 15.0, 1.5, [], include_end=True)
    assert m["settling_time"] is None  # default dwell: 10 s
    s = np.where(t < 290, 20.0, 15.0)  # 10 s: settled
    m = block_metrics(t, s, 0.0, 300.0, 15.0, 1.5, [], include_end=True)
    assert m["settling_time"] == pytest.approx(290.0)
    assert block_metrics(t, s, 0.0, 300.0, 15.0, 1.5, [], True, dwell=11.0)["settling_time"] is None
    # a short block: a tenth of it (2 s of a 20 s block)
    short = (t >= 100) & (t <= 120)
    s = np.where(t < 117, 20.0, 15.0)
    m = block_metrics(t[short], s[short], 100.0, 120.0, 15.0, 1.5, [], include_end=True)
    assert m["settling_time"] == pytest.approx(17.0)


def test_max_after_the_first_approach_is_the_papers_quality_figure() -> None:
    t = np.arange(0.0, 60.0, 0.5)
    # starts 40 m away, comes within tolerance at 20 s, then swings out to 24 m and back
    s = np.interp(t, [0, 20, 30, 40, 60], [40.0, 15.0, 24.0, 15.0, 15.0])
    m = block_metrics(t, s, 0.0, 60.0, 15.0, 1.5, [], include_end=True)
    assert m["max_distance"] == 40.0
    assert m["max_after_approach"] == 24.0
    far = block_metrics(t, np.full_like(t, 30.0), 0.0, 60.0, 15.0, 1.5, [], include_end=True)
    assert far["max_after_approach"] is None  # never approached


def test_did_you_mean_ignores_case_first() -> None:
    """``posx`` is one letter from posX and from posY: the case-only difference wins."""
    from amsa_phys.model.suggest import did_you_mean

    assert did_you_mean("posx", ["posY", "posX"]) == " (did you mean posX?)"
    assert did_you_mean("KV", ["Kw", "Kv"]) == " (did you mean Kv?)"
    assert did_you_mean("seeed", ["set", "seed"]) == " (did you mean seed?)"
    assert did_you_mean("zzz", ["seed"]) == ""
