"""Scene loading: the scene YAML and the Nav2-style params YAML, and every way a config can be bad.

Errors must surface at load, as SceneError naming the file (or parameter set), the key path and
the bad value.
"""

from __future__ import annotations

import copy
import dataclasses
import math
import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import yaml
from io_helpers import PARAMS_FILE, SCENE_FILE, params_yaml

from mount_twin.errors import SceneError
from mount_twin.scene import DOF_NAMES, load_scene_file, scene_from_params
from mount_twin.scene.params import (
    MOUNT_PARAMETERS,
    PARAMETERS,
    effective_parameters,
    flatten,
)

ROS_TYPE_CHECKS: dict[str, Callable[[Any], bool]] = {
    "string": lambda v: isinstance(v, str),
    "double": lambda v: isinstance(v, float),
    "integer": lambda v: isinstance(v, int) and not isinstance(v, bool),
    "bool": lambda v: isinstance(v, bool),
    "double_array": lambda v: isinstance(v, list) and all(isinstance(x, float) for x in v),
    "string_array": lambda v: isinstance(v, list) and all(isinstance(x, str) for x in v),
}


def scene_yaml() -> dict[str, Any]:
    return yaml.safe_load(SCENE_FILE.read_text(encoding="utf-8"))


def flat_params() -> dict[str, Any]:
    return dict(flatten(params_yaml()))


def declared_type(name: str) -> str | None:
    """ROS type the node declares for a flat parameter name, None if undeclared."""
    if name in PARAMETERS:
        return PARAMETERS[name][0]
    parts = name.split(".")
    if len(parts) == 3 and parts[0] == "mounts" and parts[2] in MOUNT_PARAMETERS:
        return MOUNT_PARAMETERS[parts[2]][0]
    return None


# --------------------------------------------------------------------------- equivalence


def test_scene_yaml_and_params_yaml_describe_the_same_scene() -> None:
    from_file = load_scene_file(SCENE_FILE)
    from_params = scene_from_params(flat_params(), f"{PARAMS_FILE}")
    assert from_params.source == str(PARAMS_FILE)
    assert dataclasses.replace(from_params, source=from_file.source) == from_file, (
        "config/params.yaml and config/pump_8_mounts.scene.yaml have drifted apart"
    )


def test_scene_file_parameter_loads_that_file() -> None:
    scene = scene_from_params({"scene_file": str(SCENE_FILE)}, "params")
    assert scene == load_scene_file(SCENE_FILE)


def test_parameters_given_with_a_scene_file_override_its_values() -> None:
    scene = scene_from_params(
        {"scene_file": str(SCENE_FILE), "body.mass": 1.0, "mounts.rr.stiffness": [1.0] * 6},
        "params",
    )
    from_file = load_scene_file(SCENE_FILE)
    assert scene.body.mass == 1.0
    assert scene.mounts[-1].stiffness == (1.0,) * 6
    assert scene.mounts[:-1] == from_file.mounts[:-1]
    assert scene.source == f"params over {SCENE_FILE}"


def test_a_scene_file_error_names_the_file_key_path_and_an_override_error_the_parameter(
    tmp_path: Path,
) -> None:
    bad = tmp_path / "bad.scene.yaml"
    data = scene_yaml()
    data["mounts"][1]["stiffness"] = [1.0, 2.0]
    bad.write_text(yaml.safe_dump(data), encoding="utf-8")
    with pytest.raises(SceneError, match=re.escape(f"{bad}: mounts[1].stiffness: expected 6")):
        scene_from_params({"scene_file": str(bad)}, "params")
    with pytest.raises(
        SceneError, match=re.escape(f"params over {SCENE_FILE}: mounts.fr.stiffness: expected 6")
    ):
        scene_from_params({"scene_file": str(SCENE_FILE), "mounts.fr.stiffness": [1.0]}, "params")
    with pytest.raises(SceneError, match=r"mount_names: \['a'\] differs from the mounts"):
        scene_from_params({"scene_file": str(SCENE_FILE), "mount_names": ["a"]}, "params")


@pytest.mark.parametrize(
    ("name", "given", "want"),
    [
        ("body.mass", 1300, 1300.0),
        ("mounts.fl.stiffness", [5.0e5, 5.0e5, 1200000, 500.0, 500.0, 500.0], None),
        ("input.max_gap_s", 1, 1.0),
    ],
)
def test_an_integer_given_for_a_double_parameter_is_taken_as_the_double(
    name: str, given: Any, want: Any
) -> None:
    """rcl would refuse `body.mass: 1300` for a double; the node takes what the user meant."""
    effective = effective_parameters({**flat_params(), name: given}, "params").values
    got = effective[name]
    assert type(got) is (list if isinstance(given, list) else float)
    assert got == (want if want is not None else [float(v) for v in given])
    assert all(isinstance(v, float) for v in (got if isinstance(got, list) else [got]))


def test_effective_parameters_hold_every_default_and_reload_to_the_same_scene() -> None:
    """What the node declares (and `ros2 param dump` writes) is complete: loading it again
    gives the same scene, and it holds the loader's defaults for what params.yaml leaves out."""
    flat = flat_params()
    assert "outputs.alarm_margin" not in flat
    scene, effective, _ = effective_parameters(flat, "params")
    assert effective["outputs.alarm_margin"] == scene.outputs.alarm_margin == 0.1
    assert effective["initial_state.pose"] == [0.0] * 6
    again, effective_again, _ = effective_parameters(effective, "params")
    assert again == scene
    assert effective_again == effective
    assert all(declared_type(n) for n in effective), [
        n for n in effective if declared_type(n) is None
    ]


def test_default_scene_has_the_documented_contents() -> None:
    scene = load_scene_file(SCENE_FILE)
    assert scene.source == str(SCENE_FILE)
    assert scene.name == "pump_8_mounts"
    assert scene.body.mass == pytest.approx(1200.0, abs=0.0)
    assert scene.dofs == DOF_NAMES
    assert [m.name for m in scene.mounts] == ["fl", "fr", "ml1", "mr1", "ml2", "mr2", "rl", "rr"]
    assert (scene.frames.foundation, scene.frames.body) == ("deck", "pump")
    assert (scene.input.topic, scene.input.frame_id) == ("/deck/imu", "deck_imu")


# --------------------------------------------------------------------------- declarations


def test_every_key_of_params_yaml_is_declared_by_the_node() -> None:
    undeclared = [name for name in flat_params() if declared_type(name) is None]
    assert not undeclared, (
        f"rclpy silently ignores undeclared parameters; not in PARAMETERS/MOUNT_PARAMETERS: "
        f"{undeclared}"
    )


def test_every_value_of_params_yaml_has_its_declared_ros_type() -> None:
    wrong = {
        name: (declared_type(name), value)
        for name, value in flat_params().items()
        if declared_type(name) and not ROS_TYPE_CHECKS[declared_type(name)](value)  # type: ignore[index]
    }
    assert not wrong, f"rcl would reject these values for their declared types: {wrong}"


def test_every_mount_of_mount_names_has_each_mount_parameter_in_params_yaml() -> None:
    flat = flat_params()
    missing = [
        f"mounts.{m}.{k}"
        for m in flat["mount_names"]
        for k in MOUNT_PARAMETERS
        if f"mounts.{m}.{k}" not in flat
    ]
    assert not missing, f"mounts without a full parameter set: {missing}"


# A valid value of each declared parameter that config/params.yaml leaves at its default.
EXTRA_VALUES = {
    "initial_state.pose": [0.0, 0.0, 0.0, 0.01, -0.02, 0.03],
    "initial_state.velocity": [0.0, 0.0, 0.1, 0.0, 0.0, 0.0],
    "outputs.tilt_warn_rad": 1.0,
    "outputs.alarm_margin": 0.2,
    "outputs.tf": False,
    "frames.mount_prefix": "pump/",
    "body_sensor.topic": "/pump/imu",
    "body_sensor.frame_id": "pump_imu",
    "body_sensor.position": [0.3, 0.1, 0.9],
    "body_sensor.orientation_rpy": [0.0, 0.0, 0.5],
    "body_sensor.lag_s": 0.017,
    "body_sensor.window_s": 30.0,
    "body_sensor.band_hz": [0.5, 25.0],
    "body_sensor.warn_nrms": 0.2,
    "body_sensor.error_nrms": 0.5,
    "body_sensor.axes": ["fx", "fy"],
    "ageing.window_s": 30.0,
    "ageing.fit": ["stiffness:fl+fr", "damping"],
    "ageing.warn": [0.9, 1.1],
    "ageing.error": [0.8, 1.2],
}


@pytest.mark.parametrize("name", sorted(set(PARAMETERS) - {"scene_file"}))
def test_every_declared_parameter_is_accepted_by_the_loader(name: str) -> None:
    """A parameter the node declares must not be rejected as unknown once it is set."""
    flat = flat_params()
    if name not in flat:
        assert name in EXTRA_VALUES, f"test needs a value for the new parameter {name}"
        flat[name] = EXTRA_VALUES[name]
    if name.startswith("ageing."):  # the ageing is tracked from the body IMU
        flat.setdefault("body_sensor.position", EXTRA_VALUES["body_sensor.position"])
    if name in ("initial_state.pose", "initial_state.velocity"):  # read with a given start
        flat["initial_state.mode"] = "given"
    scene = scene_from_params(flat, "params")
    section, _, field = name.partition(".")
    if name in EXTRA_VALUES:
        section_obj = scene.initial if section == "initial_state" else getattr(scene, section)
        got = getattr(section_obj, field)
        want = EXTRA_VALUES[name]
        assert list(got) == want if isinstance(want, list) else got == want, (
            f"{name} was accepted but not applied: {got!r}"
        )


# --------------------------------------------------------------------------- bad scene files


def _mutate_file(tmp_path: Path, change: Callable[[dict[str, Any]], None]) -> Path:
    data = scene_yaml()
    change(data)
    path = tmp_path / "bad.scene.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    return path


def _set(path: str, value: Any) -> Callable[[dict[str, Any]], None]:
    def change(d: dict[str, Any]) -> None:
        *parents, leaf = path.split("/")
        node: Any = d
        for p in parents:
            node = node[int(p)] if isinstance(node, list) else node[p]
        if isinstance(node, list):
            node[int(leaf)] = value
        else:
            node[leaf] = value

    return change


def _drop(path: str) -> Callable[[dict[str, Any]], None]:
    def change(d: dict[str, Any]) -> None:
        *parents, leaf = path.split("/")
        node: Any = d
        for p in parents:
            node = node[p]
        del node[leaf]

    return change


BAD_SCENES = [
    # (id, change, key path in the message, regex for the rest of the message)
    ("missing_body_mass", _drop("body/mass"), "body.mass", r"required key is missing"),
    (
        "negative_mass",
        _set("body/mass", -5.0),
        "body.mass",
        r"must be in \(0\.0, inf\), got -5\.0",
    ),
    ("zero_mass", _set("body/mass", 0.0), "body.mass", r"must be in \(0\.0, inf\), got 0\.0"),
    (
        "inertia_not_positive_definite",
        _set("body/inertia", [250.0, 450.0, 500.0, 400.0, 0.0, 0.0]),
        "body.inertia",
        r"not positive definite: \[250\.0, 450\.0, 500\.0, 400\.0, 0\.0, 0\.0\]",
    ),
    (
        "inertia_violates_triangle_inequality",
        _set("body/inertia", [1.0, 1.0, 5.0, 0.0, 0.0, 0.0]),
        "body.inertia",
        r"triangle inequality",
    ),
    (
        "mount_position_of_two_numbers",
        _set("mounts/2/position", [0.3, 0.4]),
        "mounts[2].position",
        r"expected 3 numbers, got 2: \[0\.3, 0\.4\]",
    ),
    (
        "mount_stiffness_negative",
        _set("mounts/5/stiffness", [5.0e5, 5.0e5, -1.0, 500.0, 500.0, 500.0]),
        "mounts[5].stiffness[2]",
        r"got -1\.0",
    ),
    ("typo_in_body_key", _set("body/mas", 3.0), "body.mas", r"unknown key"),
    (  # it said only that mass was missing
        "misspelt_required_key",
        lambda d: d["body"].update(mas=d["body"].pop("mass")),
        "body.mass",
        r"required key is missing \(given: 'mas', misspelt\?\)",
    ),
    ("typo_in_top_level_key", _set("intergration", {}), "intergration", r"unknown key"),
    (
        "typo_in_mount_key",
        _set("mounts/1/stifness", [1.0] * 6),
        "mounts[1].stifness",
        r"unknown key",
    ),
    ("unknown_dof", _set("dofs", ["x", "roll"]), "dofs[1]", r"unknown DOF 'roll'"),
    ("dof_listed_twice", _set("dofs", ["z", "z"]), "dofs[1]", r"DOF 'z' listed twice"),
    (
        "duplicate_mount_name",
        _set("mounts/3/name", "fl"),
        "mounts[3].name",
        r"duplicate mount name 'fl'",
    ),
    ("bad_hold_enum", _set("input/hold", "third_order"), "input.hold", r"got 'third_order'"),
    ("bad_gap_policy", _set("input/gap_policy", "ignore"), "input.gap_policy", r"got 'ignore'"),
    (
        "bad_msg_type",
        _set("input/msg_type", "sensor_msgs/msg/Imu2"),
        "input.msg_type",
        r"got 'sensor_msgs/msg/Imu2'",
    ),
    ("zero_max_gap", _set("input/max_gap_s", 0.0), "input.max_gap_s", r"got 0\.0"),
    (
        "string_for_number",
        _set("integration/rtol", "tight"),
        "integration.rtol",
        r"expected a number, got 'tight'",
    ),
    (
        "nan_number",
        _set("body/cg", [0.0, float("nan"), 0.5]),
        "body.cg[1]",
        r"must be finite, got nan",
    ),
    (
        "float_decimation",
        _set("outputs/decimation", 2.5),
        "outputs.decimation",
        r"expected an integer, got 2\.5",
    ),
    (
        "initial_pose_off_the_chart",
        _set("initial_state", {"mode": "given", "pose": [0.0, 0.0, 0.0, 1.0, 0.8, 0.0]}),
        "initial_state.pose",
        r"α = 1\.0, γ = 0\.8 rad tilt the body past 1\.55 rad",
    ),
    (
        "initial_pose_at_the_chart_edge",  # |α| + |γ| < π/2 holds, but cos θ = 1e-10
        _set(
            "initial_state",
            {"mode": "given", "pose": [0.0, 0.0, 0.0, 0.0, math.pi / 2 - 1e-10, 0.0]},
        ),
        "initial_state.pose",
        r"chart degenerates",
    ),
    ("mounts_not_a_list", _set("mounts", {"fl": {}}), "mounts", r"non-empty list"),
    (  # 20° meant: it made the wrong-sensor_rpy check (3 × 20 rad) never fire
        "tilt_tolerance_in_degrees",
        _set("initial_state", {"tilt_tolerance_rad": 20.0}),
        "initial_state.tilt_tolerance_rad",
        r"must be in \(0\.0, 1\.5707963267948966\], got 20\.0",
    ),
    (  # 10 % meant
        "gravity_tolerance_in_percent",
        _set("initial_state", {"gravity_tolerance": 10.0}),
        "initial_state.gravity_tolerance",
        r"must be in \(0\.0, 1\.0\], got 10\.0",
    ),
    (  # an equilibrium start is at rest: the velocity was ignored without a word
        "velocity_at_an_equilibrium_start",
        _set("initial_state", {"velocity": [0.0, 0.0, 0.1, 0.0, 0.0, 0.0]}),
        "initial_state.velocity",
        r"\[0\.0, 0\.0, 0\.1, 0\.0, 0\.0, 0\.0\]: read only with mode: given",
    ),
    (  # the free DOFs start at the equilibrium: their pose entries were ignored
        "free_pose_at_an_equilibrium_start",
        _set("initial_state", {"pose": [0.0, 0.0, 0.01, 0.0, 0.0, 0.0]}),
        "initial_state.pose",
        r"z = 0\.01 of a free DOF: read only with mode: given .*frozen DOFs",
    ),
    (
        "body_frame_is_the_foundation_frame",
        _set("frames/body", "deck"),
        "frames.body",
        r"'deck' is also frames\.foundation",
    ),
    (  # its /tf_static deck → pump beside the body's moving deck → pump on /tf
        "mount_frame_is_the_body_frame",
        _set("mounts/0/name", "pump"),
        "mounts[0].name",
        r"its frame 'pump' \(frames\.mount_prefix \+ name\) is also frames\.body",
    ),
    (
        "body_sensor_on_the_input_topic",
        _set("body_sensor", {"topic": "/deck/imu", "position": [0.0, 0.0, 0.5]}),
        "body_sensor.topic",
        r"'/deck/imu' is also input\.topic",
    ),
]


@pytest.mark.parametrize(
    ("change", "key", "rest"), [c[1:] for c in BAD_SCENES], ids=[c[0] for c in BAD_SCENES]
)
def test_bad_scene_file_fails_at_load_naming_file_key_and_value(
    tmp_path: Path, change: Callable[[dict[str, Any]], None], key: str, rest: str
) -> None:
    path = _mutate_file(tmp_path, change)
    with pytest.raises(SceneError, match=re.escape(f"{path}: {key}: ") + ".*" + rest) as info:
        load_scene_file(path)
    assert (info.value.source, info.value.path) == (str(path), key)


def test_unreadable_yaml_fails_naming_the_file(tmp_path: Path) -> None:
    path = tmp_path / "broken.scene.yaml"
    path.write_text("name: x\nbody: {mass: 1.0, cg: [0.0, 0.0\n", encoding="utf-8")
    with pytest.raises(SceneError) as info:
        load_scene_file(path)
    # one line, positions in the file counted from 1: the '[' is the 23rd character of line 2
    assert str(info.value) == (
        f"{path}: not valid YAML: line 3, column 1: expected ',' or ']', but got "
        "'<stream end>' (while parsing a flow sequence from line 2, column 23)"
    )


def test_non_existent_scene_file_fails_naming_the_file(tmp_path: Path) -> None:
    path = tmp_path / "nope.scene.yaml"
    with pytest.raises(SceneError, match=re.escape(f"{path}: cannot read: ") + "No such file"):
        load_scene_file(path)


def test_directory_instead_of_scene_file_fails_naming_it(tmp_path: Path) -> None:
    with pytest.raises(SceneError, match=re.escape(f"{tmp_path}: cannot read")):
        load_scene_file(tmp_path)


@pytest.mark.parametrize(
    "text", ["", "- a\n- b\n", "just a string\n"], ids=["empty", "list", "scalar"]
)
def test_yaml_that_is_not_a_mapping_fails_at_the_top(tmp_path: Path, text: str) -> None:
    path = tmp_path / "odd.scene.yaml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(SceneError, match=re.escape(f"{path}: expected a mapping at the top")):
        load_scene_file(path)


# --------------------------------------------------------------------------- bad parameter sets


BAD_PARAMS = [
    (
        "mount_named_without_namespace",
        {"mount_names": ["fl", "fr", "ml1", "mr1", "ml2", "mr2", "rl", "rr", "aux"]},
        "mounts.aux",
        r"mount listed in mount_names has no namespace",
    ),
    (
        "namespace_not_listed",
        {"mount_names": ["fl", "fr", "ml1", "mr1", "ml2", "mr2", "rl"]},
        "mounts.rr",
        r"namespace not listed in mount_names",
    ),
    (
        "typo_in_mount_parameter",
        {"mounts.fl.positon": [0.0, 0.0, 0.0]},
        "mounts.fl.positon",
        r"unknown key",
    ),
    ("typo_in_parameter", {"input.hld": "zero_order"}, "input.hld", r"unknown key"),
    ("bad_enum", {"input.hold": "zero"}, "input.hold", r"got 'zero'"),
    (
        "double_for_integer",
        {"outputs.decimation": 2.0},
        "outputs.decimation",
        r"expected an integer, got 2\.0",
    ),
    (
        "mount_names_a_string",
        {"mount_names": "fl"},
        "mount_names",
        r"expected a list of strings, got 'fl'",
    ),
    (  # these three were a TypeError's traceback out of the node
        "mount_names_an_integer",
        {"mount_names": 5},
        "mount_names",
        r"expected a list of strings, got 5",
    ),
    ("scene_file_an_integer", {"scene_file": 5}, "scene_file", r"expected a string, got 5"),
    (
        "mount_listed_twice",  # it was "mounts.fr: namespace not listed in mount_names"
        {"mount_names": ["fl", "fl", "ml1", "mr1", "ml2", "mr2", "rl", "rr"]},
        "mount_names",
        r"'fl' listed twice",
    ),
]


@pytest.mark.parametrize(
    ("change", "key", "rest"), [c[1:] for c in BAD_PARAMS], ids=[c[0] for c in BAD_PARAMS]
)
def test_bad_parameter_set_fails_naming_parameter_and_value(
    change: dict[str, Any], key: str, rest: str
) -> None:
    flat = {**flat_params(), **change}
    with pytest.raises(SceneError, match=re.escape(f"params.yaml: {key}: ") + ".*" + rest):
        scene_from_params(flat, "params.yaml")


def test_a_mount_namespace_that_is_a_value_fails_naming_it() -> None:
    """`mounts: {fl: 5}` in a params file (a TypeError's traceback out of the node)."""
    flat = {k: v for k, v in flat_params().items() if not k.startswith("mounts.fl.")}
    flat["mounts.fl"] = 5
    with pytest.raises(SceneError, match=re.escape("P: mounts.fl: expected its parameters")):
        scene_from_params(flat, "P")


def test_a_parameter_set_that_is_no_mapping_fails_naming_it() -> None:
    """An AttributeError's traceback: 'list' object has no attribute 'get'."""
    with pytest.raises(SceneError, match=re.escape("P: expected a mapping of parameter")):
        scene_from_params([1], "P")  # type: ignore[arg-type]


def test_missing_mount_names_parameter_fails() -> None:
    flat = flat_params()
    del flat["mount_names"]
    with pytest.raises(
        SceneError, match=re.escape("P: mount_names: required parameter is missing")
    ):
        scene_from_params(flat, "P")


def test_params_accept_floats_that_a_scene_file_may_write_as_integers() -> None:
    """An integer for a float is fine in a scene file too."""
    data = scene_yaml()
    data["body"]["mass"] = 1200
    from mount_twin.scene import scene_from_dict

    assert scene_from_dict(data, "f.yaml").body.mass == 1200.0


def test_initial_pose_just_inside_the_chart_loads() -> None:
    data = scene_yaml()
    data["initial_state"] = {"mode": "given", "pose": [0.0, 0.0, 0.0, 0.7, 0.8, 0.0]}
    from mount_twin.scene import scene_from_dict

    scene = scene_from_dict(copy.deepcopy(data), "f.yaml")
    assert abs(scene.initial.pose[3]) + abs(scene.initial.pose[4]) < math.pi / 2


def test_names_as_one_string_are_the_list_and_are_what_the_node_declares() -> None:
    """`dofs` (and an elastomer's axes) as one space-separated string is the list; it is the
    form declared, since `ros2 param dump` writes a list's y bare and rcl reads it as true."""
    flat = flat_params()
    as_list = {**flat, "dofs": ["x", "y", "z", "alpha", "gamma", "delta"]}
    as_string = {**flat, "dofs": "x y  z alpha gamma delta"}
    assert scene_from_params(as_list, "p") == scene_from_params(as_string, "p")
    effective = effective_parameters(as_list, "p").values
    assert effective["dofs"] == "x y z alpha gamma delta"
    with pytest.raises(SceneError, match=re.escape("dofs[1]: unknown DOF 'yaw'")):
        scene_from_params({**flat, "dofs": "z yaw"}, "p")
