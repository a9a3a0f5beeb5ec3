"""What a command's refusal of a bad input looks like to a user, checked in one place: exit 2
and one line on stderr that starts with the program's name and says why, no traceback. The
benchmarks' option tests share it (``tests/adapt/test_adapt_seeds*.py``), so the shape they
hold cannot drift apart between copies."""

from __future__ import annotations


def assert_one_line_refusal(code: int, err: str, says: str, prefix: str) -> None:
    """``code`` is 2 and ``err`` (the command's stderr) is the one line ``prefix...``
    containing ``says``."""
    assert code == 2, err
    assert err.count("\n") == 1, err
    assert err.startswith(prefix), err
    assert says in err, err
    assert "Traceback" not in err, err
