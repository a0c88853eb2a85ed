"""The scene a run used, from its scene file with the `input` fields the command line replaced
(`replay --topic`, `--frame-id`), and back: the file and those fields from the scene's source,
as a replay records it in its output bag (a report reloads the run's scene from it)."""

from __future__ import annotations

import os
import re
from collections.abc import Mapping
from pathlib import Path

from mount_twin.scene.checks import rated_at_start
from mount_twin.scene.description import Scene, SceneOrigin
from mount_twin.scene.loader import scene_from_dict
from mount_twin.scene.yaml_reading import read_scene_yaml

INPUT_OPTIONS = {"input.topic": "replay --topic", "input.frame_id": "replay --frame-id"}
"""The scene's input settings that --topic and --frame-id replace, and the option as a message
or the report names it where it did."""


OVERRIDDEN = " (with input {} from the command line)"
"""What `read_scene` appends to a scene's source where the command line replaced `input`
fields (their names, comma-separated); `scene_file_of` reads it back from the one text
(`io.bag_metadata.SCENE_KEY`) a replay recorded before it recorded the file and the overrides apart
(`Scene.origin`)."""


def scene_file_of(source: str) -> tuple[str, list[str]]:
    """The scene file and the `input` fields the command line replaced of a scene's source as
    `read_scene` gives it (recorded by a replay in its output bag's metadata, alone in bags
    written before `io.bag_metadata.SCENE_FILE_KEY`)."""
    before, _, after = OVERRIDDEN.partition("{}")
    found = re.fullmatch(f"(.*){re.escape(before)}([\\w, ]+){re.escape(after)}", source)
    return (found[1], found[2].split(", ")) if found else (source, [])


def read_scene(path: str | Path, input_overrides: Mapping[str, str] | None = None) -> Scene:
    """The scene file at `path`, with `input` fields replaced by `input_overrides` (checked like
    the file's own); its `origin` the file's absolute path and those fields (`input.topic`). A
    scene whose ratings or force limits are judged at the start the twin uses
    (`scene.checks.rated_at_start`) is assembled for them: its start is solved here, and again
    where the caller assembles it."""
    data = read_scene_yaml(path)
    source = str(path)
    if input_overrides and isinstance(data, dict) and isinstance(data.get("input", {}), dict):
        data["input"] = {**data.get("input", {}), **input_overrides}
        source += OVERRIDDEN.format(", ".join(sorted(input_overrides)))
    overrides = {f"input.{k}": v for k, v in sorted((input_overrides or {}).items())}
    origin = SceneOrigin(os.path.abspath(path), overrides)
    scene = scene_from_dict(data, source, refuse_unheld=True, origin=origin)
    if rated_at_start(scene):
        from mount_twin.model.assemble import assemble

        scene = assemble(scene).scene
    return scene
