"""Scene description: plain frozen dataclasses, and their loaders with key-path errors."""

from mount_twin.scene.description import DOF_NAMES, LinearMount, Mount, Scene, SceneWarning
from mount_twin.scene.loader import load_scene_file, scene_from_dict
from mount_twin.scene.params import scene_from_params

__all__ = [
    "DOF_NAMES",
    "LinearMount",
    "Mount",
    "Scene",
    "SceneWarning",
    "load_scene_file",
    "scene_from_dict",
    "scene_from_params",
]
