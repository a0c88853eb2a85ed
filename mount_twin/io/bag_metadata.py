"""A bag's metadata.yaml read (its rosbag2_bagfile_information, its custom_data), and the
custom_data keys a run records there: a bag stopped early (`PARTIAL_KEY`), a replay's scene
(`SCENE_KEY` and the others, `io.scene_record`)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

from mount_twin.errors import BagError

PARTIAL_KEY = "mount_twin.partial"
"""custom_data key in an output bag's metadata.yaml present when the bag stops early."""
SCENE_KEY = "mount_twin.scene"
"""custom_data key in a replay's output bag's metadata.yaml: where its scene came from, as
text (the file as given, and the input settings the command line replaced: `Scene.source`;
and the values changed in code since: `io.scene_record.scene_name`)."""
SCENE_FILE_KEY = "mount_twin.scene_file"
"""custom_data key in a replay's output bag's metadata.yaml: its scene file's absolute path
(`Scene.origin`; '' for none)."""
SCENE_OVERRIDES_KEY = "mount_twin.scene_overrides"
"""custom_data key in a replay's output bag's metadata.yaml: what was put over its scene
file's values, a JSON object of flat parameter name (the command line's) or key path (a value
changed in code) → value (`io.scene_record.scene_overrides`)."""
SCENE_DIGEST_KEY = "mount_twin.scene_sha256"
"""custom_data key in a replay's output bag's metadata.yaml: its scene's digest
(`scene.description.scene_digest`), which `report --scene` checks its scene against."""
SCENE_VALUE_KEY = "mount_twin.scene_value"
"""custom_data key in a replay's output bag's metadata.yaml: its scene's value, the text its
digest hashes (`scene.description.value_text`), from which `report --scene` names the values a
scene differs in where the bag's ~/scene topic was left out."""


def custom_data(path: str | Path) -> dict[str, str]:
    """The custom_data of a bag's metadata.yaml ({} if it has none, or no metadata.yaml: a
    storage file given alone, or a bag a write failure left unfinished)."""
    custom = bag_metadata(path).get("custom_data") or {}
    if not isinstance(custom, dict):
        msg = f"{Path(path) / 'metadata.yaml'}: cannot read the bag's metadata: custom_data is "
        msg += f"not a mapping: {custom!r}"
        raise BagError(msg)
    return {str(k): str(v) for k, v in custom.items()}


def bag_metadata(path: str | Path) -> dict[str, Any]:
    """The rosbag2_bagfile_information of a bag's metadata.yaml ({} if it has no
    metadata.yaml: a storage file given alone, or a bag a write failure left unfinished);
    BagError naming the file if it cannot be read."""
    meta = Path(path) / "metadata.yaml"
    if not meta.is_file():
        return {}
    try:
        info = yaml.safe_load(meta.read_text(encoding="utf-8"))["rosbag2_bagfile_information"]
        if not isinstance(info, dict):
            raise TypeError(f"rosbag2_bagfile_information is not a mapping: {info!r}")
        return info
    except (
        OSError,
        UnicodeDecodeError,
        yaml.YAMLError,
        TypeError,
        KeyError,
        AttributeError,
    ) as err:
        msg = f"{meta}: cannot read the bag's metadata: {err}"
        raise BagError(msg) from err


def partial_marker(path: str | Path) -> str:
    """Why an output bag stops early, from its metadata.yaml (`PARTIAL_KEY`): '' if it does
    not, or has no metadata.yaml to say so (a storage file given alone)."""
    return custom_data(path).get(PARTIAL_KEY, "")
