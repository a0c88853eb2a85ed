"""The package's import graph follows its layers (docs/design.md): each unit of mount_twin/ (a
subpackage, or a top-level module) imports only units of its own layer or of the layers below,
the units import one another without a cycle, and rclpy and rosbags are imported only by the
units that adapt to them (CONFINED). The imports are read from the source (an AST scan), in
every form that imports at run time:
- an `import` statement, a lazy one inside a function too: a lazy import upward is the same
  dependency, only hidden until it runs;
- an entry of a package's lazy table: the strings, "module" or "module:attribute" (relative
  ones from the package), of a module-level name that the module's `__getattr__` reads (PEP 562,
  as `mount_twin._LAZY`): a lazy name is an import on first use;
- `importlib.import_module` and `__import__` of a literal, of a module-level string constant or
  of an f-string whose literal head names a package (`f"mount_twin.commands.{name}"` imports
  under mount_twin.commands); one whose module the source does not name is refused unless
  OPAQUE says why it cannot reach a layer above.
Imports under `if TYPE_CHECKING:` are exempt from the layers (they run only in the type checker:
annotations may name a type of a layer above), not from CONFINED (a type of rclpy's named in the
core would make the core's type check need ROS; ruff bans them there too)."""

from __future__ import annotations

import ast
import re
from collections.abc import Iterable
from dataclasses import dataclass
from functools import cache
from importlib import import_module
from importlib.util import resolve_name
from pathlib import Path

import mount_twin

LAYERS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("base", ("errors", "textfiles", "figure_files", "core_sources")),
    ("core", ("_core", "_core_ext")),
    ("physics", ("physics",)),
    ("integrate", ("integrate",)),
    ("kinds", ("kinds",)),
    ("scene", ("scene",)),
    ("model", ("model",)),
    ("engine", ("engine",)),
    ("io", ("io",)),
    ("analysis", ("analysis", "sweeps", "plot")),
    ("adapters", ("stream", "replay", "replay_summary", "ros", "commands", "cli")),
    ("api", ("mount_twin",)),
)
"""The layers, lowest first, each with its units: a unit of mount_twin/ (its subpackage or
top-level module; "mount_twin" is the package's own `__init__.py`) may import the units of its
layer and of the layers listed before it. docs/design.md's table lists the same layers in the
same order."""

ROS_MESSAGES = (
    "builtin_interfaces",
    "diagnostic_msgs",
    "geometry_msgs",
    "rcl_interfaces",
    "sensor_msgs",
    "std_msgs",
    "tf2_msgs",
)
"""The ROS message packages (rclpy's classes; the rest of the package moves their CDR bytes
through rosbags' typestore, which needs no ROS install)."""
CONFINED = {"rclpy": ("ros",), "rosbags": ("io",), **dict.fromkeys(ROS_MESSAGES, ("ros",))}
"""Packages that only these units import, in every form: ruff.toml's banned-api says the same
of import statements for rclpy and rosbags, but sees no lazy or computed import, and lets each
unit it exempts import both."""

OPAQUE = {
    ("mount_twin/ros/outputs.py", "message_class"): (
        "a ROS message package (`<package>.msg`) named by a message type: rclpy's, in ros/"
    ),
}
"""Imports of a module that the source does not name, by file and enclosing function, each with
why it cannot reach a layer above or a package of CONFINED."""

LAYER_OF = {unit: layer for layer, units in LAYERS for unit in units}
RANK = {layer: rank for rank, (layer, _) in enumerate(LAYERS)}
PACKAGE = Path(mount_twin.__file__).resolve().parent
"""The package scanned: the one imported (PYTHONPATH chooses which tree)."""
DESIGN = PACKAGE.parent / "docs" / "design.md"
"""The design notes of the same tree."""
TRACKED = frozenset({"mount_twin", *CONFINED})
"""Top-level packages whose imports the rules concern."""
IMPORTERS = ("import_module", "__import__")
"""The functions that import a module named at run time (importlib's, the builtin)."""
LAZY_ENTRY = re.compile(r"(\.*)([A-Za-z_]\w*(?:\.[A-Za-z_]\w*)*)?(?::([A-Za-z_]\w*))?")
"""A lazy table's entry: a module, relative or not, and the attribute taken from it."""


@dataclass(frozen=True)
class Import:
    """One import by a mount_twin unit: where it is, which unit makes it, of what, how."""

    path: str  # relative to the package's parent: mount_twin/analysis/report.py
    line: int
    source: str  # the importing unit
    module: str  # the module imported, dotted; "" where the source does not name it
    how: str = "import"  # or "lazy name", "import_module", "__import__"
    type_only: bool = False  # under `if TYPE_CHECKING:`
    function: str = ""  # the enclosing function (dotted: Class.method), "" at module level
    attribute: str = ""  # a lazy name's: the attribute taken from the module

    @property
    def internal(self) -> bool:
        """Of a module of mount_twin."""
        return self.module.split(".")[0] == "mount_twin"

    @property
    def target(self) -> str:
        """The unit imported (under mount_twin), else the top-level package ("" unnamed)."""
        return unit_of(self.module) if self.internal else self.module.split(".")[0]

    def __str__(self) -> str:
        via = "" if self.how == "import" else f" ({self.how}: {self.module or '?'})"
        return f"{self.path}:{self.line}: {self.source} imports {self.target or '?'}{via}"


def unit_of(module: str) -> str:
    """The unit of a dotted module name under mount_twin: `mount_twin.io.input_bag` → "io", the
    package itself → "mount_twin"."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else parts[0]


def _imported(node: ast.Import | ast.ImportFrom, module: str, is_package: bool) -> list[str]:
    """The modules an import statement in `module` names (for `from mount_twin import x`, x)."""
    if isinstance(node, ast.Import):
        return [a.name for a in node.names]
    base = node.module or ""
    if node.level:  # relative: from the module's package up level - 1 packages
        package = module.split(".") if is_package else module.split(".")[:-1]
        base = ".".join([*package[: len(package) - node.level + 1], *filter(None, [base])])
    if base == "mount_twin":  # its units by name, or names of the package's own __init__
        units = units_present()
        return [f"mount_twin.{a.name}" if a.name in units else base for a in node.names]
    return [base]


def _resolved(name: str, package: str) -> str:
    """`name` made absolute from `package` ("" where it climbs above the top)."""
    try:
        return resolve_name(name, package)
    except ImportError:
        return ""


def _is_type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING"
    )


class _Reader(ast.NodeVisitor):
    """The imports of one module's source, in every form the module docstring lists."""

    def __init__(self, path: str, module: str, is_package: bool) -> None:
        self.path, self.module, self.is_package = path, module, is_package
        self.package = module if is_package else module.rpartition(".")[0]
        self.found: list[Import] = []
        self.constants: dict[str, str] = {}  # module-level NAME = "text"
        self.importers = {name: name for name in IMPORTERS}  # local name → which importer
        self.scope: list[str] = []
        self.type_only = False
        self.has_table = False
        self.in_lazy_getattr = False  # whose computed import the table names

    def add(self, line: int, module: str, how: str = "import", attribute: str = "") -> None:
        function = ".".join(self.scope)
        source = unit_of(self.module)
        self.found.append(
            Import(self.path, line, source, module, how, self.type_only, function, attribute)
        )

    def visit_Module(self, node: ast.Module) -> None:
        for statement in node.body:
            if isinstance(statement, ast.Assign) and isinstance(statement.value, ast.Constant):
                for target in statement.targets:
                    if isinstance(target, ast.Name) and isinstance(statement.value.value, str):
                        self.constants[target.id] = statement.value.value
        getattr_ = [
            s for s in node.body if isinstance(s, ast.FunctionDef) and s.name == "__getattr__"
        ]
        read = {n.id for f in getattr_ for n in ast.walk(f) if isinstance(n, ast.Name)}
        for statement in node.body:
            if isinstance(statement, ast.Assign | ast.AnnAssign) and statement.value is not None:
                targets = (
                    statement.targets if isinstance(statement, ast.Assign) else [statement.target]
                )
                if any(isinstance(t, ast.Name) and t.id in read for t in targets):
                    self._table(statement.value)
        self.generic_visit(node)

    def _table(self, table: ast.expr) -> None:
        """The entries of a lazy table: each string that names a module (a dict's key being the
        attribute where its value names none)."""
        keys: dict[int, str] = {}
        if isinstance(table, ast.Dict):
            keys = {
                id(v): k.value
                for k, v in zip(table.keys, table.values, strict=True)
                if isinstance(k, ast.Constant) and isinstance(k.value, str)
            }
        for node in ast.walk(table):
            if not (isinstance(node, ast.Constant) and isinstance(node.value, str)):
                continue
            entry = LAZY_ENTRY.fullmatch(node.value)
            if entry is None or not (entry[1] or entry[2]):
                continue
            dots, name, attribute = entry[1], entry[2] or "", entry[3] or ""
            if not dots and "." not in name and not attribute and name not in TRACKED:
                continue  # a bare name: an exported name, not a module
            self.has_table = True
            module = _resolved(dots + name, self.package)
            self.add(node.lineno, module, "lazy name", attribute or keys.get(id(node), ""))

    def visit_Import(self, node: ast.Import) -> None:
        for name in _imported(node, self.module, self.is_package):
            self.add(node.lineno, name)

    def visit_ImportFrom(self, node: ast.ImportFrom) -> None:
        if node.module in ("importlib", "builtins") and not node.level:
            for alias in node.names:
                if alias.name in IMPORTERS:
                    self.importers[alias.asname or alias.name] = alias.name
        for name in _imported(node, self.module, self.is_package):
            self.add(node.lineno, name)

    def visit_If(self, node: ast.If) -> None:
        if not _is_type_checking(node.test):
            self.generic_visit(node)
            return
        was, self.type_only = self.type_only, True
        for statement in node.body:
            self.visit(statement)
        self.type_only = was
        for statement in node.orelse:
            self.visit(statement)

    def _scoped(self, node: ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef) -> None:
        was = self.in_lazy_getattr
        if not self.scope and node.name == "__getattr__" and self.has_table:
            self.in_lazy_getattr = True
        self.scope.append(node.name)
        self.generic_visit(node)
        self.scope.pop()
        self.in_lazy_getattr = was

    def visit_FunctionDef(self, node: ast.FunctionDef) -> None:
        self._scoped(node)

    def visit_AsyncFunctionDef(self, node: ast.AsyncFunctionDef) -> None:
        self._scoped(node)

    def visit_ClassDef(self, node: ast.ClassDef) -> None:
        self._scoped(node)

    def visit_Call(self, node: ast.Call) -> None:
        func = node.func
        how = (
            self.importers.get(func.id)
            if isinstance(func, ast.Name)
            else func.attr
            if isinstance(func, ast.Attribute) and func.attr in IMPORTERS
            else None
        )
        if how is not None:
            modules = self._called(how, node)
            if modules or not self.in_lazy_getattr:
                for module in modules or [""]:
                    self.add(node.lineno, module, how)
        self.generic_visit(node)

    def _text(self, node: ast.expr | None) -> tuple[str, bool]:
        """A module name's text as the source gives it, and whether whole (else an f-string's
        literal head)."""
        if isinstance(node, ast.Constant) and isinstance(node.value, str):
            return node.value, True
        if isinstance(node, ast.Name) and node.id in self.constants:
            return self.constants[node.id], True
        if isinstance(node, ast.JoinedStr) and node.values:
            head = node.values[0]
            return (str(head.value) if isinstance(head, ast.Constant) else "", False)
        return "", False

    def _called(self, how: str, node: ast.Call) -> list[str]:
        """The modules an importer's call imports ([] where the source does not name them)."""
        args: dict[int | str, ast.expr] = dict(enumerate(node.args))
        args.update((k.arg, k.value) for k in node.keywords if k.arg)
        text, whole = self._text(args.get(0, args.get("name")))
        if not whole:  # the deepest package the f-string's head names, mount_twin's unit at least
            package = text.rpartition(".")[0]
            return [package] if package.split(".")[0] and package != "mount_twin" else []
        if how == "import_module":
            anchor = args.get(1, args.get("package"))
            if not text.startswith("."):
                return [text]
            if isinstance(anchor, ast.Name) and anchor.id in ("__name__", "__package__"):
                return [_resolved(text, self.module if anchor.id == "__name__" else self.package)]
            package, known = self._text(anchor)
            return [_resolved(text, package)] if known else []
        fromlist, level = args.get(3, args.get("fromlist")), args.get(4, args.get("level"))
        names = [
            n.value
            for n in (fromlist.elts if isinstance(fromlist, ast.Tuple | ast.List) else [])
            if isinstance(n, ast.Constant) and isinstance(n.value, str)
        ]
        depth = 0 if level is None else level.value if isinstance(level, ast.Constant) else None
        if not isinstance(depth, int):
            return []
        statement = (
            ast.ImportFrom(text or None, [ast.alias(n) for n in names], depth)
            if names or depth
            else ast.Import([ast.alias(text)])
        )
        return _imported(statement, self.module, self.is_package)


def read(text: str, path: str) -> list[Import]:
    """The imports in `text`, the source of the package's file at `path` (mount_twin/x/y.py)."""
    parts = Path(path).with_suffix("").parts
    is_package = parts[-1] == "__init__"
    reader = _Reader(path, ".".join(parts[:-1] if is_package else parts), is_package)
    reader.visit(ast.parse(text, path))
    return sorted(reader.found, key=lambda i: i.line)


@cache
def imports() -> tuple[Import, ...]:
    """Every import in the package's sources."""
    return tuple(
        i
        for file in sorted(PACKAGE.rglob("*.py"))
        for i in read(
            file.read_text(encoding="utf-8"), file.relative_to(PACKAGE.parent).as_posix()
        )
    )


@cache
def units_present() -> frozenset[str]:
    """The units the package has: its subpackages, top-level modules (and compiled ones)."""
    found = {"mount_twin"}
    for entry in PACKAGE.iterdir():
        if entry.is_dir() and (entry / "__init__.py").is_file():
            found.add(entry.name)
        elif entry.suffix in (".py", ".so", ".pyd") and entry.name != "__init__.py":
            found.add(entry.name.split(".")[0])
    return frozenset(found)


def test_every_unit_has_a_layer() -> None:
    """A new subpackage or top-level module is placed in LAYERS (and docs/design.md's table)."""
    named = {i.target for i in imports() if i.internal} | units_present()
    assert sorted(named - set(LAYER_OF)) == [], f"units in no layer of LAYERS ({__file__})"


def against_the_layers(found: Iterable[Import]) -> list[str]:
    """The imports of `found` of a layer above the importer's, at run time, each said."""
    return [
        f"{i}: the {LAYER_OF[i.source]} layer may not import the {LAYER_OF[i.target]} layer"
        for i in found
        if i.internal
        and not i.type_only
        and {i.source, i.target} <= LAYER_OF.keys()  # test_every_unit_has_a_layer names others
        and RANK[LAYER_OF[i.target]] > RANK[LAYER_OF[i.source]]
    ]


def outside_their_units(found: Iterable[Import]) -> list[str]:
    """The imports of `found` of a package of CONFINED by another unit, each said."""
    return [
        f"{i}: only {', '.join(CONFINED[i.target])} may import {i.target}"
        for i in found
        if i.target in CONFINED and i.source not in CONFINED[i.target]
    ]


def unnamed(found: Iterable[Import]) -> list[str]:
    """The imports of `found` of a module the source does not name, but OPAQUE, each said."""
    return [
        f"{i}: {i.how} of a module the source does not name: name it in a literal, or add "
        f"({i.path!r}, {i.function!r}) to OPAQUE with why it cannot reach a layer above"
        for i in found
        if not i.module and (i.path, i.function) not in OPAQUE
    ]


def test_no_unit_imports_a_layer_above_its_own() -> None:
    upward = against_the_layers(imports())
    assert upward == [], "imports against the layers (docs/design.md):\n" + "\n".join(upward)


def test_rclpy_and_rosbags_are_imported_only_by_their_units() -> None:
    strays = outside_their_units(imports())
    assert strays == [], "imports of confined packages (docs/design.md):\n" + "\n".join(strays)


def test_every_computed_import_names_its_module_or_says_why_not() -> None:
    used = {(i.path, i.function) for i in imports() if not i.module}
    stale = [f"OPAQUE names {key}, where no such import is" for key in OPAQUE if key not in used]
    said = unnamed(imports()) + stale
    assert said == [], "\n".join(said)


def test_every_lazy_name_imports_and_is_there() -> None:
    """Each entry of a lazy table names a module that imports and defines the attribute (one
    that names no module is the test above's)."""
    broken = []
    for i in imports():
        if i.how != "lazy name" or not i.module:
            continue
        try:
            module = import_module(i.module)
        except ImportError as error:
            broken.append(f"{i}: {error}")
            continue
        if i.attribute and not hasattr(module, i.attribute):
            broken.append(f"{i}: {i.module} has no attribute {i.attribute!r}")
    assert broken == [], "lazy names that do not import:\n" + "\n".join(broken)


Edges = dict[str, dict[str, Import]]
"""The unit graph: source → target → an import that makes the edge."""


def path(edges: Edges, start: str, goal: str) -> list[Import] | None:
    """The imports of a shortest chain from unit `start` to unit `goal` (breadth first); None
    where there is none."""
    came: dict[str, list[Import]] = {start: []}
    frontier = [start]
    while frontier:
        following = []
        for unit in frontier:
            for target, imp in sorted(edges.get(unit, {}).items()):
                if target not in came:
                    came[target] = [*came[unit], imp]
                    following.append(target)
        if goal in came:
            return came[goal]
        frontier = following
    return None


def cycles(edges: Edges) -> list[tuple[list[str], list[Import]]]:
    """Each set of units that import one another round (a strongly connected component of the
    graph, units in order), with a shortest cycle through its first unit, as imports in order."""
    found: list[tuple[list[str], list[Import]]] = []
    done: set[str] = set()
    for unit in sorted(edges):
        if unit in done:
            continue
        round_trips = [
            [imp, *back]
            for target, imp in sorted(edges[unit].items())
            if (back := path(edges, target, unit)) is not None
        ]
        if round_trips:
            component = [u for u in sorted(edges) if u == unit or _both_ways(edges, unit, u)]
            done.update(component)
            found.append((component, min(round_trips, key=len)))
    return found


def _both_ways(edges: Edges, a: str, b: str) -> bool:
    return path(edges, a, b) is not None and path(edges, b, a) is not None


def test_units_import_one_another_without_a_cycle() -> None:
    """Within a layer the units may import one another, but not round in a circle (a cycle
    across layers holds an upward import too, which the test above names)."""
    edges: Edges = {}
    for i in imports():
        if i.internal and not i.type_only and i.target != i.source:
            edges.setdefault(i.source, {}).setdefault(i.target, i)
    said = [
        f"{', '.join(units)} import one another round, for one:\n" + "\n".join(map(str, chain))
        for units, chain in cycles(edges)
    ]
    assert said == [], "cycles of imports between units:\n" + "\n\n".join(said)


def test_the_cycle_search_finds_each_set_of_units_in_a_cycle() -> None:
    """The search above, on graphs drawn by hand."""

    def graph(*pairs: str) -> Edges:
        edges: Edges = {}
        for a, b in (tuple(pair) for pair in pairs):
            edges.setdefault(a, {})[b] = Import(f"mount_twin/{a}.py", 1, a, f"mount_twin.{b}")
        return edges

    def units(edges: Edges) -> list[tuple[str, str]]:
        """Per cycle found: its set of units, and its chain's units from first to last."""
        return [
            ("".join(found), "".join([i.source for i in chain] + [chain[-1].target]))
            for found, chain in cycles(edges)
        ]

    assert units(graph("ab", "bc", "ca")) == [("abc", "abca")]
    assert units(graph("ab", "ac", "bd", "cd")) == []  # a diamond: two ways, no way back
    assert units(graph("ab", "ba", "bc", "cd", "dc")) == [("ab", "aba"), ("cd", "cdc")]
    assert units(graph("ab", "bc", "cd", "da", "ca")) == [("abcd", "abca")]  # the shorter


def test_design_md_lists_these_layers_in_this_order() -> None:
    """The table in docs/design.md that says what each layer holds gives LAYERS' order."""
    text = DESIGN.read_text(encoding="utf-8")
    table = text[text.index("| layer | package | role |") :].split("\n\n")[0]
    named = [row.split("|")[1].strip() for row in table.splitlines()[2:]]
    assert named == [layer for layer, _ in LAYERS]


PLANTED = """\
from typing import TYPE_CHECKING
import importlib
from importlib import import_module as load
from . import loader
from .. import ros
if TYPE_CHECKING:
    import rclpy
    from mount_twin.engine import engine
else:
    import rosbags
STREAM = "mount_twin.stream"
_LAZY = {
    "Node": "mount_twin.ros.node",
    "draw": "..plot",
    "Reader": "rosbags.rosbag2:AnyReader",
}
def __getattr__(name):
    return getattr(importlib.import_module(_LAZY[name]), name)
class Hidden:
    def run(self, name):
        import mount_twin.io.messages
        load(STREAM)
        __import__("mount_twin", fromlist=["replay"])
        importlib.import_module(f"mount_twin.commands.{name}")
        importlib.import_module(".description", __package__)
        return load(name)
"""
"""A scene package's `__init__.py` that imports in every form read, above its layer too."""


def test_the_scan_reads_every_form_of_import() -> None:
    found = [
        (i.line, i.module, i.how, i.type_only, i.function, i.attribute)
        for i in read(PLANTED, "mount_twin/scene/__init__.py")
    ]
    assert found == [
        (1, "typing", "import", False, "", ""),
        (2, "importlib", "import", False, "", ""),
        (3, "importlib", "import", False, "", ""),
        (4, "mount_twin.scene", "import", False, "", ""),
        (5, "mount_twin.ros", "import", False, "", ""),
        (7, "rclpy", "import", True, "", ""),
        (8, "mount_twin.engine", "import", True, "", ""),
        (10, "rosbags", "import", False, "", ""),
        (13, "mount_twin.ros.node", "lazy name", False, "", "Node"),
        (14, "mount_twin.plot", "lazy name", False, "", "draw"),
        (15, "rosbags.rosbag2", "lazy name", False, "", "AnyReader"),
        (21, "mount_twin.io.messages", "import", False, "Hidden.run", ""),
        (22, "mount_twin.stream", "import_module", False, "Hidden.run", ""),
        (23, "mount_twin.replay", "__import__", False, "Hidden.run", ""),
        (24, "mount_twin.commands", "import_module", False, "Hidden.run", ""),
        (25, "mount_twin.scene.description", "import_module", False, "Hidden.run", ""),
        (26, "", "import_module", False, "Hidden.run", ""),
    ]


def test_the_rules_refuse_the_planted_imports() -> None:
    """The planted package's imports of the layers above (its engine's only for the type
    checker), of rclpy (the type checker's too) and rosbags, and its import of a name."""
    planted = read(PLANTED, "mount_twin/scene/__init__.py")
    file = "mount_twin/scene/__init__.py"
    assert against_the_layers(planted) == [
        f"{file}:5: scene imports ros: the scene layer may not import the adapters layer",
        f"{file}:13: scene imports ros (lazy name: mount_twin.ros.node): the scene layer may not "
        "import the adapters layer",
        f"{file}:14: scene imports plot (lazy name: mount_twin.plot): the scene layer may not "
        "import the analysis layer",
        f"{file}:21: scene imports io: the scene layer may not import the io layer",
        f"{file}:22: scene imports stream (import_module: mount_twin.stream): the scene layer may "
        "not import the adapters layer",
        f"{file}:23: scene imports replay (__import__: mount_twin.replay): the scene layer may "
        "not import the adapters layer",
        f"{file}:24: scene imports commands (import_module: mount_twin.commands): the scene layer "
        "may not import the adapters layer",
    ]
    assert outside_their_units(planted) == [
        f"{file}:7: scene imports rclpy: only ros may import rclpy",
        f"{file}:10: scene imports rosbags: only io may import rosbags",
        f"{file}:15: scene imports rosbags (lazy name: rosbags.rosbag2): only io may import "
        "rosbags",
    ]
    assert unnamed(planted) == [
        f"{file}:26: scene imports ? (import_module: ?): import_module of a module the source "
        f"does not name: name it in a literal, or add ({file!r}, 'Hidden.run') to OPAQUE with "
        "why it cannot reach a layer above"
    ]
