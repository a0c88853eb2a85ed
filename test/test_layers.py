"""The package's import graph follows its layers (docs/design.md): each unit of mount_twin/ (a
subpackage, or a top-level module) imports only units of its own layer or of the layers below,
and the units import one another without a cycle. Every `import` of mount_twin.* is read from
the source (an AST scan), a lazy one inside a function too: a lazy import upward is the same
dependency, only hidden until it runs. Imports under `if TYPE_CHECKING:` are exempt (they run
only in the type checker: annotations may name a type of a layer above)."""

from __future__ import annotations

import ast
from collections.abc import Iterator
from dataclasses import dataclass
from functools import cache
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

LAYER_OF = {unit: layer for layer, units in LAYERS for unit in units}
RANK = {layer: rank for rank, (layer, _) in enumerate(LAYERS)}
PACKAGE = Path(mount_twin.__file__).resolve().parent
"""The package scanned: the one imported (PYTHONPATH chooses which tree)."""
DESIGN = PACKAGE.parent / "docs" / "design.md"
"""The design notes of the same tree."""


@dataclass(frozen=True)
class Import:
    """One import of a mount_twin unit: where it is, and from which unit to which."""

    path: str  # relative to the package's parent: mount_twin/analysis/report.py
    line: int
    source: str
    target: str
    type_only: bool  # under `if TYPE_CHECKING:`

    def __str__(self) -> str:
        return f"{self.path}:{self.line}: {self.source} imports {self.target}"


def unit_of(module: str) -> str:
    """The unit of a dotted module name under mount_twin: `mount_twin.io.input_bag` → "io", the
    package itself → "mount_twin"."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else parts[0]


def module_name(path: Path) -> str:
    """The dotted name of the module at `path` in the package."""
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _type_checking_lines(tree: ast.Module) -> set[int]:
    """The lines of the statements under `if TYPE_CHECKING:` (or `typing.TYPE_CHECKING`)."""
    lines: set[int] = set()
    for node in ast.walk(tree):
        if (
            isinstance(node, ast.If)
            and isinstance(node.test, ast.Name | ast.Attribute)
            and ast.unparse(node.test).endswith("TYPE_CHECKING")
        ):
            lines.update(
                n.lineno for s in node.body for n in ast.walk(s) if isinstance(n, ast.stmt)
            )
    return lines


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


@cache
def imports() -> tuple[Import, ...]:
    """Every import of one mount_twin unit by another in the package's sources."""
    return tuple(_scan())


def _scan() -> Iterator[Import]:
    for file in sorted(PACKAGE.rglob("*.py")):
        module = module_name(file)
        tree = ast.parse(file.read_text(encoding="utf-8"), str(file))
        type_only = _type_checking_lines(tree)
        statements = (n for n in ast.walk(tree) if isinstance(n, ast.Import | ast.ImportFrom))
        for node in statements:
            for name in _imported(node, module, file.name == "__init__.py"):
                if name.split(".")[0] != "mount_twin":
                    continue
                source, target = unit_of(module), unit_of(name)
                if target != source:
                    relative = file.relative_to(PACKAGE.parent).as_posix()
                    yield Import(relative, node.lineno, source, target, node.lineno in type_only)


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
    named = {i.target for i in imports()} | units_present()
    assert sorted(named - set(LAYER_OF)) == [], f"units in no layer of LAYERS ({__file__})"


def test_no_unit_imports_a_layer_above_its_own() -> None:
    upward = [
        f"{i}: the {LAYER_OF[i.source]} layer may not import the {LAYER_OF[i.target]} layer"
        for i in imports()
        if not i.type_only
        and {i.source, i.target} <= LAYER_OF.keys()  # the test above names the others
        and RANK[LAYER_OF[i.target]] > RANK[LAYER_OF[i.source]]
    ]
    assert upward == [], "imports against the layers (docs/design.md):\n" + "\n".join(upward)


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
        if not i.type_only:
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
            edges.setdefault(a, {})[b] = Import(f"mount_twin/{a}.py", 1, a, b, False)
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
