"""``amsa-phys import`` against hostile models (issue 33 items 3-6).

A model never makes import run code (a module it names is imported only when the user names
it on the command line); a file that is not a regular file is refused at once; a huge or
wrong file is refused by a bound on what is built (root judged on its start tag, at most
:data:`MAX_ELEMENTS` elements and :data:`MAX_NAMESPACES` namespace declarations), and
resolving references is linear (asserted by counting the children the resolver indexes,
never by timing); names that a world cannot hold are refused with the model's line, and an
imported world that does not load is reported against the model, not a removed temp file.
Memory is asserted on each import in a fresh process (its own peak resident size), which
does not depend on speed.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from amsa_phys.cli.main import main
from amsa_phys.interop import amsacore
from amsa_phys.interop.xmlsafe import MAX_BYTES, MAX_ELEMENTS, MAX_NAMESPACES

ROOT = Path(__file__).resolve().parent.parent.parent
WORLD = ROOT / "worlds" / "mde_challenge.yaml"
#: Peak memory any import may reach (the issue's bound).
MEMORY_BOUND_MB = 300
OUTPUT = "//@rootComponent/@components.0/@outputs.0"


@pytest.fixture(scope="module")
def exported(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The MDE challenge as AMSA files (``mdeChallenge.amsacore`` and ``.amsatemplate``)."""
    out = tmp_path_factory.mktemp("amsa") / "files"
    assert main(["export", "amsa", str(WORLD), "-o", str(out)]) == 0
    return out


def _model(exported: Path, tmp: Path, edit: callable, name: str = "m.amsacore") -> Path:  # type: ignore[valid-type]
    text = (exported / "mdeChallenge.amsacore").read_text()
    path = tmp / name
    path.write_text(edit(text))
    return path


def _import(model: Path, exported: Path, out: Path, *extra: str) -> int:
    templates = str(exported / "mdeChallenge.amsatemplate")
    return main(["import", str(model), "--templates", templates, "-o", str(out), *extra])


def _insert_data(text: str, n: int) -> str:
    extra = "".join(
        f'    <data name="d{i}" source="//@rootComponent/@components.0/@outputs.0"/>\n'
        for i in range(n)
    )
    at = text.index("    <components")
    return text[:at] + extra + text[at:]


# -- item 3: no code a file names ------------------------------------------------------------


def test_a_module_the_model_names_is_never_imported_unless_the_user_names_it(
    exported: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    marker = tmp_path / "MARK"
    (tmp_path / "evil_templates.py").write_text(
        f"open({str(marker)!r}, 'w').close()\nfrom amsa_phys.sensors.gps import GPS\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    model = _model(
        exported,
        tmp_path,
        lambda t: t.replace(
            '<xmi:Extension extender="amsa-phys">',
            '<xmi:Extension extender="amsa-phys">\n'
            '    <template name="GPS" implementation="evil_templates:GPS"/>',
        ),
    )
    assert _import(model, exported, tmp_path / "w.yaml") == 2
    err = capsys.readouterr().err
    assert "template GPS is implemented by 'evil_templates:GPS', Python code the model names" in err
    assert "give --template-module evil_templates" in err
    assert not marker.exists()
    assert "evil_templates" not in sys.modules
    assert not (tmp_path / "w.yaml").exists()
    # the user who trusts it says so: then (and only then) it is imported
    args = ["--template-module", "evil_templates"]
    try:
        assert _import(model, exported, tmp_path / "w.yaml", *args) == 0
    finally:
        sys.modules.pop("evil_templates", None)
    assert marker.exists()
    assert 'template: "evil_templates:GPS"' in (tmp_path / "w.yaml").read_text()


# -- item 4: bounded parse, linear resolution ------------------------------------------------


def test_a_wrong_root_is_refused_on_its_start_tag(
    tmp_path: Path, exported: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The rest of the file is not even parsed: broken XML after the root does not matter."""
    model = tmp_path / "m.amsacore"
    model.write_bytes(b"<a>" + b"<b/>" * 100_000 + b"<<<< not XML")
    assert _import(model, exported, tmp_path / "w.yaml") == 2
    err = capsys.readouterr().err
    assert "m.amsacore:1: is not an AMSA model: the root element is a, expected" in err


def test_too_many_elements_or_namespaces_are_refused(
    tmp_path: Path, exported: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    def children(t: str) -> str:
        at = t.index("\n", t.index("<rootComponent")) + 1
        return t[:at] + "<a/>" * MAX_ELEMENTS + t[at:]

    model = _model(exported, tmp_path, children)
    assert _import(model, exported, tmp_path / "w.yaml") == 2
    assert f"has more than {MAX_ELEMENTS} elements" in capsys.readouterr().err

    spaces = " ".join(f'xmlns:p{i}="urn:x{i}"' for i in range(MAX_NAMESPACES + 1))
    model = _model(
        exported,
        tmp_path,
        lambda t: t.replace("<AMSA:AMSAFramework ", f"<AMSA:AMSAFramework {spaces} ", 1),
    )
    assert _import(model, exported, tmp_path / "w.yaml") == 2
    assert f"declares more than {MAX_NAMESPACES} namespaces" in capsys.readouterr().err


def test_resolving_references_visits_each_element_a_bounded_number_of_times(
    tmp_path: Path, exported: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Issue: 20,000 Data took 41.7 s (each reference rescanned the root's children). Every
    walk over an element's children is counted: the total is a small multiple of the
    elements (quadratic resolution would be ~n x n = 4,000,000 here)."""
    n = 2000
    model = _model(exported, tmp_path, lambda t: _insert_data(t, n))
    visited = [0]

    class Counting(list):  # type: ignore[type-arg]
        def __iter__(self):  # type: ignore[no-untyped-def]
            visited[0] += len(self)
            return super().__iter__()

    def counted(elem: amsacore.Element) -> amsacore.Element:
        elem.children = Counting(counted(c) for c in elem.children)
        return elem

    real = amsacore.parse_file
    monkeypatch.setattr(amsacore, "parse_file", lambda *a: counted(real(*a)))
    read = amsacore.read_model(model)
    assert len(read.data) == n + 15
    elements = model.read_text().count("<") - 1  # the XML declaration
    assert visited[0] <= 6 * elements


#: ``amsa-phys import`` in a fresh process that reports its own peak resident size (KiB).
#: VmHWM is this process image's own high-water mark (``ru_maxrss`` survives ``exec`` on
#: Linux: a child of a big pytest process would report pytest's size).
_MEASURED = (
    "import sys\n"
    "from amsa_phys.cli.main import main\n"
    "code = main(sys.argv[1:])\n"
    "hwm = [ln for ln in open('/proc/self/status') if ln.startswith('VmHWM:')]\n"
    "print('peak', hwm[0].split()[1], file=sys.stderr)\n"
    "sys.exit(code)\n"
)


def _import_peak_mb(args: list[str]) -> tuple[int, str, float]:
    """Exit code, stderr and peak memory (MiB) of ``amsa-phys import ARGS`` on its own."""
    done = subprocess.run(
        [sys.executable, "-c", _MEASURED, "import", *args],
        capture_output=True,
        text=True,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )
    peak = [ln for ln in done.stderr.splitlines() if ln.startswith("peak ")]
    assert peak, done.stderr
    return done.returncode, done.stderr, int(peak[-1].split()[1]) / 1024


@pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="needs Linux's /proc")
def test_files_under_the_size_cap_stay_under_the_memory_bound(
    tmp_path: Path, exported: Path
) -> None:
    """The issue's files: 5,000 namespaces on the root and 100,000 children (was 9.96 GiB),
    an 18.8 MB file of ``<a/>`` (was 2.4 GiB), a valid root with 16 MB of children, and the
    largest valid model the element cap allows (Data elements, each a reference)."""
    text = (exported / "mdeChallenge.amsacore").read_text()
    at = text.index("\n", text.index("<rootComponent")) + 1
    spaces = " ".join(f'xmlns:p{i}="urn:x{i}"' for i in range(5000))
    cases = {
        "namespaces": text[:at].replace("<AMSA:AMSAFramework ", f"<AMSA:AMSAFramework {spaces} ")
        + "<a/>" * 100_000
        + text[at:],
        "wrong-root": "<a>" + "<a/>" * 4_700_000 + "</a>",
        "children": text[:at] + "<a/>" * 4_000_000 + text[at:],
        "data": _insert_data(text, MAX_ELEMENTS - text.count("<") - 10),
    }
    templates = str(exported / "mdeChallenge.amsatemplate")
    for name, body in cases.items():
        model = tmp_path / f"{name}.amsacore"
        model.write_text(body)
        assert model.stat().st_size <= MAX_BYTES, name
        code, err, peak_mb = _import_peak_mb(
            [str(model), "--templates", templates, "-o", str(tmp_path / f"{name}.yaml")]
        )
        assert code == (0 if name == "data" else 2), (name, err)
        assert "Traceback" not in err
        assert peak_mb < MEMORY_BOUND_MB, (name, peak_mb)


# -- item 5: only regular files --------------------------------------------------------------


@pytest.mark.parametrize("which", ["model", "templates"])
def test_devices_and_fifos_are_refused_without_reading(
    tmp_path: Path, exported: Path, capsys: pytest.CaptureFixture[str], which: str
) -> None:
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)  # nobody writes to it: reading would block forever
    good_model = exported / "mdeChallenge.amsacore"
    good_templates = exported / "mdeChallenge.amsatemplate"
    for bad, kind in ((Path("/dev/zero"), "device"), (fifo, "FIFO")):
        model, templates = (bad, good_templates) if which == "model" else (good_model, bad)
        argv = ["import", str(model), "--templates", str(templates), "-o", str(tmp_path / "w.yaml")]
        assert main(argv) == 2
        assert f"{bad}: is not a regular file (a {kind})" in capsys.readouterr().err


# -- item 6: names into YAML -----------------------------------------------------------------


@pytest.mark.parametrize(
    ("old", "new", "what"),
    [
        (
            '<data name="',
            f'<data name="x&#10;pwn: 1" source="{OUTPUT}"/>\n    <data name="',
            "a Data",
        ),
        ('name="LeaderGPS"', 'name="Leader&quot;GPS"', "a LeafComponent"),
        ('name="LeaderGPS"', 'name="a: {b: 1}"', "a LeafComponent"),
    ],
    ids=["data-newline", "component-quote", "component-flow"],
)
def test_names_a_world_cannot_hold_are_refused_with_the_models_line(
    tmp_path: Path,
    exported: Path,
    capsys: pytest.CaptureFixture[str],
    old: str,
    new: str,
    what: str,
) -> None:
    model = _model(exported, tmp_path, lambda t: t.replace(old, new, 1))
    assert _import(model, exported, tmp_path / "w.yaml") == 2
    err = capsys.readouterr().err
    assert err.startswith(f"error: {model}:")
    assert f"{what} is named" in err
    assert "amsa-phys names are a letter or _, then letters, digits and _" in err
    assert err.count("\n") == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.amsacore"]


def test_a_world_that_does_not_load_is_reported_against_the_model(
    tmp_path: Path, exported: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A value amsa-phys's loader refuses (a physics setting out of range): the message names
    the model and what the world would say, never the temporary file (removed)."""
    model = _model(exported, tmp_path, lambda t: t.replace('"rate": 100', '"rate": -5', 1))
    assert _import(model, exported, tmp_path / "w.yaml") == 2
    err = capsys.readouterr().err
    assert err.startswith(f"error: {model}: the world it imports to does not load (line ")
    assert "of the world w.yaml: physics.rate" in err
    assert ".tmp-" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.amsacore"]


def test_a_world_extension_nested_too_deeply_is_one_line(
    exported: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The amsa-phys extension's world is JSON inside an attribute: 100,000 nested arrays
    (200 KB) were a RecursionError traceback; now one line naming the model's line."""
    deep = "[" * 100_000 + "]" * 100_000
    model = _model(
        exported,
        tmp_path,
        lambda t: t.replace(
            '<xmi:Extension extender="amsa-phys">',
            f'<xmi:Extension extender="amsa-phys">\n    <world json="{deep}"/>',
        ),
    )
    assert _import(model, exported, tmp_path / "w.yaml") == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err
    assert "nested too deeply" in err
    assert not (tmp_path / "w.yaml").exists()
