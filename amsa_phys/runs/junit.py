"""JUnit XML for CI systems: one testcase per expectation, one suite per scenario.

Each test case is named by its check and bound (``max_distance (phase 1) below 26``), its
class is the scenario file's path (two scenarios may share a name, never a path), and every
case records the measured value as a property (a pass also as ``system-out``), so a CI's
history shows how close a passing check came to its bound.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

from ..atomic import write_atomic
from ..errors import one_line
from .suite import ScenarioResult

#: The report's root name: ``test --junit`` replaces only a file whose root says it
#: (``runs/outfile.py``, :func:`~amsa_phys.runs.outfile.junit_by_us`)
SUITE_NAME = "amsa-phys"


def write_junit(results: list[ScenarioResult], path: Path) -> None:
    """Write ``path`` atomically."""
    root = ET.Element("testsuites", name=SUITE_NAME)
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
            case = ET.SubElement(suite, "testcase", classname=r.path, name="load and run")
            ET.SubElement(case, "error", message=r.error).text = r.error
            continue
        for c in r.checks:
            # the bound is part of the name: two checks on one metric (below 26, above 2)
            # are two distinct test cases in a CI's history
            case = ET.SubElement(suite, "testcase", classname=r.path, name=f"{c.what} {c.bound}")
            props = ET.SubElement(case, "properties")
            value = "none" if c.value is None else repr(c.value)
            ET.SubElement(props, "property", name="measured", value=value)
            ET.SubElement(props, "property", name="bound", value=c.bound)
            if c.skipped:
                ET.SubElement(case, "skipped", message=c.describe())
            elif not c.passed:
                ET.SubElement(case, "failure", message=c.describe()).text = c.describe()
            else:  # a pass records what was measured too, not only that it passed
                ET.SubElement(case, "system-out").text = c.describe()
    for element in root.iter():  # names, paths and messages are the user's: see _xml_safe
        element.attrib = {k: _xml_safe(v) for k, v in element.attrib.items()}
        if element.text is not None:
            element.text = _xml_safe(element.text)
    tree = ET.ElementTree(root)
    ET.indent(tree)
    write_atomic(path, ET.tostring(root, encoding="unicode", xml_declaration=True) + "\n")


def _xml_safe(text: str) -> str:
    """``text`` shown as the terminal shows it (``\\x01``, ``\\udcff``): ElementTree writes
    control characters as they are, which XML 1.0 forbids (a scenario named ``a\\x01b`` made
    a report no CI could parse), and a file name that is not UTF-8 could not be encoded."""
    return one_line(text)
