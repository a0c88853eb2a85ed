"""Sweep cases: every combination of the variations × every input, applied to the base scene.

Key paths: dotted keys into the scene mapping, a list selected by `[*]` (every item), `[name]`
(the item whose `name` is that: mounts), or `[i]` (by index); e.g. `mounts[*].stiffness`,
`mounts[fl].position`, `body.mass`.
"""

from __future__ import annotations

import copy
import hashlib
import itertools
import json
import re
from dataclasses import dataclass
from typing import Any

from mount_twin.errors import SceneError
from mount_twin.sweeps.spec import InputCase, SweepSpec

SEGMENT = re.compile(r"^(\w+)(?:\[([^\]]+)\])?$")


@dataclass(frozen=True)
class Case:
    """One run: the values set by key path, and the input."""

    case_id: str
    settings: tuple[tuple[str, str, Any], ...]
    """(key path, 'set' or 'scale', value) per variation."""
    input: InputCase


def expand(spec: SweepSpec) -> list[Case]:
    """Every case of the sweep, in a stable order, each with a stable id: a hash of the base
    scene's mapping, what the case sets and its input's definition (name, bag path and the
    digest of its files, generate options), so that a rerun recognises finished cases and only
    those. An id of what it sets and its input's name alone had a rerun after an edit of the
    base scene (or of a generated input) skip every case as finished, its table and summary the
    old design's; one of the bag's path, after the bag was recorded again there."""
    columns = [[(v.key, v.op, x) for x in v.values] for v in spec.variations]
    combos = (
        itertools.product(*columns) if spec.combine == "product" else zip(*columns, strict=True)
    )
    cases = []
    for combo in combos:
        for inp in spec.inputs:
            given = [inp.name, inp.bag, list(inp.generate)]
            # (a generated input has no content: its ids stay those of its earlier results)
            what = [spec.base, list(combo), [*given, inp.content] if inp.content else given]
            text = json.dumps(what, sort_keys=True, default=str)
            cases.append(Case(hashlib.sha1(text.encode()).hexdigest()[:12], tuple(combo), inp))
    return cases


def apply(base: dict[str, Any], settings: tuple[tuple[str, str, Any], ...]) -> dict[str, Any]:
    """A copy of the scene mapping `base` with each setting applied; an unknown key path or a
    selector that matches nothing raises KeyError naming it."""
    data = copy.deepcopy(base)
    for key, op, value in settings:
        _apply_one(data, key, op, value)
    return data


def _targets(node: Any, segments: list[str], key: str) -> list[tuple[dict[str, Any], str]]:
    """The (mapping, key) pairs a key path designates; its last key may be missing from its
    mapping (a value the scene leaves at its default: set, it is added; whether the scene
    knows the key is its loader's to say)."""
    match = SEGMENT.match(segments[0])
    last_plain = len(segments) == 1 and match is not None and match.group(2) is None
    if not match or not isinstance(node, dict) or (match.group(1) not in node and not last_plain):
        raise KeyError(f"{key}: no {segments[0]!r} here")
    name, selector = match.groups()
    if selector is None:
        if len(segments) == 1:
            return [(node, name)]
        return _targets(node[name], segments[1:], key)
    items = node[name]
    if not isinstance(items, list):
        raise KeyError(f"{key}: {name} is not a list")
    if selector == "*":
        chosen = items
    elif selector.isdigit():
        chosen = [items[int(selector)]] if int(selector) < len(items) else []
    else:
        chosen = [i for i in items if isinstance(i, dict) and i.get("name") == selector]
    if not chosen:
        raise KeyError(f"{key}: no item [{selector}] in {name}")
    if len(segments) == 1:
        raise KeyError(f"{key}: a whole list item cannot be set; name a key inside it")
    return [t for item in chosen for t in _targets(item, segments[1:], key)]


def _apply_one(data: dict[str, Any], key: str, op: str, value: Any) -> None:
    for mapping, name in _targets(data, key.split("."), key):
        if op == "set":
            mapping[name] = copy.deepcopy(value)
        elif isinstance(mapping.get(name), list):
            mapping[name] = [float(v) * value for v in mapping[name]]
        elif isinstance(mapping.get(name), (int, float)):
            mapping[name] = float(mapping[name]) * value
        else:
            raise KeyError(f"{key}: {name} holds no number to scale")


def key_unit(key: str, base: dict[str, Any]) -> str | None:
    """The unit of the value a key path sets, as the scene's parameter tables state it
    (`stated_unit`; a mount's key by its kind, one unit for every mount it selects), or None:
    no number, no one unit stated, a key path the tables do not know."""
    from mount_twin.scene.params import PARAMETERS, mount_parameters, stated_unit

    first, _, rest = key.partition(".")
    match = SEGMENT.match(first)
    if match is None or match.group(2) is None:  # no selector: a flat parameter's name
        return stated_unit(PARAMETERS[key]) if key in PARAMETERS else None
    if match.group(1) != "mounts" or not rest:
        return None
    try:
        mounts = [m for m, _ in _targets(base, [first, "kind"], key)]
    except KeyError:
        return None
    entries = [mount_parameters(str(m.get("kind", "linear"))).get(rest) for m in mounts]
    units = {stated_unit(e) if e else None for e in entries}
    return units.pop() if len(units) == 1 else None


def check(spec: SweepSpec) -> list[Case]:
    """The cases, after checking that every variation's key path names a key of the scene (in
    the base, or one its loader knows and the base leaves at its default; an error names the
    sweep file and the variation); scene values are checked per case, where a bad one is that
    case's failure, not the sweep's."""
    in_base = _unknown_key(spec.base)  # the base's own: every case's to fail on
    for i, v in enumerate(spec.variations):
        try:
            data = apply(spec.base, ((v.key, v.op, v.values[0]),))
        except KeyError as err:
            raise SceneError(spec.source, f"vary[{i}].key", str(err.args[0])) from err
        if (unknown := _unknown_key(data)) is not None and unknown != in_base:
            raise SceneError(spec.source, f"vary[{i}].key", f"{v.key}: {unknown[1]}")
    return expand(spec)


def _unknown_key(data: dict[str, Any]) -> tuple[str, str] | None:
    """The scene loader's complaint about an unknown key in `data` (key path, message), or
    None (any other complaint is about a value: the case's to fail on)."""
    from mount_twin.scene.loader import scene_from_dict

    try:
        scene_from_dict(data, "sweep case")
    except SceneError as err:
        return (err.path, err.message) if err.message.startswith("unknown key") else None
    return None
