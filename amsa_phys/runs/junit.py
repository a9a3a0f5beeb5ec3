"""JUnit XML for CI systems: one testcase per expectation, one suite per scenario."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

from ..atomic import write_atomic
from .suite import ScenarioResult


def write_junit(results: list[ScenarioResult], path: Path) -> None:
    """Write ``path`` atomically."""
    root = ET.Element("testsuites", name="amsa-phys")
    for r in results:
        failures = sum(1 for c in r.checks if not c.passed)
        suite = ET.SubElement(
            root,
            "testsuite",
            name=r.name,
            file=r.path,
            tests=str(max(1, len(r.checks))),
            failures=str(failures),
            errors=str(int(r.error is not None)),
            time=f"{r.wall_s:.3f}",
        )
        if r.error is not None:
            case = ET.SubElement(suite, "testcase", classname=r.name, name="load and run")
            ET.SubElement(case, "error", message=r.error).text = r.error
            continue
        for c in r.checks:
            case = ET.SubElement(suite, "testcase", classname=r.name, name=c.what)
            if c.skipped:
                ET.SubElement(case, "skipped", message=c.describe())
            elif not c.passed:
                ET.SubElement(case, "failure", message=c.describe()).text = c.describe()
    tree = ET.ElementTree(root)
    ET.indent(tree)
    write_atomic(path, ET.tostring(root, encoding="unicode", xml_declaration=True) + "\n")
