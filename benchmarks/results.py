"""The benchmark results file: every performance figure the docs state, with its provenance.

Why one file: a figure in the docs is true only if anyone can regenerate it with one command
and see the sitting it came from. ``python -m benchmarks.perf --save`` measures and writes
``benchmarks/results/perf.json`` (a row per figure: value, spread, baseline or ratio, target,
machine load, date, commit), then rewrites every generated block of the docs and README from it.
A block is::

    <!-- results: TARGET [TARGET ...] -->
    (the table, generated)
    <!-- /results -->

``docs/hooks.py`` renders the same tables when the site is built, and a test fails when a block
in the sources differs from its rendering or when a page states a performance figure outside
such a block. ``python -m benchmarks.results`` rewrites the blocks without measuring.
"""

from __future__ import annotations

import contextlib
import datetime
import io
import json
import os
import re
import subprocess
import sys
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "benchmarks" / "results" / "perf.json"

#: A generated block: the targets it shows, then the table, up to its end marker.
BLOCK = re.compile(r"(<!-- results: ([\w ,-]+?) -->\n)(.*?)(<!-- /results -->)", re.DOTALL)

#: ``median (min A, max B)`` as ``perf.med`` prints it, then whatever the line adds.
_MED = re.compile(r"^\s*(-?[\d.e+-]+) \(min (-?[\d.e+-]+), max (-?[\d.e+-]+)\)(.*)$", re.DOTALL)
_MED_ANYWHERE = re.compile(r"(-?[\d.]+(?:e[+-]?\d+)?) \(min (-?[\d.e+-]+), max (-?[\d.e+-]+)\)")
_AIM = re.compile(r"(?:target |\()([<>]=? ?[\d.,]+ ?[a-zA-Z]*)")
_LEAD = re.compile(r"^\s*(-?\d[\d,]*(?:\.\d+)?(?:e[+-]?\d+)?)(?:;|$)(.*)$", re.DOTALL)
_NUMBER = re.compile(r"-?\d+(?:\.\d+)?(?:e[+-]?\d+)?")


@dataclass
class Row:
    """One measured figure, as the docs show it."""

    target: str  #: the ``perf.py --only`` name that measures it
    figure: str  #: what is measured, e.g. "run process CPU / python -c pass"
    value: float | None  #: the median, None when the line held no number
    spread: list[float] | None  #: [min, max] over the repetitions
    ratio_to: str  #: the baseline of a ratio measured in the same sitting ("" for none)
    detail: str  #: the rest of the printed line (baselines' own figures)
    target_text: str  #: the aim, e.g. "<= 15"
    verdict: str  #: PASS or MISS; INFO without an aim; SKIP when it could not be measured
    reps: int
    load: list[float]  #: the 1-minute load average before and after the target ran
    date: str  #: UTC, ISO 8601
    commit: str  #: ``git rev-parse --short HEAD`` (``-dirty`` when the tree was modified)
    extra: dict[str, Any] = field(default_factory=dict)


#: What a benchmark calls for each figure: ``report(name, measured, aim, ok, skipped=False)``
#: (``perf.report`` prints the line and records it).
Report = Callable[..., None]


def verdict(ok: bool | None, skipped: bool = False) -> str:
    """PASS or MISS against the aim; INFO for a figure without one; SKIP when not measured."""
    if skipped:
        return "SKIP"
    if ok is None:
        return "INFO"
    return "PASS" if ok else "MISS"


def print_report(
    name: str, measured: str, aim: str, ok: bool | None, skipped: bool = False
) -> None:
    """``perf.report``'s line, for a benchmark run on its own (nothing recorded)."""
    aim = f"   target {aim}" if aim else ""
    print(f"{verdict(ok, skipped):4s}  {name:34s} {measured}{aim}", flush=True)


def commit() -> str:
    """The measured code's commit, marked dirty when the work tree differs from it."""
    try:
        head = subprocess.run(
            ["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"],
            capture_output=True,
            text=True,
            check=True,
        ).stdout.strip()
        dirty = subprocess.run(
            ["git", "-C", str(ROOT), "status", "--porcelain", "--untracked-files=no"],
            capture_output=True,
            text=True,
            check=True,
        ).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"
    return head + ("-dirty" if dirty else "")


def parse_measured(measured: str) -> tuple[float | None, list[float] | None, str]:
    """(median, [min, max], the rest) from a ``report`` line's measured text."""
    m = _MED.match(measured)
    if m:
        return float(m[1]), [float(m[2]), float(m[3])], m[4].strip(" ;")
    lead = _LEAD.match(measured)  # "1.42; bag 5.3 MiB": one value, then what it adds
    if lead:
        return float(lead[1].replace(",", "")), None, lead[2].strip(" ;")
    first = _NUMBER.search(measured)
    return (float(first[0]) if first else None), None, measured.strip()


def ratio_baseline(figure: str) -> str:
    """The baseline a ratio figure is measured against ("a / b" or "a vs b"), else ""."""
    for sep in (" / ", " vs "):
        if sep in figure:
            return figure.split(sep, 1)[1].strip()
    return ""


class Recorder:
    """Collects the rows of one ``perf.py`` sitting, then merges them into the file.

    A sitting replaces the rows of the targets it measured and keeps the others, so one
    target can be re-measured alone; each row keeps its own date, load and commit.
    """

    def __init__(self, reps: int) -> None:
        self.reps = reps
        self.rows: list[Row] = []
        self.target = ""
        self.load_before = 0.0
        self.commit = commit()

    def start(self, target: str) -> None:
        self.target = target
        self.load_before = os.getloadavg()[0]

    def add(
        self, figure: str, measured: str, aim: str, ok: bool | None, skipped: bool = False
    ) -> None:
        """A line of ``perf.report``: name, measured text, aim and verdict apart.

        ``ok`` None is a figure shown without an aim (INFO); ``skipped`` a figure that could
        not be measured here, ``measured`` saying why (SKIP: the row keeps the reason, so a
        table says what is missing instead of dropping it)."""
        if skipped:
            self.add_row(figure, None, None, measured.strip(), aim, None, skipped=True)
            return
        value, spread, detail = parse_measured(measured)
        self.add_row(figure, value, spread, detail, aim, ok)

    def add_line(self, line: str) -> None:
        """A PASS/MISS line printed by a benchmark of its own (``bench_engine``,
        ``bench_batch``): kept whole as the figure, its median and aim read from it."""
        ok, _, text = line.strip().partition(" ")
        text = text.strip()
        med = _MED_ANYWHERE.search(text)
        value, spread = None, None  # the line itself, shown whole, says what it measured
        if med:
            value, spread = float(med[1]), [float(med[2]), float(med[3])]
        aim = _AIM.search(text)
        self.add_row(text, value, spread, "", aim[1] if aim else "", ok == "PASS")

    def add_row(
        self,
        figure: str,
        value: float | None,
        spread: list[float] | None,
        detail: str,
        aim: str,
        ok: bool | None,
        skipped: bool = False,
    ) -> None:
        self.rows.append(
            Row(
                target=self.target,
                figure=figure.strip(),
                value=value,
                spread=spread,
                ratio_to=ratio_baseline(figure),
                detail=detail,
                target_text=aim,
                verdict=verdict(ok, skipped),
                reps=self.reps,
                load=[round(self.load_before, 2), round(os.getloadavg()[0], 2)],
                date=datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
                commit=self.commit,
            )
        )

    def save(self, path: Path = RESULTS) -> None:
        measured = {r.target for r in self.rows}
        kept = [r for r in load(path) if r["target"] not in measured]
        rows = kept + [asdict(r) for r in self.rows]
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps({"rows": rows}, indent=1) + "\n")


class Tee(io.TextIOBase):
    """Standard output that also hands the PASS/MISS lines of benchmarks printing their own
    to the recorder (lines that ``perf.report`` printed are recorded there, not here)."""

    def __init__(self, out: Any, recorder: Recorder) -> None:
        self.out, self.recorder, self.buffer_ = out, recorder, ""
        self.quiet = False  #: set while ``perf.report`` prints a line it records itself

    def write(self, text: str) -> int:
        self.out.write(text)
        self.buffer_ += text
        *lines, self.buffer_ = self.buffer_.split("\n")
        for line in lines:
            if not self.quiet and line.startswith(("PASS", "MISS")):
                self.recorder.add_line(line)
        return len(text)

    def flush(self) -> None:
        self.out.flush()


@contextlib.contextmanager
def quiet(tee: Tee | None) -> Any:
    """Within it the tee records nothing (the caller records the line itself)."""
    if tee is not None:
        tee.quiet = True
    try:
        yield
    finally:
        if tee is not None:
            tee.quiet = False


def load(path: Path = RESULTS) -> list[dict[str, Any]]:
    """The file's rows (none when it does not exist yet)."""
    if not path.exists():
        return []
    return list(json.loads(path.read_text())["rows"])


def _num(x: float) -> str:
    """Four significant digits, thousands separated as the docs write them."""
    if abs(x) >= 1000:
        return f"{x:,.0f}"
    return f"{x:.4g}"


#: Blocks rendered from a results file of their own by the code that wrote it (not perf.json):
#: ``amsa-phys adapt --validate --results FILE`` writes the held-out validation's table;
#: ``benchmarks/adapt_demo.py`` and ``adapt_outside.py`` write a table of their own (a
#: ``columns`` file: the cells as they print them).
ADAPT = ROOT / "scenarios" / "rules"
OWN_TABLES = {
    "adapt-validate": ADAPT / "adaptive_rules.validate.json",
    "adapt-demo": ROOT / "benchmarks" / "results" / "adapt_demo.json",
    "adapt-outside": ROOT / "benchmarks" / "results" / "adapt_outside.json",
    "adapt-fresh": ROOT / "benchmarks" / "results" / "adapt_fresh.json",
    "adapt-swing": ROOT / "benchmarks" / "results" / "adapt_swing.json",
    "adapt-seeds": ROOT / "benchmarks" / "results" / "adapt_seeds.json",
    "adapt-seeds-set": ROOT / "benchmarks" / "results" / "adapt_seeds_set.json",
    "adapt-seeds-fine": ROOT / "benchmarks" / "results" / "adapt_seeds_fine.json",
    "adapt-stall": ROOT / "benchmarks" / "results" / "adapt_stall.json",
    "physics-step": ROOT / "benchmarks" / "results" / "physics_step.json",
}


def _own_table(target: str) -> str:
    """The table of a block in :data:`OWN_TABLES`, rendered as its writer renders it."""
    path = OWN_TABLES[target]
    if not path.exists():
        return f"*Not measured yet: no {path.relative_to(ROOT)}.*\n"
    doc = json.loads(path.read_text())
    if "columns" in doc:
        return table_markdown(doc)
    if "draws" in doc:  # benchmarks/adapt_seeds.py's: three tables of its own
        from benchmarks.adapt_seeds import markdown as seeds_markdown

        return seeds_markdown(doc)
    from amsa_phys.adapt.validate import markdown

    return markdown(doc)


def table_markdown(doc: dict[str, Any]) -> str:
    """A ``columns`` results file as Markdown: its rows, then its caption, sitting and command."""
    lines = [
        "| " + " | ".join(doc["columns"]) + " |",
        "| " + " | ".join("---" for _ in doc["columns"]) + " |",
    ]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in doc["rows"]]
    load_ = "–".join(f"{x:g}" for x in doc["load"])
    lines += [
        "",
        f"*{doc['caption']} (load {load_}, {doc['date'][:10]}). Regenerate: `{doc['command']}`.*",
    ]
    return "\n".join(lines) + "\n"


def table_doc(
    columns: list[str], rows: list[list[Any]], caption: str, command: str, **extra: Any
) -> dict[str, Any]:
    """A ``columns`` results file (what :func:`table_markdown` renders), with its sitting:
    the machine's load and the date (the figures do not depend on them when the runs are
    deterministic; they say when the table was made)."""
    return {
        "columns": columns,
        "rows": rows,
        "caption": caption,
        "command": command,
        "load": [round(x, 2) for x in os.getloadavg()],
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        **extra,
    }


def render(targets: list[str], rows: list[dict[str, Any]] | None = None) -> str:
    """The markdown table of the targets' rows, or a line saying they are still to measure."""
    if len(targets) == 1 and targets[0] in OWN_TABLES:
        return _own_table(targets[0])
    rows = load() if rows is None else rows
    mine = [r for r in rows if r["target"] in targets]
    command = f"python -m benchmarks.perf --save --only {' '.join(targets)}"
    if not mine:
        return f"*Not measured yet: `{command}` measures it and fills this table.*\n"
    lines = [
        "| figure | median | min–max | target | verdict | reps | load | date | commit |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for r in mine:
        value = "" if r["value"] is None else _num(r["value"])
        spread = "" if not r["spread"] else f"{_num(r['spread'][0])}–{_num(r['spread'][1])}"
        figure = r["figure"] + (f" ({r['detail']})" if r["detail"] else "")
        load_ = "–".join(f"{x:g}" for x in r["load"])
        lines.append(
            f"| {figure} | {value} | {spread} | {r['target_text']} | {r['verdict']} "
            f"| {r['reps']} | {load_} | {r['date'][:10]} | `{r['commit']}` |"
        )
    lines.append("")
    lines.append(f"*Regenerate: `{command}`.*")
    return "\n".join(lines) + "\n"


def fill(text: str, rows: list[dict[str, Any]] | None = None) -> str:
    """``text`` with every generated block's table rendered from the results."""
    rows = load() if rows is None else rows

    def one(m: re.Match[str]) -> str:
        targets = m[2].replace(",", " ").split()
        return m[1] + render(targets, rows) + m[4]

    return BLOCK.sub(one, text)


def pages() -> list[Path]:
    """Every user-facing page that may hold a generated block."""
    docs = [p for p in sorted((ROOT / "docs").rglob("*.md")) if "_incoming" not in p.parts]
    return [ROOT / "README.md", *docs]


def write_pages() -> list[Path]:
    """Rewrite the generated blocks of every page; the pages that changed."""
    rows = load()
    changed = []
    for page in pages():
        text = page.read_text()
        new = fill(text, rows)
        if new != text:
            page.write_text(new)
            changed.append(page)
    return changed


def main() -> None:
    """Rewrite every page's generated blocks from ``benchmarks/results/perf.json``."""
    for page in write_pages():
        print(f"rewrote {page.relative_to(ROOT)}", file=sys.stderr)


if __name__ == "__main__":
    main()
