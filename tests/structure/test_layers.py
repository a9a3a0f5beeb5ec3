"""The package's structure (issue 32), checked on the source, not by convention.

* imports flow one way: model -> engine -> physics|sensors|control|interop -> plots|view -> runs
  -> ros -> cli|api -> gym, relative imports of any depth resolved;
* no import circle, inside a package included, an import inside a function counted (it
  only hides the circle until the function runs); ``if TYPE_CHECKING:`` imports excepted;
* nothing points back up to the package root (``amsa_phys/__init__.py``, ``__main__``), and
  the root's own modules (``errors``, ``_version``, ...) import only each other;
* no module imports another module's private name (``from .x import _y``): join the two
  modules or publish the name;
* no production module writes another module's globals or patches another module's class
  (``batch.ENABLED = ...``, ``PhysicsWorld.step = ...``): such a write changes every user of
  that module, in whatever order the imports ran;
* no module over 500 lines but generated code.

Each check is a function of a package directory, so the tests below also run it on a scratch
copy of the package with one bad line added and see it fail (the mutation check).
"""

from __future__ import annotations

import ast
import functools
import shutil
from pathlib import Path

import pytest

PKG = Path(__file__).resolve().parent.parent.parent / "amsa_phys"
LAYER = {
    "stl": -1,  # STL syntax and monitor: numpy and text only, read by the loader and engine
    "model": 0,
    "requirements": 0.5,  # objective names (metrics, robustness.NAME) and their sense
    "engine": 1,
    "physics": 2,
    "sensors": 2,
    "control": 2,
    "interop": 2,
    "plots": 3,
    "view": 3,
    "runs": 4,
    "stdmsgs": 4.5,  # the standard ROS messages of a world: model only, for ros/ and bag/
    "adapt": 5,
    "ros": 5,
    "bag": 5.5,  # a run as an MCAP bag: engine, stdmsgs; used by cli/ and api/
    "falsify": 5,
    "cli": 6,
    "api": 6,
    "gym": 7,
    # robust tuning: runs over contexts (runs), below adapt, which falls back on its answer
    "tune": 4.8,
}
MODULES = sorted(p for p in PKG.rglob("*.py") if p.parent != PKG)


def module_name(path: Path, pkg: Path = PKG) -> str:
    """``amsa_phys.ros.runtime.leaf`` for ``amsa_phys/ros/runtime/leaf.py`` (a package's
    ``__init__.py`` is the package)."""
    parts = list(path.relative_to(pkg.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def known_modules(pkg: Path = PKG) -> set[str]:
    """Every module of the package under ``pkg``, by dotted name."""
    return {module_name(p, pkg) for p in pkg.rglob("*.py")}


KNOWN = known_modules()


@functools.cache
def parse(source: str) -> ast.Module:
    """The module's tree, parsed once per text (the scratch copies repeat the package's)."""
    return ast.parse(source)


def imports_of(
    path: Path,
    source: str | None = None,
    top_level: bool = False,
    pkg: Path = PKG,
    known: set[str] | None = None,
    typing: bool = True,
) -> set[str]:
    """The ``amsa_phys`` modules ``path`` imports, relative imports of any depth resolved
    (``from ...engine import x`` in ``ros/runtime/``), ``from pkg import module`` as the
    module. ``top_level``: only imports run when the module loads (not those inside
    functions, nor under ``if TYPE_CHECKING:``); ``typing=False``: every import that runs,
    late ones included, none under ``if TYPE_CHECKING:`` — the ones that make a circle."""
    known = KNOWN if known is None else known
    tree = parse(path.read_text() if source is None else source)
    me = module_name(path, pkg)
    package = me if path.name == "__init__.py" else me.rpartition(".")[0]
    nodes: list[ast.AST] = []

    def collect(body: list[ast.stmt]) -> None:
        for node in body:
            if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
                continue
            nodes.append(node)
            for field in ("body", "orelse", "finalbody"):
                # a class body and a with block run when the module loads, as an if does
                if isinstance(node, ast.If | ast.Try | ast.With | ast.ClassDef) and hasattr(
                    node, field
                ):
                    collect(getattr(node, field))
            for handler in getattr(node, "handlers", []):
                collect(handler.body)

    if top_level:
        collect(tree.body)
    elif typing:
        nodes = list(ast.walk(tree))
    else:
        hidden = {
            id(inner)
            for node in ast.walk(tree)
            if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test)
            for inner in ast.walk(node)
        }
        nodes = [node for node in ast.walk(tree) if id(node) not in hidden]
    found = set()
    for node in nodes:
        if isinstance(node, ast.Import):
            found |= {a.name for a in node.names if a.name.startswith("amsa_phys")}
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - (node.level - 1)]
                full = ".".join([*base, *([node.module] if node.module else [])])
            else:
                full = node.module or ""
            if full == "amsa_phys" or full.startswith("amsa_phys."):
                for alias in node.names:
                    sub = f"{full}.{alias.name}"
                    found.add(sub if sub in known else full)
    return found - {me}


def imported_packages(path: Path, pkg: Path = PKG, known: set[str] | None = None) -> set[str]:
    """The layers (``model``, ``engine``, ...) ``path`` imports from."""
    found = imports_of(path, pkg=pkg, known=known)
    return {m.split(".")[1] for m in found if m.count(".") >= 1} & set(LAYER)


def layer_problems(path: Path, pkg: Path = PKG, known: set[str] | None = None) -> list[str]:
    """``path``'s imports of a layer above its own or beside it, as ``file imports layer``."""
    own = path.relative_to(pkg).parts[0]
    return [
        f"{path.relative_to(pkg)} imports {other}"
        for other in sorted(imported_packages(path, pkg, known) - {own})
        if not LAYER[other] < LAYER[own]
    ]


@pytest.mark.parametrize("path", MODULES, ids=[str(p.relative_to(PKG)) for p in MODULES])
def test_no_upward_or_sideways_imports(path: Path) -> None:
    assert layer_problems(path) == []


def test_relative_imports_of_any_depth_are_seen() -> None:
    """A three-dot import from ``ros/runtime`` names its layer (the old check missed it)."""
    path = PKG / "ros" / "runtime" / "leaf.py"
    code = "from ...engine.runner import Simulation\nfrom ..graph import x\nfrom . import rosio\n"
    assert imports_of(path, code) == {
        "amsa_phys.engine.runner",
        "amsa_phys.ros.graph",
        "amsa_phys.ros.runtime.rosio",
    }
    assert imported_packages(path) >= {"ros"}
    sideways = PKG / "engine" / "x.py"
    assert {m.split(".")[1] for m in imports_of(sideways, "from ..runs import sweep\n")} == {"runs"}


def circles(pkg: Path = PKG) -> list[list[str]]:
    """Groups of modules that import each other, at load or later (Tarjan's components)."""
    known = known_modules(pkg)
    graph = {
        module_name(p, pkg): imports_of(p, pkg=pkg, known=known, typing=False) & known
        for p in pkg.rglob("*.py")
    }
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    out: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            group = []
            while True:
                w = stack.pop()
                group.append(w)
                if w == v:
                    break
            if len(group) > 1:
                out.append(sorted(group))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def test_no_import_circles_even_inside_a_package() -> None:
    assert circles() == []


#: the package root: what nothing inside the package may import
ROOT_PACKAGE = {"amsa_phys", "amsa_phys.__main__"}


def root_problems(pkg: Path = PKG, known: set[str] | None = None) -> list[str]:
    """Arrows back up to the package root, and root modules importing from the layers."""
    known = known_modules(pkg) if known is None else known
    roots = {module_name(p, pkg) for p in pkg.glob("*.py")} - ROOT_PACKAGE
    out = []
    for path in sorted(pkg.rglob("*.py")):
        me = module_name(path, pkg)
        if me in ROOT_PACKAGE:
            continue
        found = imports_of(path, pkg=pkg, known=known, typing=False)
        out += [f"{path.relative_to(pkg)} imports {m}" for m in sorted(found & ROOT_PACKAGE)]
        if me in roots:
            out += [f"{path.relative_to(pkg)} imports {m}" for m in sorted(found - roots)]
    return out


def test_nothing_points_back_up_to_the_package_root() -> None:
    assert root_problems() == []


def private_imports(pkg: Path = PKG) -> list[str]:
    """``from .x import _y``: a private name of one module imported by another (a private
    module, ``from . import _step``, is a module, not a name, and is not counted)."""
    known = known_modules(pkg)
    out = []
    for path in sorted(pkg.rglob("*.py")):
        me = module_name(path, pkg)
        package = me if path.name == "__init__.py" else me.rpartition(".")[0]
        for node in ast.walk(parse(path.read_text())):
            if not isinstance(node, ast.ImportFrom):
                continue
            if node.level:
                base = package.split(".")[: len(package.split(".")) - (node.level - 1)]
                full = ".".join([*base, *([node.module] if node.module else [])])
            else:
                full = node.module or ""
            if full != "amsa_phys" and not full.startswith("amsa_phys."):
                continue
            for alias in node.names:
                private = alias.name.startswith("_") and not alias.name.startswith("__")
                # ``from . import _step``: a module of the package (here a C extension)
                module = f"{full}.{alias.name}" in known or (node.level and not node.module)
                if private and not module:
                    out.append(f"{path.relative_to(pkg)}:{node.lineno} imports {alias.name}")
    return out


def test_no_module_imports_another_modules_private_name() -> None:
    assert private_imports() == []


def test_only_physics_imports_pymunk() -> None:
    for path in PKG.rglob("*.py"):
        tree = parse(path.read_text())
        names = {
            a.name.split(".")[0]
            for n in ast.walk(tree)
            if isinstance(n, ast.Import)
            for a in n.names
        }
        names |= {
            n.module.split(".")[0]
            for n in ast.walk(tree)
            if isinstance(n, ast.ImportFrom) and n.module and n.level == 0
        }
        if "pymunk" in names:
            assert path.relative_to(PKG).parts[0] == "physics", path


# -- writes into other modules ------------------------------------------------------------------
#: Methods that change a container in place: ``mod.TABLE.update(...)`` writes mod's global.
MUTATORS = frozenset(
    {
        "append",
        "extend",
        "insert",
        "update",
        "setdefault",
        "pop",
        "popitem",
        "clear",
        "remove",
        "add",
        "discard",
        "__setitem__",
        "__delitem__",
    }
)
#: The interpreter's own documented hooks, each written by one module for a stated reason.
ALLOWED_WRITES = {
    # configures SDL before pygame loads (the only pygame importer): the process environment
    ("view/pg.py", "os.environ"),
    # Gymnasium registration when Gymnasium is imported later: an import hook is the API
    ("gymreg.py", "sys.meta_path"),
    ("gymreg.py", "sys.meta_path[:]"),
    # Debian's rospy lives outside the venv; appended after it, only if rospy is missing
    ("ros/runtime/rosio.py", "sys.path"),
    # the CLI entry point: one BLAS thread unless the user chose, before numpy is imported
    ("cli/main.py", "os.environ"),
    # its own module: importing the package binds amsa_phys.falsify, the public function's
    # name, so the package is made callable as that function
    ("falsify/__init__.py", "sys.modules[__name__].__class__"),
    # a sweep's ROS 2 lane runs in a pool worker of its own: its process's domain, read when
    # each run's bridge starts (the parent's environment is never touched)
    ("runs/sweep.py", "os.environ['ROS_DOMAIN_ID']"),
}


def _root(node: ast.expr) -> str | None:
    while isinstance(node, ast.Attribute | ast.Subscript):
        node = node.value
    return node.id if isinstance(node, ast.Name) else None


@functools.cache
def foreign_writes(source: str) -> tuple[tuple[int, str], ...]:
    """``(line, target)`` of each write into a name the module imported: an assignment,
    augmented assignment or ``del`` of an attribute or item (``batch.ENABLED = False``,
    ``PhysicsWorld.step = f``), ``setattr``/``delattr``/``object.__setattr__`` on it, or an
    in-place change of a container it holds (``registry.TABLE.update(...)``).

    Imported names are the modules and classes of other modules: writing into them changes
    every importer (tests do it with ``monkeypatch``, which restores it). A module's own
    globals (``global _cached``) are its own business.
    """
    tree = parse(source)
    imported = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            imported |= {a.asname or a.name.split(".")[0] for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            imported |= {a.asname or a.name for a in node.names}
    found = []

    def hit(node: ast.AST, target: ast.expr) -> None:
        if _root(target) in imported:
            found.append((getattr(node, "lineno", 0), ast.unparse(target)))

    for node in ast.walk(tree):
        targets: list[ast.expr] = []
        if isinstance(node, ast.Assign | ast.Delete):
            targets = list(node.targets)
        elif isinstance(node, ast.AugAssign | ast.AnnAssign):
            targets = [node.target]
        for target in targets:
            parts = target.elts if isinstance(target, ast.Tuple | ast.List) else [target]
            for part in parts:
                if isinstance(part, ast.Attribute | ast.Subscript):
                    hit(node, part)
        if isinstance(node, ast.Call) and node.args:
            name = ast.unparse(node.func).rpartition(".")[2]
            if name in {"setattr", "delattr", "__setattr__", "__delattr__"}:
                hit(node, node.args[0])
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute):
            holder = node.func.value
            if node.func.attr in MUTATORS and isinstance(holder, ast.Attribute | ast.Subscript):
                hit(node, holder)
    return tuple(found)


def write_problems(pkg: Path = PKG) -> list[str]:
    """Every write into another module's globals or classes, as ``file:line target``."""
    out = []
    for path in sorted(pkg.rglob("*.py")):
        rel = path.relative_to(pkg).as_posix()
        for line, target in foreign_writes(path.read_text()):
            if (rel, target) not in ALLOWED_WRITES:
                out.append(f"{rel}:{line} writes {target}")
    return out


def test_no_module_writes_another_modules_globals_or_patches_its_classes() -> None:
    assert write_problems() == []


def test_each_allowed_write_is_still_there() -> None:
    """An allowance whose write went away is removed, so it cannot excuse a new one."""
    seen = {
        (path.relative_to(PKG).as_posix(), target)
        for path in PKG.rglob("*.py")
        for _, target in foreign_writes(path.read_text())
    }
    assert seen >= ALLOWED_WRITES


# -- module size --------------------------------------------------------------------------------
MAX_LINES = 500
#: Generated code (``model/shapegen.py`` writes the schema validators) may be longer.
GENERATED = ("model/shapes/",)
#: Modules still over the limit, each with the work that splits it. An entry fails once its
#: module is short enough, so the exemption goes with the split.
PENDING: dict[str, str] = {}  # module -> why it may stay long for now (none)


def long_modules(pkg: Path = PKG) -> dict[str, int]:
    """Modules over :data:`MAX_LINES` lines, generated ones left out."""
    out = {}
    for path in sorted(pkg.rglob("*.py")):
        rel = path.relative_to(pkg).as_posix()
        lines = len(path.read_text().splitlines())
        if lines > MAX_LINES and not rel.startswith(GENERATED):
            out[rel] = lines
    return out


def test_no_module_over_500_lines_but_generated_code() -> None:
    long = long_modules()
    assert {k: v for k, v in long.items() if k not in PENDING} == {}
    assert set(PENDING) <= set(long), f"split: remove {set(PENDING) - set(long)} from PENDING"


# -- the checks above, mutation-checked on a scratch copy of the package ------------------------
@pytest.fixture
def scratch(tmp_path: Path) -> Path:
    """A copy of the package's Python sources to break on purpose."""
    copy = tmp_path / "amsa_phys"
    shutil.copytree(PKG, copy, ignore=shutil.ignore_patterns("*.so", "*.c", "__pycache__"))
    return copy


def add_line(path: Path, line: str) -> None:
    path.write_text(path.read_text() + line + "\n")


def test_the_checks_pass_on_an_unchanged_copy(scratch: Path) -> None:
    known = known_modules(scratch)
    assert known == KNOWN
    assert circles(scratch) == []
    assert write_problems(scratch) == []
    assert root_problems(scratch) == []
    assert private_imports(scratch) == []
    modules = sorted(p for p in scratch.rglob("*.py") if p.parent != scratch)
    assert [p for m in modules for p in layer_problems(m, scratch, known)] == []


def test_a_three_dot_import_upward_from_a_subpackage_is_caught(scratch: Path) -> None:
    leaf = scratch / "ros" / "runtime" / "leaf.py"
    add_line(leaf, "from ...cli.main import main")
    assert layer_problems(leaf, scratch, known_modules(scratch)) == [
        "ros/runtime/leaf.py imports cli"
    ]
    add_line(leaf, "from ...gym import env")  # a package, not a module: still its layer
    assert "ros/runtime/leaf.py imports gym" in layer_problems(
        leaf, scratch, known_modules(scratch)
    )


#: zones imports space, which imports terrain: a zone imported by terrain closes the circle
CIRCLE = ["amsa_phys.physics.space", "amsa_phys.physics.terrain", "amsa_phys.physics.zones"]


def test_a_circle_inside_one_package_is_caught(scratch: Path) -> None:
    # the circle issue 32 found: zones imports terrain, terrain imported a zone template
    add_line(scratch / "physics" / "terrain.py", "from .zones import FrictionZone")
    assert circles(scratch) == [CIRCLE]


def test_a_late_import_is_a_circle_too_but_a_type_checking_one_is_not(scratch: Path) -> None:
    """An import inside a function only hides a circle until the function runs; one under
    TYPE_CHECKING never runs."""
    terrain = scratch / "physics" / "terrain.py"
    add_line(
        terrain, "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from . import zones"
    )
    assert circles(scratch) == []
    add_line(terrain, "def _late():\n    from .zones import FrictionZone\n    return FrictionZone")
    assert circles(scratch) == [CIRCLE]


def test_an_arrow_back_up_to_the_root_is_caught(scratch: Path) -> None:
    add_line(scratch / "runs" / "single.py", "def _v():\n    from .. import __version__")
    add_line(scratch / "errors.py", "from .model import params")
    assert root_problems(scratch) == [
        "errors.py imports amsa_phys.model.params",
        "runs/single.py imports amsa_phys",
    ]


def test_a_private_name_from_another_module_is_caught(scratch: Path) -> None:
    add_line(scratch / "runs" / "single.py", "from ..model.scenariobuild import _world")
    lines = len((scratch / "runs" / "single.py").read_text().splitlines())
    assert private_imports(scratch) == [f"runs/single.py:{lines} imports _world"]


@pytest.mark.parametrize(
    ("bad", "target"),
    [
        ("from ..engine import batch\nbatch.ENABLED = False", "batch.ENABLED"),
        ("from ..physics.space import PhysicsWorld\nPhysicsWorld.step = len", "PhysicsWorld.step"),
        ("from ..engine import batch\nsetattr(batch, 'ENABLED', 0)", "batch"),
        ("from ..model import template\ntemplate.BUILTINS['x'] = 'a:B'", "template.BUILTINS['x']"),
        ("from ..model import template\ntemplate.BUILTINS.update(x='a:B')", "template.BUILTINS"),
        ("import amsa_phys.engine.batch as b\nb.MIN_GROUP += 1", "b.MIN_GROUP"),
    ],
)
def test_a_write_into_another_module_is_caught(scratch: Path, bad: str, target: str) -> None:
    single = scratch / "runs" / "single.py"
    add_line(single, bad)
    lines = len(single.read_text().splitlines())
    assert write_problems(scratch) == [f"runs/single.py:{lines} writes {target}"]


def test_writes_to_its_own_state_are_not_caught() -> None:
    own = (
        "X = 1\nclass A:\n    def f(self):\n        self.y = 2\n"
        "A.z = 3\ndef g():\n    global X\n    X = 2\n"
    )
    assert foreign_writes(own) == ()


def test_a_long_module_is_caught(scratch: Path) -> None:
    add_line(scratch / "physics" / "forces.py", "\n" * MAX_LINES)
    assert "physics/forces.py" in long_modules(scratch)
    assert "model/shapes/scenario.py" not in long_modules(scratch)  # generated
