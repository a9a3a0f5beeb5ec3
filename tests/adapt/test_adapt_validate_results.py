"""``adapt --validate --results FILE.json``: the table the docs show, with every seed's value.

The file is what docs/adaptation.md renders its validation table from, so it must hold the
numbers the command printed (the seed means are the means of the seeds written) and render
them as the docs show them; a results file without --validate is refused before any work.
"""

from __future__ import annotations

import json
import statistics
from pathlib import Path

from sweepfiles import two_context_sweep

from amsa_phys.adapt.validate import markdown
from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parents[2]
WORLD = str(ROOT / "worlds" / "mde_adaptive.yaml")


def _sweep(tmp_path: Path) -> tuple[Path, Path]:
    """A two-context sweep whose table says Kv 0.35 is best on worn motors."""
    return two_context_sweep(
        tmp_path,
        {("healthy", 0.2): 0.5, ("healthy", 0.35): 0.9, ("worn", 0.2): 0.9, ("worn", 0.35): 0.5},
    )


def test_results_hold_every_seed_and_render_the_printed_table(tmp_path, capsys) -> None:
    path, sweep = _sweep(tmp_path)
    results = tmp_path / "validate.json"
    argv = ["adapt", str(sweep), "--scenario", str(path), "-o", str(tmp_path / "r.yaml")]
    argv += ["--margin", "inf", "--validate", "--sequences", "1", "--seeds", "2"]
    main([*argv, "--duration", "120", "--results", str(results)])
    printed = capsys.readouterr().out.splitlines()
    doc = json.loads(results.read_text())
    assert doc["settings"]["seeds"] == 2
    assert doc["robust"] == {"MyFollowerController.Kv": 0.2}
    (row,) = doc["rows"]
    for way in ("robust", "oracle", "rules"):
        values = row["seeds"]["adaptive" if way == "rules" else way]
        assert len(values) == 2
        assert row[way] == statistics.fmean(values)
    # the printed row and the rendered one hold the same numbers
    line = next(x for x in printed if x.endswith(row["sequence"]))
    numbers = [cell.strip() for cell in line.split("|")][:3]
    table = markdown(doc).splitlines()
    assert table[0].startswith("| robust Kv 0.2 | oracle | rules |")
    assert [c.strip() for c in table[2].split("|")[1:4]] == numbers
    assert "--results" in table[-1]  # how to regenerate it


def test_results_without_validate_is_refused_before_any_work(tmp_path, capsys) -> None:
    path, sweep = _sweep(tmp_path)
    argv = ["adapt", str(sweep), "--scenario", str(path), "-o", str(tmp_path / "r.yaml")]
    assert main([*argv, "--results", str(tmp_path / "v.json")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert "--results" in err
    assert "--validate" in err
    assert not (tmp_path / "r.yaml").exists()
