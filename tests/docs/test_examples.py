"""The examples under ``examples/`` run as a user would run them, so they cannot rot."""

from __future__ import annotations

import json
import os
import re
import tempfile
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parent.parent.parent
EXAMPLES = ROOT / "examples"
TEMPLATE_DIR = EXAMPLES / "user_template"


def test_the_api_tour_notebook_runs_cell_by_cell(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # no jupyter needed: the notebook is JSON; its code cells run in one namespace, in order,
    # from the notebook's folder (as Jupyter runs them)
    notebook = json.loads((EXAMPLES / "api_tour.ipynb").read_text())
    assert notebook["nbformat"] == 4
    cells = [c for c in notebook["cells"] if c["cell_type"] == "code"]
    assert len(cells) >= 5
    monkeypatch.chdir(EXAMPLES)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))  # its save() lands here
    import matplotlib.pyplot as plt

    namespace: dict[str, object] = {"__name__": "__main__"}
    for i, cell in enumerate(cells):
        source = "".join(cell["source"])
        assert not re.search(r"^\s*[%!]", source, re.MULTILINE), "no IPython magics"
        exec(compile(source, f"api_tour.ipynb cell {i}", "exec"), namespace)
    plt.close("all")
    assert namespace["best"] == 0.35  # the degraded context's best Kv (paper, Fig. 6)
    saved = namespace["out"]
    assert isinstance(saved, Path)
    assert (saved / "trace.csv").is_file()
    assert saved.parent.parent == tmp_path


@pytest.fixture
def template_importable(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.syspath_prepend(str(TEMPLATE_DIR))  # as PYTHONPATH=examples/user_template


@pytest.mark.usefixtures("template_importable")
def test_the_user_template_example_runs_and_its_derivative_term_damps(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "pd"
    argv = ["run", str(TEMPLATE_DIR / "scenario.yaml"), "--headless", "--out", str(out)]
    code = main([*argv, "--no-plot", "-q"])
    printed = capsys.readouterr()
    assert code == 0, printed.err  # both expectations hold: P alone oscillates, PD holds 15 m
    metrics = json.loads((out / "metrics.json").read_text())
    p_only, pd = metrics["phases"]
    assert p_only["rms_error"] > 2.0
    assert p_only["settling_time"] is None
    assert pd["settling_time"] < 30.0
    assert pd["final_distance"] == pytest.approx(15.0, abs=1.5)
    assert "MyFollowerController.LeftPower" in (out / "trace.csv").read_text().split("\n")[0]


@pytest.mark.usefixtures("template_importable")
def test_the_templates_step_many_agrees_with_do_step() -> None:
    from pd_follower import PDFollower  # type: ignore[import-not-found]

    from amsa_phys.engine.batch import ParamArrays

    params = [
        {"Kp": 0.35, "Kd": 0.5, "Kw": 0.04, "distanceRef": 15.0},
        {"Kp": 0.1, "Kd": 0.0, "Kw": 0.2, "distanceRef": 12.0},
        {"Kp": 1.0, "Kd": 2.0, "Kw": 0.0, "distanceRef": 20.0},
    ]
    comps = [PDFollower(f"Car{i}.Pilot", p) for i, p in enumerate(params, 1)]
    for c in comps:
        c.initialize(None)
    rng = np.random.default_rng(4)
    state: dict[str, object] = {}
    arrays = ParamArrays(comps)
    for step in range(12):
        t = Fraction(step, 4)
        inp = {port.name: rng.uniform(-20, 20, size=3) for port in PDFollower.inputs}
        inp["distanceLeaderFollower"] = rng.uniform(0, 30, size=3) * (step > 1)  # 0: unmeasured
        many, published = PDFollower.step_many(comps, t, inp, arrays, state)
        assert published is None
        for i, c in enumerate(comps):
            one = c.do_step(t, {k: float(v[i]) for k, v in inp.items()})
            for port, value in one.items():
                assert many[port][i] == pytest.approx(value, rel=1e-12, abs=1e-9)


def test_the_manual_shows_the_example_template_as_it_is() -> None:
    """The README or a page of the manual (docs/templates.md today) shows the file's code."""
    pages = [ROOT / "README.md", *(ROOT / "docs").rglob("*.md")]
    source = (TEMPLATE_DIR / "pd_follower.py").read_text()
    code = source.split('"""\n\n', 1)[1]  # the module without its docstring
    shown = [
        p.name
        for p in pages
        if "_incoming" not in p.parts and f"```python\n{code}```" in p.read_text()
    ]
    assert shown, "no page of the README or docs/ shows examples/user_template/pd_follower.py"


def test_a_template_without_a_valid_kind_lists_the_kinds(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "mine.py").write_text(
        "from amsa_phys import Port, Template\n\n"
        "class Pilot(Template):\n"
        "    kind = 'controler'\n"
        "    outputs = (Port('u'),)\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    world = tmp_path / "w.yaml"
    world.write_text("components:\n  P: {template: 'mine:Pilot'}\n")
    assert main(["validate", str(world)]) == 2
    err = capsys.readouterr().err
    assert err == (
        f"error: {world}:2: components.P.template: template 'mine:Pilot' declares no valid "
        "kind (got 'controler'); valid kinds: process, environment, sensor, actuator, "
        "controller, observer (e.g. kind = Kind.CONTROLLER, from amsa_phys import Kind)\n"
    )
    world.write_text("components:\n  P: {template: 'mine:Pilott'}\n")
    assert main(["validate", str(world)]) == 2
    assert "module 'mine' has no 'Pilott' (did you mean Pilot?)" in capsys.readouterr().err
    assert os.path.isfile(tmp_path / "mine.py")
