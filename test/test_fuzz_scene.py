"""Hostile scene files, fuzzed (hypothesis, derandomized): the bundled scenes with keys dropped,
values of the wrong type, huge, negative, NaN and infinite numbers, numbers written as strings
or scaled by a unit factor, deep nesting, random unicode names, duplicated list items, and the
YAML text itself damaged. Whatever comes, loading gives a Scene or a SceneError, never another
exception, and answers within a time budget."""

from __future__ import annotations

import copy
import time
from datetime import timedelta
from functools import cache
from pathlib import Path
from typing import Any

import pytest
import yaml
from hypothesis import given
from hypothesis import strategies as st
from io_helpers import CONFIG, fuzz_settings

from mount_twin.errors import SceneError
from mount_twin.scene import Scene, load_scene_file, scene_from_dict

SCENES = sorted(p.name for p in CONFIG.glob("*.scene.yaml"))
BUDGET_S = 2.0
"""Longest a single load may take (the bundled scenes load in ~20 ms)."""
FUZZ = fuzz_settings(800, deadline=timedelta(seconds=BUDGET_S))

KeyPath = tuple[str | int, ...]

WEIRD = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-(2**70), 2**70),
    st.integers(0, 400).map(lambda k: 10**k),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from(["3e5", "1e-3", "-2E+4", "1,5", "NaN", "inf", "", "x²", "/deck imu"]),
    st.sampled_from(["~foo", "{node}/imu", "a//b", "2deck", "deg", "pump frame", "-1"]),
    st.text(max_size=12),
    st.lists(st.floats(allow_nan=True, allow_infinity=True), max_size=7),
    st.dictionaries(st.text(max_size=4), st.integers(-5, 5), max_size=3),
)
"""Replacement values: wrong types, absurd numbers, numbers as strings, bad ROS names."""
OPS = ("drop", "replace", "scale", "stringify", "nest", "duplicate")


@cache
def bundled(name: str) -> dict[str, Any]:
    """A bundled scene's document (parsed once; mutate a deep copy)."""
    return yaml.safe_load((CONFIG / name).read_text(encoding="utf-8"))


def node_paths(node: Any, path: KeyPath = ()) -> list[KeyPath]:
    """Path of every value below `node` (containers and leaves), depth first."""
    if isinstance(node, dict):
        items: Any = node.items()
    elif isinstance(node, list):
        items = enumerate(node)
    else:
        return []
    return [p for k, v in items for p in [(*path, k), *node_paths(v, (*path, k))]]


def _nested(value: Any, depth: int) -> Any:
    for _ in range(depth):
        value = [value]
    return value


def mutate(draw: st.DrawFn, doc: dict[str, Any], path: KeyPath) -> None:
    """Apply one drawn operation to the value at `path` of `doc`, in place."""
    parent: Any = doc
    for key in path[:-1]:
        parent = parent[key]
    key, value = path[-1], parent[path[-1]]
    op = draw(st.sampled_from(OPS))
    if op == "drop":
        del parent[key]
    elif op == "scale" and isinstance(value, (int, float)) and not isinstance(value, bool):
        parent[key] = value * draw(st.sampled_from([1e3, 1e-3, -1.0, 1e6, 1e300]))
    elif op == "stringify" and not isinstance(value, (dict, list)):
        parent[key] = str(value)
    elif op == "nest":
        parent[key] = _nested(value, draw(st.integers(1, 120)))
    elif op == "duplicate" and isinstance(parent, list):
        parent.append(copy.deepcopy(value))
    else:
        parent[key] = draw(WEIRD)


@st.composite
def mutated_scenes(draw: st.DrawFn) -> tuple[dict[str, Any], str]:
    """(mutated document, its YAML text, possibly damaged as text)."""
    doc = copy.deepcopy(bundled(draw(st.sampled_from(SCENES))))
    for _ in range(draw(st.integers(1, 4))):
        paths = node_paths(doc)
        if not paths:
            break
        mutate(draw, doc, paths[draw(st.integers(0, len(paths) - 1))])
    text = yaml.safe_dump(doc, allow_unicode=True, sort_keys=False)
    damage = draw(st.sampled_from(["none", "none", "insert", "truncate", "append"]))
    at = draw(st.integers(0, len(text)))
    if damage == "insert":
        text = text[:at] + draw(st.characters()) + text[at:]
    elif damage == "truncate":
        text = text[:at]
    elif damage == "append":
        text += draw(
            st.sampled_from(["mounts: []\n", "a: &x [1]\nb: *x\n", "? [a]\n: 1\n", "\t- x\n"])
        )
    return doc, text


def load_outcome(doc: dict[str, Any], text: str, file: Path) -> list[Scene | SceneError]:
    """Load `text` as a scene file and `doc` as a mapping; SceneErrors are returned, any other
    exception propagates."""
    file.write_text(text, encoding="utf-8")
    outcomes: list[Scene | SceneError] = []
    for load in (lambda: load_scene_file(file), lambda: scene_from_dict(doc, "fuzz")):
        try:
            outcomes.append(load())
        except SceneError as err:
            outcomes.append(err)
    return outcomes


@pytest.fixture(scope="module")
def scene_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("fuzz") / "fuzz.scene.yaml"


@FUZZ
@given(case=mutated_scenes())
def test_a_mutated_scene_file_is_a_scene_or_a_scene_error_in_time(
    scene_file: Path, case: tuple[dict[str, Any], str]
) -> None:
    start = time.perf_counter()
    for outcome in load_outcome(*case, scene_file):
        # a loaded scene's warnings and an error's message must render
        text = [str(w) for w in outcome.warnings] if isinstance(outcome, Scene) else [str(outcome)]
        assert all(text)
    assert time.perf_counter() - start < BUDGET_S
