"""What ``falsify --resume`` reads back from a search's directory, judged as data.

The directory of an interrupted search may come from anywhere, so nothing in it is trusted:

* ``falsify.json`` and ``trial.json`` are bounded JSON records (:mod:`.records`); a finished
  trial's fields are type-checked, and must agree with each other and with this search
  (its seed, its budget), or the trial would be summarised from nonsense;
* ``results.csv`` is read only if it is a regular file within a size that grows with the
  budget (:func:`results_limit`), every row as wide as the header, its run numbers those of
  the budget and its metric cells numbers: one line naming the file and the line (exit 2);
* a ``trial-NNN`` that is a symbolic link, or not a directory, is refused before anything is
  written: a trial's files are written only into a real directory inside ``--out``, never
  through a link to somewhere else (:func:`check_trial_dirs`).
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
import stat
from pathlib import Path
from typing import Any

from ..atomic import write_atomic
from ..errors import ConfigError, OutputError
from ..model.params import short_repr
from ..model.yamlio import read_regular_file
from .records import read_record
from .trials import Trial

#: Columns of results.csv that are not numbers.
TEXT_COLUMNS = ("error",)

#: the results.csv allowed per run of the budget (a row is ~1 KB: its axes, a dozen metrics
#: per phase, a requirement's robustness, an error line; a categorical axis's value may be a
#: list, up to the CSV reader's 128 KiB a cell)
MAX_ROW_BYTES = 256 << 10

#: the largest results.csv read whatever the budget
MAX_RESULTS_BYTES = 256 << 20

#: what may sit under a trial's directory that amsa-phys replaces: the counterexample's run
TRIAL_SUBDIRS = ("counterexample",)


def results_limit(budget: int) -> int:
    """The largest results.csv of a search of ``budget`` runs read back."""
    return min(MAX_RESULTS_BYTES, MAX_ROW_BYTES * (budget + 1))


def read_trial(path: Path, seed: int, budget: int) -> Trial | None:
    """A finished trial back (None if it has no ``trial.json``: it did not finish).

    ``seed`` and ``budget`` are this search's: a record of another search is refused.
    """
    if not os.path.lexists(path):
        return None
    doc = read_record(path, "a trial's trial.json")
    fields = set(Trial.__dataclass_fields__)
    if set(doc) != fields:
        odd = sorted(set(doc) ^ fields)
        raise ConfigError(
            f"not a finished trial: {'unknown' if set(doc) - fields else 'missing'} "
            f"key {short_repr(odd[0])}",
            file=path,
        )
    why = _trial_problem(doc, seed, budget)
    if why is not None:
        key, what = why
        raise ConfigError(f"{what} (not a finished trial of this search)", file=path, key=key)
    return Trial(**doc)


def _trial_problem(doc: dict[str, Any], seed: int, budget: int) -> tuple[str, str] | None:
    """The key of ``trial.json`` that is wrong and why (None if none)."""
    if not _integer(doc["seed"]) or doc["seed"] != seed:
        return "seed", f"is {short_repr(doc['seed'])}, this trial's seed is {seed}"
    if not isinstance(doc["falsified"], bool):
        return "falsified", "is not true or false"
    if not _integer(doc["runs"]) or not 0 <= doc["runs"] <= budget:
        return "runs", f"is {short_repr(doc['runs'])}, not a count of runs from 0 to {budget}"
    sims = doc["simulations"]
    if sims is not None and (not _integer(sims) or not 1 <= sims <= doc["runs"]):
        return "simulations", f"is {short_repr(sims)}, not a count from 1 to runs"
    if doc["falsified"] != (sims is not None):
        return "simulations", "a falsified trial has simulations, another has null"
    if doc["least"] is not None and not _finite(doc["least"]):
        return "least", f"is {short_repr(doc['least'])}, not a finite number or null"
    if not _finite(doc["cpu_s"]) or doc["cpu_s"] < 0:
        return "cpu_s", f"is {short_repr(doc['cpu_s'])}, not seconds"
    return None


def _integer(value: Any) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def _finite(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


def _cell(key: str, text: str) -> Any:
    if key in TEXT_COLUMNS:
        return text
    if text == "":
        return None
    if text.lstrip("-").isdigit():  # written from an int (a float always shows "." or "e")
        return int(text)
    try:
        return float(text)
    except ValueError:
        return text  # a categorical axis's value


def read_cached(path: Path, budget: int) -> dict[int, dict[str, Any]]:
    """The rows of an interrupted search's results.csv, by run number (none: no file)."""
    if not os.path.lexists(path):
        return {}
    raw = read_regular_file(
        path, results_limit(budget), "a falsification's results.csv", follow=False
    )
    text = io.TextIOWrapper(io.BytesIO(raw), encoding="utf-8", newline="")
    reader = csv.reader(text)
    out: dict[int, dict[str, Any]] = {}
    try:
        header = next(reader, [])
        _check_header(header, path)
        numbers = header[header.index("error") + 1 :]  # the metrics, robustness, generation
        for cells in reader:
            if not cells:
                continue
            line = reader.line_num
            if len(cells) != len(header):
                raise ConfigError(
                    f"cannot resume from it: {len(cells)} cells where the header has {len(header)}",
                    file=path,
                    line=line,
                )
            row = {k: _cell(k, v) for k, v in zip(header, cells, strict=True)}
            _check_row(row, numbers, budget, out, path, line)
            row.pop("robustness", None)  # judged again
            row.pop("generation", None)
            out[row["run"]] = row
    except (UnicodeDecodeError, csv.Error) as exc:
        raise ConfigError(
            f"cannot resume from it: {'not UTF-8 text' if isinstance(exc, ValueError) else exc}",
            file=path,
            line=reader.line_num or None,
        ) from None
    return out


def _check_header(header: list[str], path: Path) -> None:
    needed = ("run", "seed_index", "seed", "error")
    missing = [k for k in needed if k not in header]
    if header[:1] != ["run"] or missing:
        raise ConfigError(
            f"cannot resume from it: not a falsification's results.csv (no "
            f"{', '.join(missing or ['run (first)'])} column)",
            file=path,
            line=1,
        )
    if len(set(header)) != len(header):
        twice = next(k for k in header if header.count(k) > 1)
        raise ConfigError(
            f"cannot resume from it: the column {short_repr(twice)} appears twice",
            file=path,
            line=1,
        )


def _check_row(
    row: dict[str, Any],
    numbers: list[str],
    budget: int,
    seen: dict[int, dict[str, Any]],
    path: Path,
    line: int,
) -> None:
    """A cached row is taken as the search's own: its run number must be one of the
    budget's, once, and its metrics numbers (the objective computes with them)."""
    run = row["run"]
    if not isinstance(run, int) or not 0 <= run < budget:
        raise ConfigError(
            f"cannot resume from it: run is {short_repr(run)}, not a run number from 0 to "
            f"{budget - 1}",
            file=path,
            line=line,
        )
    if run in seen:
        raise ConfigError(f"cannot resume from it: run {run} appears twice", file=path, line=line)
    for key in ("seed_index", "seed"):
        if not isinstance(row[key], int):
            raise ConfigError(
                f"cannot resume from it: {key} is {short_repr(row[key])}, not an integer",
                file=path,
                line=line,
            )
    for key in numbers:
        if isinstance(row[key], str):
            raise ConfigError(
                f"cannot resume from it: {short_repr(key)} is {short_repr(row[key])}, not a number",
                file=path,
                line=line,
            )


def check_same_search(path: Path, settings: dict[str, Any], resume: bool) -> None:
    """``falsify.json`` records the search's settings; ``--resume`` refuses a directory of
    another search (its rows would be taken for this one's)."""
    if resume:
        if not os.path.lexists(path):
            raise ConfigError("not a falsification to resume (no falsify.json)", file=path.parent)
        before = read_record(path, "a falsification's falsify.json")
        if before != settings:
            changed = sorted(k for k in settings if before.get(k) != settings[k])
            raise ConfigError(
                f"cannot resume: this search differs in {', '.join(changed) or 'its settings'}",
                file=path.parent,
                key="--resume",
            )
        return
    write_atomic(path, json.dumps(settings, indent=1, sort_keys=True) + "\n")


def _not_a_real_dir(path: Path) -> str | None:
    """Why amsa-phys may not write into ``path`` (None: absent, or a real directory)."""
    try:
        mode = os.lstat(path).st_mode
    except FileNotFoundError:
        return None
    if stat.S_ISLNK(mode):
        return (
            "is a symbolic link; amsa-phys writes a trial's files only into a real "
            "directory inside --out (remove the link)"
        )
    if not stat.S_ISDIR(mode):
        return "exists and is not a directory"
    return None


def check_trial_dirs(dirs: list[Path]) -> None:
    """Refuse, before anything is written, a trial's directory (or the counterexample run
    under it) that is a symbolic link or not a directory."""
    for d in dirs:
        for place in (d, *(d / sub for sub in TRIAL_SUBDIRS)):
            why = _not_a_real_dir(place)
            if why is not None:
                raise ConfigError(why, file=place)


def make_trial_dir(path: Path) -> None:
    """Create a trial's directory; one already there must be a real directory (a link put
    there since :func:`check_trial_dirs` is refused, not followed)."""
    try:
        os.mkdir(path)
    except FileExistsError:
        why = _not_a_real_dir(path)
        if why is not None:
            raise ConfigError(why, file=path) from None
    except OSError as exc:
        raise OutputError(path, f"cannot create the directory: {exc.strerror}") from None
