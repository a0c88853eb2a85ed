"""The scene a run ran, recorded beside its outputs, and read back.

The node publishes it on `~/scene` (std_msgs/String, latched: reliable, transient local, depth
1, once at its start), as robot_state_publisher does /robot_description, and a replay writes
the same message into its output bag (offered latched like /tf_static); its data is one JSON
object (`scene_text`): the scene's digest (`sha256`, `scene.description.scene_digest`), its
file (`file`, an absolute path, or null), what was put over the file's values (`overrides`,
by flat parameter name, or by key path for a value changed in code: `scene_overrides`) and
its value (`value`, `scene_value`), which hashes to the digest.
A replay also records the digest, the file, the overrides and the value apart in its output
bag's metadata (`io.bag_metadata`'s SCENE_*_KEY), for a bag whose topic was left out (the
value is a few kB: 0.2-0.4 kB a mount, about what the metadata's entry of the mount's wrench
topic takes, so it grows with the metadata as it is). `recorded_scene` reads back whichever a
bag holds, for `report --scene`.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from rosbags.highlevel import AnyReader

from mount_twin.errors import BagError
from mount_twin.io.bag_metadata import (
    SCENE_DIGEST_KEY,
    SCENE_FILE_KEY,
    SCENE_KEY,
    SCENE_OVERRIDES_KEY,
    SCENE_VALUE_KEY,
    custom_data,
)
from mount_twin.io.input_bag import reader_paths
from mount_twin.io.messages import TYPESTORE
from mount_twin.model.scene_file import scene_file_of
from mount_twin.scene.description import (
    Scene,
    scene_digest,
    scene_value,
    value_differences,
    value_digest,
    value_text,
)

SCENE_TOPIC = "~/scene"
"""The run's scene (std_msgs/String of `scene_text`); publish it latched
(`io.output_bag.LATCHED_QOS`)."""
STRING = "std_msgs/msg/String"


def scene_text(scene: Scene) -> str:
    """The `~/scene` message's data: the JSON object of the scene's digest (`sha256`), file
    (`file`: absolute path, or null), overrides (`overrides`: `scene_overrides`) and value
    (`value`); one line."""
    record = {
        "sha256": scene_digest(scene),
        "file": scene.origin.file,
        "overrides": scene_overrides(scene),
        "value": scene_value(scene),
    }
    return json.dumps(record, default=list)  # default: rclpy's arrays of a parameter


def scene_overrides(scene: Scene) -> dict[str, Any]:
    """What was put over the values of the scene's file: its origin's overrides (flat
    parameter name → value), then the values changed in code since (`_changed_in_code`); the
    file with them put over it is the scene."""
    return {**scene.origin.overrides, **_changed_in_code(scene)}


NAMED_CHANGES = 3
"""How many of the values changed in code a replay's `SCENE_KEY` names (`scene_name`)."""


def scene_name(scene: Scene) -> str:
    """The scene as a replay names it in its metadata (`SCENE_KEY`), for messages: its source,
    with the values changed in code since it was loaded (`NAMED_CHANGES` of them)."""
    changed = list(_changed_in_code(scene))
    if not changed:
        return scene.source
    more = len(changed) - NAMED_CHANGES
    named = ", ".join(changed[:NAMED_CHANGES]) + (f" and {more} more" if more > 0 else "")
    return f"{scene.source} (with {named} changed in code)"


def _changed_in_code(scene: Scene) -> dict[str, Any]:
    """Each value of the scene changed in code since its file and overrides built it
    (`dataclasses.replace` on the scene loaded: `SceneOrigin.value`), by key path
    (`mounts[0].stiffness[2]`, `outputs.diagnostics_period_s`: `value_differences`) → its
    value here."""
    origin = scene.origin
    changed = value_differences(scene_value(scene), origin.value) if origin.value else []
    return {path: here for path, here, _ in changed}


def scene_message(scene: Scene, stamp_ns: int) -> tuple[str, int, bytes]:
    """The `~/scene` message, as (unresolved topic, stamp ns: its log time in a bag, CDR)."""
    msg = TYPESTORE.types[STRING](data=scene_text(scene))
    return SCENE_TOPIC, int(stamp_ns), bytes(TYPESTORE.serialize_cdr(msg, STRING))


def scene_metadata(scene: Scene) -> dict[str, str]:
    """What a replay records of its scene in its output bag's metadata: its name as text
    (`SCENE_KEY`: `scene_name`), its file's absolute path (`SCENE_FILE_KEY`, '' for none),
    the overrides (`scene_overrides`) as JSON (`SCENE_OVERRIDES_KEY`), its digest
    (`SCENE_DIGEST_KEY`) and its value, the text the digest hashes (`SCENE_VALUE_KEY`)."""
    value = scene_value(scene)
    return {
        SCENE_KEY: scene_name(scene),
        SCENE_FILE_KEY: scene.origin.file or "",
        SCENE_OVERRIDES_KEY: json.dumps(scene_overrides(scene), default=list),
        SCENE_DIGEST_KEY: value_digest(value),
        SCENE_VALUE_KEY: value_text(value),
    }


@dataclass(frozen=True)
class RecordedScene:
    """The scene a bag records its run ran (`recorded_scene`).

    Attributes:
        sha256: its digest.
        where: what in the bag records it, for messages ("its /mount_twin/scene topic").
        named: the run's scene as the bag names it, for messages (a replay's `SCENE_KEY`).
        file: its scene file as recorded (None: none; relative in bags written before
            `SCENE_FILE_KEY`: from the replay's directory).
        overrides: what was put over the file's values, flat parameter name (or key path of
            a value changed in code: `scene_overrides`) → value (None: a value the bag does
            not hold: one written before `SCENE_OVERRIDES_KEY` names the input fields only;
            the run's, its input status records).
        value: its value (`scene_value`, read back from JSON), or None: the bag holds only
            its digest (a replay's metadata written before `SCENE_VALUE_KEY`).
        replayed: a replay recorded it (its metadata names the scene), else a recording of
            the node's topics.
        given: a replay's scene file as it was given (`SCENE_KEY`'s: relative to where it
            ran, or absolute), where its value is not recorded: looked for where `file` is
            not found (a project directory moved); else None.
    """

    sha256: str
    where: str
    named: str
    file: str | None = None
    overrides: Mapping[str, Any] = field(default_factory=dict)
    value: dict[str, Any] | None = None
    replayed: bool = False
    given: str | None = None


def recorded_scene(bag: str | Path) -> RecordedScene | None:
    """The scene a bag records: from its `~/scene` topic (a std_msgs/String topic named
    `…/scene` whose data is `scene_text`'s: a replay's, or the node's recorded), else from
    its metadata; None where neither records one. A message (or metadata) whose value does
    not hash to its digest, or messages of two scenes, are a BagError naming the topic (the
    key)."""
    meta = custom_data(bag)
    found = _from_topic(Path(bag))
    return _metadata_scene(bag, meta) if found is None else _topic_scene(*found, meta)


def _topic_scene(topic: str, record: dict[str, Any], meta: dict[str, str]) -> RecordedScene:
    """The scene a `~/scene` message on `topic` records (`record`: its JSON object), named
    as a replay's metadata (`meta`) names it, else by its file and overrides."""
    named, file, overrides = meta.get(SCENE_KEY), record.get("file"), record.get("overrides")
    text = named or file or "a parameter set without a scene file"
    if file and not named and overrides:
        text += f" with {', '.join(overrides)} over it"
    return RecordedScene(
        record["sha256"],
        f"its {topic} topic",
        text,
        file,
        overrides or {},
        record["value"],
        named is not None,
    )


def _metadata_scene(bag: str | Path, meta: dict[str, str]) -> RecordedScene | None:
    """The scene a replay's metadata (`meta`) records, or None where it records none."""
    digest = meta.get(SCENE_DIGEST_KEY)
    if not digest:
        return None
    named = meta.get(SCENE_KEY)
    file: str | None = None
    overrides: dict[str, Any] = {}
    if SCENE_FILE_KEY in meta:
        file = meta[SCENE_FILE_KEY] or None
        overrides = _overrides(bag, meta.get(SCENE_OVERRIDES_KEY) or "{}")
    elif named:  # a bag written before the file and the overrides were recorded apart
        file, keys = scene_file_of(named)
        overrides = {f"input.{k}": None for k in keys}
    value = _value(bag, meta[SCENE_VALUE_KEY], digest) if SCENE_VALUE_KEY in meta else None
    held = SCENE_DIGEST_KEY if value is None else f"{SCENE_DIGEST_KEY}, {SCENE_VALUE_KEY}"
    given = scene_file_of(named)[0] if named and value is None else None
    named = named or "a scene it does not name"
    where = f"its metadata ({held})"
    return RecordedScene(digest, where, named, file, overrides, value, replayed=True, given=given)


def _value(bag: str | Path, text: str, digest: str) -> dict[str, Any]:
    """The scene's value a bag's metadata records (`SCENE_VALUE_KEY`'s JSON object), which
    must hash to its `digest`."""
    try:
        value = json.loads(text)
    except ValueError:
        value = None
    if not isinstance(value, dict) or value_digest(value) != digest:
        msg = (
            f"{bag}: {SCENE_VALUE_KEY} in its metadata is no scene's value that hashes to its "
            f"{SCENE_DIGEST_KEY} ({digest}): the metadata is damaged"
        )
        raise BagError(msg)
    return value


def _overrides(bag: str | Path, text: str) -> dict[str, Any]:
    """The overrides a bag's metadata records (`SCENE_OVERRIDES_KEY`'s JSON object)."""
    try:
        overrides = json.loads(text)
    except ValueError:
        overrides = None
    if not isinstance(overrides, dict):
        msg = f"{bag}: {SCENE_OVERRIDES_KEY} in its metadata is no JSON object: {text!r}"
        raise BagError(msg)
    return overrides


def _from_topic(bag: Path) -> tuple[str, dict[str, Any]] | None:
    """(topic, record: the JSON object) of the bag's `~/scene` messages, or None where it has
    none."""
    try:
        with AnyReader(reader_paths(bag), default_typestore=TYPESTORE) as reader:
            conns = [
                c for c in reader.connections if c.msgtype == STRING and c.topic.endswith("/scene")
            ]
            messages = []
            for c, _, raw in reader.messages(connections=conns) if conns else ():
                string: Any = reader.deserialize(raw, STRING)
                messages.append((c.topic, str(string.data)))
    except Exception as err:  # rosbags raises its own types for unreadable bags
        msg = f"{bag}: cannot read the output bag: {err}"
        raise BagError(msg) from err
    found: dict[str, tuple[str, dict[str, Any]]] = {}
    for topic, data in messages:
        record = _record(data)
        if record is None:  # another node's /scene
            continue
        if value_digest(record["value"]) != record["sha256"]:
            msg = (
                f"{bag}: {topic}: the scene's value does not hash to the sha256 it gives "
                f"({record['sha256']}): the message is damaged"
            )
            raise BagError(msg)
        found.setdefault(record["sha256"], (topic, record))
    if len(found) > 1:
        msg = (
            f"{bag}: {', '.join(sorted({t for t, _ in found.values()}))}: records "
            f"{len(found)} scenes (sha256 {', '.join(found)}): the bag holds more than one run"
        )
        raise BagError(msg)
    return next(iter(found.values()), None)


def _record(data: str) -> dict[str, Any] | None:
    """A `~/scene` message's JSON object, or None where `data` is none (another node's)."""
    try:
        record = json.loads(data)
    except ValueError:
        return None
    ours = isinstance(record, dict) and isinstance(record.get("sha256"), str)
    return record if ours and isinstance(record.get("value"), dict) else None
