"""Mistaken and hostile scene files, as users reported them: each refused at load naming the
file, line or key path, or loaded with a SceneWarning naming the key path. (The fuzz over
mutated scenes is test_fuzz_scene.py.)"""

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
from io_helpers import CONFIG, PARAMS_FILE, G
from physics_helpers import base_scene, mount

from mount_twin.errors import SceneError
from mount_twin.model.assemble import assemble
from mount_twin.scene import (
    Scene,
    SceneWarning,
    load_scene_file,
    scene_from_dict,
    scene_from_params,
)
from mount_twin.scene.params import as_params
from mount_twin.scene.ros_names import topic_name_problem
from mount_twin.scene.yaml_reading import load_yaml, read_scene_yaml

PUMP = CONFIG / "pump_8_mounts.scene.yaml"
CORNERS = [(0.5, 0.4), (-0.5, 0.4), (-0.5, -0.4), (0.5, -0.4)]


def _file(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "s.scene.yaml"
    path.write_text(text, encoding="utf-8")
    return path


def _pump_text() -> str:
    return PUMP.read_text(encoding="utf-8")


def _pump() -> dict[str, Any]:
    return yaml.safe_load(_pump_text())


def _warnings(scene: Scene) -> dict[str, str]:
    """Key path → message of each warning of `scene`."""
    return {w.path: w.message for w in scene.warnings}


# ------------------------------------------------------------------ 1. duplicate keys
def test_a_key_given_twice_is_an_error_naming_the_lines(tmp_path: Path) -> None:
    pump = _pump_text()
    text = pump + "mounts:\n  - {name: x, position: [0, 0, 0], stiffness: [1, 1, 1, 0, 0, 0]}\n"
    second = pump.count("\n") + 1  # the appended line
    first = pump.splitlines().index("mounts:") + 1
    with pytest.raises(
        SceneError,
        match=rf"s\.scene\.yaml: line {second}: key 'mounts' given twice in one "
        rf"mapping \(first on line {first}\)",
    ):
        load_scene_file(_file(tmp_path, text))


@pytest.mark.parametrize(
    ("value", "says"),
    [("010", "octal: 8"), ("-0010", "octal: -8"), ("1:30", "base 60: 90")],
)
def test_an_integer_yaml_1_1_reads_otherwise_is_an_error(
    tmp_path: Path, value: str, says: str
) -> None:
    """`decimation: 010` loaded as 8, `max_substeps: 010000` as 4096, without a word."""
    text = _pump_text().replace("  decimation: 1\n", f"  decimation: {value}\n")
    line = text.splitlines().index(f"  decimation: {value}") + 1
    with pytest.raises(
        SceneError, match=rf"line {line}: {value} is read by YAML 1\.1 as {says}; write"
    ):
        load_scene_file(_file(tmp_path, text))


def test_a_key_given_twice_inside_a_mount_is_an_error_too(tmp_path: Path) -> None:
    text = _pump_text().replace(
        "    kind: linear\n    position: [0.9, 0.4, 0.0]\n",
        "    kind: linear\n    position: [0.9, 0.4, 0.0]\n    position: [0.9, -0.4, 0.0]\n",
    )
    with pytest.raises(SceneError, match=r"line 18: key 'position' given twice"):
        load_scene_file(_file(tmp_path, text))


def test_the_scene_file_a_params_file_names_is_read_by_the_same_rules(tmp_path: Path) -> None:
    """The package reads no params YAML itself (rcl does); the scene_file it names goes
    through the scene loader."""
    path = _file(tmp_path, _pump_text() + "name: again\n")
    with pytest.raises(SceneError, match=r"s\.scene\.yaml: line \d+: key 'name' given"):
        scene_from_params({"scene_file": str(path)}, "params")


def test_an_unhashable_key_is_a_yaml_error_not_a_type_error(tmp_path: Path) -> None:
    with pytest.raises(SceneError, match=r"(?s)not valid YAML: .*found unhashable key"):
        read_scene_yaml(_file(tmp_path, "? [a, b]\n: 1\n"))


# ------------------------------------------------------------------ 2. 3e5 is a number
@pytest.mark.parametrize(
    ("text", "value"),
    [
        ("3e5", 3e5),
        ("1e-3", 1e-3),
        ("-2E+4", -2e4),
        ("+4e2", 400.0),
        ("1.5e3", 1500.0),
        (".5e3", 500.0),
        ("-.5E-3", -5e-4),
        ("5.0e+5", 5e5),
        ("1_000e3", 1e6),
        ("e5", "e5"),
        ("1e5x", "1e5x"),
        ("1e", "1e"),
    ],
)
def test_exponents_without_a_dot_or_sign_are_numbers(text: str, value: float | str) -> None:
    assert load_yaml(f"k: {text}\n") == {"k": value}


def test_a_scene_with_exponents_without_a_dot_loads(tmp_path: Path) -> None:
    text = _pump_text().replace(
        "stiffness: [5.0e+5, 5.0e+5, 1.2e+6,", "stiffness: [5e5, 5e5, 12E5,"
    )
    scene = load_scene_file(_file(tmp_path, text))
    assert scene.mounts[0].stiffness[:3] == (5e5, 5e5, 1.2e6)  # type: ignore[union-attr]


# ------------------------------------------------------------------ 3. free DOFs
def _vertical_only(dofs: list[str] | None = None, **initial: Any) -> dict[str, Any]:
    """Mounts stiff along z only (no shear, no rotational stiffness): nothing holds x, y, δ."""
    mounts = [
        mount(f"m{i}", (x, y, 0.0), (0.0, 0.0, 1e6, 0.0, 0.0, 0.0))
        for i, (x, y) in enumerate(CORNERS)
    ]
    return base_scene(
        500.0, [0.0, 0.0, 0.3], [50.0, 60.0, 70.0, 0, 0, 0], mounts, dofs, initial=initial or None
    )


def test_a_free_dof_no_mount_holds_is_refused_at_load_naming_it(tmp_path: Path) -> None:
    """The body would drift under any lateral input (0.51 m in 2 s, as reported)."""
    says = r"mounts: no mount holds x, y, delta: .* leave x, y, delta out of `dofs`"
    path = _file(tmp_path, yaml.safe_dump(_vertical_only()))
    with pytest.raises(SceneError, match=rf"s\.scene\.yaml: {says}"):
        load_scene_file(path)
    with pytest.raises(SceneError, match=rf"params: {says}"):
        scene_from_params(as_params(_vertical_only()), "params")


def test_a_reduced_scene_only_needs_its_free_dofs_held() -> None:
    data = _vertical_only(["z", "alpha", "gamma"])
    assert scene_from_dict(data, "reduced", refuse_unheld=True).warnings == ()


def test_an_unheld_dof_is_a_warning_from_a_given_start_or_for_a_scene_built_in_code() -> None:
    """Torque-free and free-flight studies start a body nothing holds on purpose; tests of one
    mount's law build scenes that are never run (the model refuses them at the start)."""
    given = _vertical_only(mode="given", pose=[0.0] * 6, velocity=[0.0] * 6)
    for data, refuse in ((given, True), (_vertical_only(), False)):
        warned = _warnings(scene_from_dict(data, "z only", refuse_unheld=refuse))
        assert warned["mounts"].startswith("no mount holds x, y, delta: the body moves freely")


def test_a_pendulum_is_held_by_its_weight() -> None:
    """One point spring above the CG (k_x, k_z only): the mounts leave the swing about it
    free, the weight hanging from it holds it (physics notes §7, geometric stiffness)."""
    hook = [mount("hook", (0.0, 0.0, 0.5), (2e5, 0, 3e5, 0, 0, 0))]
    data = base_scene(20.0, [0.0, 0.0, 0.0], [0.5, 0.8, 0.6, 0, 0, 0], hook, ["x", "z", "gamma"])
    assert scene_from_dict(data, "pendulum", refuse_unheld=True).warnings == ()
    data["input"]["g"] = 0.0  # weightless: nothing holds the swing
    with pytest.raises(SceneError, match=r"no mount holds x \(86%\), gamma \(14%\)"):
        scene_from_dict(data, "pendulum", refuse_unheld=True)


def test_a_body_the_weight_overturns_is_warned_of() -> None:
    """A CG 1 m above four soft mounts 0.2 m apart: m·g·h beyond the rocking stiffness."""
    mounts = [
        mount(f"m{i}", (x / 5, y / 5, 0.0), (2e5, 2e5, 1e5, 0.0, 0.0, 0.0))
        for i, (x, y) in enumerate(CORNERS)
    ]
    data = base_scene(500.0, [0.0, 0.0, 1.0], [60.0, 80.0, 90.0, 0, 0, 0], mounts)
    assert (
        "the weight overturns the body in" in _warnings(scene_from_dict(data, "tall"))["body.cg"]
    )


def test_the_bundled_scenes_load_without_warnings() -> None:
    for path in sorted(CONFIG.glob("*.scene.yaml")):
        assert load_scene_file(path).warnings == (), path


# ------------------------------------------------------------------ 4. ROS names
@pytest.mark.parametrize("topic", ["/deck/imu", "imu/data", "~/imu", "/_hidden/imu", "/a1/b_2"])
def test_ros_topic_names_are_accepted(topic: str) -> None:
    assert topic_name_problem(topic) == ""


@pytest.mark.parametrize(
    ("topic", "problem"),
    [
        ("", "it is empty"),
        ("/deck imu", "only ASCII letters"),
        ("/deck/ümlaut", "only ASCII letters"),
        ("2deck", "a token starts with a digit"),
        ("/deck/2imu", "a token starts with a digit"),
        ("/deck/", "it ends with '/'"),
        ("/", "it ends with '/'"),
        ("~foo", "'~' only as the '~/'"),
        ("/a~b", "'~' only as the '~/'"),
        ("/a//b", "empty token"),
        ("{node}/imu", "{substitutions} are not accepted"),
        ("/" + "a" * 247, "longer than 247 characters"),
    ],
)
def test_a_topic_rclpy_would_refuse_is_refused_at_load(topic: str, problem: str) -> None:
    data = _pump()
    data["input"]["topic"] = topic
    with pytest.raises(SceneError, match=rf"pump: input\.topic: .* {re.escape(problem)}"):
        scene_from_dict(data, "pump")


@pytest.mark.parametrize("name", ["x²", "_m", "2m", "m" * 101])
def test_a_mount_name_that_is_no_ros_name_token_is_refused(name: str) -> None:
    data = _pump()
    data["mounts"][0]["name"] = name
    with pytest.raises(SceneError, match=r"pump: mounts\[0\]\.name: must be a ROS name token"):
        scene_from_dict(data, "pump")


@pytest.mark.parametrize(
    ("section", "key", "frame", "says"),
    [
        ("frames", "body", "", "is not a tf2 frame id"),
        ("frames", "body", "pump frame", "is not a tf2 frame id"),
        ("frames", "body", "/pump", "is not a tf2 frame id"),
        ("input", "frame_id", "deck imu", "is not a frame id \\(it has whitespace\\)"),
    ],
)
def test_a_bad_frame_id_is_refused(section: str, key: str, frame: str, says: str) -> None:
    data = _pump()
    data[section][key] = frame
    with pytest.raises(SceneError, match=rf"pump: {section}\.{key}: .* {says}"):
        scene_from_dict(data, "pump")


def test_the_input_frame_id_may_be_a_ros1_one_with_a_leading_slash() -> None:
    """A ROS 1 bag's header says '/imu': the scene can name it (it was refused as no tf2 id)."""
    data = _pump()
    data["input"]["frame_id"] = "/imu"
    assert scene_from_dict(data, "pump").input.frame_id == "/imu"


# ------------------------------------------------------------------ 5. absurd numbers, sizes
def _deep(depth: int) -> list[Any]:
    value: list[Any] = []
    for _ in range(depth):
        value = [value]
    return value


@pytest.mark.parametrize(
    ("change", "key", "says"),
    [
        (lambda d: d["body"].update(cg=[1e300, 0, 0.5]), "body.cg[0]", r"beyond 1e\+15"),
        (lambda d: d["body"].update(mass=10**400), "body.mass", r"beyond 1e\+15"),
        (lambda d: d["body"].update(cg=_deep(5000)), "body.cg", r"expected 3 numbers"),
        (
            lambda d: d["outputs"].update(decimation=2**63),
            "outputs.decimation",
            r"must be in \[1, 1000000000\]",
        ),
        (
            lambda d: (
                d["mounts"][0].update(position=[900.0, 400.0, 0.0])
                or d["mounts"][1].update(position=[900.0, -4000.0, 0.0])
            ),
            "mounts[1].position",
            "millimetres",
        ),
        (
            lambda d: d["mounts"][2].update(stiffness=[5e5, 5e5, 1.2e14, 500.0, 500.0, 500.0]),
            "mounts[2].stiffness[2]",
            r"nominal stiffness 1\.2e\+14 is beyond 1e\+13 N/m",
        ),
        (
            lambda d: d["mounts"][0].update(orientation_rpy=[-30.0, 0.0, 0.0]),
            "mounts[0].orientation_rpy",
            "radians, not degrees",
        ),
        (
            lambda d: d["input"].update(sensor_rpy=[0.0, 90.0, 0.0]),
            "input.sensor_rpy",
            "radians, not degrees",
        ),
        (lambda d: d.update(mounts=d["mounts"] * 130), "mounts", "at most 1000"),
    ],
)
def test_implausible_values_are_refused_with_their_key_path(
    change: Callable[[dict[str, Any]], None], key: str, says: str
) -> None:
    data = _pump()
    change(data)
    with pytest.raises(SceneError, match=says) as err:
        scene_from_dict(data, "pump")
    assert f"pump: {key}: " in str(err.value)


def test_a_bolted_joint_beyond_the_stiffness_limit_names_its_keys() -> None:
    data = yaml.safe_load((CONFIG / "genset_bolted_keyed.scene.yaml").read_text())
    data["mounts"][0]["clamp_stiffness"] = 3.5e13  # in N/mm: 3.5e9 N/m is 3.5e6 N/mm
    with pytest.raises(
        SceneError, match=re.escape("mounts[0].bolt_stiffness + clamp_stiffness: nominal")
    ):
        scene_from_dict(data, "genset")


@pytest.mark.parametrize("index, kind", [(0, "bolted_joint"), (6, "shear_key")])
def test_a_mount_whose_kind_line_was_lost_is_told_its_kind(index: int, kind: str) -> None:
    """It was read as linear, and the message named linear's missing `stiffness`."""
    data = yaml.safe_load((CONFIG / "genset_bolted_keyed.scene.yaml").read_text())
    assert data["mounts"][index].pop("kind") == kind
    with pytest.raises(SceneError, match=f"read as a {kind}: give kind: {kind}") as err:
        scene_from_dict(data, "genset")
    assert f"genset: mounts[{index}].kind: missing, so the mount was read as linear" in str(
        err.value
    )


def test_a_linear_mount_without_kind_still_names_its_own_missing_key() -> None:
    data = _pump()
    del data["mounts"][2]["stiffness"]
    with pytest.raises(SceneError, match=r"pump: mounts\[2\]\.stiffness: required key is"):
        scene_from_dict(data, "pump")


def test_an_elastomer_given_stiffness_for_stiffness_linear_is_told_the_unknown_key() -> None:
    """It failed the check across keys instead: "each axis needs k1 > 0 or a force_table"."""
    data = _pump()
    data["mounts"][0] = {
        "name": "fl",
        "kind": "elastomer",
        "position": [0.5, 0.4, 0.0],
        "stiffness": [2e5, 2e5, 5e5],
    }
    with pytest.raises(SceneError, match=r"pump: mounts\[0\]\.stiffness: unknown key"):
        scene_from_dict(data, "pump")


def _replaced(scene: Scene, path: str, value: Any) -> Scene:
    """`scene` with the attribute at `path` ("body.mass", "mounts[2].stiffness") replaced."""
    head, _, rest = path.partition(".")
    name, _, index = head.partition("[")
    if index:
        items = list(getattr(scene, name))
        items[int(index[:-1])] = _replaced(items[int(index[:-1])], rest, value)
        return dataclasses.replace(scene, **{name: tuple(items)})
    if rest:
        return dataclasses.replace(scene, **{name: _replaced(getattr(scene, name), rest, value)})
    return dataclasses.replace(scene, **{name: value})


@pytest.mark.parametrize(
    ("path", "value", "says"),
    [  # each assembled before: a negative mass ran and failed at every sample; the rest ran
        ("body.mass", -1200.0, "body.mass: must be > 0 kg, got -1200.0"),
        ("body.inertia", (100.0, 100.0, 100.0, 150.0, 0.0, 0.0), "body.inertia: not positive"),
        ("mounts[2].orientation_rpy", (0.0, 30.0, 0.0), "mounts[2].orientation_rpy: [0.0, 30.0"),
        ("input.sensor_rpy", (0.0, 0.0, 90.0), "input.sensor_rpy: [0.0, 0.0, 90.0]: beyond a"),
        ("mounts[1].stiffness", (1e5, 1e5, -1e5, 0.0, 0.0, 0.0), "mounts[1].stiffness[2]: must"),
        ("body.cg", (0.0, 0.0, float("nan")), "body.cg[2]: must be finite, got nan"),
        ("mounts[0].kind", "elastomer", "mounts[0].kind: 'elastomer' is not the kind of a Linear"),
        ("dofs", ("x", "roll"), "dofs: expected distinct names of x, y, z, alpha"),
    ],
)
def test_a_scene_built_in_code_is_checked_at_assembly(path: str, value: Any, says: str) -> None:
    pump = load_scene_file(PUMP)
    with pytest.raises(SceneError) as err:
        assemble(_replaced(pump, path, value))
    assert str(err.value).startswith(f"{PUMP}: {says}")


@pytest.mark.parametrize(
    ("path", "value"),
    [("clamp_stiffness", -3.5e9), ("axial_damping", -5e4), ("preload", float("inf"))],
)
def test_a_kinds_values_built_in_code_are_checked_too(path: str, value: float) -> None:
    """A bolt's coefficients are named otherwise than a linear mount's (`clamp_stiffness`):
    a negative one, given as a float or an int, must not reach the core either."""
    genset = load_scene_file(CONFIG / "genset_bolted_keyed.scene.yaml")
    for given in (value, int(value) if math.isfinite(value) else value):
        with pytest.raises(SceneError, match=re.escape(f"mounts[0].{path}: must be")):
            assemble(_replaced(genset, f"mounts[0].{path}", given))


def _laughs(levels: int) -> str:
    lines = ['l0: &l0 ["lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol"]']
    for i in range(1, levels):
        lines.append(f"l{i}: &l{i} [{', '.join([f'*l{i - 1}'] * 9)}]")
    return "\n".join(lines) + "\n"


def _many_mounts(n: int) -> str:
    head, tail = _pump_text().split("mounts:\n")[0], _pump_text().split("input:")[1]
    row = "  - {name: m%d, position: [0.1, 0.2, 0.0], stiffness: [1e5, 1e5, 1e5, 0, 0, 0]}\n"
    return head + "mounts:\n" + "".join(row % i for i in range(n)) + "input:" + tail


@pytest.mark.parametrize(
    ("text", "says"),
    [
        (_laughs(9), r"line 2: aliases \(\*l0\) are not accepted"),
        ("k: " + "[" * 500 + "]" * 500 + "\n", "line 1: nested deeper than 50"),
        ("mass: 1" + "0" * 400 + "\n", "line 1: an integer of 401 characters"),
        (_many_mounts(20_000), r"\d+ characters: a scene file has at most 1000000"),
    ],
    ids=["billion_laughs", "deep_nesting", "huge_integer", "20000_mounts"],
)
def test_hostile_yaml_is_refused_at_once(tmp_path: Path, text: str, says: str) -> None:
    """Refused where it starts (the alias, the 51st level, the 401st digit, the size), which
    the message names: before anything is expanded or built."""
    with pytest.raises(SceneError, match=rf"s\.scene\.yaml: {says}"):
        read_scene_yaml(_file(tmp_path, text))


def test_a_file_that_is_not_utf8_is_refused_naming_the_byte(tmp_path: Path) -> None:
    path = tmp_path / "s.scene.yaml"
    path.write_bytes(b"name: \xff\xfe\n")
    with pytest.raises(SceneError, match=r"not UTF-8 text: byte 6 is b'\\xff'"):
        read_scene_yaml(path)


# ------------------------------------------------------------------ 6. unit guard rails
def test_stiffness_in_n_per_mm_warns_of_the_sag_and_the_rated_travel() -> None:
    """N/mm read as N/m: 2.6 m of sag with every status OK, as reported (here 1.3 m)."""
    data = _pump()
    for m in data["mounts"]:
        m["stiffness"] = [v / 1000.0 for v in m["stiffness"][:3]] + m["stiffness"][3:]
    warned = _warnings(scene_from_dict(data, "pump"))
    assert re.search(r"the CG sags 1\.33 m .* stiffness in N/mm, or mass in g\?", warned["mounts"])
    travel = next(k for k in warned if k.endswith(".rated_travel"))
    assert re.search(r"112 times the rated 0\.012 m \(and 7 more mounts\)", warned[travel])


def test_a_static_load_beyond_the_rated_load_is_warned_of() -> None:
    data = _pump()
    data["mounts"][2]["rated_load"] = [6000.0, 6000.0, 900.0]
    warned = _warnings(scene_from_dict(data, "pump"))
    assert list(warned) == ["mounts[2].rated_load"]
    assert re.search(
        r"static load .* along local z, is 1\.\d+ times the rated 900 N",
        warned["mounts[2].rated_load"],
    )


def test_positions_in_millimetres_are_warned_of() -> None:
    """A mount 500 mm from the CG written as 500: 500 m, inside the 1000 m reach."""
    data = _pump()
    data["mounts"][0]["position"] = [900.0, 400.0, 0.0]
    warned = _warnings(scene_from_dict(data, "pump"))
    assert re.search(
        r"^984\.8 m from the CG, .* positions in millimetres\?$", warned["mounts[0].position"]
    )


@pytest.mark.parametrize(
    ("section", "key", "says"),
    [
        ("input", "sensor_position", "the twin takes the deck as rigid between them"),
        ("body_sensor", "position", "outside the body"),
    ],
)
def test_sensor_positions_in_millimetres_are_warned_of(section: str, key: str, says: str) -> None:
    """A deck IMU 500 mm above F's origin written as 500 gave 3.4× the mount forces, and a body
    IMU's position the same way, without a word."""
    data = _pump()
    data.setdefault(section, {"topic": "/pump/imu"})[key] = [0.05, 0.0, 500.5]  # CG + 500 m
    warned = _warnings(scene_from_dict(data, "pump"))
    assert re.search(rf"^500 m from the CG, .*{says}.* millimetres\?$", warned[f"{section}.{key}"])


def test_a_cg_in_millimetres_is_named_beside_the_restraint_it_breaks() -> None:
    """cg: [0.05, 0.0, 500.0] said only "mounts: no mount holds y, x"."""
    data = _pump()
    data["body"]["cg"] = [0.05, 0.0, 500.0]
    with pytest.raises(
        SceneError,
        match=r"pump: mounts: no mount holds .*; likely why: mounts\[\d\]\.position: "
        r"\d+\.?\d* m from the CG.* millimetres\?",
    ):
        scene_from_dict(data, "pump", refuse_unheld=True)


def test_a_warning_names_the_parameter_of_a_params_scene() -> None:
    flat = as_params(_pump())
    flat["mounts.fl.position"] = [900.0, 400.0, 0.0]
    assert "mounts.fl.position" in _warnings(scene_from_params(flat, "params"))


def test_inertia_in_kg_mm2_is_warned_of() -> None:
    data = _pump()
    data["body"]["inertia"] = [v * 1e6 for v in data["body"]["inertia"]]
    warned = _warnings(scene_from_dict(data, "pump"))
    assert "radius of gyration √(I/m) is 645 m" in warned["body.inertia"]


@pytest.mark.parametrize("dofs", [None, ["x", "y", "z"]])
def test_a_body_too_compact_to_turn_is_refused_for_it_not_as_unheld(dofs: list | None) -> None:
    """Inertia 1e-9 kg·m² on 1200 kg: √(I/m) ≈ 9.1e-7 m. It was refused as 'no mount holds
    z, x, y'; with no rotation free it does not matter and loads."""
    data = _pump()
    data["body"]["inertia"] = [1e-9, 1e-9, 1e-9, 0.0, 0.0, 0.0]
    if dofs is not None:
        data["dofs"] = dofs
        scene_from_dict(data, "pump", refuse_unheld=True)
        return
    says = r"pump: body\.inertia: the body's smallest radius of gyration √\(I/m\) is 9\.13e-07 m"
    with pytest.raises(SceneError, match=says):
        scene_from_dict(data, "pump", refuse_unheld=True)


def test_an_imu_input_without_gravity_is_warned_of() -> None:
    data = _pump()
    data["input"]["includes_gravity"] = False
    warned = _warnings(scene_from_dict(data, "pump"))
    assert "linear_acceleration is specific force" in warned["input.includes_gravity"]
    data["input"]["msg_type"] = "geometry_msgs/msg/AccelStamped"
    assert scene_from_dict(data, "pump").warnings == ()


def test_warnings_print_like_errors_and_are_not_part_of_the_scene_value() -> None:
    scene = load_scene_file(PUMP)
    warning = SceneWarning(str(PUMP), "input.includes_gravity", "false for an Imu")
    assert str(warning) == f"{PUMP}: input.includes_gravity: false for an Imu"
    assert dataclasses.replace(scene, warnings=(warning,)) == scene
    assert copy.deepcopy(scene).warnings == ()


def test_the_weight_is_the_scene_s_own() -> None:
    """The sag is under m·input.g: a scene for the Moon sags a sixth (1.33 m on Earth)."""
    data = _pump()
    for m in data["mounts"]:
        m["stiffness"] = [v / 1000.0 for v in m["stiffness"][:3]] + m["stiffness"][3:]
    data["input"]["g"] = G / 6.0
    assert "the CG sags 0.221 m" in _warnings(scene_from_dict(data, "moon"))["mounts"]


def test_a_ros_parameters_file_given_as_a_scene_is_named_as_one(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """`mount-twin replay … --scene config/params.yaml` said `body: required key is missing`
    of a file whose `/**: ros__parameters:` holds a body: it is the node's parameters file,
    and the command says so, pointing at a scene file (exit 2, as any bad scene)."""
    from mount_twin.cli import main

    with pytest.raises(SceneError, match=r"params\.yaml: a ROS 2 parameters file \(/\*\*"):
        load_scene_file(PARAMS_FILE)
    assert main(["info", str(PARAMS_FILE)]) == 2
    err = capsys.readouterr().err
    assert "(--ros-args --params-file), not a scene file" in err
    assert "required key" not in err
