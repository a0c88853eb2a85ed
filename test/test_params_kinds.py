"""Nav2-style parameters (what the rclpy node declares and reads) for every mount kind load the
same scene as the equivalent scene YAML, through the one loader."""

from __future__ import annotations

import copy
from typing import Any

import pytest
import yaml
from io_helpers import SCENE_FILE

from mount_twin.scene import scene_from_dict, scene_from_params
from mount_twin.scene.params import as_params, effective_parameters, flatten, mount_parameters

MOUNTS: list[dict[str, Any]] = [
    {
        "name": "rubber",
        "kind": "elastomer",
        "position": [0.5, 0.4, 0.0],
        "stiffness_linear": [2.0e5, 2.0e5, 0.0],
        "stiffness_cubic": [1.0e9, 1.0e9, 0.0],
        "damping": [300.0, 300.0, 500.0],
        "rated_deflection": [0.01, 0.01, 0.008],
        "force_table": {
            "z": {"deflection": [-0.01, 0.0, 0.005, 0.01], "force": [-8.0e3, 0.0, 3.0e3, 9.0e3]}
        },
        "hysteresis": {"ratio": 0.2, "beta": 250.0, "gamma": 250.0, "axes": ["z"]},
        "snubber": {"gap": 0.006, "stiffness": 5.0e7, "axes": ["x", "y"]},
    },
    {
        "name": "bolt",
        "kind": "bolted_joint",
        "position": [-0.5, 0.4, 0.0],
        "bolt_stiffness": 7.0e8,
        "clamp_stiffness": 3.5e9,
        "preload": 1.0e5,
        "yield_force": 1.57e5,
        "ultimate_force": 1.96e5,
        "friction": 0.12,
    },
    {
        "name": "key",
        "kind": "shear_key",
        "position": [0.0, -0.4, 0.0],
        "stiffness": [1.0e9, 0.0, 0.0],
        "clearance": 2.0e-4,
    },
]


def _tree() -> dict[str, Any]:
    tree = yaml.safe_load(SCENE_FILE.read_text())
    tree["mounts"] = [*tree["mounts"][:2], *copy.deepcopy(MOUNTS)]
    return tree


def test_params_of_every_kind_load_the_same_scene_as_the_yaml() -> None:
    tree = _tree()
    assert scene_from_params(as_params(tree), "params") == scene_from_dict(
        copy.deepcopy(tree), "params"
    )


def test_effective_parameters_of_every_kind_reload_to_the_same_scene() -> None:
    """What the node declares for each kind (defaults included) is a complete parameter set."""
    scene, effective, _ = effective_parameters(as_params(_tree()), "params")
    assert effective["mounts.bolt.hardening"] == 0.02  # a kind's default, declared
    assert effective_parameters(effective, "params").scene == scene


@pytest.mark.parametrize("mount", MOUNTS, ids=[m["kind"] for m in MOUNTS])
def test_every_key_of_a_kind_is_a_declared_parameter_of_the_right_type(
    mount: dict[str, Any],
) -> None:
    """rclpy ignores undeclared parameters: each key a kind reads must be declared, typed."""
    declared = mount_parameters(mount["kind"])
    for key, value in flatten({k: v for k, v in mount.items() if k != "name"}):
        assert key in declared, f"{mount['kind']}: {key} not declared"
        ptype = declared[key][0]
        if isinstance(value, list):
            # a list of names (axes) is declared as one space-separated string (Reader.names)
            want = "string" if isinstance(value[0], str) else "double_array"
        else:
            want = {str: "string", float: "double", bool: "bool", int: "integer"}[type(value)]
        assert ptype == want, f"{mount['kind']}.{key}: declared {ptype}, value {value!r}"
