"""Every example in the README and the manual runs as written.

The convention (docs/development.md, "Examples in the docs"): a fenced ```` ```python ```` block
is run as a script, and each ``$ `` line of a ```` ```console ```` block as a shell command
(a line ending in ``\\`` continues it; lines without ``$ `` are the output shown). They run in
order, page by page, in a scratch copy of the project's ``scenarios/``, ``worlds/``,
``examples/`` and ``docs/examples/`` (so an example may write ``runs/...`` or even
``scenarios/rules/...``). An HTML comment on the line before a block changes how it runs:

- ``<!-- docs-test: skip REASON -->``: shown, not run (a ROS launch on a robot, an install);
- ``<!-- docs-test: sub "OLD" "NEW" -->``: run with OLD replaced by NEW (a shorter duration or
  budget for a long example; repeatable);
- ``<!-- docs-test: exit 0,1 -->``: the exit codes a command may end with (default 0), for an
  example that documents a failing check.

Commands written in any other fence (``sh``, ``bash``, none) would escape the test, so a
test refuses them.
"""

from __future__ import annotations

import os
import re
import shlex
import shutil
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

import pytest

pytestmark = pytest.mark.docs  # every example of the manual, run: minutes

ROOT = Path(__file__).resolve().parents[2]
PAGES = [
    ROOT / "README.md",
    *sorted(p for p in (ROOT / "docs").rglob("*.md") if "_incoming" not in p.parts),
]
FENCE = re.compile(r"^([ \t]*)```[ \t]*([\w+-]*)[^\n]*\n(.*?)^\1```[ \t]*$", re.M | re.S)
MARK = re.compile(r"<!--\s*docs-test:\s*(.*?)\s*-->")
#: the folders an example may read (copied, so one that writes into them changes nothing)
TREE = ("scenarios", "worlds", "examples", "docs/examples")


@dataclass
class Example:
    """One runnable block: where it is, what it runs and how."""

    page: Path
    line: int
    lang: str
    code: str
    skip: str = ""
    subs: list[tuple[str, str]] = field(default_factory=list)
    exits: tuple[int, ...] = (0,)

    @property
    def id(self) -> str:
        return f"{self.page.relative_to(ROOT)}:{self.line}"

    def commands(self) -> list[str]:
        """The ``$ `` lines of a console block, continuations joined."""
        out: list[str] = []
        more = False
        for raw in self.code.splitlines():
            if more:
                out[-1] += "\n" + raw
            elif raw.startswith("$ "):
                out.append(raw[2:])
            else:
                continue
            more = raw.rstrip().endswith("\\")
        return out

    def prepared(self, text: str) -> str:
        for old, new in self.subs:
            assert old in self.code, f"{self.id}: docs-test sub {old!r} not found in the block"
            text = text.replace(old, new)
        return text


def _options(example: Example, spec: str) -> None:
    """Read a ``docs-test:`` comment into ``example``; unknown words are an error."""
    head, _, rest = spec.partition(" ")
    if head == "skip":  # the reason is prose (apostrophes and all)
        if not rest.strip():
            raise ValueError(f"{example.id}: docs-test skip needs a reason")
        example.skip = rest.strip()
        return
    words = shlex.split(spec)
    while words:
        word = words.pop(0)
        if word == "sub" and len(words) >= 2:
            example.subs.append((words.pop(0), words.pop(0)))
        elif word == "exit" and words:
            example.exits = tuple(int(c) for c in words.pop(0).split(","))
        else:
            raise ValueError(f"{example.id}: unknown docs-test option {word!r} in {spec!r}")


#: a pymdownx.snippets inclusion: ``--8<-- "PATH"`` on a line, or PATH between two ``--8<--``
SNIPPET = re.compile(r'^--8<-- "([^"]+)"$|^--8<--\n(.*?)\n--8<--$', re.M | re.S)


def _expand(body: str) -> str:
    """A block's text as the site shows it: snippets replaced by the files they name."""

    def included(m: re.Match[str]) -> str:
        names = [m.group(1)] if m.group(1) else m.group(2).split()
        return "".join((ROOT / n).read_text() for n in names).rstrip("\n")

    return SNIPPET.sub(included, body)


def blocks(page: Path) -> list[tuple[int, str, str, str]]:
    """(line, language, body dedented and snippets expanded, the text just before) of every
    fenced block."""
    text = page.read_text()
    found = []
    for m in FENCE.finditer(text):
        indent, lang, body = m.groups()
        line = text.count("\n", 0, m.start()) + 1
        if indent:
            body = "".join(
                ln[len(indent) :] if ln.startswith(indent) else ln
                for ln in body.splitlines(keepends=True)
            )
        before = text[: m.start()].rstrip().rsplit("\n", 1)[-1]
        found.append((line, lang, _expand(body), before))
    return found


def collect() -> list[Example]:
    """Every python and console block of the README and the manual, in reading order."""
    examples = []
    for page in PAGES:
        for line, lang, body, before in blocks(page):
            if lang not in ("python", "console"):
                continue
            ex = Example(page, line, lang, body)
            mark = MARK.search(before)
            if mark:
                _options(ex, mark.group(1))
            examples.append(ex)
    return examples


EXAMPLES = collect()


@pytest.fixture(scope="module")
def workspaces(tmp_path_factory: pytest.TempPathFactory) -> dict[Path, Path]:
    """A scratch project per page, made on first use (a page's examples build on each other)."""
    return {}


def _workspace(cache: dict[Path, Path], page: Path, factory: pytest.TempPathFactory) -> Path:
    if page not in cache:
        work = factory.mktemp(page.stem)
        for name in TREE:
            shutil.copytree(ROOT / name, work / name)
        (work / "assets").mkdir()
        cache[page] = work
    return cache[page]


def _env() -> dict[str, str]:
    bindir = str(Path(sys.executable).parent)
    return {
        **os.environ,
        "PATH": bindir + os.pathsep + os.environ.get("PATH", ""),
        "SDL_VIDEODRIVER": "dummy",
        "MPLBACKEND": "Agg",
    }


@pytest.mark.parametrize("example", EXAMPLES, ids=[e.id for e in EXAMPLES])
def test_the_example_runs(
    example: Example,
    workspaces: dict[Path, Path],
    tmp_path_factory: pytest.TempPathFactory,
) -> None:
    if example.skip:
        pytest.skip(f"marked not runnable: {example.skip}")
    work = _workspace(workspaces, example.page, tmp_path_factory)
    if example.lang == "python":
        runs = [[sys.executable, "-c", example.prepared(example.code)]]
    else:
        runs = [["bash", "-c", example.prepared(c)] for c in example.commands()]
        assert runs, f"{example.id}: a console block without a `$ ` command"
    for argv in runs:
        done = subprocess.run(
            argv, cwd=work, env=_env(), capture_output=True, text=True, timeout=900, check=False
        )
        assert done.returncode in example.exits, (
            f"{example.id}: {argv[-1][:200]!r} exited {done.returncode}\n"
            f"{done.stdout[-1500:]}\n{done.stderr[-3000:]}"
        )


def test_the_readme_and_the_manual_have_examples_of_each_interface() -> None:
    """The README shows the CLI, Python, Gymnasium and ROS; all but ROS run here."""
    readme = [e for e in EXAMPLES if e.page.name == "README.md"]
    code = "\n".join(e.code for e in readme)
    for needle in (
        "$ amsa-phys run",
        "import amsa_phys as ap",
        'gymnasium.make("amsa_phys/',
        "roslaunch",
    ):
        assert needle in code, needle
    assert sum(not e.skip for e in readme) >= 3  # all but ROS
    assert sum(not e.skip for e in EXAMPLES) >= 15


def test_commands_are_never_in_a_fence_the_test_does_not_run() -> None:
    """A command shown in a ``sh``/``bash``/bare fence would never be checked: such blocks
    must be ``console`` (run, or marked skip with a reason) or ``text`` (output)."""
    hidden = []
    for page in PAGES:
        for line, lang, body, _ in blocks(page):
            if lang in ("", "sh", "bash", "shell") and re.search(
                r"^\s*(\$ |amsa-phys |python |pip |roslaunch )", body, re.M
            ):
                hidden.append(f"{page.relative_to(ROOT)}:{line}")
    assert not hidden, f"commands outside a console block: {hidden}"


def test_a_docs_test_comment_is_read_exactly() -> None:
    ex = Example(ROOT / "README.md", 1, "console", "$ amsa-phys run a \\\n  --seed 2\nout\n$ ls\n")
    assert ex.commands() == ["amsa-phys run a \\\n  --seed 2", "ls"]
    _options(ex, 'sub "--seed 2" "--seed 3" exit 0,1')
    assert ex.subs == [("--seed 2", "--seed 3")]
    assert ex.exits == (0, 1)
    assert ex.prepared(ex.commands()[0]).endswith("--seed 3")
    with pytest.raises(ValueError, match="unknown docs-test option 'skp'"):
        _options(ex, "skp ROS")
    with pytest.raises(ValueError, match="needs a reason"):
        _options(ex, "skip")
