"""YAML as scene files are read: safe, with the mistakes YAML lets pass made errors.

- A key given twice in one mapping is an error naming the line (PyYAML keeps the last: a
  second `mounts:` silently replaced eight mounts with one).
- `3e5`, `-2E+4`, `1e-3` are floats (YAML 1.1 reads an exponent without a dot as a string).
- Aliases (`*name`) are refused: nested aliases expand exponentially ("billion laughs") and a
  scene is small enough to write out.
- Nesting deeper than MAX_DEPTH is refused instead of exhausting the recursion.
"""

from __future__ import annotations

import re
from typing import Any

import yaml
from yaml.nodes import MappingNode, Node

MAX_DEPTH = 50
"""Deepest nesting of mappings and lists accepted (a scene needs 4)."""
FLOAT_WITH_EXPONENT = re.compile(r"^[-+]?(?:[0-9][0-9_]*)(?:\.[0-9_]*)?[eE][-+]?[0-9]+$")


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
            if key in seen:
                raise SceneYamlError(
                    f"line {line}: key {key!r} given twice in one mapping (first on line "
                    f"{seen[key]}): YAML would keep the last one only"
                )
            seen[key] = line
        return super().construct_mapping(node, deep=deep)


SceneLoader.add_implicit_resolver(
    "tag:yaml.org,2002:float", FLOAT_WITH_EXPONENT, list("-+0123456789")
)


def load_yaml(text: str) -> Any:
    """The document in `text`, read by `SceneLoader`."""
    return yaml.load(text, Loader=SceneLoader)
