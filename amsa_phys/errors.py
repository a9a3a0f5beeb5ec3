"""Errors a user can cause, each carrying the exit code the CLI returns for it.

Library code raises these; only ``cli.main`` catches them and prints ``str(err)`` as one
line. Any other exception is a bug and keeps its traceback.
"""

from __future__ import annotations

import re
from fractions import Fraction
from pathlib import Path


class AmsaError(Exception):
    """Base of every error a user can cause; ``exit_code`` is what the CLI returns."""

    exit_code = 2


class ConfigError(AmsaError):
    """A world, scenario or command-line value is wrong.

    Printed as ``file:line: key.path: message`` so an editor can jump to it.
    """

    def __init__(
        self,
        message: str,
        *,
        file: str | Path | None = None,
        line: int | None = None,
        key: str | None = None,
    ) -> None:
        self.message = message
        self.file = str(file) if file is not None else None
        self.line = line
        self.key = key
        #: which front end the message is worded for: "cli" (flags) or "api" (arguments)
        self.front = "cli"
        super().__init__(str(self))

    @property
    def option(self) -> str | None:
        """The command-line option the error is about (``--set``), if any.

        Library code names an option the way the CLI spells it (``key="--set Comp.param"``,
        ``key="--duration"``); the flag is the parameter, and :meth:`worded_for_api` words
        it for the Python API instead.
        """
        if self.key and self.key.startswith("--"):
            return self.key.partition(" ")[0]
        return None

    def worded_for_api(self) -> ConfigError:
        """Word this error for ``amsa_phys.run``/``load`` (``set=``, ``duration=``); returns it.

        The API's front door calls this on the way out, so a Python user reads the argument
        they passed, not a flag they never typed; the CLI keeps the default wording.
        """
        self.front = "api"
        self.args = (str(self),)
        return self

    def __str__(self) -> str:
        where = ""
        if self.file is not None:
            where = self.file + (f":{self.line}" if self.line is not None else "") + ": "
        key, message = self.key, self.message
        if self.front == "api":
            key, message = _api_key(key), api_text(message)
        key = f"{key}: " if key else ""
        return one_line(f"{where}{key}{message}")


#: a CLI option -> how the Python API (``amsa_phys.run``, ``load``, ``Run.save``) spells it:
#: the one table both front ends' wording comes from
API_WORDS = {
    "--set": "set=",
    "--duration": "duration=",
    "--seed": "seed=",
    "--log-rate": "log_rate=",
    "--trace-columns": "trace_columns=",
    "--no-adapt": "adapt=False",
    "--bag": "bag=",
    "--out": "out=",
    "--force": "force=True",
    "--ros2": "ros2=",
    "--ros2-timeout": "ros2_timeout=",
    "--search-on": "search_on=True",  # ``amsa_phys.falsify``'s
    "--requirement": "requirement=",
}
#: keys only (a message's "give its values with --grid" stays as the command says it):
#: ``amsa_phys.falsify``'s box of ranges and grids
_API_KEYS = {**API_WORDS, "--range": "box=", "--grid": "box="}
#: the flags whose key names a ``Comp.param`` the API passes as a mapping's key
_API_MAPPINGS = ("--set", "--range", "--grid")
_API_FLAG = re.compile(r"(?<![\w-])(" + "|".join(map(re.escape, API_WORDS)) + r")(?![\w-])")


def api_text(text: str) -> str:
    """``text`` (an error's or a warning's) with each CLI option the API has spelt as the
    API's argument (``--set`` -> ``set=``)."""
    return _API_FLAG.sub(lambda m: API_WORDS[m[0]], text)


def _api_key(key: str | None) -> str | None:
    """``--set Comp.param`` -> ``set={"Comp.param": ...}``, ``--duration`` -> ``duration=``."""
    if not key or not key.startswith("--"):
        return key
    flag, _, rest = key.partition(" ")
    word = _API_KEYS.get(flag)
    if word is None:  # an option the API does not have: as the CLI says it
        return key
    if not rest:
        return word
    if flag in _API_MAPPINGS:
        quoted = rest.replace("\\", "\\\\").replace('"', '\\"')
        return f'{word}{{"{quoted}": ...}}'  # as the user wrote it: set={"Comp.param": value}
    return f"{word} {rest}"


def one_line(text: str) -> str:
    """Escape control characters so a message stays one line and cannot drive the terminal.

    A key may hold a newline, a scenario's ``name`` or a component's exception an ANSI
    escape (``\\x1b[2J`` clears the screen): every message, table cell and name amsa-phys
    prints goes through here, so what reaches the terminal is always printable text.
    """
    if text.isprintable():
        return text
    return "".join(
        c if c.isprintable() else c.encode("unicode_escape").decode("ascii") for c in text
    )


class RunFault(AmsaError):
    """A fault during a run (non-finite value, exception in a component, physics blow-up)."""

    exit_code = 3

    def __init__(self, component: str, t: Fraction | float, cause: str) -> None:
        self.component = component
        self.t = float(t)
        self.cause = cause
        super().__init__(str(self))

    def __str__(self) -> str:
        return one_line(f"run fault at t={self.t:.3f} s in {self.component}: {self.cause}")


class OutputError(AmsaError):
    """An output file could not be written (disk full, read-only file system, a directory
    in the way): exit 3 like a run fault, with one line naming the file.

    The file's final name never holds a partial file (``amsa_phys.atomic``).
    """

    exit_code = 3

    def __init__(self, path: str | Path, reason: str) -> None:
        self.path = str(path)
        self.reason = reason
        super().__init__(str(self))

    def __str__(self) -> str:
        return one_line(f"cannot write {self.path}: {self.reason}")


class ExpectationFailed(AmsaError):
    """One or more scenario expectations did not hold."""

    exit_code = 1


class Interrupted(KeyboardInterrupt):
    """The user interrupted a run (Ctrl-C or SIGTERM); outputs so far were finalised.

    A KeyboardInterrupt, not an :class:`AmsaError`: code that records a run's error and goes
    on (a sweep's row, a suite's scenario) must not swallow the user's Ctrl-C.
    """

    exit_code = 130
