"""`value_differences` / `scene_differences`: which values two scenes differ in, by key path
(what `report --scene` names when its scene's digest is not the run's)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import yaml

from mount_twin.scene.description import Scene, scene_differences, value_differences
from mount_twin.scene.loader import scene_from_dict

PUMP = Path(__file__).resolve().parents[1] / "config" / "pump_8_mounts.scene.yaml"


def test_equal_values_differ_nowhere() -> None:
    value = {"a": 1.0, "b": {"c": [1, 2], "d": None}}
    assert value_differences(value, {"b": {"d": None, "c": (1, 2)}, "a": 1.0}) == []


def test_each_differing_leaf_is_named_by_its_path_in_the_first_values_order() -> None:
    here = {"z": 1, "m": [{"k": 2.0}, {"k": 3.0}], "s": {"t": "x"}}
    there = {"s": {"t": "y"}, "m": [{"k": 2.0}, {"k": 4.0}], "z": 1, "extra": 5}
    assert value_differences(here, there) == [
        ("m[1].k", 3.0, 4.0),
        ("s.t", "x", "y"),
        ("extra", None, 5),
    ]


def test_sequences_of_another_length_or_values_of_another_shape_differ_as_a_whole() -> None:
    assert value_differences({"v": [1, 2]}, {"v": [1, 2, 3]}) == [("v", [1, 2], [1, 2, 3])]
    assert value_differences({"v": {"a": 1}}, {"v": None}) == [("v", {"a": 1}, None)]


def _changed(mass: float) -> Scene:
    """The pump's scene, mount ml1's z stiffness and the mass replaced."""
    data = yaml.safe_load(PUMP.read_text(encoding="utf-8"))
    data["mounts"][2]["stiffness"][2] = 1.3e6  # the file's 1.2e6 for every mount
    data["body"]["mass"] = mass  # the file's 1200
    return scene_from_dict(data, "changed")


def test_two_scenes_differ_in_the_values_changed_a_mount_named_as_the_scene_names_it() -> None:
    """The pump's scene, mount ml1's (mounts[2]) z stiffness and the mass changed by hand."""
    run = scene_from_dict(yaml.safe_load(PUMP.read_text(encoding="utf-8")), str(PUMP))
    here = _changed(1500.0)
    assert scene_differences(here, run) == [
        ("body.mass", 1500.0, 1200.0),
        ("mounts[2].stiffness[2]", 1.3e6, 1.2e6),
    ]
    # a parameter set's mounts are named mounts.<name>
    named = dataclasses.replace(here, mount_paths=tuple(f"mounts.{m.name}" for m in here.mounts))
    assert scene_differences(named, run)[1][0] == "mounts.ml1.stiffness[2]"
    # the file a scene came from is not part of its value
    assert scene_differences(dataclasses.replace(run, source="elsewhere"), run) == []
