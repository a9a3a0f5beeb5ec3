"""``amsa-phys import`` / ``export amsa``: the original AMSA files in and out.

The reference model of the paper imports to a world that validates and, once a scenario
supplies the values the model leaves empty, runs exactly like ``worlds/mde_challenge.yaml``;
every empty value is named in one warning line; exported files conform to the metamodel
(``amsaCore.ecore``, read here independently of the importer) and import back to the same
world. Bad input is one line, exit 2, and nothing written.
"""

from __future__ import annotations

import csv
import os
from pathlib import Path

import pytest

from amsa_phys.cli.main import main
from amsa_phys.interop.xmlsafe import Element, parse_file
from amsa_phys.model.world import WorldSpec, load_world

ROOT = Path(__file__).resolve().parent.parent.parent
# the original files are not shipped (no stated licence): AMSA_REFERENCE_DIR, else where the
# CI machines keep them, else beside the project as in this organisation's checkouts
REF = Path(os.environ.get("AMSA_REFERENCE_DIR", "/work/shared/reference/amsa"))
if not REF.is_dir():
    REF = ROOT.parent.parent / "shared" / "reference" / "amsa"
MODEL = REF / "mdeChallenge.amsacore"
ECORE = REF / "amsaCore.ecore"
needs_reference = pytest.mark.skipif(
    not MODEL.is_file(), reason="the original AMSA files are absent (set AMSA_REFERENCE_DIR)"
)

XSI = "{http://www.w3.org/2001/XMLSchema-instance}type"


def cli(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def world_key(world: WorldSpec) -> tuple[object, ...]:
    """Everything that makes a world run as it does (not its comments or key order)."""
    leaves = {
        p: (f.template_ref, f.freq, f.params, f.inputs, f.timing) for p, f in world.leaves.items()
    }
    return (
        world.name,
        leaves,
        world.order,
        world.schedule,
        world.physics,
        world.data_names,
        world.timing,
    )


# -- the reference model ------------------------------------------------------------------
@needs_reference
def test_reference_model_imports_with_every_empty_value_named(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "mde.yaml"
    code, stdout, err = cli(capsys, "import", str(MODEL), "-o", str(out))
    assert code == 0, err
    warnings = err.splitlines()
    assert all(w.startswith("warning: ") for w in warnings)
    expected = [
        "MyFollowerController.Kv is empty",
        "MyFollowerController.Kw is empty",
        "Leader.behavior is empty",
        "MyNormalizePower.motorCoef is 0 in the model",
        "MyNormalizePower has no frequency: the AMSA metamodel's default 10 Hz",
        "MyDistanceMonitor has no frequency",
        "Leader has no frequency",
        "start at the same place",
        "automatic scheduling",
    ]
    for text in expected:
        assert sum(text in w for w in warnings) == 1, text
    assert len(warnings) == len(expected)
    world = load_world(out)
    assert len(world.leaves) == 8
    assert world.leaves["MyNormalizePower"].freq == 10
    assert world.leaves["LeaderGPS"].freq == 4
    # the model's Data names are kept
    assert world.data_names["posXLeader"] == "Leader.posX"
    assert world.data_names["distanceFollowerLeader"] == (
        "MyDistanceMonitor.distanceFollowerToLeader"
    )
    assert len(world.data_names) == 15
    text = out.read_text()
    assert "Kv: 0.1  # empty in the model" in text
    assert "freq: 10  # not in the model" in text
    assert "8 components, 9 warnings" in stdout


@needs_reference
def test_imported_model_runs_like_the_projects_world(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Values the model leaves empty supplied by a scenario: the same trace, column by column."""
    imported = tmp_path / "imported.yaml"
    assert main(["import", str(MODEL), "-o", str(imported)]) == 0
    common = (
        "duration: 40\nseed: 3\n"
        "quality: {signal: MyDistanceMonitor.distanceFollowerToLeader, reference: 15}\n"
        "timeline:\n  - {at: 20, set: {MyFollowerController.Kv: 0.1}}\n"
        "  - {at: 30, set: {MyNormalizePower.motorCoef: 60, LeaderGPS.lostDataGPS: 20}}\n"
    )
    ours = tmp_path / "ours.yaml"
    ours.write_text(
        f"world: {ROOT / 'worlds' / 'mde_challenge.yaml'}\n{common}"
        "set: {Leader.behavior: 4, MyFollowerController.Kv: 0.35}\n"
    )
    # the sensors' noise model and the wheels' motor model are amsa-phys's own (the 2019
    # model's GPS has only lostDataGPS, its rovers no motor): the world ships realistic
    # noise and the challenge's fast rover, which a scenario of the imported model supplies too
    project, model = load_world(ROOT / "worlds" / "mde_challenge.yaml"), load_world(imported)
    noise = {
        f"{path}.{name}": value
        for path in ("LeaderGPS", "FollowerGPS", "FollowerCompass", "Leader", "Follower")
        for name, value in project.leaves[path].params.items()
        if value != model.leaves[path].params.get(name)
        and name not in ("lostDataGPS", "x", "behavior")
    }
    assert "LeaderGPS.stddev" in noise
    assert "Follower.stallForce" in noise
    # so is the loop timing: the 2019 model has no latency (its ROS nodes had one)
    noise["MyFollowerController.latency"] = project.leaves["MyFollowerController"].timing.latency
    assert noise["MyFollowerController.latency"] > 0
    theirs = tmp_path / "theirs.yaml"
    # and the floor the paper-calibrated rovers drive on (the model has no physics)
    ground = project.physics["ground"]
    theirs.write_text(
        f"world: {imported}\n{common}"
        f"physics: {{ground: {{rolling_resistance: {ground['rolling_resistance']!r}}}}}\n"
        "set: {Leader.behavior: 4, MyFollowerController.Kv: 0.35,\n"
        # the values the original model leaves empty
        "      Leader.x: 15.0, MyFollowerController.Kw: 0.04, MyNormalizePower.motorCoef: 100,\n"
        "      MyNormalizePower.freq: 4, MyDistanceMonitor.freq: 4, Leader.freq: 10,\n"
        + "".join(
            f"      {k}: {str(v) if k.endswith('latency') else repr(v)},\n"
            for k, v in noise.items()
        )
        + "}\n"
    )
    traces = []
    for name, scenario in (("a", ours), ("b", theirs)):
        out = tmp_path / name
        assert main(["run", str(scenario), "--headless", "--out", str(out), "-q", "--no-plot"]) == 0
        rows = list(csv.reader((out / "trace.csv").open()))
        traces.append({col: [r[i] for r in rows[1:]] for i, col in enumerate(rows[0])})
    assert set(traces[0]) == set(traces[1])
    for column in traces[0]:
        assert traces[0][column] == traces[1][column], column
    capsys.readouterr()


# -- export, round trip, metamodel -----------------------------------------------------------
NESTED = """
name: nested
description: a Composite inside the root, with named Data and loop timing
physics: {rate: 50, obstacles: [{type: circle, x: 30, y: 5, radius: 1}]}
timing: {free_running: true, resolution: 0.005}
data: {leaderX: Leader.posX, Team.fix: Team.Gps.gpsPosX}
components:
  Leader: {template: freeRobot, freq: 5, params: {behavior: 5, x: 10.0,
           waypoints: [[20, 0], [30, 10.5]]}}
  Team:
    components:
      Rover: {template: controlledRobot, freq: 4,
              inputs: {powerL: Drive.normalizedPowerL, powerR: Drive.normalizedPowerR}}
      Gps: {template: GPS, freq: 4, params: {noise: 0.25}, jitter: 0.1, phase: random,
            inputs: {posX: Leader.posX, posY: Leader.posY}}
      MyGps: {template: GPS, freq: 4, inputs: {posX: Rover.posX, posY: Rover.posY}}
      Compass: {template: Compass, freq: 4, inputs: {heading: Rover.heading}}
      Dist: {template: DistanceMonitor, freq: 4,
             inputs: {xLeader: Leader.posX, yLeader: Leader.posY,
                      xFollower: Rover.posX, yFollower: Rover.posY}}
      Pilot: {template: FollowerController, freq: 4, params: {Kv: 0.2}, latency: "1/3",
              inputs: {xLeader: Gps.gpsPosX, yLeader: Gps.gpsPosY, xFollower: MyGps.gpsPosX,
                       yFollower: MyGps.gpsPosY, headingFollower: Compass.compassHeading,
                       distanceLeaderFollower: Dist.distanceFollowerToLeader}}
      Drive: {template: NormalizePower, freq: 4, params: {motorCoef: 70}, phase: 0,
              inputs: {powerL: Pilot.LeftPower, powerR: Pilot.RightPower}}
schedule: [Team.Rover, Team.Drive, Team.Pilot, Team.MyGps, Team.Compass, Team.Dist]
"""


def _worlds(tmp_path: Path) -> list[Path]:
    nested = tmp_path / "nested.yaml"
    nested.write_text(NESTED)
    found = [ROOT / "worlds" / "mde_challenge.yaml", ROOT / "worlds" / "platoon.yaml", nested]
    return found


def test_export_amsa_imports_back_to_the_same_world(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    for i, path in enumerate(_worlds(tmp_path)):
        out = tmp_path / f"amsa{i}"
        code, _stdout, err = cli(capsys, "export", "amsa", str(path), "-o", str(out))
        assert code == 0, err
        world = load_world(path)
        core = out / f"{world.name}.amsacore"
        back = tmp_path / f"back{i}.yaml"
        code, _, err = cli(capsys, "import", str(core), "-o", str(back))
        assert code == 0, err
        assert err == ""  # amsa-phys wrote every value: nothing is left empty
        assert world_key(load_world(back)) == world_key(world), path.name


def _metamodel() -> dict[str, dict[str, object]]:
    """``amsaCore.ecore``: class -> abstract, supers, features (name -> kind, type, containment)."""
    root = parse_file(ECORE)
    classes: dict[str, dict[str, object]] = {}
    for c in root.children:
        if c.local != "eClassifiers":
            continue
        features = {}
        for f in c.children:
            if f.local == "eStructuralFeatures":
                kind = f.qname(f.get(XSI) or "").rpartition("}")[2]
                etype = (f.get("eType") or "").rpartition("//")[2]
                features[f.get("name")] = (kind, etype, f.get("containment") == "true")
        supers = [s.rpartition("//")[2] for s in (c.get("eSuperTypes") or "").split()]
        classes[c.get("name") or ""] = {
            "abstract": c.get("abstract") == "true",
            "supers": supers,
            "features": features,
        }
    return classes


def _all_features(classes: dict[str, dict[str, object]], name: str) -> dict[str, tuple]:
    out: dict[str, tuple] = {}
    for s in classes[name]["supers"]:  # type: ignore[union-attr]
        out.update(_all_features(classes, s))
    out.update(classes[name]["features"])  # type: ignore[arg-type]
    return out


def _conforms(classes: dict[str, dict[str, object]], sub: str, sup: str) -> bool:
    return sub == sup or any(_conforms(classes, s, sup) for s in classes[sub]["supers"])  # type: ignore[union-attr]


def metamodel_errors(path: Path) -> list[str]:
    """Every element, attribute and contained object of an .amsacore checked against the ecore."""
    classes = _metamodel()
    errors: list[str] = []

    def check(elem: Element, cls: str) -> None:
        if classes[cls]["abstract"]:
            errors.append(f"line {elem.line}: abstract class {cls} without xsi:type")
        features = _all_features(classes, cls)
        for attr in elem.attrib:
            if attr.startswith("{"):
                continue  # xmi:version, xsi:type, namespace declarations
            if attr not in features:
                errors.append(f"line {elem.line}: {cls} has no feature {attr!r}")
            elif features[attr][0] == "EReference" and features[attr][2]:
                errors.append(f"line {elem.line}: containment {attr!r} written as an attribute")
        for child in elem.children:
            if child.tag == "{http://www.omg.org/XMI}Extension":
                continue
            feature = features.get(child.local)
            if feature is None or feature[0] != "EReference":
                errors.append(f"line {child.line}: {cls} has no reference {child.local!r}")
                continue
            if not feature[2]:
                if child.get("href") is None:
                    errors.append(f"line {child.line}: cross-document {child.local} without href")
                continue
            xsi = child.get(XSI)
            sub = xsi.rpartition(":")[2] if xsi else feature[1]
            if sub not in classes or not _conforms(classes, sub, feature[1]):
                errors.append(f"line {child.line}: {sub} is not a {feature[1]}")
                continue
            check(child, sub)

    root = parse_file(path)
    if root.local != "AMSAFramework":
        return [f"root is {root.local}"]
    check(root, "AMSAFramework")
    return errors


@needs_reference
def test_exported_files_conform_to_the_metamodel(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert metamodel_errors(MODEL) == []  # the checker accepts the original tool's file
    for i, path in enumerate(_worlds(tmp_path)):
        out = tmp_path / f"amsa{i}"
        assert main(["export", "amsa", str(path), "-o", str(out)]) == 0
        core = next(out.glob("*.amsacore"))
        assert metamodel_errors(core) == [], path.name
        template = next(out.glob("*.amsatemplate")).read_text()
        assert "Template GPS {" in template
    # ... and refuses a feature the metamodel does not have
    bad = tmp_path / "bad.amsacore"
    bad.write_text(MODEL.read_text().replace('name="LeaderGPS" freq', 'name="LeaderGPS" rate'))
    assert any("no feature 'rate'" in e for e in metamodel_errors(bad))
    capsys.readouterr()


# -- bad input --------------------------------------------------------------------------------
def _reference_copy(tmp_path: Path, old: str = "", new: str = "") -> Path:
    (tmp_path / "mdeChallenge.amsatemplate").write_text(
        (REF / "mdeChallenge.amsatemplate").read_text()
    )
    path = tmp_path / "model.amsacore"
    text = MODEL.read_text()
    assert old in text
    path.write_text(text.replace(old, new, 1))
    return path


@needs_reference
@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        ("http://com.merconcept/AMSA", "http://example.org/x", "is not an AMSA model"),
        ("@data.9", "@data.99", "dangling reference '//@rootComponent/@data.99'"),
        ("@components.7/@outputs.0", "@components.7/@outputs.5", "there is no outputs number 5"),
        ("#GPS", "#Lidar", "unknown template 'Lidar'"),
        ('value="100.0"', 'value="lots"', "powerMax: expected a number"),
        ('name="lostDataGPS"', 'name="lostData"', "unknown parameter 'lostData'"),
        ('"FollowerCompass" freq="4.0"', '"FollowerCompass" freq="-4"', "freq must be > 0"),
        ("<?xml", '<!DOCTYPE x [<!ENTITY a "aaaa">]>\n<?xml', "DOCTYPE"),
        ("</AMSA:AMSAFramework>", "", "is not well-formed AMSA XMI"),
    ],
)
def test_bad_model_is_one_line_and_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], old: str, new: str, message: str
) -> None:
    model = _reference_copy(tmp_path, old, new)
    out = tmp_path / "world.yaml"
    code, _stdout, err = cli(capsys, "import", str(model), "-o", str(out))
    assert code == 2
    assert err.count("\n") == 1, err
    assert err.startswith("error: "), err
    assert message in err, err
    assert "model.amsacore" in err
    assert not out.exists()
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []


@needs_reference
def test_bad_templates_and_outputs(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    model = _reference_copy(tmp_path)
    templates = tmp_path / "mdeChallenge.amsatemplate"
    good = templates.read_text()
    templates.write_text(good.replace("output gpsPosX", "output gpsPosZ, gpsPosX"))
    code, _, err = cli(capsys, "import", str(model), "-o", str(tmp_path / "w.yaml"))
    assert code == 2
    assert "mdeChallenge.amsatemplate:" in err
    assert "has no output 'gpsPosZ'" in err
    templates.write_text(good.replace("int lostDataGPS;", "int lostDataGPS"))
    code, _, err = cli(capsys, "import", str(model), "-o", str(tmp_path / "w.yaml"))
    assert code == 2
    assert "mdeChallenge.amsatemplate:19: expected ';'" in err
    templates.write_text(good)
    # an existing output is kept unless --force
    out = tmp_path / "w.yaml"
    out.write_text("mine\n")
    code, _, err = cli(capsys, "import", str(model), "-o", str(out))
    assert code == 2
    assert "exists (use --force" in err
    assert out.read_text() == "mine\n"
    assert cli(capsys, "import", str(model), "-o", str(out), "--force")[0] == 0
    assert load_world(out).name == "mdeChallenge"
    # export amsa: a directory that exists and is not empty, without --force
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("keep\n")
    world = str(ROOT / "worlds" / "mde_challenge.yaml")
    code, _, err = cli(capsys, "export", "amsa", world, "-o", str(mine))
    assert code == 2
    assert "directory exists and was not made by amsa-phys" in err  # --force would not help
    code, _, err = cli(capsys, "export", "amsa", world, "-o", str(mine), "--force")
    assert code == 2
    assert "not made by amsa-phys" in err
    assert sorted(p.name for p in mine.iterdir()) == ["notes.txt"]
