"""STL formulas in rtamt's discrete-time syntax, parsed to a small tree.

A requirement is written as rtamt (the STL library most robotics users know) would read it:
``always[150:500](abs(Monitor.distance - 15) <= 3.5)``; signals are trace columns
(``Component.output``, and the run's time ``t``), time bounds are seconds (an optional
``s`` or ``ms`` unit). Supported: comparisons (``<  <=  >  >=  ==  !==``), ``+ - * /``,
``abs``, ``not``, ``and``, ``or``, ``implies``, ``iff``, ``xor``, the future operators
``always``, ``eventually``, ``until`` and the past ones ``historically``, ``once``,
``since``, each with an optional ``[a:b]`` interval.

Precedence, loosest first: ``implies``/``iff``/``xor``, ``or``, ``and``, ``until``/``since``,
then the prefix operators, which take the one operand that follows (a parenthesised formula,
or a comparison): parenthesise as rtamt users do, ``always[0:5](a > 1 and b < 2)``.

The parser is ours, not rtamt's: rtamt pins an ANTLR runtime and parses at every
specification, and the monitor here evaluates a whole batch of runs as numpy columns. A test
checks both agree on random formulas over recorded traces.
"""

from __future__ import annotations

import functools
import math
import re
from dataclasses import dataclass, field
from fractions import Fraction

#: Longest formula accepted: a requirement is a line of a scenario, not a program.
MAX_LENGTH = 4000
#: Deepest nesting of parentheses and prefix operators (``not``, ``always``, ``abs``, unary
#: ``-``) accepted: the parser recurses once per level.
MAX_DEPTH = 60
#: Deepest formula tree accepted, whatever the operators: a chain ``a + b + c`` is as deep as
#: it is long. Every walk of the tree (signals, horizon, monitor, messages) recurses once per
#: level, so a bound here keeps them all inside Python's stack.
MAX_TREE_DEPTH = 200

UNARY_TEMPORAL = ("always", "eventually", "historically", "once")
BINARY_TEMPORAL = ("until", "since")
COMPARISONS = ("<=", ">=", "!==", "==", "<", ">")
_KEYWORDS = {
    "not",
    "and",
    "or",
    "implies",
    "iff",
    "xor",
    "abs",
    *UNARY_TEMPORAL,
    *BINARY_TEMPORAL,
}

_TOKEN = re.compile(
    r"\s*(?:"
    r"(?P<num>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)"
    r"|(?P<name>[A-Za-z_][A-Za-z0-9_]*(?:\.[A-Za-z_][A-Za-z0-9_]*)*)"
    r"|(?P<op><->|->|!==|==|<=|>=|&&|\|\||[<>()\[\]:+\-*/!&|,])"
    r")"
)


class FormulaError(ValueError):
    """A formula that does not parse; the message says where."""


_TOO_DEEP = (
    f"nested too deeply: more than {MAX_TREE_DEPTH} operators inside one another (a chain "
    "such as a + b + c counts one level per operator)"
)


@dataclass(frozen=True)
class Node:
    """One node of a formula: ``op`` and its ``args``.

    ``op`` is ``num`` (``value``), ``sig`` (``name``), an arithmetic operator
    (``+ - * / neg abs``), a comparison, ``not and or implies iff xor``, or a temporal
    operator with its interval ``lo``/``hi`` in seconds (``hi`` None: unbounded).
    """

    op: str
    args: tuple[Node, ...] = ()
    value: float = 0.0
    name: str = ""
    lo: Fraction | None = None
    hi: Fraction | None = None
    depth: int = field(default=1, init=False, compare=False, repr=False)

    def __post_init__(self) -> None:
        # Counted as the tree is built, children first, so no node deeper than the bound
        # ever exists for a recursive walk to overflow on.
        depth = 1 + max((a.depth for a in self.args), default=0)
        if depth > MAX_TREE_DEPTH:
            raise FormulaError(_TOO_DEEP)
        object.__setattr__(self, "depth", depth)

    @property
    def is_formula(self) -> bool:
        """Whether this node has a truth value (robustness), not a plain number."""
        return self.op in COMPARISONS or self.op in _LOGIC or self.op in _TEMPORAL

    def signals(self) -> set[str]:
        """Every signal the formula reads."""
        out = {self.name} if self.op == "sig" else set()
        for a in self.args:
            out |= a.signals()
        return out

    def text(self) -> str:
        """The formula written back (fully parenthesised), for messages."""
        if self.op == "num":
            return f"{self.value:g}"
        if self.op == "sig":
            return self.name
        if self.op == "neg":
            return f"-({self.args[0].text()})"
        if self.op in ("abs", "not"):
            return f"{self.op}({self.args[0].text()})"
        if self.op in UNARY_TEMPORAL:
            return f"{self.op}{self.interval()}({self.args[0].text()})"
        a, b = self.args
        op = f"{self.op}{self.interval()}" if self.op in BINARY_TEMPORAL else self.op
        return f"({a.text()} {op} {b.text()})"

    def interval(self) -> str:
        """``[a:b]`` in seconds, or empty for an unbounded operator."""
        if self.lo is None:
            return ""
        hi = "inf" if self.hi is None else f"{float(self.hi):g}"
        return f"[{float(self.lo):g}:{hi}]"


_LOGIC = {"not", "and", "or", "implies", "iff", "xor"}
_TEMPORAL = {*UNARY_TEMPORAL, *BINARY_TEMPORAL}
_ALIASES = {"!": "not", "&": "and", "&&": "and", "|": "or", "||": "or", "->": "implies"}
_ALIASES["<->"] = "iff"


def _tokens(text: str) -> list[tuple[str, str, int]]:
    """(kind, text, column) tokens; kind is ``num``, ``name`` or ``op``."""
    out = []
    pos = 0
    while pos < len(text):
        if text[pos:].strip() == "":
            break
        m = _TOKEN.match(text, pos)
        if m is None or m.end() == pos:
            at = len(text) - len(text[pos:].lstrip())
            raise FormulaError(f"unexpected {text[at]!r} at column {at + 1}")
        kind = m.lastgroup or "op"
        out.append((kind, m.group(kind), m.start(kind) + 1))
        pos = m.end()
    return out


class _Parser:
    def __init__(self, text: str) -> None:
        self.toks = _tokens(text)
        self.i = 0
        self.depth = 0

    def peek(self) -> str | None:
        if self.i >= len(self.toks):
            return None
        _kind, tok, _ = self.toks[self.i]
        return _ALIASES.get(tok, tok)

    def where(self) -> str:
        if self.i >= len(self.toks):
            return "the end"
        return f"{self.toks[self.i][1]!r} at column {self.toks[self.i][2]}"

    def take(self, want: str | None = None) -> str:
        tok = self.peek()
        if tok is None or (want is not None and tok != want):
            expected = f"expected {want!r}" if want else "expected more"
            raise FormulaError(f"{expected}, got {self.where()}")
        self.i += 1
        return tok

    def deeper(self) -> None:
        self.depth += 1
        if self.depth > MAX_DEPTH:
            raise FormulaError(
                f"nested too deeply: more than {MAX_DEPTH} levels of parentheses or prefix "
                "operators"
            )

    # formula levels
    def formula(self) -> Node:
        self.deeper()
        left = self.disjunction()
        while self.peek() in ("implies", "iff", "xor"):
            op = self.take()
            left = Node(op, (left, self.disjunction()))
        self.depth -= 1
        return left

    def disjunction(self) -> Node:
        left = self.conjunction()
        while self.peek() == "or":
            self.take()
            left = Node("or", (left, self.conjunction()))
        return left

    def conjunction(self) -> Node:
        left = self.binary_temporal()
        while self.peek() == "and":
            self.take()
            left = Node("and", (left, self.binary_temporal()))
        return left

    def binary_temporal(self) -> Node:
        left = self.unary()
        while self.peek() in BINARY_TEMPORAL:
            op = self.take()
            lo, hi = self.maybe_interval(op)
            left = Node(op, (left, self.unary()), lo=lo, hi=hi)
        return left

    def unary(self) -> Node:
        tok = self.peek()
        if tok == "not":
            self.take()
            self.deeper()
            out = Node("not", (self.need_formula(self.unary()),))
            self.depth -= 1
            return out
        if tok in UNARY_TEMPORAL:
            self.take()
            lo, hi = self.maybe_interval(tok)
            self.deeper()
            out = Node(tok, (self.need_formula(self.unary()),), lo=lo, hi=hi)
            self.depth -= 1
            return out
        return self.comparison()

    def need_formula(self, node: Node) -> Node:
        if not node.is_formula:
            raise FormulaError(
                f"{node.text()} is a value (a signal or a number), not a formula: compare it "
                f"(e.g. {node.text()} > 0)"
            )
        return node

    def comparison(self) -> Node:
        start = self.i
        first: tuple[int, FormulaError] | None = None
        if self.peek() == "(":  # a parenthesised formula, or arithmetic: try a formula first
            self.take("(")
            try:
                inner = self.formula()
                self.take(")")
                arithmetic = ("+", "-", "*", "/", *COMPARISONS)
                if inner.is_formula and self.peek() not in arithmetic:
                    return inner
            except FormulaError as exc:
                first = (self.i, exc)
            self.i = start
        try:
            return self.arithmetic_comparison(start)
        except FormulaError:
            if first is not None and first[0] >= self.i:  # the formula reading got further
                raise first[1] from None
            raise

    def arithmetic_comparison(self, start: int) -> Node:
        left = self.sum()
        if self.peek() in COMPARISONS:
            op = self.take()
            right = self.sum()
            if self.peek() in COMPARISONS:
                raise FormulaError(f"chained comparison at {self.where()}: use 'and'")
            return Node(op, (left, right))
        if self.i == start:
            raise FormulaError(f"expected a formula, got {self.where()}")
        return left

    def sum(self) -> Node:
        left = self.product()
        while self.peek() in ("+", "-"):
            op = self.take()
            left = Node(op, (left, self.product()))
        return left

    def product(self) -> Node:
        left = self.factor()
        while self.peek() in ("*", "/"):
            op = self.take()
            left = Node(op, (left, self.factor()))
        return left

    def factor(self) -> Node:
        tok = self.peek()
        if tok == "-":
            self.take()
            self.deeper()
            out = Node("neg", (self.factor(),))
            self.depth -= 1
            return out
        if tok == "(":
            self.take()
            self.deeper()
            inner = self.sum()
            self.depth -= 1
            self.take(")")
            return inner
        if self.i >= len(self.toks):
            raise FormulaError("expected a number or a signal, got the end")
        kind, text, _ = self.toks[self.i]
        if kind == "num":
            self.i += 1
            value = float(text)
            if not math.isfinite(value):
                raise FormulaError(f"{text} is not a finite number")
            return Node("num", value=value)
        if kind == "name" and text == "abs":
            self.take()
            self.take("(")
            self.deeper()
            inner = self.sum()
            self.depth -= 1
            self.take(")")
            return Node("abs", (inner,))
        if kind == "name" and text not in _KEYWORDS:
            self.i += 1
            return Node("sig", name=text)
        raise FormulaError(f"expected a number or a signal, got {self.where()}")

    def maybe_interval(self, op: str) -> tuple[Fraction | None, Fraction | None]:
        if self.peek() != "[":
            return None, None
        self.take("[")
        lo = self.bound(op)
        self.take(":")
        hi = self.bound(op)
        self.take("]")
        if hi is not None and lo is not None and lo > hi:
            raise FormulaError(f"{op}[{float(lo):g}:{float(hi):g}]: the interval is empty")
        if lo is None:
            raise FormulaError(f"{op}: the interval cannot start at infinity")
        return lo, hi

    def bound(self, op: str) -> Fraction | None:
        if self.i >= len(self.toks):
            raise FormulaError(f"{op}: the interval is not closed")
        kind, text, _ = self.toks[self.i]
        if kind == "name" and text == "inf":
            self.i += 1
            return None
        if kind != "num":
            raise FormulaError(f"{op}: expected a time in seconds, got {self.where()}")
        self.i += 1
        value = Fraction(text)
        if self.i < len(self.toks) and self.toks[self.i][1] in ("s", "ms"):
            if self.toks[self.i][1] == "ms":
                value /= 1000
            self.i += 1
        return value


def parse(text: str) -> Node:
    """The formula's tree; :class:`FormulaError` with the column if it does not parse.

    Cached: every run of a sweep asks for its scenario's requirements, whose text is the
    same (the tree is immutable, so sharing it is safe)."""
    if not isinstance(text, str):
        raise FormulaError(f"a formula is text, got {type(text).__name__}")
    return _parse(text)


@functools.lru_cache(maxsize=256)
def _parse(text: str) -> Node:
    if not isinstance(text, str):
        raise FormulaError(f"a formula is text, got {type(text).__name__}")
    if len(text) > MAX_LENGTH:
        raise FormulaError(f"longer than {MAX_LENGTH} characters")
    p = _Parser(text)
    if not p.toks:
        raise FormulaError("the formula is empty")
    try:
        node = p.formula()
    except RecursionError:  # the bounds above should make this unreachable: a backstop
        raise FormulaError(_TOO_DEEP) from None
    if p.i != len(p.toks):
        raise FormulaError(f"unexpected {p.where()}")
    if not node.is_formula:
        raise FormulaError(
            f"{node.text()} is a value (a signal or a number), not a formula: compare it "
            f"(e.g. {node.text()} > 0)"
        )
    return node
