"""Each escaper of ``ros/quote.py`` against its own language's parser, with hostile payloads.

A value escaped for a string context must read back as exactly the value (XML through
ElementTree, YAML through PyYAML and through roslaunch's rosparam loader, CMake through
``cmake -P``, C++ through g++ and the program's own output, Python through ``ast``, a shell
word through ``sh``); a value escaped for a comment must leave the code around it exactly as
it was. Payloads include the issue's: newlines, quotes, ``\"\"\"``, ``--``, ``$(...)``,
``${...}``, ``!tag``, backticks, backslashes, YAML's other line breaks, C++ trigraphs.
"""

from __future__ import annotations

import ast
import json
import re
import shutil
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
import yaml

from amsa_phys.errors import ConfigError
from amsa_phys.ros import quote

PAYLOADS = {
    "yaml-tag": "x\npwn: !radians __import__('os').system('touch MARK')",
    "rad-resolver": "rad(__import__('os').system('touch MARK'))",
    "rad-expr": "rad(2*2)",
    "cmake-newline": 'x\nexecute_process(COMMAND touch MARK)\n# ")',
    "docstring": 'x"""\nimport os; os.system("touch MARK")\n"""',
    "dashdash": "a--b--",
    "subst": "$(eval __import__('os').system('touch MARK'))",
    "cmake-var": "${CMAKE_COMMAND} @PROJECT_NAME@ $ENV{HOME}",
    "tag": "!radians 1",
    "backtick": "`touch MARK`",
    "backslash-end": "a\\",
    "quotes": "'\"'''\"\"\"",
    "cr": "x\rpwn: 1",
    "nel-ls-ps": "x\x85pwn: 1\u2028q: 2\u2029r: 3",
    "trigraph": "??/\nint pwn;",
    "markup": "<!-- </launch> &amp; ]]> -->",
    "control": "a\x01\x1b[2Jb\tc",
    "unicode": "héllo wörld ✓",
    "semicolon": "a;b;c",
}
IDS = list(PAYLOADS)
VALUES = [PAYLOADS[k] for k in IDS]


def _xml_legal(text: str) -> str:
    """What XML 1.0 can carry of ``text`` (the escaper replaces the rest by ``?``)."""
    return "".join("?" if (ord(c) < 0x20 and c not in "\t\n\r") else c for c in text)


@pytest.mark.parametrize("value", VALUES, ids=IDS)
def test_xml_text_and_attribute_read_back_exactly(value: str) -> None:
    if "$(" in value:
        with pytest.raises(ConfigError, match=r"roslaunch would evaluate"):
            quote.xml_attr(value)
        attr = "x"
    else:
        attr = quote.xml_attr(value)
    elem = ET.fromstring(f'<a b="{attr}">{quote.xml_text(value)}</a>')
    assert elem.text == _xml_legal(value)
    if attr != "x":
        assert elem.get("b") == _xml_legal(value)


@pytest.mark.parametrize("value", VALUES, ids=IDS)
def test_xml_comment_never_ends_the_comment(value: str) -> None:
    text = f"<a><!-- {quote.xml_comment(value)} --><b/></a>"
    elem = ET.fromstring(text, parser=ET.XMLParser(target=ET.TreeBuilder(insert_comments=True)))
    assert [c.tag for c in elem] == [ET.Comment, "b"]


@pytest.mark.parametrize("value", VALUES, ids=IDS)
def test_yaml_scalar_comment_and_document_read_back_exactly(value: str) -> None:
    assert yaml.safe_load(f"k: {quote.yaml_scalar(value)}\n") == {"k": value}
    assert yaml.safe_load(f"k: 1 # {quote.yaml_comment(value)}\nj: 2\n") == {"k": 1, "j": 2}
    doc = {"k": value, "list": [value, 1.5], "ok": True}
    assert yaml.safe_load(quote.yaml_dump(doc)) == doc


ROSPARAM = Path("/usr/lib/python3/dist-packages/rosparam/__init__.py")


@pytest.mark.skipif(not ROSPARAM.exists(), reason="ROS 1's rosparam is not installed")
def test_rosparam_loader_reads_the_same_values_and_runs_nothing(tmp_path: Path) -> None:
    """roslaunch's loader (with its !radians/rad() resolvers) reads what PyYAML reads."""
    marker = tmp_path / "MARK"
    values = [v.replace("MARK", str(marker)) for v in VALUES]
    docs = [
        quote.yaml_dump({"k": v, "list": [v]})
        + f"c: 1  # {quote.yaml_comment(v)}\nd: {quote.yaml_scalar(v)}\n"
        for v in values
    ]
    code = (
        "import json, sys; sys.path.append('/usr/lib/python3/dist-packages'); import rosparam\n"
        "docs = json.load(sys.stdin)\n"
        "print(json.dumps([rosparam.load_str(d, 'test.yaml', default_namespace='/')[0][0]"
        " for d in docs]))\n"
    )
    done = subprocess.run(
        ["/usr/bin/python3", "-c", code], input=json.dumps(docs), capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr
    for got, v in zip(json.loads(done.stdout), values, strict=True):
        assert got == {"k": v, "list": [v], "c": 1, "d": v}
    assert not marker.exists()


@pytest.mark.skipif(shutil.which("cmake") is None, reason="cmake is not installed")
def test_cmake_argument_and_comment_read_back_exactly(tmp_path: Path) -> None:
    marker = tmp_path / "MARK"
    values = [v.replace("MARK", str(marker)) for v in VALUES]
    lines = ["cmake_minimum_required(VERSION 3.0)"]
    for i, v in enumerate(values):
        lines.append(f"# {quote.cmake_comment(v)}")
        lines.append(f'file(WRITE "{tmp_path}/{i}.txt" {quote.cmake_arg(v)})')
    script = tmp_path / "script.cmake"
    script.write_text("\n".join(lines) + "\n")
    done = subprocess.run(["cmake", "-P", str(script)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    for i, v in enumerate(values):
        # control characters other than tab, CR and LF are written as ? (never raw)
        legal = re.sub(r"[\x00-\x08\x0b\x0c\x0e-\x1f\x7f-\x9f\u2028\u2029]", "?", v)
        assert (tmp_path / f"{i}.txt").read_bytes() == legal.encode(), IDS[i]
    assert not marker.exists()


@pytest.mark.skipif(shutil.which("g++") is None, reason="g++ is not installed")
def test_cpp_string_and_comment_read_back_exactly(tmp_path: Path) -> None:
    """A program prints each literal; each comment is followed by a line that must survive."""
    lines = ["#include <cstdio>", "#include <cstring>"]
    for i, v in enumerate(VALUES):
        lines.append(f"// {quote.cpp_comment(v)}")
        lines.append(f"static const char* s{i} = {quote.cpp_string(v)};")
    lines.append("int main() {")
    lines.append(f"  const char* all[] = {{{', '.join(f's{i}' for i in range(len(VALUES)))}}};")
    lines.append("  for (const char* s : all) { fwrite(s, 1, strlen(s), stdout); putchar(0); }")
    lines.append("}")
    src = tmp_path / "t.cpp"
    src.write_text("\n".join(lines) + "\n")
    for std in ("-std=c++14", "-std=gnu++14"):  # trigraphs are on in strict ISO mode
        build = subprocess.run(
            ["g++", std, "-Wall", "-o", str(tmp_path / "t"), str(src)],
            capture_output=True,
            text=True,
        )
        assert build.returncode == 0, build.stderr
        out = subprocess.run([str(tmp_path / "t")], capture_output=True).stdout
        assert out.split(b"\0")[:-1] == [v.encode() for v in VALUES]


@pytest.mark.parametrize("value", VALUES, ids=IDS)
def test_python_string_docstring_and_comment_read_back_exactly(value: str) -> None:
    assert ast.literal_eval(quote.py_string(value)) == value
    module = ast.parse(f'"""{quote.py_doc(value)}"""\nx = 1  # {quote.py_comment(value)}\ny = 2\n')
    assert ast.get_docstring(module, clean=False) == value
    assert [type(s).__name__ for s in module.body] == ["Expr", "Assign", "Assign"]


@pytest.mark.parametrize("value", VALUES, ids=IDS)
def test_shell_word_is_one_word(value: str) -> None:
    done = subprocess.run(
        ["sh", "-c", f"printf %s {quote.sh_word(value)}"], capture_output=True, check=True
    )
    assert done.stdout == value.encode()


@pytest.mark.parametrize("value", VALUES, ids=IDS)
def test_markdown_code_and_text_stay_on_one_line(value: str) -> None:
    for text in (quote.md_code(value), quote.md_text(value)):
        assert "\n" not in text
        assert "\r" not in text
    assert quote.md_code(value).count("`") == 2


def test_fill_escapes_every_hole_and_takes_code_only_where_asked() -> None:
    text = quote.fill(
        "# @@{a:py_comment}\nx = @@{b:py_string}\n@@{c:code}",
        a="1\n2",
        b="'",
        c=quote.Code("y = 1"),
    )
    assert text == '# 1?2\nx = "\'"\ny = 1'
    with pytest.raises(TypeError, match="takes generated code"):
        quote.fill("@@{c:code}", c="import os")
    with pytest.raises(KeyError):
        quote.fill("@@{c:py_string}")
    with pytest.raises(KeyError, match="fill no hole"):
        quote.fill("x", c="y")


@pytest.mark.parametrize(
    "name", ["a'b", 'a"b', "a\\b", "a\nb", "a\x00b", "a\x85b", "a\u2028b", "a\u202eb", "a`b"]
)
def test_names_with_quotes_backslashes_or_control_characters_are_refused(name: str) -> None:
    with pytest.raises(ConfigError, match="may not hold quotes, backslashes or control"):
        quote.check_name(name, "the scenario's name")
    assert "\n" not in str(ConfigError("x", file=name))


@pytest.mark.parametrize("name", ["a--b", "$(x)", "${x}", "!radians", "rad(x)", "a b.yaml", "é"])
def test_other_names_pass_and_are_escaped_instead(name: str) -> None:
    quote.check_name(name, "the scenario's name")
