"""YAML as scene files are read: safe, with the mistakes YAML lets pass made errors.

- A key given twice in one mapping is an error naming the line (PyYAML keeps the last: a
  second `mounts:` silently replaced eight mounts with one).
- `3e5`, `-2E+4`, `1e-3`, `1.5e3`, `.5e3` are floats (YAML 1.1 reads an exponent without a dot
  and a sign as a string).
- Aliases (`*name`) are refused: nested aliases expand exponentially ("billion laughs") and a
  scene is small enough to write out.
- An integer with a leading zero (`010`, octal 8 in YAML 1.1) or colons (`1:30`, base 60: 90)
  is refused: the value read is not the one written.
- Nesting deeper than MAX_DEPTH is refused instead of exhausting the recursion.
- A text longer than MAX_CHARS is refused before it is parsed (PyYAML reads ~0.3 MB/s: a 20 000
  mount file took 8 s only to be refused for its mount count), and an integer written with more
  than MAX_INT_CHARS characters is refused (Python refuses to convert one of 4300 digits, and no
  scene value needs 10³⁰).

A scene file is read into its document by `read_scene_yaml` (at most SCENE_MAX_BYTES, UTF-8),
every error a SceneError naming the file (PyYAML's on one line, with 1-based positions).
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import yaml
from yaml.nodes import MappingNode, Node, ScalarNode

from mount_twin.errors import SceneError
from mount_twin.scene.reader import shown
from mount_twin.textfiles import MIB, FileTooLargeError, read_limited

MAX_DEPTH = 50
"""Deepest nesting of mappings and lists accepted (a scene needs 4)."""
MAX_CHARS = 1_000_000
"""Longest scene text accepted, characters (1000 mounts written as in the bundled scenes take
0.4 MB; PyYAML parses 1 MB in ~4 s)."""
MAX_INT_CHARS = 30
"""Longest integer scalar accepted, characters."""
READ_OTHERWISE = re.compile(r"^[-+]?(?:0[0-9_]+|[0-9][0-9_]*(?::[0-5]?[0-9])+)$")
"""Integers YAML 1.1 does not read in base 10: a leading zero (010 is octal 8) and colons
(1:30 is base 60, 90)."""
FLOAT_WITH_EXPONENT = re.compile(
    r"^[-+]?(?:[0-9][0-9_]*(?:\.[0-9_]*)?|\.[0-9][0-9_]*)[eE][-+]?[0-9]+$"
)


class SceneYamlError(yaml.YAMLError):
    """A YAML construct scene files do not accept (duplicate key, alias, deep nesting)."""


class SceneLoader(yaml.SafeLoader):
    """yaml.SafeLoader with the rules of this module."""

    def compose_node(self, parent: Node | None, index: Any) -> Node | None:
        if self.check_event(yaml.AliasEvent):
            event = self.peek_event()
            raise SceneYamlError(
                f"line {event.start_mark.line + 1}: aliases (*{event.anchor}) are not accepted "
                "in scene files; write the values out"
            )
        self._depth = getattr(self, "_depth", 0) + 1
        try:
            if self._depth > MAX_DEPTH:
                mark = self.peek_event().start_mark
                raise SceneYamlError(f"line {mark.line + 1}: nested deeper than {MAX_DEPTH}")
            return super().compose_node(parent, index)  # type: ignore[no-any-return]
        finally:
            self._depth -= 1

    def construct_mapping(self, node: MappingNode, deep: bool = False) -> dict[Any, Any]:
        seen: dict[Any, int] = {}
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=deep)  # type: ignore[no-untyped-call]
            line = key_node.start_mark.line + 1
            if not _hashable(key):
                continue  # SafeLoader refuses it below ("found unhashable key")
            if key in seen:
                raise SceneYamlError(
                    f"line {line}: key {shown(key)} given twice in one mapping (first on line "
                    f"{seen[key]}): YAML would keep the last one only"
                )
            seen[key] = line
        return super().construct_mapping(node, deep=deep)

    def construct_yaml_int(self, node: ScalarNode) -> int:
        if len(node.value) > MAX_INT_CHARS:
            raise SceneYamlError(
                f"line {node.start_mark.line + 1}: an integer of {len(node.value)} characters "
                f"(at most {MAX_INT_CHARS} are accepted)"
            )
        value: int = super().construct_yaml_int(node)  # type: ignore[no-untyped-call]
        if READ_OTHERWISE.match(node.value):
            base = "base 60" if ":" in node.value else "octal"
            raise SceneYamlError(
                f"line {node.start_mark.line + 1}: {node.value} is read by YAML 1.1 as "
                f"{base}: {value}; write the number you mean without a leading zero or ':'"
            )
        return value


def _hashable(key: Any) -> bool:
    try:
        hash(key)
    except TypeError:
        return False
    return True


SceneLoader.add_constructor("tag:yaml.org,2002:int", SceneLoader.construct_yaml_int)

SceneLoader.add_implicit_resolver(
    "tag:yaml.org,2002:float", FLOAT_WITH_EXPONENT, list("-+.0123456789")
)


def load_yaml(text: str) -> Any:
    """The document in `text`, read by `SceneLoader`."""
    if len(text) > MAX_CHARS:
        msg = f"{len(text)} characters: a scene file has at most {MAX_CHARS}"
        raise SceneYamlError(msg)
    return yaml.load(text, Loader=SceneLoader)


SCENE_MAX_BYTES = 16 * MIB
"""Largest scene, parameter or sweep YAML file read (the bundled scenes are < 10 kB)."""


def read_scene_yaml(path: str | Path) -> Any:
    """The YAML document of a scene file, unvalidated; errors name the file."""
    path = Path(path)
    try:
        return load_yaml(read_limited(path, SCENE_MAX_BYTES, "SCENE_MAX_BYTES"))
    except FileTooLargeError as err:
        raise SceneError(str(path), "", f"cannot read: {err}") from err
    except OSError as err:
        raise SceneError(str(path), "", f"cannot read: {err.strerror}") from err
    except UnicodeDecodeError as err:
        msg = f"not UTF-8 text: byte {err.start} is {err.object[err.start : err.start + 1]!r}"
        raise SceneError(str(path), "", msg) from err
    except SceneYamlError as err:
        raise SceneError(str(path), "", str(err)) from err
    except yaml.YAMLError as err:
        raise SceneError(str(path), "", f"not valid YAML: {_yaml_problem(err)}") from err


def _yaml_problem(err: yaml.YAMLError) -> str:
    """PyYAML's error on one line, with 1-based positions in the file (its text spans five
    lines, quoting the line with a caret, and names the file '<unicode string>'):
    `line 3, column 1: expected ',' or ']', but got '<stream end>' (while parsing a flow
    sequence from line 2, column 23)`."""
    if not isinstance(err, yaml.MarkedYAMLError) or err.problem_mark is None:
        return " ".join(str(err).split())
    mark = err.problem_mark
    text = f"line {mark.line + 1}, column {mark.column + 1}: {err.problem}"
    if err.context:
        where = err.context_mark
        at = "" if where is None else f" from line {where.line + 1}, column {where.column + 1}"
        text += f" ({err.context}{at})"
    return text
